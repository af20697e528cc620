// Oriented-particle plant dynamics after Hädrich et al. 2017 (climbing-plants-particles.txt,
// section 4.1 and the appendix), usable from C++ without the language: particles, shape matching
// with ellipsoid moments, goals, age-dependent stiffness, roots, anchors, growth, obstacles,
// collisions, breaking and wind. The sources go by concept: world.cpp (particles, edits and the
// step's phases in order), shape_matching.cpp (groups, moments, goals, the passes), frames.cpp
// (group rotations), collisions.cpp (obstacles and contacts), growth.cpp (growth and branching),
// grab.cpp (a hand pulling a stem), shadow.cpp (the obstacles' shade, declared in light.hpp).
//
// Particles are stored one array per field (PositionBasedDynamics' habit); a particle is named by
// a {index, generation} handle (Box2D's), and a parent's index is always below its children's.
#pragma once

#include "plant/big_pages.hpp"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <vector>

namespace plant::physics {

// The per-particle arrays and the solver's scratch live in 2 MiB pages (plant/big_pages.hpp): a
// step over 25,000 particles touches about 20 MB, which faulted in 4 KiB at a time took the
// first step 108 ms on a VM where a fault costs 10 us (docs/physics.md, "Memory").
template <typename T> using Array = PagedVector<T>;

struct Handle {
    std::uint32_t index = ~0u;
    std::uint32_t generation = 0;
    bool valid() const { return index != ~0u; }
};

// Growth and branching (section 4.2, 4.3; Table 2's parameters).
struct Growth {
    double segment_length = 0.1; // a new particle every this much of growth
    double speed = 0.05;         // apical growth, m/s
    std::size_t max_particles = 25000;
    double branch_probability = 0; // BP: chance that a new particle carries a lateral bud
    double branch_variance = 0.5;  // V in [0, 1]: a lateral turns up to V * 90 degrees away
    int max_lateral = 1;           // B: lateral buds per particle
    double falloff = 0.8;          // thickness of a lateral relative to its parent
    glm::dvec3 to_light{0, 1, 0};
    double phototropism = 0;     // eta (Eq. 7)
    double adaption = 0;         // tau (Eq. 6)
    double adaption_range = 0.3; // obstacles nearer than this steer the apex
    double opacity = 0.15;       // Eq. 7's O = 1 - exp(-opacity * particles between the apex and the light)
    double light_cell = 0.1;     // the cells those particles are counted in
    bool obstacle_shade = true;  // an obstacle between the apex and the light: O = 1 (shadow.cpp)
    double diffuse = 0;          // the share of the light from the open sky (scene_occlusion)
    std::uint64_t seed = 1;
};

struct Settings {
    glm::dvec3 gravity{0.0, -9.81, 0.0};
    double dt = 0.025;           // the paper's step, 25 ms
    double density = 700.0;      // kg/m^3, for masses (Eq. 2)
    double damping = 0.02;       // fraction of velocity removed per step
    double stiffening_time = 10; // t_m: a particle reaches full stiffness at this age (s = t_l / t_m)
    double fixed_stiffness = -1; // >= 0: every particle has this stiffness instead (tests, tools)
    Growth growth;
    int iterations = 2; // shape-matching passes per step
    // The root-to-tip sweep after the passes (docs/physics.md, "Length and bending"): each step a
    // particle moves bending * s of the way to where its parent's turn from rest carries its rest
    // offset, then to its rest distance from the parent. 0: the passes alone hold the shape.
    double bending = 0.7;
    int threads = 1; // threads for the shape-matching passes (results do not depend on it)
    // Rotation-extraction iterations per group and pass. Each pass warm-starts from the last
    // one's rotation, so the iterations add up over a step's passes, as Müller et al. 2016
    // suggest for simulations; a cold solve (goals(), group_rotation()) runs up to 20.
    int rotation_iterations = 1;
    // Plant-plant and self collision between particles not joined to each other (section 5.2).
    bool collisions = true;
    // Links of different plants collided as capsules (link_contacts.cpp; needs `collisions`).
    // Off by default; a climber grammar switches it on with `plant_contacts: 1`
    // (docs/plant-contacts.md).
    bool link_collisions = false;
    // No step gives a particle mechanical energy that gravity, the wind and the air did not give
    // it (energy.cpp; docs/physics.md, "The energy budget"). Off: the solver as it was before.
    bool energy_budget = true;
};

// Growth directions (Hädrich et al., section 4.2). Each returns the apex's forward vector turned
// by the response, as an axis and an angle would (Eq. 6, 7) applied to it.
// Surface adaption, Eq. 6: toward being parallel to a nearby surface; `to_surface` points to the
// closest surface point, tau in [0, 1].
glm::dvec3 surface_adaption(const glm::dvec3& forward, const glm::dvec3& to_surface, double tau, double dt);
// Phototropism, Eq. 7: toward the light by (1 - O) eta dt, O the occlusion in [0, 1]. The axis is
// forward x to_light, so the apex turns toward the light (the printed v_l x v_f turns it away:
// docs/physics.md notes it).
glm::dvec3 phototropism(const glm::dvec3& forward, const glm::dvec3& to_light, double occlusion, double eta,
                        double dt);

// Obstacles for particles: signed distance fields.
// A signed distance sampled on a regular grid (a triangle mesh's, say): trilinear inside the
// grid; outside it, the distance to the grid's box plus the value at the nearest grid point.
struct DistanceGrid {
    glm::dvec3 lo{0.0};
    double cell = 1;
    glm::ivec3 n{0};
    std::vector<double> d; // x fastest
    double sample(const glm::dvec3& p) const;
};

struct Obstacle {
    enum Kind { Sphere, Box, Plane, Grid } kind = Plane;
    glm::dvec3 a{0.0}, b{0.0, 1.0, 0.0}; // sphere: center, (radius in b.x); box: min, max; plane: point,
                                         // normal; grid: a is its offset from where it was sampled
    std::shared_ptr<const DistanceGrid> grid{}; // Grid: the sampled distance (shared, never changed)
    double friction = 0.5;                      // fraction of the tangential velocity removed on contact
    double elasticity = 0.0;                    // fraction of the normal velocity kept, reversed, on contact
    double distance(const glm::dvec3& p) const;
    glm::dvec3 normal(const glm::dvec3& p) const; // gradient of the distance
};

// The least-squares rotation of a moment matrix A, by Müller et al. 2016 ("A robust method to
// extract the rotational part of deformations"): iterations on a quaternion, warm-started with
// `q`. Always a proper rotation; zero, rank-deficient and reflected input leave q as it is or
// turn it the best it can.
glm::dquat extract_rotation(const glm::dmat3& A, glm::dquat q, int iterations = 20);

class World {
  public:
    explicit World(Settings s = {}) : settings_(s) {}

