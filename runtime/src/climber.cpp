// The climber environment: a physics::World driven by the grammar's bound modules.
#include "plant/climber.hpp"
#include "plant/diagnostics.hpp"

#include "geometry.hpp"
#include "obstacle_args.hpp"
#include "triangle_mesh.hpp"

#include <fmt/format.h>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>

namespace plant {

namespace {

constexpr ValueType N = ValueType::Number;
constexpr ValueType V = ValueType::Vec3;

// The frame's columns are the particle's axes: x = -left, y = heading, z = up.
glm::dquat quat_of(const glm::dmat3& frame) {
    return glm::normalize(glm::quat_cast(frame));
}

} // namespace

namespace {

constexpr EnvAccess Pure = EnvAccess::Pure, Edit = EnvAccess::Edit;
using M = ClimberMethod;

constexpr EnvMethod kClimberMethods[] = {
    env_method(M::GrowDir, "grow_dir", {V, V}, V, Pure, false,
               "heading h at p turned by surface adaption (Eq. 6), attractors and phototropism (Eq. 7)"),
    env_method(M::Occlusion, "occlusion", {V}, N, Pure, true,
               "light occlusion at p, 0 to 1: 1 behind an obstacle (1 - diffuse * sky seen, with `diffuse`), "
               "else by the plant's particles"),
    env_method(M::Anchored, "anchored", {N}, N, Pure, false,
               "1 when module id's particle is anchored (to a surface, or lying on another plant's stem)"),
    env_method(M::Particles, "particles", {}, N, Pure, false, "particles in the world"),
    env_method(M::Seeded, "seeded", {N}, N, Pure, false,
               "1 in the step after a hook seeded a branch at module id (ivy.seed(id))"),
    env_method(M::Pull, "pull", {N, V}, N, Edit, false,
               "hold module id's particle at a point through the next step's physics"),
    env_method(M::Cut, "cut", {N}, N, Edit, false,
               "cut the branch at module id: it falls for fall_time, then leaves the string"),
    env_method(M::Wind, "wind", {V}, N, Edit, false, "set the wind (vec3(0, 0, 0): off)"),
    env_method(M::Move, "move", {N, V}, N, Edit, false,
               "move obstacle k (in the order declared: spheres, boxes, planes, meshes) by a vector"),
    env_method(M::Seed, "seed", {N}, N, Edit, false,
               "seed a new branch at module id: ivy.seeded(id) holds in the next step"),
    env_method(M::Emit, "emit", {N, V}, N, Edit, false,
               "set emitter k's air velocity (in the order declared; vec3(0, 0, 0): off)"),
    env_method(M::ClearDir, "clear_dir", {V, V, N}, V, Pure, false,
               "unit heading of v, turned as little as keeps the segment p to p + v (radius r) out of "
               "every obstacle"),
    env_method(M::Thickness, "thickness", {N}, N, Pure, false,
               "radius of module id's particle (0: none): with `strand`, thickened by secondary growth "
               "to sqrt(r0^2 + strand^2 n), r0 its radius at birth and n the segments beyond it"),
    env_method(M::Grab, "grab", {N, V}, N, Edit, false,
               "pull module id's particle toward a point at grab_speed through the next step, its stem "
               "following within its length and coming off its supports"),
    env_method(M::Remove, "remove", {N}, N, Edit, false,
               "take obstacle k away (numbered as for move): the particles anchored to it let go"),
};
static_assert(method_table(kClimberMethods, M::Remove));

} // namespace

const EnvironmentKind& climber_kind() {
    static constexpr EnvironmentKind kind{
        "climber", "the particle physics behind bound segments (Hädrich et al. 2017)", kClimberMethods, true};
    return kind;
}

namespace {

// The first entry of a list sorted by identity (Climber::particle_of_) at or after `id`.
template <class List> auto first_at(List& list, ModuleId id) {
    return std::lower_bound(list.begin(), list.end(), id, [](const auto& b, ModuleId v) { return b.id < v; });
}

// The slot of a module identity in Climber::bound_index_ (Fibonacci hashing: identities are
// consecutive numbers)
std::size_t bound_slot(ModuleId id, std::size_t size) {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(id) * 0x9e3779b97f4a7c15ull) >> 32) &
           (size - 1);
}

} // namespace

