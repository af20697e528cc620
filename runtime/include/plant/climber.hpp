// The `climber` environment: the particle runtime (runtime/physics/) behind a grammar
// (docs/language.md, environments and bound modules; Hädrich et al. 2017).
//
//   env ivy = climber(gravity: vec3(0, -9.81, 0), substeps: 4, stiffness: 1, break_threshold: 0.5,
//                     light: vec3(-1, 1, 0), phototropism: 0.5, adaption: 0.5, anchor: 0.3,
//                     box_min: ..., box_max: ..., attractor: vec3(...), attractor_radius: 0.3);
//   module Seg(len, r) bound ivy;
//
// In the environment phase of every step the string is drawn once by the turtle: each bound
// module without a particle
// gets one where the turtle put its segment's end, child of the particle of the bound module
// before it on its path (a plant's first one hangs from a fixed root at its segment's start).
// Particles whose modules left the string are removed. Then the world runs `substeps` steps of
// 25 ms. A part that broke off (or was cut) leaves the string, from its first module to the end
// of its branch. Every turtle pass (queries, skeleton, meshes) draws bound modules at their
// particles.
//
// Methods (ClimberMethod and its table in climber.cpp): grow_dir(p, h) (h turned by surface
// adaption, Eq. 6, by painted attractors and by phototropism weighted by occlusion, Eq. 7),
// occlusion(p), anchored(id), particles(), seeded(id), clear_dir(p, v, r) (v's direction turned
// as little as keeps the segment from p to p + v, a capsule of radius r, out of every obstacle),
// thickness(id) (its particle's radius: with the argument `strand`, grown by secondary growth,
// the pipe model, by one strand of that radius for every segment beyond it);
// edits, in hooks only: pull(id, target), grab(id, target) (a hand pulling the branch toward the
// target at grab_speed, its stem following within its length: physics::World::grab),
// cut(id), wind(a), move(k, delta), seed(id), emit(k, velocity).
//
// With air_min and air_max the climber also runs SPH air in that box (section 5.3): each 25 ms
// physics step runs ten 2.5 ms air steps coupled both ways with the full-grown particles, and
// `wind` (argument and hook method) is the air's inflow velocity in m/s instead of a steady
// acceleration. `emitter: vec3(...)` with `emitter_velocity: vec3(...)` (and optionally
// `emitter_radius: r`, default 0.2) places a wind stream in the air (physics::Emitter); repeat
// the three for more emitters, and switch one with `ivy.emit(k, velocity)` from a hook.
#pragma once

#include "plant/environment.hpp"
#include "plant/memory_budget.hpp"
#include "plant/physics/fluid.hpp"
#include "plant/physics/light.hpp"
#include "plant/physics/world.hpp"
#include "plant/turtle.hpp"

#include <glm/glm.hpp>

#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace plant {

// A climber's methods, in the order of its table (climber.cpp).
enum class ClimberMethod : std::uint8_t {
    GrowDir,
    Occlusion,
    Anchored,
    Particles,
    Seeded,
    // edits
    Pull,
    Cut,
    Wind,
    Move,
    Seed,
    Emit,
    // queries, after the edits so that their numbers stay
    ClearDir,
    Thickness,
    Grab,   // an edit, after the queries so that their numbers stay
    Remove, // an edit too
};

const EnvironmentKind& climber_kind();