    // A root: fixed where it is, with effectively infinite mass in its groups (or, with
    // fixed = false, the free first particle of a loose branch).
    Handle add_root(const glm::dvec3& position, const glm::dquat& orientation, const glm::dvec3& radii,
                    bool fixed = true);
    // A particle attached to `parent`, at `position` in the rest state (now).
    Handle add_particle(Handle parent, const glm::dvec3& position, const glm::dquat& orientation,
                        const glm::dvec3& radii);

    // One step of Δt: predict (Eq. 1), pull anchored particles in (Eq. 5), match shapes (Eq. 3,
    // 4, 14, 15), move toward the goals by the stiffness, keep particles out of obstacles,
    // integrate (Eq. 17-20), damp, break overstretched connections.
    void step();

    // A particle placed next to a parent that may have moved or bent since it was made: its rest
    // state is taken relative to the parent's rest state as its current state is to the parent's
    // current state, so growth becomes part of the shape the plant returns to (Eq. 9-10).
    Handle add_grown(Handle parent, const glm::dvec3& position, const glm::dquat& orientation,
                     const glm::dvec3& radii);
    // Removes h and everything attached below it (cutting a branch).
    void remove(Handle h);
    // Whether h still hangs from a fixed root (false once its branch broke off or was cut).
    bool attached(Handle h) const;
    // attached() of every slot at once, in one pass (a parent's index is below its children's):
    // 1 where the particle is alive and hangs from a fixed root
    void attached_all(std::vector<std::uint8_t>& out) const;
    // External acceleration a_e of Eq. 1 on every free particle (a steady wind).
    void set_wind(const glm::dvec3& a) { wind_ = a; }
    const std::vector<Obstacle>& obstacles() const { return obstacles_; }
    // Adds to a particle's external acceleration (Eq. 1's a_e) for the next step only: the
    // fluid's push on a branch.
    void add_external(Handle h, const glm::dvec3& a) {
        if (external_.size() < x_.size()) external_.resize(x_.size(), glm::dvec3(0.0));
        external_[h.index] += a;
    }
    // The handle of the particle in slot i (alive or not).
    Handle handle(std::uint32_t i) const { return {i, generation_[i]}; }
    // Full grown: at full stiffness (with a fixed stiffness, always). Only these meet the fluid.
    bool full_grown(Handle h) const { return stiffness(h.index) >= 1.0 || settings_.fixed_stiffness >= 0; }
    glm::dvec3 radii(Handle h) const { return radii_[h.index]; }
    // Secondary growth: a particle's radii change as its stem thickens, and its mass with them
    // (Eq. 2); its groups are rebuilt before the next step (growth.cpp).
    void set_radii(Handle h, const glm::dvec3& radii);

