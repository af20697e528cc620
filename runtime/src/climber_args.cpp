// The climber's arguments: `env name = climber(...)` read argument by argument, checked as a
// whole, and the environment made from them (make_climber).
#include "plant/climber.hpp"
#include "plant/diagnostics.hpp"

#include "geometry.hpp"
#include "obstacle_args.hpp"
#include "triangle_mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace plant {

namespace {

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// What `climber(...)` says, read argument by argument, then checked as a whole.
struct ClimberArgs {
    physics::Settings s;
    Climber::Config c;
    ObstacleArgs shapes{climber_kind().name};
    std::vector<glm::dvec3> attract, emit_at, emit_v;
    std::vector<double> attract_r, attract_s, emit_r;
    double friction = 0.5, elasticity = 0.0, break_threshold = 0;
    glm::dvec3 wind{0.0};
    std::vector<std::string> meshes;
    double mesh_cell = 0.05;
    bool air_min = false, air_max = false;

    ClimberArgs() { s.fixed_stiffness = 1.0; } // the paper used s = 1 for most results
    bool read(const EnvArg& a, std::string& error);
    void set(const std::string& key, double x, const glm::dvec3& v); // a checked argument's value
    bool check(std::string& error);
};

// The largest adaption_range and mesh_cell (docs/language.md, "Limits").
constexpr double kMaxMeshReach = 1000;
// Emitters and attractors (docs/language.md, "Limits"): every air particle is driven by every
// emitter each air step, and every growing tip looks at every attractor, so their counts size
// the work; a radius sizes how many particles one reaches, a velocity how fast the air moves.
constexpr std::size_t kMaxEmitters = 64, kMaxAttractors = 100000;
constexpr double kMaxEmitterRadius = 1000, kMaxEmitterSpeed = 1e6, kMaxAttractorRadius = 1000;

// The bound on one argument, checked as it is read: a message naming it and the bound, or "".
std::string bounded(const std::string& key, double x, const glm::dvec3& v, std::size_t emitters,
                    std::size_t attractors) {
    if ((key == "adaption_range" || key == "mesh_cell") && x > kMaxMeshReach)
        return fmt::format("climber: '{}' must be at most {}, found {}", key, kMaxMeshReach, x);
    if (key == "emitter_radius" && x > kMaxEmitterRadius)
        return fmt::format("climber: 'emitter_radius' must be at most {}, found {}", kMaxEmitterRadius, x);
    if (key == "attractor_radius" && x > kMaxAttractorRadius)
        return fmt::format("climber: 'attractor_radius' must be at most {}, found {}", kMaxAttractorRadius,
                           x);
    // the length scaled by the largest component, so that 1e300 does not square to infinity
    const double big = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    const double speed = big > 0 ? big * glm::length(v / big) : 0.0;
    if (key == "emitter_velocity" && speed > kMaxEmitterSpeed)
        return fmt::format("climber: 'emitter_velocity' must be at most {:g} m/s long, found {:g}",
                           kMaxEmitterSpeed, speed);
    if (key == "emitter" && emitters >= kMaxEmitters)
        return fmt::format("climber: at most {} 'emitter' arguments", kMaxEmitters);
    if (key == "attractor" && attractors >= kMaxAttractors)
        return fmt::format("climber: at most {} 'attractor' arguments", kMaxAttractors);
    return "";
}

bool ClimberArgs::read(const EnvArg& a, std::string& error) {
    // besides the obstacle shapes (ObstacleArgs) and meshes
    static const char* numbers[] = {
        "substeps",       "iterations",       "stiffness",          "stiffening_time", "break_threshold",
        "damping",        "density",          "phototropism",       "adaption",        "adaption_range",
        "response",       "anchor",           "anchor_range",       "anchor_release",  "friction",
        "elasticity",     "attractor_radius", "attractor_strength", "threads",         "light_cell",
        "opacity",        "air_spacing",      "air_density",        "air_viscosity",   "air_stiffness",
        "air_coupling",   "mesh_cell",        "attractor_reach",    "emitter_radius",  "strand",
        "obstacle_shade", "grab_speed",       "fall_time",          "plant_contacts",  "energy_budget",
        "diffuse"};
    static const char* vectors[] = {"gravity", "light",   "wind",    "attractor",
                                    "air_min", "air_max", "emitter", "emitter_velocity"};
    if (a.key == "mesh") {
        if (!shapes.mesh(a, error)) return false;
        meshes.push_back(a.text);
        return true;
    }
    if (ObstacleArgs::is_shape(a.key)) return shapes.read(a, error);
    bool is_number =
        std::any_of(std::begin(numbers), std::end(numbers), [&](const char* k) { return a.key == k; });
    bool is_vector =
        std::any_of(std::begin(vectors), std::end(vectors), [&](const char* k) { return a.key == k; });
    if (!is_number && !is_vector) {
        error = a.key.empty() ? "climber: arguments are named, as in climber(gravity: vec3(0, -9.81, 0))"
                              : fmt::format("climber: unknown argument '{}'", a.key);
        return false;
    }
    if (is_vector != (a.type == ValueType::Vec3)) {
        error = fmt::format("climber: '{}' must be a {}", a.key, is_vector ? "vec3" : "number");
        return false;
    }
    const double x = a.v[0];
    const glm::dvec3 v(a.v[0], a.v[1], a.v[2]);
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
        error = fmt::format("climber: '{}' must be finite", a.key);
        return false;
    }
    // the numbers that size work or memory have bounds (the distance grid of a mesh spans the
    // mesh grown by 4 mesh_cell + adaption_range)
    if (error = bounded(a.key, x, v, emit_at.size(), attract.size()); !error.empty()) return false;
    set(a.key, x, v);
    return true;
}