void Climber::index_bounds() {
    std::size_t size = 16;
    while (size < 2 * particle_of_.size()) size *= 2;
    bound_index_.assign(size, 0);
    for (std::size_t k = 0; k < particle_of_.size(); ++k) {
        std::size_t slot = bound_slot(particle_of_[k].id, size);
        while (bound_index_[slot] != 0) slot = (slot + 1) & (size - 1);
        bound_index_[slot] = static_cast<std::uint32_t>(k + 1);
    }
    index_current_ = true;
}

const Climber::Bound* Climber::bound(ModuleId id) const {
    if (index_current_) {
        const std::size_t size = bound_index_.size();
        for (std::size_t slot = bound_slot(id, size); bound_index_[slot] != 0; slot = (slot + 1) & (size - 1))
            if (const Bound& b = particle_of_[bound_index_[slot] - 1]; b.id == id) return &b;
        return nullptr;
    }
    auto it = first_at(particle_of_, id);
    return it == particle_of_.end() || it->id != id ? nullptr : &*it;
}

physics::Handle Climber::particle(ModuleId id) const {
    const Bound* b = bound(id);
    return b ? b->particle : physics::Handle{};
}

namespace {

// A module identity from a number, or 0 (no module) for anything that is not one.
ModuleId id_of(double v) {
    return std::isfinite(v) && v > 0 && v < 9.0e15 ? static_cast<ModuleId>(v) : 0;
}
bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// Drops the elements `drop` says to, visiting them front to back (its side effects happen in
// that order), the others kept in order.
template <class T, class Drop> void drop_in_order(std::vector<T>& v, Drop&& drop) {
    std::size_t kept = 0;
    for (std::size_t i = 0; i < v.size(); ++i)
        if (!drop(v[i])) v[kept++] = v[i];
    v.resize(kept);
}

} // namespace

void Climber::query(std::size_t method, const double* a, double* r) const {
    switch (static_cast<M>(method)) {
    case M::GrowDir: {
        glm::dvec3 g = grow_dir(vec(a), vec(a + 3));
        r[0] = g.x, r[1] = g.y, r[2] = g.z;
        return;
    }
    case M::Occlusion:
        r[0] = occlusion(vec(a));
        return;
    case M::ClearDir: {
        glm::dvec3 g = clear_dir(vec(a), vec(a + 3), a[6]);
        r[0] = g.x, r[1] = g.y, r[2] = g.z;
        return;
    }
    case M::Anchored: {
        physics::Handle h = particle(id_of(a[0]));
        r[0] = h.valid() && world_.alive(h) && world_.anchored(h) ? 1 : 0;
        return;
    }
    case M::Particles:
        r[0] = static_cast<double>(particle_of_.size());
        return;
    case M::Seeded:
        r[0] = seeded_.count(id_of(a[0])) ? 1 : 0;
        return;
    case M::Thickness:
        r[0] = thickness(id_of(a[0]));
        return;
    default: // edits: not queries
        r[0] = 0;
    }
}

namespace {

// The length of `v`, scaled by its largest component so that 1e300 does not square to infinity.
double emit_speed(const glm::dvec3& v) {
    const double big = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    return big > 0 ? big * glm::length(v / big) : 0.0;
}

} // namespace