class Climber : public Environment {
  public:
    struct Attractor {
        glm::dvec3 point;
        double radius, strength;
    };
    struct Config {
        int substeps = 4;          // physics steps of dt per derivation step
        glm::dvec3 light{0, 1, 0}; // toward the light
        double phototropism = 0;   // eta, Eq. 7
        double adaption = 0.5;     // tau, Eq. 6
        double adaption_range = 0.3;
        double response = 10;       // growth responses act over substeps * dt * response seconds
        double anchor = 0;          // phi of Eq. 5 for new particles near a surface (0: no anchors)
        double anchor_range = 0.05; // how near (beyond the particle's radius)
        double anchor_release = 0.3;
        double light_cell = 0.1;    // occupancy grid for occlusion
        double opacity = 0.15;      // occlusion 1 - exp(-opacity * particles between p and the light)
        bool obstacle_shade = true; // an obstacle between p and the light: occlusion 1 (full shade)
        double diffuse = 0;         // the share of the light from the open sky (scene_occlusion)
        std::vector<Attractor> attractors;
        double attractor_reach = 0.1; // a painted sample a particle comes this near is used up
        double strand = 0;            // secondary growth: a pipe's radius per segment beyond (0: none)
        double grab_speed = 1;        // m/s: how fast grab(id, target) pulls a particle toward its target
        double fall_time = 1; // s a broken-off or cut part falls before it leaves the string (0: at once)
        bool air = false;     // SPH air fills [air_min, air_max] (section 5.3)
        physics::FluidSettings fluid;
    };

    Climber(physics::Settings settings, Config config) : world_(settings), config_(std::move(config)) {}
    // Fills the air box, once the world has its settings and obstacles: the climber as declared.
    void fill_air() {
        attractors_ = config_.attractors;
        if (config_.air) {
            charge_particles(air_particles(config_.fluid));
            fluid_ = physics::Fluid(config_.fluid);
            fluid_.fill(config_.fluid.domain_lo, config_.fluid.domain_hi);
        }
    }
    void geometry(std::vector<glm::dvec3>& triangles, const glm::dvec3& lo,
                  const glm::dvec3& hi) const override;
    // A loaded mesh's triangles for obstacle k (a sampled grid), to show it.
    void show_mesh(std::size_t k, std::vector<glm::dvec3> triangles) {
        meshes_.emplace_back(k, std::move(triangles));
    }

    // Environment
    const EnvironmentKind& kind() const override { return climber_kind(); }
    // The particles, the air and the edits asked for: a copied derivation's climber goes on alone.
    std::unique_ptr<Environment> clone() const override { return std::make_unique<Climber>(*this); }
    void query(std::size_t method, const double* args, double* result) const override;
    void edit(std::size_t method, const double* args) override;
    bool pose(ModuleId id, glm::dvec3& position, glm::dmat3& frame) const override;
    bool starts_loose(ModuleId id) const override;

    // The environment phase: begin, be shown every bound module the turtle drew (in string
    // order), advance; `left` receives the modules whose particles broke off or were cut.
    void begin_segments() override;
    void segment(const BoundSegment& s) override;
    void advance(std::set<ModuleId>& left) override;
    bool sees_plant() const override { return false; } // its particles are its plant

    physics::World& world() { return world_; }
    const physics::World& world() const { return world_; }
    physics::Handle particle(ModuleId id) const;

    // What a particle costs in memory, for the budget: the world's arrays and step buffers hold
    // about 800 bytes a segment particle, the SPH air's (neighbour lists included) about 350 an
    // air particle; both rounded up.
    static constexpr std::size_t kBytesPerParticle = 1024, kBytesPerAirParticle = 512;

  private:
    // Eq. 7's O at p; with `sky` false, of the direct light alone (the share `diffuse` left out)
    double occlusion(const glm::dvec3& p, bool sky = true) const;
    // The obstacle nearest to p if one is nearer than `within`, and its distance.
    const physics::Obstacle* nearest_obstacle(const glm::dvec3& p, double within, double& distance) const;
    glm::dvec3 grow_dir(const glm::dvec3& p, const glm::dvec3& h) const;
    glm::dvec3 clear_dir(const glm::dvec3& p, const glm::dvec3& v, double r) const;
    void rebuild_occupancy();
    // Secondary growth (docs/climber-growth.md, "Growth rate and secondary growth"): with a `strand`,
    // thicken() counts the segments beyond every particle before each step's physics and widens
    // each segment from the radius it was born with.
    void place_pending(std::set<ModuleId>& left); // the new bound modules become particles
    void drop_fallen(std::set<ModuleId>& left);   // loose parts: fall, then leave the string
    void count_beyond();
    void thicken();
    double thickness(ModuleId id) const;