    // Apical growth: every apex (a particle without children) lengthens; each segment_length a
    // new particle continues it, turned by surface adaption and phototropism weighted by the
    // plant's own shade (Eq. 6-8), and with probability BP a lateral bud starts beside it, turned
    // by up to V * 90 degrees. New particles enter the rest state as add_grown places them
    // (Eq. 9-10). Random draws depend on the seed and the particles' indices only.
    void grow();
    // The unit forward vector of a particle (its orientation's +y).
    glm::dvec3 forward(Handle h) const { return q_[h.index] * glm::dvec3(0, 1, 0); }
    std::size_t laterals(Handle h) const { return laterals_[h.index]; }

    // Eq. 5: each step the particle's predicted position moves a fraction phi of the way to the
    // anchor; past `release` from it, the anchor lets go.
    // The anchor belongs to the obstacle whose surface is nearest the point (within 5 cm): it is
    // kept in that obstacle's frame, so it moves with the obstacle (Fig. 9); otherwise it is a
    // fixed point.
    void add_anchor(Handle h, const glm::dvec3& point, double phi, double release);
    bool anchored(Handle h) const;
    // Where h's first anchor holds it now (its obstacle's moves and the plant-plant contacts'
    // pushes included, remade where h lies when they had lifted it off while h is back on a
    // support: part_plants); NaN when h has none.
    glm::dvec3 anchor_of(Handle h) const;
    // Whether h is anchored to obstacle k.
    bool anchored_to(Handle h, std::size_t k) const;
    void add_obstacle(const Obstacle& o) {
        obstacles_.push_back(o);
        unit_.push_back(o.kind == Obstacle::Plane ? glm::normalize(o.b) : glm::dvec3(0.0));
    }
    // `to` moved as little as it takes for the segment from `from`, a capsule of radius r, to lie
    // outside every obstacle, at the segment's length from `from` (a new segment's end, before it
    // is drawn: segment_contacts.cpp). Where `from` itself is too near an obstacle, as far as it can.
    glm::dvec3 clear_segment_end(const glm::dvec3& from, const glm::dvec3& to, double r) const;
    // Unlinks h from its parent: h and what hangs from it become a loose part, which falls (a cut
    // that keeps the part; remove() takes it away).
    void cut_loose(Handle h) {
        if (alive(h)) detach(h.index);
    }
    // The anchors of particles whose `attached` entry (attached_all) is 0 let go: a loose part
    // falls, its pieces "fall down due to gravity" (Hädrich et al., section 6.1).
    void release_loose(const std::vector<std::uint8_t>& attached);
    // Removes obstacle k (later ones move down one); its anchors let go, so what it held falls.
    void remove_obstacle(std::size_t k);
    // Moves obstacle k by `delta` (section 5.2: the user moves objects and the plants adapt).
    void move_obstacle(std::size_t k, const glm::dvec3& delta) {
        if (k >= obstacles_.size()) return;
        Obstacle& o = obstacles_[k];
        o.a += delta;
        if (o.kind == Obstacle::Box) o.b += delta;
    }
    // Connections whose length differs from the rest length by more than this fraction break
    // (0: never); the child's part becomes a loose branch.
    void set_break_threshold(double t) { break_threshold_ = t; }
    // Number of connected parts (a broken-off branch is one more).
    std::size_t components() const;
    std::uint32_t parent(Handle h) const { return parent_[h.index]; }
    bool has_children(Handle h) const { return alive(h) && !children_[h.index].empty(); }

