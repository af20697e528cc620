// Growth and branching (Hädrich et al., section 4.2-4.3): the growth directions (Eq. 6-7), apical
// growth with lateral buds, and new particles entering the rest state (Eq. 9-10).
#define GLM_ENABLE_EXPERIMENTAL // glm::rotation (gtx/quaternion)
#include "plant/physics/light.hpp"
#include "plant/physics/world.hpp"
#include "plant/random.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/gtx/quaternion.hpp>

namespace plant::physics {

glm::dvec3 surface_adaption(const glm::dvec3& forward, const glm::dvec3& to_surface, double tau, double dt) {
    glm::dvec3 f = glm::normalize(forward), s = glm::normalize(to_surface);
    // Eq. 6: about v_s x v_f by (v_s . v_f) tau dt: a forward vector leaning into the surface
    // turns away from it, toward the tangent plane, and one parallel to it stays
    glm::dvec3 axis = glm::cross(s, f);
    double len = glm::length(axis);
    if (len < 1e-12) return f;
    double angle = glm::dot(s, f) * tau * dt;
    return glm::normalize(glm::angleAxis(angle, axis / len) * f);
}

glm::dvec3 phototropism(const glm::dvec3& forward, const glm::dvec3& to_light, double occlusion, double eta,
                        double dt) {
    glm::dvec3 f = glm::normalize(forward), l = glm::normalize(to_light);
    glm::dvec3 axis = glm::cross(f, l); // toward the light (docs/physics.md: not the printed v_l x v_f)
    double len = glm::length(axis);
    if (len < 1e-12) return f;
    // Eq. 7, and never past the light direction itself
    double angle = std::min((1 - std::clamp(occlusion, 0.0, 1.0)) * eta * dt,
                            std::acos(std::clamp(glm::dot(f, l), -1.0, 1.0)));
    return glm::normalize(glm::angleAxis(angle, axis / len) * f);
}

Handle World::add_grown(Handle parent, const glm::dvec3& position_in, const glm::dquat& orientation_in,
                        const glm::dvec3& radii) {
    const glm::dvec3 position = position_in;
    const glm::dquat orientation = orientation_in;
    Handle h = add_particle(parent, position, orientation, radii);
    // Hädrich et al., Eq. 9-10: growth enters the rest state too. The turn taking the parent's
    // current frame to its rest frame carries the new particle's offset and orientation over.
    // The offset goes back by the parent's turn as the length and bending sweep reads it
    // (keep_shape(): the segment into the parent), so a new particle starts where the sweep
    // holds it.
    const std::uint32_t p = parent.index, i = h.index;
    const glm::dquat back = glm::normalize(rest_q_[p] * glm::inverse(q_[p]));
    rest_x_[i] = rest_x_[p] + carried(p, position - x_[p], true);
    rest_q_[i] = glm::normalize(back * orientation);
    return h;
}

void World::set_radii(Handle h, const glm::dvec3& radii) {
    if (!alive(h)) return;
    radii_[h.index] = radii;
    // Hädrich et al., Eq. 2: the mass of an ellipsoid
    m_[h.index] = 4.0 * std::numbers::pi * radii.x * radii.y * radii.z * settings_.density / 3.0;
    groups_stale_ = true;
}

namespace {

// Counter-based random numbers (plant/random.hpp): a draw depends on (seed, particle, draw).
double random_unit(std::uint64_t seed, std::uint64_t particle, std::uint64_t draw) {
    return plant::random_unit(plant::random_bits(seed, particle, draw));
}

glm::dquat heading_to(const glm::dvec3& forward) {
    return glm::rotation(glm::dvec3(0, 1, 0), glm::normalize(forward));
}

} // namespace

void World::grow() {
    const Growth& g = settings_.growth;
    const std::size_t n = x_.size();
    // the plant's shade as it stands before this growth (Eq. 7's O), counted when the first
    // apex of this call turns: most calls only lengthen apices
    LightGrid shade;
    bool shade_counted = false;
    auto occlusion = [&](const glm::dvec3& p) {
        if (!shade_counted) {
            Array<glm::dvec3> points;
            for (std::size_t k = 0; k < n; ++k)
                if (alive_[k]) points.push_back(x_[k]);
            shade.build(points, g.light_cell);
            shade_counted = true;
        }
        return scene_occlusion(shade, obstacles_, g.obstacle_shade, p, glm::normalize(g.to_light), g.opacity,
                               g.diffuse);
    };
    for (std::uint32_t i = 0; i < n && x_.size() < g.max_particles; ++i) {
        if (!alive_[i] || !children_[i].empty()) continue;
        length_[i] += g.speed * settings_.dt;
        if (length_[i] < g.segment_length) continue;
        length_[i] = 0;
        glm::dvec3 f = q_[i] * glm::dvec3(0, 1, 0);
        // Eq. 6: the nearest obstacle in range steers the apex parallel to its surface
        if (g.adaption > 0) {
            double best = g.adaption_range;
            const Obstacle* near = nullptr;
            for (const auto& o : obstacles_) {
                double d = o.distance(x_[i]);
                if (d < best) best = d, near = &o;
            }
            if (near) f = surface_adaption(f, -near->normal(x_[i]), g.adaption, settings_.dt * 40);
        }
        // Eq. 7, turning less in the plant's shade
        if (g.phototropism > 0) {
            f = phototropism(f, g.to_light, occlusion(x_[i]), g.phototropism, settings_.dt * 40);
        }
        // never grow into an obstacle: the new segment, as a capsule, clear of all of them
        const glm::dvec3 pos = clear_segment_end(x_[i], x_[i] + f * g.segment_length, radii_[i].x);
        Handle parent{i, generation_[i]};
        add_grown(parent, pos, heading_to(f), radii_[i]);
        // lateral branching with probability BP, at most B buds per particle
        for (int b = 0; b < g.max_lateral && x_.size() < g.max_particles; ++b) {
            if (random_unit(g.seed, i, 3 * static_cast<std::uint64_t>(b)) >= g.branch_probability) continue;
            double angle = random_unit(g.seed, i, 3 * static_cast<std::uint64_t>(b) + 1) * g.branch_variance *
                           std::numbers::pi / 2;
            double around =
                random_unit(g.seed, i, 3 * static_cast<std::uint64_t>(b) + 2) * 2 * std::numbers::pi;
            glm::dvec3 side = glm::normalize(
                glm::cross(f, std::fabs(f.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0)));
            glm::dvec3 axis = glm::angleAxis(around, f) * side;
            glm::dvec3 lf = glm::angleAxis(angle, axis) * f;
            const glm::dvec3 at =
                clear_segment_end(x_[i], x_[i] + lf * g.segment_length, radii_[i].x * g.falloff);
            add_grown(parent, at, heading_to(lf), radii_[i] * g.falloff);
            ++laterals_[i];
        }
    }
}

} // namespace plant::physics