void Climber::edit(std::size_t method, const double* a) {
    const auto m = static_cast<M>(method);
    // edits with a non-finite vector are ignored: they would poison the world
    const bool vector = m == M::Pull || m == M::Grab || m == M::Wind || m == M::Move || m == M::Emit;
    if (vector && !finite(vec(m == M::Wind ? a : a + 1))) return;
    switch (m) {
    case M::Pull:
        pulls_.emplace_back(id_of(a[0]), vec(a + 1));
        return;
    case M::Grab:
        grabs_.emplace_back(id_of(a[0]), vec(a + 1));
        return;
    case M::Cut:
        cuts_.push_back(id_of(a[0]));
        return;
    case M::Wind:
        wind_ = vec(a);
        wind_changed_ = true;
        return;
    case M::Move:
        if (std::isfinite(a[0]) && a[0] >= 0 && a[0] < 1e9)
            moves_.emplace_back(static_cast<std::size_t>(a[0]), vec(a + 1));
        return;
    case M::Seed:
        seed_requests_.push_back(id_of(a[0]));
        return;
    case M::Remove:
        if (std::isfinite(a[0]) && a[0] >= 0 && a[0] < 1e9)
            removals_.push_back(static_cast<std::size_t>(a[0]));
        return;
    case M::Emit:
        // the bound of `emitter_velocity` (docs/language.md "Limits") holds for emit too; the VM
        // places the error on the call
        if (const double speed = emit_speed(vec(a + 1)); speed > 1e6)
            throw RuntimeError(RuntimeErrorKind::General, Span{},
                               fmt::format("emit: the velocity must be at most 1e6 m/s long, as an "
                                           "emitter_velocity, found {:g}",
                                           speed));
        if (std::isfinite(a[0]) && a[0] >= 0 && a[0] < 1e9)
            emits_.emplace_back(static_cast<std::size_t>(a[0]), vec(a + 1));
        return;
    default: // queries: not edits
        return;
    }
}

bool Climber::pose(ModuleId id, glm::dvec3& position, glm::dmat3& frame) const {
    physics::Handle h = particle(id);
    if (!h.valid() || !world_.alive(h)) return false;
    position = world_.position(h);
    frame = glm::mat3_cast(world_.orientation(h));
    return true;
}

bool Climber::starts_loose(ModuleId id) const {
    // a bound module's particle hangs from its plant's fixed root or from another bound one's,
    // so one with no parent is where a break or a cut let go
    const physics::Handle h = particle(id);
    return h.valid() && world_.alive(h) && world_.parent(h) == ~0u;
}

const physics::Obstacle* Climber::nearest_obstacle(const glm::dvec3& p, double within,
                                                   double& distance) const {
    const physics::Obstacle* nearest = nullptr;
    distance = within;
    for (const auto& o : world_.obstacles()) {
        double d = o.distance(p);
        if (d < distance) distance = d, nearest = &o;
    }
    return nearest;
}

void Climber::geometry(std::vector<glm::dvec3>& triangles, const glm::dvec3& lo, const glm::dvec3& hi) const {
    const auto& obstacles = world_.obstacles();
    for (const auto& o : obstacles) obstacle_triangles(o, lo, hi, triangles);
    for (const auto& [k, mesh] : meshes_) {
        const glm::dvec3 offset =
            k < obstacles.size() ? obstacles[k].a : glm::dvec3(0.0); // moved since loaded
        for (const auto& v : mesh) triangles.push_back(v + offset);
    }
}

void Climber::remove_obstacles() {
    for (const std::size_t declared : removals_) {
        const std::size_t now = obstacle_now(declared);
        if (now == ~std::size_t{0} || now >= world_.obstacles().size()) continue; // gone, or never there
        if (obstacle_at_.empty())
            for (std::size_t k = 0; k < world_.obstacles().size(); ++k) obstacle_at_.push_back(k);
        world_.remove_obstacle(now); // its anchors let go
        for (std::size_t& k : obstacle_at_)
            if (k != ~std::size_t{0} && k > now) --k;
        obstacle_at_[declared] = ~std::size_t{0};
        std::erase_if(meshes_, [&](const auto& m) { return m.first == now; });
        for (auto& m : meshes_)
            if (m.first > now) --m.first;
    }
    removals_.clear();
}

void Climber::begin_segments() {
    for (Bound& b : particle_of_) b.seen = false;
    pending_.clear();
    rethickened_.clear();
}