    bool alive(Handle h) const;
    glm::dvec3 position(Handle h) const { return x_[h.index]; }
    glm::dvec3 rest_position(Handle h) const { return rest_x_[h.index]; }
    glm::dquat orientation(Handle h) const { return q_[h.index]; }
    glm::dvec3 velocity(Handle h) const { return v_[h.index]; }
    double mass(Handle h) const { return m_[h.index]; }
    std::size_t size() const { return x_.size(); }
    Settings& settings() { return settings_; }
    const Settings& settings() const { return settings_; }

    // Moves a particle (tests); its rest state stays.
    void set_position(Handle h, const glm::dvec3& p) { x_[h.index] = p; }
    // The candidate pairs of links of different plants (by the particles' indices, in index
    // order) that the plant-plant contacts would find at the present positions (tests: the broad
    // phase of link_contacts.cpp against every pair).
    std::vector<std::pair<std::uint32_t, std::uint32_t>> link_candidates();
    // Holds a particle at `target` through the next step, as a user dragging it would.
    void pull(Handle h, const glm::dvec3& target) { pulls_.push_back({h.index, target}); }
    // A hand grabbing particle h and pulling it toward `target`, by at most `reach` this step
    // (grab.cpp; Fig. 7 c): the stem between it and its root follows within its length (an
    // ancestor moves while its link is taut, and a hand beyond the stem's length from its root
    // gets as far as the stem reaches), clear of the obstacles; the particles moved are held
    // there through the next step, and an anchor lets go once its particle is past the anchor's
    // release distance. Call it before each step the hand holds on.
    void grab(Handle h, const glm::dvec3& target, double reach);
    void set_orientation(Handle h, const glm::dquat& q) { q_[h.index] = q; }

    // The goal positions the shape matching gives for the current positions (Eq. 4), without
    // stepping: what a rigid motion must leave unchanged.
    std::vector<glm::dvec3> goals() const;
    // The rotation of particle i's own group (parent, itself, children).
    glm::dquat group_rotation(std::uint32_t i) const;

    // Where the last step's time went (milliseconds): shape matching and integration, and the
    // collisions with obstacles and between particles.
    struct StepTimes {
        double dynamics = 0, collision = 0;
    };
    const StepTimes& last_step_times() const { return times_; }
    // The fastest particle's speed at the end of any step since clear_peak_speed() (m/s): a
    // growing shoot should not move at metres a second (docs/whipping.md).
    double peak_speed() const { return peak_speed_; }
    // The most, at the end of any step since clear_peak_speed(), that a particle moved faster than
    // a fall from the highest point it has been at (at a step's start or end) gives: |v| - sqrt(2 (phi_max -
    // phi)), phi = -g.x (m/s; 0 when every particle is within it). Only gravity gives a passive
    // plant speed, so more is motion the solver made up (docs/physics.md, "The energy budget").
    double unexplained_speed() const { return unexplained_speed_; }
    void clear_peak_speed() { peak_speed_ = 0, unexplained_speed_ = 0; }