    std::vector<Attractor> attractors_; // the painted samples not yet reached
    physics::World world_;
    physics::Fluid fluid_;
    Config config_;
    // Module identity to particle, in identity order (removals happen in that order), with
    // whether the last turtle pass drew the module: a sorted array, found through bound_index_.
    // (A std::map's node per segment made each of the turtle's lookups, one per bound module and
    // pass, a chain of cache misses, and a std::set of the drawn modules allocated a node each
    // per step: together about a tenth of Table 1's scene, Fig. 14 right.)
    struct Bound {
        ModuleId id;
        physics::Handle particle;
        bool seen = false;
        std::uint32_t loose = 0; // derivation steps its part has hung from no fixed root
    };
    std::vector<Bound> particle_of_;
    // particle_of_ hashed by identity (1 + the entry's index, 0 for an empty slot; open
    // addressing), made at the end of each advance: the turtle's passes look up every bound
    // module in string order, which is not identity order (one lookup in eight came next in the
    // array in Fig. 14 right), and halving the array for each was 2.8 % of that figure's run.
    // While advance changes particle_of_, bound() searches it by halving instead.
    std::vector<std::uint32_t> bound_index_;
    bool index_current_ = false;
    void index_bounds();
    const Bound* bound(ModuleId id) const;
    Bound* bound(ModuleId id) { return const_cast<Bound*>(std::as_const(*this).bound(id)); }
    std::vector<physics::Handle> roots_; // the fixed roots made for plants' first segments
    std::vector<std::uint8_t> attached_; // (advance) World::attached_all, kept for its memory
    std::vector<std::pair<std::size_t, std::vector<glm::dvec3>>> meshes_; // obstacle index, its triangles
    std::vector<BoundSegment> pending_; // bound modules without a particle yet
    // edits asked for by hooks since the last advance
    std::vector<std::pair<ModuleId, glm::dvec3>> pulls_, grabs_;
    std::vector<ModuleId> cuts_;
    std::vector<std::pair<std::size_t, glm::dvec3>> moves_;
    std::vector<std::size_t> removals_; // obstacles, numbered as declared
    // Each declared obstacle's index in the world now (~0: removed); empty until one is removed,
    // so that move(k, delta) and remove(k) keep the declared numbers after a removal.
    std::vector<std::size_t> obstacle_at_;
    std::size_t obstacle_now(std::size_t declared) const {
        return obstacle_at_.empty()
                   ? declared
                   : (declared < obstacle_at_.size() ? obstacle_at_[declared] : ~std::size_t{0});
    }
    void remove_obstacles(); // removals_, in the order asked
    std::vector<ModuleId> seed_requests_;
    std::vector<std::pair<std::size_t, glm::dvec3>> emits_; // emitter, its new velocity
    std::set<ModuleId> seeded_;
    glm::dvec3 wind_{0.0};
    bool wind_changed_ = false;
    physics::LightGrid light_;          // the particles, for occlusion
    std::vector<std::uint32_t> beyond_; // per world slot: the alive particles hanging from it
    std::vector<double> born_radius_;   // per world slot: the radius its segment was born with
    // bound modules drawn with another radius than their particle's (thickened by the grammar)
    std::vector<std::pair<physics::Handle, BoundSegment>> rethickened_;
    // The particles' arrays (world and air) as charged against --max-memory, ahead of growing them.
    memory::Reservation memory_;
    void charge_particles(std::size_t air);
    static std::size_t air_particles(const physics::FluidSettings& fluid);
};

// Makes a climber from `env name = climber(key: value, ...)`; null and a message on bad input.
std::unique_ptr<Environment> make_climber(const std::vector<EnvArg>& args, std::string& error);

} // namespace plant