void Climber::segment(const BoundSegment& s) {
    if (Bound* b = bound(s.id)) {
        b->seen = true;
        // a segment the grammar thickened (secondary growth) thickens its particle too, so
        // collisions and its mass (Eq. 2) follow the stem drawn
        if (world_.alive(b->particle) && std::isfinite(s.radius) && s.radius > 0 &&
            std::abs(std::clamp(s.radius, 1e-4, 1e6) - world_.radii(b->particle).x) > 1e-12)
            rethickened_.emplace_back(b->particle, s);
        return;
    }
    pending_.push_back(s);
}

std::size_t Climber::air_particles(const physics::FluidSettings& fluid) {
    const glm::dvec3 cells =
        glm::max(glm::floor((fluid.domain_hi - fluid.domain_lo) / fluid.spacing + 1e-9), glm::dvec3(1.0));
    return static_cast<std::size_t>(std::min(cells.x * cells.y * cells.z, 1e12));
}

void Climber::charge_particles(std::size_t air) {
    memory::Stage stage("physics");
    // a new segment may bring a fixed root with it
    memory_.resize((world_.size() + 2 * pending_.size()) * kBytesPerParticle + air * kBytesPerAirParticle);
}

void Climber::place_pending(std::set<ModuleId>& left) {
    // new bound modules become particles where the turtle drew them; a part that is falling
    // (broken off or cut) does not grow: what it grew leaves the string, and with it the rest of
    // its branch (the apex that grew it)
    for (const BoundSegment& p : pending_) {
        if (const physics::Handle from = particle(p.parent);
            from.valid() && world_.alive(from) && !world_.attached(from)) {
            left.insert(p.id);
            continue;
        }
        const double r = std::isfinite(p.radius) ? std::clamp(p.radius, 1e-4, 1e6) : 1e-4;
        const double length = std::isfinite(p.length) ? std::clamp(p.length, 0.0, 1e6) : 0.0;
        const glm::dvec3 radii(r, std::max(length / 2, r), r);
        const glm::dquat q = quat_of(p.frame);
        physics::Handle parent = particle(p.parent);
        if (!parent.valid() || !world_.alive(parent)) {
            parent = world_.add_root(p.from, q, radii, true);
            roots_.push_back(parent);
        }
        physics::Handle h = world_.add_grown(parent, p.to, q, radii);
        // new modules' identities are above the old ones', so this nearly always appends
        auto at = first_at(particle_of_, p.id);
        if (at != particle_of_.end() && at->id == p.id)
            at->particle = h;
        else
            particle_of_.insert(at, Bound{p.id, h});
        if (born_radius_.size() <= h.index) born_radius_.resize(h.index + 1, 0.0);
        born_radius_[h.index] = r;
        // Eq. 5: a particle born near a surface holds on to it
        if (config_.anchor > 0) {
            double best = 0;
            if (const physics::Obstacle* nearest = nearest_obstacle(p.to, r + config_.anchor_range, best)) {
                glm::dvec3 n = nearest->normal(p.to);
                glm::dvec3 point = p.to - n * (nearest->distance(p.to) - r);
                world_.add_anchor(h, point, config_.anchor, config_.anchor_release);
            }
        }
    }
}