    // A hash of the whole state, for determinism tests.
    std::uint64_t state_hash() const;

  private:
    // The shape-matching group of particle i: its parent, itself, its children.
    template <class F> void for_group(std::uint32_t i, F&& f) const {
        if (parent_[i] != kNone) f(parent_[i]);
        f(i);
        for (std::uint32_t c : children_[i]) f(c);
    }
    static constexpr std::uint32_t kNone = ~0u; // no parent
    // The particle's own rotation from rest: a warm start for its group's rotation.
    glm::dquat rotation_from_rest(std::uint32_t i) const {
        return glm::normalize(q_[i] * glm::inverse(rest_q_[i]));
    }
    // A group's mass center now and its rotation (Eq. 14-15), also as a matrix for the goals.
    struct Frame {
        glm::dvec3 c{0.0};
        glm::dquat R{1, 0, 0, 0};
        glm::dmat3 M{1.0};
        bool valid = false;
    };
    // A particle's mass inside group sums: a fixed root's is effectively infinite.
    double matching_mass(std::uint32_t j) const;
    glm::dmat3 rest_moment(std::uint32_t j) const; // Eq. 15's fixed part, 0.2 m D R̄ᵀ
    glm::dmat3 ellipsoid_moment(std::uint32_t j) const;
    // Unlinks i from its parent: it becomes the root of a loose part.
    void detach(std::uint32_t i);
    // What shape matching reads of the groups that does not change within a step, flattened:
    // each group's members (parent, itself, children) with their masses and rest offsets from
    // the group's rest center, and each particle's goal sources (the groups it belongs to, with
    // Eq. 4's weights and its rest offset in each). Built when growth, a cut or a break changes
    // them instead of walked through the child lists in every pass; the fixed factors (masses
    // over the group's, Eq. 4's weights over their sum) are applied here once.
    struct Groups {
        struct Member {
            std::uint32_t particle;
            double share;  // m_j / M_i, for the mass center
            glm::dvec3 mr; // m_j (x̄_j - c̄_i), for Eq. 14's sum
        };
        struct Source {
            std::uint32_t group;
            double weight;     // Eq. 4's weight over the sum of j's weights
            glm::dvec3 offset; // x̄_j - c̄_i
        };
        Array<std::uint32_t> start; // group i: member[start[i] .. start[i + 1])
        Array<Member> member;
        Array<std::uint32_t> source_start; // particle j: source[source_start[j] .. source_start[j + 1])
        Array<Source> source;
        Array<glm::dvec3> rest_center; // per group: c̄, while building
    };
    void build_groups(Groups& g) const;
    // Eq. 15's ellipsoid moments of every particle (`each`) and their sums over each group.
    void group_moments(const Groups& groups, Array<glm::dmat3>& each, Array<glm::dmat3>& sums) const;
    // Group i's frame, given the sum of its members' ellipsoid moments, with at most
    // `iterations` rotation-extraction iterations warm-started from `warm`; with `warm_matrix`,
    // out.M is warm's rotation matrix already.
    void group_frame(std::uint32_t i, glm::dquat warm, const glm::dmat3& moment, int iterations,
                     const Groups& groups, Frame& out, bool warm_matrix = false) const;
    // group_frame for two groups with the same number of members, each warm-started from its
    // frame with one iteration: the same results, computed two lanes at a time.
    void frame_pair(const std::uint32_t (&group)[2], const Array<glm::dmat3>& moments, const Groups& groups,
                    Array<Frame>& frames) const;
    // One shape-matching pass: every group's frame (Eq. 14-15, warm-started from `frames`),
    // with at most `iterations` rotation-extraction iterations per group; `moments` holds each
    // group's moment sum (group_moments).
    void match_shapes(Array<Frame>& frames, const Array<glm::dmat3>& moments, int iterations,
                      const Groups& groups) const;
    // Particle j's goal from the groups' frames (Eq. 3-4).
    glm::dvec3 goal_of(std::uint32_t j, const Array<Frame>& frames, const Groups& groups) const;
    // x'_g = x_p + s (x_g - x_p) toward the goal of the last frames, for one particle or for two
    // with as many goal sources at once (lane by lane, the same results)
    void move_one(std::uint32_t i);
    void move_pair(std::uint32_t i, std::uint32_t j);
    double stiffness(std::uint32_t i) const;