void ClimberArgs::set(const std::string& key, double x, const glm::dvec3& v) {
    if (key == "substeps")
        c.substeps = static_cast<int>(std::clamp(x, 0.0, 1000.0));
    else if (key == "iterations")
        s.iterations = static_cast<int>(std::clamp(x, 1.0, 100.0));
    else if (key == "stiffness")
        s.fixed_stiffness = x; // negative: grows with age, s = t_l / t_m
    else if (key == "stiffening_time")
        s.stiffening_time = std::max(x, 1e-6);
    else if (key == "break_threshold")
        break_threshold = std::max(x, 0.0);
    else if (key == "damping")
        s.damping = std::clamp(x, 0.0, 1.0);
    else if (key == "density")
        s.density = std::max(x, 1e-9);
    else if (key == "phototropism")
        c.phototropism = std::max(x, 0.0);
    else if (key == "adaption")
        c.adaption = std::clamp(x, 0.0, 1.0);
    else if (key == "adaption_range")
        c.adaption_range = std::max(x, 0.0);
    else if (key == "response")
        c.response = std::max(x, 0.0);
    else if (key == "anchor")
        c.anchor = std::clamp(x, 0.0, 1.0);
    else if (key == "anchor_range")
        c.anchor_range = std::max(x, 0.0);
    else if (key == "anchor_release")
        c.anchor_release = std::max(x, 0.0);
    else if (key == "friction")
        friction = std::clamp(x, 0.0, 1.0);
    else if (key == "elasticity")
        elasticity = std::clamp(x, 0.0, 1.0);
    else if (key == "attractor_radius")
        attract_r.push_back(x);
    else if (key == "attractor_strength")
        attract_s.push_back(x);
    else if (key == "threads")
        s.threads = static_cast<int>(std::clamp(x, 1.0, 256.0));
    else if (key == "light_cell")
        c.light_cell = std::max(x, 1e-3);
    else if (key == "opacity")
        c.opacity = std::max(x, 0.0);
    else if (key == "gravity")
        s.gravity = v;
    else if (key == "light")
        c.light = v;
    else if (key == "wind")
        wind = v;
    else if (key == "attractor")
        attract.push_back(v);
    else if (key == "emitter")
        emit_at.push_back(v);
    else if (key == "emitter_velocity")
        emit_v.push_back(v);
    else if (key == "emitter_radius")
        emit_r.push_back(std::max(x, 1e-3));
    else if (key == "air_min")
        c.fluid.domain_lo = v, air_min = true;
    else if (key == "air_max")
        c.fluid.domain_hi = v, air_max = true;
    else if (key == "air_spacing")
        c.fluid.spacing = std::max(x, 1e-3), c.fluid.support = 2 * c.fluid.spacing;
    else if (key == "air_density")
        c.fluid.rest_density = std::max(x, 1e-6);
    else if (key == "air_viscosity")
        c.fluid.viscosity = std::max(x, 0.0);
    else if (key == "air_stiffness")
        c.fluid.stiffness = std::max(x, 1e-6);
    else if (key == "air_coupling")
        c.fluid.coupling = std::max(x, 0.0);
    else if (key == "mesh_cell")
        mesh_cell = std::max(x, 1e-3);
    else if (key == "attractor_reach")
        c.attractor_reach = std::max(x, 0.0);
    else if (key == "strand")
        c.strand = std::clamp(x, 0.0, 1.0); // a strand wider than 1 m is no stem
    else if (key == "grab_speed")
        c.grab_speed = std::clamp(x, 0.0, 1e3); // a hand faster than 1 km/s is no hand
    else if (key == "fall_time")
        c.fall_time = std::clamp(x, 0.0, 1e6);
    else if (key == "obstacle_shade")
        c.obstacle_shade = x != 0;
    else if (key == "diffuse")
        c.diffuse = std::clamp(x, 0.0, 1.0);
    else if (key == "plant_contacts")
        s.link_collisions = x != 0; // links of different plants collided as capsules (off: see docs)
    else if (key == "energy_budget")
        s.energy_budget = x != 0; // no particle gains energy gravity and forcing did not give it
}

