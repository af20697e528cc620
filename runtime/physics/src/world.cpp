// The particle world: adding particles, cutting and breaking branches, anchors, and one step as
// the list of its phases (the phases live with their concepts: shape_matching.cpp, collisions.cpp).
#include "plant/physics/world.hpp"

#include "parallel.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

namespace plant::physics {

Handle World::add_root(const glm::dvec3& position_in, const glm::dquat& orientation_in,
                       const glm::dvec3& radii_in, bool fixed) {
    // copies first: the arguments may refer into the arrays that grow below
    const glm::dvec3 position = position_in, radii = radii_in;
    const glm::dquat orientation = orientation_in;
    Handle h{static_cast<std::uint32_t>(x_.size()), 0};
    groups_stale_ = true;
    x_.push_back(position);
    v_.emplace_back(0.0);
    rest_x_.push_back(position);
    radii_.push_back(radii);
    q_.push_back(orientation);
    rest_q_.push_back(orientation);
    // Hädrich et al., Eq. 2: the mass of an ellipsoid
    m_.push_back(4.0 * std::numbers::pi * radii.x * radii.y * radii.z * settings_.density / 3.0);
    age_.push_back(0);
    length_.push_back(0);
    laterals_.push_back(0);
    parent_.push_back(kNone);
    generation_.push_back(0);
    children_.emplace_back();
    fixed_.push_back(fixed ? 1 : 0);
    alive_.push_back(1);
    return h;
}

Handle World::add_particle(Handle parent, const glm::dvec3& position, const glm::dquat& orientation,
                           const glm::dvec3& radii) {
    Handle h = add_root(position, orientation, radii, false); // copies its arguments before growing
    parent_[h.index] = parent.index;
    children_[parent.index].push_back(h.index);
    return h;
}

void World::detach(std::uint32_t i) {
    if (parent_[i] == kNone) return;
    groups_stale_ = true;
    auto& siblings = children_[parent_[i]];
    siblings.erase(std::remove(siblings.begin(), siblings.end(), i), siblings.end());
    parent_[i] = kNone;
}

void World::remove(Handle h) {
    if (!alive(h)) return;
    groups_stale_ = true;
    std::vector<std::uint32_t> todo{h.index};
    detach(h.index);
    while (!todo.empty()) {
        std::uint32_t i = todo.back();
        todo.pop_back();
        alive_[i] = 0;
        ++generation_[i];
        for (std::uint32_t c : children_[i]) todo.push_back(c);
        children_[i].clear();
    }
    std::erase_if(anchors_, [&](const Anchor& a) { return !alive_[a.particle]; });
}

void World::release_loose(const std::vector<std::uint8_t>& attached) {
    std::erase_if(anchors_,
                  [&](const Anchor& a) { return a.particle >= attached.size() || !attached[a.particle]; });
}

bool World::attached(Handle h) const {
    if (!alive(h)) return false;
    std::uint32_t i = h.index;
    while (parent_[i] != kNone) i = parent_[i];
    return fixed_[i] != 0;
}

void World::attached_all(std::vector<std::uint8_t>& out) const {
    // whether each slot's chain of parents ends at a fixed root (dead slots too, as attached()
    // walks through them), then only the live ones
    out.assign(x_.size(), 0);
    for (std::size_t i = 0; i < x_.size(); ++i)
        out[i] = parent_[i] == kNone ? (fixed_[i] != 0) : out[parent_[i]];
    for (std::size_t i = 0; i < x_.size(); ++i) out[i] = out[i] && alive_[i];
}

bool World::alive(Handle h) const {
    return h.index < x_.size() && generation_[h.index] == h.generation && alive_[h.index];
}

void World::add_anchor(Handle h, const glm::dvec3& point, double phi, double release) {
    // the obstacle it holds on to: the nearest surface within 5 cm. Obstacles only translate
    // (move_obstacle), so its frame is its `a`.
    Anchor a{h.index, point, std::clamp(phi, 0.0, 1.0), release};
    double best = 0.05;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
        const double d = std::fabs(obstacles_[k].distance(point));
        if (d < best) best = d, a.obstacle = k;
    }
    if (a.obstacle < obstacles_.size()) a.origin = obstacles_[a.obstacle].a;
    anchors_.push_back(a);
}

bool World::anchored_to(Handle h, std::size_t k) const {
    return std::any_of(anchors_.begin(), anchors_.end(),
                       [&](const Anchor& a) { return a.particle == h.index && a.obstacle == k; });
}

void World::remove_obstacle(std::size_t k) {
    if (k >= obstacles_.size()) return;
    obstacles_.erase(obstacles_.begin() + static_cast<std::ptrdiff_t>(k));
    unit_.erase(unit_.begin() + static_cast<std::ptrdiff_t>(k));
    std::erase_if(anchors_, [&](const Anchor& a) { return a.obstacle == k; });
    for (Anchor& a : anchors_)
        if (a.obstacle != ~std::size_t{0} && a.obstacle > k) --a.obstacle;
}

const World::Anchor* World::anchor_for(Handle h) const {
    for (const auto& a : anchors_)
        if (a.particle == h.index) return &a;
    return nullptr;
}