    // The phases of step(), in order (world.cpp, shape_matching.cpp, collisions.cpp).
    void predict();             // Eq. 1: predicted positions; the old ones go to scratch_.old
    void pull_to_anchors();     // Eq. 5, letting go of anchors too far away
    void refresh_groups();      // rebuilds the groups and rest moments when they are stale
    void match_shapes_passes(); // the shape-matching passes: positions toward their goals, then orientations
    // root to tip: bending toward the rest shape (with `bend`), then each rest length; with
    // `orient`, the orientations follow their segments too
    void keep_shape(bool orient, bool bend = true);
    // after the last sweep (orient.cpp): each particle in scratch_.oriented turned so that its
    // rest direction lies along its link (scratch_.dir), keeping its twist about it
    void orient_along_links();
    // after the last shape-matching pass (orient.cpp): each free particle's orientation blended
    // toward its group's rotation of its rest orientation, by its stiffness over the passes
    void blend_orientations();
    void blend_one(std::uint32_t i);
    void blend_pair(std::uint32_t i, std::uint32_t j);
    void orient_one(std::uint32_t i);
    void orient_pair(std::uint32_t i, std::uint32_t j);
    void build_links();       // the sweep's rest links, with the groups
    void build_sweep_order(); // (with the links) the sweep's order, two chains at a time
    // pushes x out of every obstacle it is in, r off the surface (across the face its parent
    // lies on, when given and against the same obstacle); whether any pushed
    bool outside_obstacles(glm::dvec3& x, double r, const glm::dvec3* parent = nullptr) const;
    // v (an offset in p's rest frame) turned as p's frame has turned from rest: by the shortest
    // turn of the segment from p's parent to p, or by p's own rotation when p has no parent;
    // with `back`, the other way (a current offset to p's rest frame)
    glm::dvec3 carried(std::uint32_t p, const glm::dvec3& v, bool back = false) const;
    // segment_contacts.cpp: x pushed out of obstacle k, r off its surface, by the shortest way that
    // does not end inside another obstacle (a box's nearest clear face) when there is one; with
    // `normal`, the direction it went
    glm::dvec3 exit_point(const glm::dvec3& x, double r, std::size_t k, glm::dvec3* normal = nullptr) const;
    // every link (particle and parent) as a capsule of the particle's thinnest radius out of the
    // obstacles, both ends moved by their barycentric weights and inverse masses; `fresh` at a
    // step's first call (the links found clear by the calls before it in the step are not
    // tested again while their ends stay where they were)
    void resolve_segments(bool fresh);
    void weigh_particles(); // scratch_.inverse_mass, for this step's contact passes of links
    void segment_sweeps(const Array<std::uint32_t>& links); // (resolve_segments) its sweeps
    // the contacts of the link into i with the obstacles, ends weighted wp and wi; whether any
    bool link_contacts(std::uint32_t i, double wp, double wi);
    void separate_particles(); // contacts between particles (section 5.2)
    // the contact grid of separate_particles: scratch_.table from each cell's key to its run of
    // particles in scratch_.members, and each particle's cell in scratch_.cell_of, for cells of
    // `cell` and the particles no thicker than `limit`; returns the table's size (a power of 2)
    std::size_t fill_contact_grid(double cell, double limit);
    // link_contacts.cpp: each particle's plant (its root), kept with the groups; the pairs of
    // links of different plants whose capsules' bounds overlap (scratch_.link_pairs); and those
    // pairs' capsules pushed apart, the four ends by their barycentric weights and inverse masses
    void build_plants();
    void find_link_pairs();
    void grid_link_pairs(double cell); // (find_link_pairs)
    // with find false, the pairs found by the last call are pushed again (a later round of a
    // step); returns the deepest overlap its first sweep pushed (0: none). Its first sweep visits
    // every pair, the later ones those the first found near; they stop once none of those
    // overlaps by kLinksParted, and the step's rounds once a first sweep finds none that does.
    double separate_links(bool find);
    static constexpr double kLinksParted = 1e-4;
    // the rounds of separate_links and the obstacles that part the plants in a step; the anchors
    // of the particles they moved move with them, and a particle back on a support holds on to it
    void part_plants();
    void integrate(); // Eq. 17-18 with damping, and contacts with obstacles
    // energy.cpp: each particle's mechanical energy before the step and the forcing on it (open,
    // before predict); after integrate, a particle that ends the step with more than that energy
    // plus the forcing's work, damped, has its velocity scaled down to it (close)
    void open_energy_budget();
    void close_energy_budget();
    void break_overstretched(); // connections stretched past the break threshold let go