void Climber::advance(std::set<ModuleId>& left) {
    index_current_ = false; // (particle_of_ changes below; index_bounds at the end)
    charge_particles(fluid_.size());
    // particles whose modules the grammar removed go too
    drop_in_order(particle_of_, [&](const Bound& b) {
        if (b.seen) return false;
        world_.remove(b.particle);
        return true;
    });
    place_pending(left);
    // painted samples a new particle reached are used up, so shoots move on across the region
    // instead of circling a sample (as a space-colonization attractor is removed once reached)
    if (!attractors_.empty()) {
        const double reach2 = config_.attractor_reach * config_.attractor_reach;
        for (const BoundSegment& p : pending_)
            std::erase_if(attractors_, [&](const Attractor& a) {
                const glm::dvec3 d = a.point - p.to;
                return glm::dot(d, d) < reach2;
            });
    }
    pending_.clear();
    for (const auto& [h, s] : rethickened_) {
        if (!world_.alive(h)) continue;
        const double r = std::clamp(s.radius, 1e-4, 1e6);
        const double length = std::isfinite(s.length) ? std::clamp(s.length, 0.0, 1e6) : 0.0;
        world_.set_radii(h, glm::dvec3(r, std::max(length / 2, r), r));
    }
    rethickened_.clear();
    thicken(); // secondary growth, before the physics, so the step collides the stems as thick as drawn
    for (ModuleId id : cuts_) { // edits from hooks: the part cut off falls (fall_time)
        physics::Handle h = particle(id);
        if (h.valid() && world_.alive(h)) world_.cut_loose(h);
    }
    cuts_.clear();
    // seeds asked for since the last step are visible to this step's productions
    seeded_.clear();
    seeded_.insert(seed_requests_.begin(), seed_requests_.end());
    seed_requests_.clear();
    for (const auto& [k, delta] : moves_)
        if (const std::size_t now = obstacle_now(k); now != ~std::size_t{0}) world_.move_obstacle(now, delta);
    moves_.clear();
    remove_obstacles();
    auto& emitters = fluid_.settings().emitters;
    for (const auto& [k, velocity] : emits_)
        if (k < emitters.size()) emitters[k].velocity = velocity;
    emits_.clear();
    if (wind_changed_) {
        if (config_.air)
            fluid_.settings().wind = wind_;
        else
            world_.set_wind(wind_);
        wind_changed_ = false;
    }
    const int air_steps =
        config_.air ? std::max(1, static_cast<int>(std::lround(world_.settings().dt / config_.fluid.dt))) : 0;
    world_.clear_peak_speed(); // what a test reads after the derivation step: its substeps' fastest
    for (int k = 0; k < config_.substeps; ++k) {
        for (const auto& [id, target] : pulls_) {
            physics::Handle h = particle(id);
            if (h.valid() && world_.alive(h)) world_.pull(h, target);
        }
        for (const auto& [id, target] : grabs_) {
            physics::Handle h = particle(id);
            if (h.valid() && world_.alive(h))
                world_.grab(h, target, config_.grab_speed * world_.settings().dt);
        }
        try {
            for (int a = 0; a < air_steps; ++a) fluid_.step(&world_);
        } catch (const physics::AirCrowded& e) {
            throw RuntimeError(RuntimeErrorKind::Physics, Span{},
                               std::string(e.what()) +
                                   ": lower the emitters' velocities or the wind, or raise air_stiffness");
        }
        world_.step();
    }
    pulls_.clear();
    grabs_.clear();
    // a wind, pull or segment far beyond any scene can push particles out of finite space; the
    // plant cannot be drawn from there, so the derivation ends (the caller names the climber)
    for (const Bound& b : particle_of_)
        if (!finite(world_.position(b.particle)))
            throw RuntimeError(RuntimeErrorKind::Physics, Span{},
                               fmt::format("the segment of module #{} left finite space (its position is "
                                           "infinite or not a number): lower the wind, pulls, segment "
                                           "lengths or box sizes that drove it there",
                                           b.id));
    for (const glm::dvec3& x : fluid_.positions())
        if (!finite(x))
            throw RuntimeError(RuntimeErrorKind::Physics, Span{},
                               "the air left finite space (a particle's position is infinite or not a "
                               "number): lower the wind or the emitters' velocities");
    drop_fallen(left);
    // a fixed root whose plant is gone would only be in the way of the next one planted there
    for (auto it = roots_.begin(); it != roots_.end();) {
        if (world_.has_children(*it)) {
            ++it;
            continue;
        }
        world_.remove(*it);
        it = roots_.erase(it);
    }
    rebuild_occupancy();
    index_bounds();
}

