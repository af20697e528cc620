#include "plant/physics/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>

namespace plant::physics {

namespace {

constexpr double kFixedMass = 1e12; // "effectively infinite" inside group sums (PLANTS.md pitfall)
constexpr std::uint32_t kNone = ~0u;

glm::dmat3 outer(const glm::dvec3& a, const glm::dvec3& b) {
    // glm is column-major: column j is a * b[j]
    return glm::dmat3(a * b.x, a * b.y, a * b.z);
}

} // namespace

glm::dquat extract_rotation(const glm::dmat3& A, glm::dquat q, int iterations) {
    // Müller et al. 2016, Eq. 10-12: turn R toward the columns of A about omega
    for (int k = 0; k < iterations; ++k) {
        glm::dmat3 R = glm::mat3_cast(q);
        glm::dvec3 omega = glm::cross(R[0], A[0]) + glm::cross(R[1], A[1]) + glm::cross(R[2], A[2]);
        double denom = std::fabs(glm::dot(R[0], A[0]) + glm::dot(R[1], A[1]) + glm::dot(R[2], A[2])) + 1e-9;
        omega /= denom;
        double w = glm::length(omega);
        if (!(w >= 1e-9)) break; // converged, or nothing to match (zero A), or NaN
        q = glm::normalize(glm::angleAxis(w, omega / w) * q);
    }
    return q;
}

Handle World::add_root(const glm::dvec3& position, const glm::dquat& orientation, const glm::dvec3& radii,
                       bool fixed) {
    Handle h{static_cast<std::uint32_t>(x_.size()), 0};
    x_.push_back(position);
    v_.emplace_back(0.0);
    rest_x_.push_back(position);
    radii_.push_back(radii);
    q_.push_back(orientation);
    rest_q_.push_back(orientation);
    // Hädrich et al., Eq. 2: the mass of an ellipsoid
    m_.push_back(4.0 * std::numbers::pi * radii.x * radii.y * radii.z * settings_.density / 3.0);
    age_.push_back(0);
    parent_.push_back(kNone);
    generation_.push_back(0);
    children_.emplace_back();
    fixed_.push_back(fixed ? 1 : 0);
    alive_.push_back(1);
    return h;
}

Handle World::add_particle(Handle parent, const glm::dvec3& position, const glm::dquat& orientation,
                           const glm::dvec3& radii) {
    Handle h = add_root(position, orientation, radii, false);
    parent_[h.index] = parent.index;
    children_[parent.index].push_back(h.index);
    return h;
}

bool World::alive(Handle h) const {
    return h.index < x_.size() && generation_[h.index] == h.generation && alive_[h.index];
}

std::vector<std::uint32_t> World::group(std::uint32_t i) const {
    std::vector<std::uint32_t> g;
    if (parent_[i] != kNone) g.push_back(parent_[i]);
    g.push_back(i);
    for (std::uint32_t c : children_[i]) g.push_back(c);
    return g;
}

double World::stiffness(std::uint32_t i) const {
    if (settings_.fixed_stiffness >= 0) return std::min(1.0, settings_.fixed_stiffness);
    // s = t_l / t_m, clamped to [0, 1]; t_l starts at 0.2 (section 4.3)
    return std::clamp((0.2 + age_[i]) / settings_.stiffening_time, 0.0, 1.0);
}

glm::dquat World::group_rotation(std::uint32_t i) const {
    const auto g = group(i);
    double M = 0;
    glm::dvec3 c(0.0), rc(0.0);
    for (std::uint32_t j : g) {
        double m = fixed_[j] ? kFixedMass : m_[j];
        M += m;
        c += m * x_[j];
        rc += m * rest_x_[j];
    }
    c /= M;
    rc /= M;
    // Eq. 14 with Eq. 15's ellipsoid moment written R D R̄ᵀ (PLANTS.md pitfall), positions
    // relative to the centers to keep the sums well conditioned
    glm::dmat3 A(0.0);
    for (std::uint32_t j : g) {
        double m = fixed_[j] ? kFixedMass : m_[j];
        const glm::dvec3& r = radii_[j];
        glm::dmat3 D(0.0);
        D[0][0] = r.x * r.x, D[1][1] = r.y * r.y, D[2][2] = r.z * r.z;
        A += 0.2 * m * glm::mat3_cast(q_[j]) * D * glm::transpose(glm::mat3_cast(rest_q_[j]));
        A += m * outer(x_[j] - c, rest_x_[j] - rc);
    }
    // warm start: the particle's own rotation from rest
    glm::dquat warm = glm::normalize(q_[i] * glm::inverse(rest_q_[i]));
    return extract_rotation(A, warm);
}

std::vector<glm::dvec3> World::goals() const {
    const std::size_t n = x_.size();
    std::vector<glm::dvec3> sum(n, glm::dvec3(0.0));
    std::vector<double> weight(n, 0.0);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        const auto g = group(i);
        double M = 0;
        glm::dvec3 c(0.0), rc(0.0);
        for (std::uint32_t j : g) {
            double m = fixed_[j] ? kFixedMass : m_[j];
            M += m;
            c += m * x_[j];
            rc += m * rest_x_[j];
        }
        c /= M;
        rc /= M;
        glm::dmat3 R = glm::mat3_cast(group_rotation(i));
        for (std::uint32_t j : g) {
            // Eq. 3: the target of member j in group i; Eq. 4: weighted by mass, the group of a
            // particle's parent counting twice as much as its own, its children's half
            glm::dvec3 target = R * (rest_x_[j] - rc) + c;
            double w = m_[j] * (j == i ? 1.0 : (i == parent_[j] ? 2.0 : 0.5));
            sum[j] += w * target;
            weight[j] += w;
        }
    }
    std::vector<glm::dvec3> out(n);
    for (std::size_t j = 0; j < n; ++j) out[j] = weight[j] > 0 ? sum[j] / weight[j] : x_[j];
    return out;
}

void World::step() {
    const double dt = settings_.dt;
    const std::size_t n = x_.size();
    std::vector<glm::dvec3> old = x_;
    // Eq. 1: predicted positions (no fluid acceleration yet)
    for (std::size_t i = 0; i < n; ++i)
        if (alive_[i] && !fixed_[i]) x_[i] = x_[i] + v_[i] * dt + settings_.gravity * (dt * dt / 2);
    // shape matching on the predictions; small overlapping groups pass a correction on by one
    // particle per iteration, so a chain needs several to hold its shape
    std::vector<glm::dquat> rot(n);
    for (int it = 0; it < settings_.iterations; ++it) {
        std::vector<glm::dvec3> goal = goals();
        for (std::uint32_t i = 0; i < n; ++i) rot[i] = alive_[i] ? group_rotation(i) : q_[i];
        for (std::uint32_t i = 0; i < n; ++i) {
            if (!alive_[i]) continue;
            if (fixed_[i]) {
                x_[i] = rest_x_[i];
                continue;
            }
            // x'_g = x_p + s (x_g - x_p) (section 4.3)
            x_[i] = x_[i] + stiffness(i) * (goal[i] - x_[i]);
            q_[i] = glm::normalize(glm::slerp(q_[i], glm::normalize(rot[i] * rest_q_[i]), stiffness(i)));
        }
    }
    // Eq. 17-18, with damping
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        v_[i] = fixed_[i] ? glm::dvec3(0.0) : (x_[i] - old[i]) / dt * (1.0 - settings_.damping);
        age_[i] += dt;
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