    Settings settings_;
    Array<glm::dvec3> x_, v_, rest_x_, radii_;
    Array<glm::dquat> q_, rest_q_;
    Array<double> m_, age_, length_;
    Array<std::uint32_t> laterals_;
    Array<std::uint32_t> parent_, generation_;
    Array<Array<std::uint32_t>> children_;
    Array<std::uint8_t> fixed_, alive_;
    struct Anchor {
        std::uint32_t particle;
        // where it was made or last remade, moved by the plant-plant rounds since (part_plants)
        glm::dvec3 point;
        double phi, release;
        std::size_t obstacle = ~std::size_t{0}; // none: a fixed point in the world
        glm::dvec3 origin{0.0};                 // the obstacle's `a` when `point` was set
    };
    // where the anchor is now: `point` moved as far as its obstacle has moved since it was set
    glm::dvec3 anchor_point(const Anchor& a) const {
        return a.obstacle < obstacles_.size() ? a.point + (obstacles_[a.obstacle].a - a.origin) : a.point;
    }
    const Anchor* anchor_for(Handle h) const; // h's first anchor, or nullptr
    std::vector<Anchor> anchors_;
    double peak_speed_ = 0, unexplained_speed_ = 0;
    Array<double> highest_; // each particle's highest potential per unit mass at a step's ends
    std::vector<Obstacle> obstacles_;
    // each plane's unit normal, normalized once when it is added (the distance of every particle to
    // a plane normalized it at every call: about 2 % of a step); zero for other kinds
    std::vector<glm::dvec3> unit_;
    // obstacle k's signed distance at p, as signed_distance (obstacle_field.hpp) computes it
    double distance_to(std::size_t k, const glm::dvec3& p) const;
    std::vector<std::pair<std::uint32_t, glm::dvec3>> pulls_;
    double break_threshold_ = 0;
    glm::dvec3 wind_{0.0};
    StepTimes times_;
    Array<glm::dvec3> external_; // per particle, cleared after each step
    // A cell of the collision pass's hash table: its key and its particles' run in `members`.
    struct Cell {
        std::uint64_t key = 0;
        std::uint32_t begin = 0, end = 0;
    };
    // A cell of the link grid (link_contacts.cpp): its coordinates and its links' run.
    struct LinkCell {
        glm::i64vec3 cell{0};
        std::uint32_t begin = 0, count = 0, fill = 0;
    };
    // Whether the particles, their links, rest states or masses changed since the groups and
    // the rest moments were built: growth, cuts and breaks do, a step without them does not.
    bool groups_stale_ = true;
    struct Scratch {
        Array<Frame> frames;
        Array<glm::dmat3> moments, group_moment; // per particle, and summed per group
        Array<glm::dvec3> old;
        Array<Cell> table;                     // the collision pass's cells
        Array<std::uint32_t> used_cells;       // the slots of `table` the last step filled
        Array<std::uint32_t> slot_of, members; // particles grouped by table slot
        Array<glm::i64vec3> cell_of;           // each particle's collision cell
        Array<double> thin;                    // each particle's thinnest radius
        Array<std::uint32_t> oversized;        // contacts: particles too wide for the grid
        Array<glm::dmat3> rest_moment;         // 0.2 m D R̄ᵀ, while the groups are current
        Array<glm::dvec3> push;
        Array<std::uint8_t> near; // links near an obstacle (resolve_segments)
        // (resolve_segments) the distance test of each link, where each particle was when the
        // last call looked, and which have moved since
        Array<std::uint8_t> near_base, near_moved;
        Array<glm::dvec3> near_seen;
        Array<std::uint8_t> ring_flag;      // (resolve_segments) particles whose links join a near one
        Array<std::uint32_t> contact_links; // the same, as a list in index order
        // (resolve_segments) the links its contact sweeps found clear this step, and where their
        // ends were then: a parent's at 2 i, the particle's at 2 i + 1
        Array<std::uint8_t> found_clear;
        Array<glm::dvec3> clear_ends;
        // (segment_sweeps) the links a sweep's pushes reached: flags for this sweep and the next
        Array<std::uint8_t> woken_now, woken_next;
        Array<double> inverse_mass; // (weigh_particles) 0 for a particle that does not move
        Array<double> stiffness;    // each particle's s, during a step
        Groups groups;
        // the length and bending sweep (length.cpp): each link's rest offset from the parent,
        // its rest length and unit direction (kept with the groups), and its direction now
        Array<glm::dvec3> rest_link, rest_dir, dir;
        Array<double> rest_length;
        // the order the sweep visits the particles in: two chains at a time, interleaved, every
        // parent before its children (build_links)
        Array<std::uint32_t> sweep;
        Array<std::uint32_t> oriented; // (keep_shape) the particles to orient after the sweep
        // links of different plants (link_contacts.cpp): each particle's plant (root index) and
        // how many plants have a link, kept with the groups; each link's capsule bounds, the
        // link grid and the candidate pairs, per step
        Array<std::uint32_t> plant;
        std::size_t plants = 0;
        Array<glm::dvec3> box_lo, box_hi;
        Array<std::uint32_t> link_list, link_members;
        Array<std::uint32_t> link_sorted, plant_start, plant_roots; // (grid_link_pairs) by plant
        Array<std::uint32_t> link_table, link_used, link_entry_cell, link_entry_link; // (find_link_pairs)
        Array<glm::i64vec3> link_range_lo, link_range_hi; // (grid_link_pairs) each link's cells
        Array<LinkCell> link_cells;
        Array<std::pair<std::uint32_t, std::uint32_t>> link_pairs;
        Array<std::uint32_t> link_near; // (separate_links) the pairs its later sweeps visit
        Array<std::uint32_t> link_big;  // link contacts: boxes too large for the grid
        // the energy budget (energy.cpp): the forcing on each particle this step, its energy
        // per unit mass before the step, and whether the hand holds it
        Array<glm::dvec3> forcing;
        Array<double> energy_before;
        Array<std::uint8_t> held;
        Array<glm::dvec3> anchored_before; // (part_plants) each anchor's particle before the rounds

        static double thin_of(std::uint32_t i, const Array<glm::dvec3>& radii) {
            return std::min({radii[i].x, radii[i].y, radii[i].z});
        }
    } scratch_;
};

} // namespace plant::physics