glm::dvec3 World::anchor_of(Handle h) const {
    const Anchor* a = anchor_for(h);
    return a ? anchor_point(*a) : glm::dvec3(std::numeric_limits<double>::quiet_NaN());
}

bool World::anchored(Handle h) const {
    return anchor_for(h) != nullptr;
}

std::size_t World::components() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < x_.size(); ++i)
        if (alive_[i] && parent_[i] == kNone) ++n;
    return n;
}

void World::step() {
    using clock = std::chrono::steady_clock;
    using ms = std::chrono::duration<double, std::milli>;
    const auto t_start = clock::now();
    // where each particle starts the step counts toward its highest point (unexplained_speed):
    // growth and the climber place particles between steps
    highest_.resize(x_.size(), -std::numeric_limits<double>::infinity());
    for (std::size_t i = 0; i < x_.size(); ++i)
        if (alive_[i]) highest_[i] = std::max(highest_[i], -glm::dot(settings_.gravity, x_[i]));
    if (settings_.energy_budget) open_energy_budget();
    predict();
    pull_to_anchors();
    refresh_groups();
    match_shapes_passes();
    auto t0 = clock::now();
    if (settings_.collisions) separate_particles();
    // contacts and obstacles push particles: the links get their lengths back (length.cpp)
    keep_shape(false, false);
    // and the links between particles, as capsules, out of the obstacles (segment_contacts.cpp)
    weigh_particles();
    resolve_segments(true);
    // and the links of different plants, as capsules, apart (link_contacts.cpp)
    if (settings_.collisions && settings_.link_collisions) part_plants();
    double collision_ms = ms(clock::now() - t0).count();
    t0 = clock::now();
    integrate();
    if (settings_.energy_budget) close_energy_budget();
    collision_ms += ms(clock::now() - t0).count();
    double fastest = 0; // squared
    for (std::size_t i = 0; i < x_.size(); ++i) {
        if (!alive_[i]) continue;
        const double speed2 = glm::dot(v_[i], v_[i]), phi = -glm::dot(settings_.gravity, x_[i]);
        fastest = std::max(fastest, speed2);
        highest_[i] = std::max(highest_[i], phi);
        unexplained_speed_ =
            std::max(unexplained_speed_, std::sqrt(speed2) - std::sqrt(2 * (highest_[i] - phi)));
    }
    peak_speed_ = std::max(peak_speed_, std::sqrt(fastest));
    if (break_threshold_ > 0) break_overstretched();
    pulls_.clear();
    times_.collision = collision_ms;
    times_.dynamics = ms(clock::now() - t_start).count() - collision_ms;
}

void World::predict() {
    const double dt = settings_.dt;
    const std::size_t n = x_.size();
    Array<glm::dvec3>& old = scratch_.old;
    old.resize(n);
    // Eq. 1: predicted positions; a_e is the steady wind plus what the fluid pushed (Fluid::step)
    if (external_.size() < n) external_.resize(n, glm::dvec3(0.0));
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            old[i] = x_[i];
            if (alive_[i] && !fixed_[i])
                x_[i] = x_[i] + v_[i] * dt + (settings_.gravity + wind_ + external_[i]) * (dt * dt / 2);
            external_[i] = glm::dvec3(0.0);
        }
    });
}

void World::pull_to_anchors() {
    // Eq. 5: anchors pull their particles in; one too far away lets go
    for (std::size_t k = 0; k < anchors_.size();) {
        Anchor& a = anchors_[k];
        const glm::dvec3 point = anchor_point(a); // where its obstacle has it now
        if (glm::length(x_[a.particle] - point) > a.release) {
            anchors_.erase(anchors_.begin() + static_cast<std::ptrdiff_t>(k));
            continue;
        }
        x_[a.particle] += a.phi * (point - x_[a.particle]);
        ++k;
    }
}

void World::break_overstretched() {
    // breaking: a connection stretched past the threshold lets its child go (section 4.3)
    const std::size_t n = x_.size();
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t p = parent_[i];
        if (!alive_[i] || p == kNone) continue;
        double rest = glm::length(rest_x_[i] - rest_x_[p]);
        double now = glm::length(x_[i] - x_[p]);
        if (rest > 0 && std::fabs(now - rest) / rest > break_threshold_) {
            detach(i); // the loose part keeps its own shape and falls
        }
    }
}

std::uint64_t World::state_hash() const {
    // FNV-1a over the bytes of positions, velocities and orientations
    std::uint64_t h = 1469598103934665603ULL;
    auto eat = [&](const void* p, std::size_t bytes) {
        const auto* b = static_cast<const unsigned char*>(p);
        for (std::size_t k = 0; k < bytes; ++k) h = (h ^ b[k]) * 1099511628211ULL;
    };
    for (std::size_t i = 0; i < x_.size(); ++i) {
        eat(&x_[i], sizeof(glm::dvec3));
        eat(&v_[i], sizeof(glm::dvec3));
        eat(&q_[i], sizeof(glm::dquat));
    }
    return h;
}

} // namespace plant::physics