// Broken-off and cut parts fall for fall_time (Hädrich et al., section 6.1: the pieces fall under
// gravity), then leave the string (and the world). Whether each particle hangs from a fixed root
// is found in one pass (asked of each particle, a walk to its root: a sum of depths over 25,000
// particles every step).
void Climber::drop_fallen(std::set<ModuleId>& left) {
    world_.attached_all(attached_);
    const double step_time = config_.substeps * world_.settings().dt;
    const auto fall_steps =
        static_cast<std::uint32_t>(std::ceil(std::min(config_.fall_time / step_time - 1e-9, 1e9)));
    bool came_loose = false;
    drop_in_order(particle_of_, [&](Bound& b) {
        if (world_.alive(b.particle) && attached_[b.particle.index]) {
            b.loose = 0;
            return false;
        }
        came_loose = came_loose || b.loose == 0;
        if (world_.alive(b.particle) && ++b.loose <= fall_steps) return false; // still falling
        left.insert(b.id);
        world_.remove(b.particle); // no longer drawn, so no longer simulated
        return true;
    });
    if (came_loose)
        world_.release_loose(attached_); // a part that has just come loose lets go of its supports
}

void Climber::count_beyond() {
    // a parent's slot is below its children's, so one sweep from the last slot down adds every
    // particle's count into its parent's
    beyond_.assign(world_.size(), 0);
    for (std::uint32_t i = static_cast<std::uint32_t>(world_.size()); i-- > 0;) {
        const physics::Handle h = world_.handle(i);
        const std::uint32_t parent = world_.parent(h);
        if (!world_.alive(h) || parent >= beyond_.size()) continue;
        beyond_[parent] += beyond_[i] + 1;
    }
}

double Climber::thickness(ModuleId id) const {
    const physics::Handle h = particle(id);
    return h.valid() && world_.alive(h) ? world_.radii(h).x : 0.0;
}

void Climber::thicken() {
    if (!(config_.strand > 0)) return;
    count_beyond();
    const double t2 = config_.strand * config_.strand;
    for (std::uint32_t i = 0; i < born_radius_.size() && i < world_.size(); ++i) {
        const physics::Handle h = world_.handle(i);
        if (!(born_radius_[i] > 0) || !world_.alive(h)) continue;
        // the pipe model (Shinozaki et al. 1964; Holton 1994's strands, which Hädrich et al. 2017,
        // section 4, name for secondary growth): a stem's cross-section is the one it was born
        // with plus one strand's for every segment beyond it
        // wood does not shrink: a segment keeps its girth when what it carried is cut or breaks off
        const glm::dvec3 radii = world_.radii(h);
        double r = std::max(std::sqrt(born_radius_[i] * born_radius_[i] + t2 * beyond_[i]), radii.x);
        // a plant's first segment hangs from a fixed root, which no contact moves: it is only as
        // thick as the room around its root and along it allows (0.5 mm kept free), never thinner
        // than at birth. The root counts: a capsule leaning from a root in the ground enters the
        // ground by r (1 - sin of its lean) just beyond one radius from the root, and the lean
        // changes after the radius is set (docs/climber-growth.md, "Secondary growth in the figures")
        const std::uint32_t parent = world_.parent(h);
        if (parent < world_.size() && world_.parent(world_.handle(parent)) == ~0u) {
            const glm::dvec3 a = world_.position(world_.handle(parent)), b = world_.position(h);
            double room = 1e300, d = 0;
            for (double t : {0.0, 0.25, 0.5, 0.75, 1.0})
                if (nearest_obstacle(a + (b - a) * t, 1e300, d)) room = std::min(room, d - 5e-4);
            r = std::max(born_radius_[i], std::min(r, room));
        }
        if (std::abs(r - radii.x) > 1e-12)
            world_.set_radii(h, glm::dvec3(r, radii.y > radii.x ? std::max(radii.y, r) : r, r));
    }
}

void Climber::rebuild_occupancy() {
    std::vector<glm::dvec3> points;
    points.reserve(particle_of_.size());
    for (const Bound& b : particle_of_) points.push_back(world_.position(b.particle));
    light_.build(points, config_.light_cell);
}