bool ClimberArgs::check(std::string& error) {
    if (!shapes.paired(error)) return false;
    if (attract_r.size() > attract.size() || attract_s.size() > attract.size()) {
        error = "climber: an attractor_radius or attractor_strength without an attractor";
        return false;
    }
    if (air_min != air_max) {
        error = "climber: give both air_min and air_max for SPH air, or neither";
        return false;
    }
    if (emit_v.size() != emit_at.size() || emit_r.size() > emit_at.size()) {
        error = "climber: give each emitter an emitter_velocity (and at most one emitter_radius)";
        return false;
    }
    if (!emit_at.empty() && !air_min) {
        error = "climber: an emitter blows SPH air: give air_min and air_max too";
        return false;
    }
    for (std::size_t i = 0; i < emit_at.size(); ++i)
        c.fluid.emitters.push_back({emit_at[i], i < emit_r.size() ? emit_r[i] : 0.2, emit_v[i]});
    if (air_min) {
        c.air = true;
        const glm::dvec3 lo = glm::min(c.fluid.domain_lo, c.fluid.domain_hi),
                         hi = glm::max(c.fluid.domain_lo, c.fluid.domain_hi);
        c.fluid.domain_lo = lo;
        c.fluid.domain_hi = hi;
        if (!finite(lo) || !finite(hi)) {
            error = "climber: air_min and air_max must be finite";
            return false;
        }
        // counted as Fluid::fill will fill it: at least one particle along each axis
        glm::dvec3 cells = glm::max(glm::floor((hi - lo) / c.fluid.spacing + 1e-9), glm::dvec3(1.0));
        if (cells.x * cells.y * cells.z > 200000) {
            error = "climber: the air box holds more than 200,000 particles at this air_spacing";
            return false;
        }
        c.fluid.wind = wind;
        c.fluid.threads = s.threads;
        c.fluid.dt = s.dt / 10;
        wind = glm::dvec3(0.0); // the air carries the wind
    }
    if (glm::length(c.light) == 0) {
        error = "climber: 'light' must not be zero";
        return false;
    }
    for (std::size_t i = 0; i < attract.size(); ++i)
        c.attractors.push_back({attract[i], i < attract_r.size() ? attract_r[i] : 0.3,
                                i < attract_s.size() ? attract_s[i] : 1.0});
    return true;
}

} // namespace

std::unique_ptr<Environment> make_climber(const std::vector<EnvArg>& args, std::string& error) {
    ClimberArgs p;
    for (const auto& a : args)
        if (!p.read(a, error)) return nullptr;
    if (!p.check(error)) return nullptr;
    auto climber = std::make_unique<Climber>(p.s, p.c);
    physics::World& w = climber->world();
    w.set_break_threshold(p.break_threshold);
    w.set_wind(p.wind);
    auto add = [&](physics::Obstacle o) {
        o.friction = p.friction;
        o.elasticity = p.elasticity;
        w.add_obstacle(o);
    };
    std::vector<physics::Obstacle> obstacles;
    if (!p.shapes.shapes(obstacles, error)) return nullptr;
    for (const physics::Obstacle& o : obstacles) add(o);
    for (const auto& path : p.meshes) {
        std::vector<Triangle> mesh;
        if (!load_triangles(path, mesh, climber_kind().name, error)) return nullptr;
        physics::Obstacle o;
        o.kind = physics::Obstacle::Grid;
        o.grid = distance_grid(mesh, p.mesh_cell, 4 * p.mesh_cell + p.c.adaption_range);
        if (!o.grid) {
            error = fmt::format("climber: the mesh '{}' reaches too far for a distance grid (its corners, "
                                "grown by 4 mesh_cell + adaption_range, must stay finite)",
                                path);
            return nullptr;
        }
        std::vector<glm::dvec3> shown;
        for (const auto& t : mesh) shown.insert(shown.end(), {t.a, t.b, t.c});
        climber->show_mesh(w.obstacles().size(), std::move(shown));
        add(o);
    }
    climber->fill_air();
    return climber;
}

} // namespace plant