double Climber::occlusion(const glm::dvec3& p, bool sky) const {
    // Eq. 7's O: an obstacle between p and the light is opaque, a full shade (the paper's shadow
    // maps include the scene); else the particles in the cells between p and the light
    return physics::scene_occlusion(light_, world_.obstacles(), config_.obstacle_shade, p,
                                    glm::normalize(config_.light), config_.opacity,
                                    sky ? config_.diffuse : 0.0);
}

glm::dvec3 Climber::grow_dir(const glm::dvec3& p, const glm::dvec3& h) const {
    const double time = config_.substeps * world_.settings().dt * config_.response;
    glm::dvec3 f = finite(h) && glm::length(h) > 0 ? glm::normalize(h) : glm::dvec3(0, 1, 0);
    if (!finite(p)) return f;
    // Eq. 6: parallel to the nearest surface in range; before that, a plant searches for the
    // support and grows toward it (section 4.2), more the farther it still is
    const physics::Obstacle* nearest = nullptr;
    glm::dvec3 normal(0.0);
    if (config_.adaption > 0) {
        double best = 0;
        nearest = nearest_obstacle(p, config_.adaption_range, best);
        // a surface the shoot grows away from (more than 30 degrees off it: the ground under a
        // free shoot) neither draws it back nor turns it flat; Eq. 6 alone would, by the same
        // angle as a shoot leaning into it (docs/physics.md)
        if (nearest && glm::dot(f, nearest->normal(p)) > 0.5) nearest = nullptr;
        if (nearest) {
            normal = nearest->normal(p);
            f = physics::surface_adaption(f, -normal, config_.adaption, time);
            const double reach = std::clamp(best / config_.adaption_range, 0.0, 1.0);
            f = glm::normalize(f - normal * (config_.adaption * time * reach));
        }
    }
    // painted attractors (section 5.1): toward their weighted average within their radii
    glm::dvec3 pull(0.0);
    for (const auto& a : attractors_) {
        glm::dvec3 d = a.point - p;
        double len = glm::length(d);
        if (len >= a.radius || len < 1e-12) continue;
        pull += d / len * (a.strength * (1 - len / a.radius));
    }
    if (glm::length(pull) > 0) f = glm::normalize(f + pull * time);
    // Eq. 7: toward the light, less where the plant shades itself. On a support the shoot follows
    // the light along it: the turn does not lift it off the surface. The turn is toward the
    // light's direction, so it is weighed by the direct light alone: a shoot in an obstacle's
    // shadow, lit by the open sky (`diffuse`), does not turn toward the sun behind the obstacle.
    if (config_.phototropism > 0) {
        glm::dvec3 g = physics::phototropism(f, glm::normalize(config_.light), occlusion(p, false),
                                             config_.phototropism, time);
        if (nearest) {
            glm::dvec3 kept = g + normal * (glm::dot(f, normal) - glm::dot(g, normal));
            if (glm::length(kept) > 1e-9) g = glm::normalize(kept);
        }
        f = g;
    }
    return f;
}

glm::dvec3 Climber::clear_dir(const glm::dvec3& p, const glm::dvec3& v, double r) const {
    // the new segment resolved against the obstacles before it is drawn (docs/physics.md,
    // "Obstacles"): the turtle draws it from p along the heading returned, as long as v
    const double len = finite(v) ? glm::length(v) : 0;
    const glm::dvec3 f = len > 1e-12 && len < 1e6 ? v / len : glm::dvec3(0, 1, 0);
    if (!finite(p) || !(len > 1e-12 && len < 1e6) || !std::isfinite(r) || r <= 0) return f;
    const glm::dvec3 end = world_.clear_segment_end(p, p + v, std::min(r, 1e6));
    const glm::dvec3 d = end - p;
    const double l = glm::length(d);
    return finite(d) && l > 1e-12 ? d / l : f;
}

} // namespace plant
