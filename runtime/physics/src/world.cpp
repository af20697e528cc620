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

glm::dvec3 phototropism(const glm::dvec3& forward, const glm::dvec3& to_light, double occlusion, double eta, double dt) {
    glm::dvec3 f = glm::normalize(forward), l = glm::normalize(to_light);
    glm::dvec3 axis = glm::cross(f, l); // toward the light (PLANTS.md pitfall)
    double len = glm::length(axis);
    if (len < 1e-12) return f;
    // Eq. 7, and never past the light direction itself
    double angle = std::min((1 - std::clamp(occlusion, 0.0, 1.0)) * eta * dt, std::acos(std::clamp(glm::dot(f, l), -1.0, 1.0)));
    return glm::normalize(glm::angleAxis(angle, axis / len) * f);
}

double Obstacle::distance(const glm::dvec3& p) const {
    switch (kind) {
    case Sphere: return glm::length(p - a) - b.x;
    case Box: {
        glm::dvec3 c = (a + b) * 0.5, h = (b - a) * 0.5, q = glm::abs(p - c) - h;
        return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
    case Plane: return glm::dot(p - a, glm::normalize(b));
    }
    return 1e300;
}

glm::dvec3 Obstacle::normal(const glm::dvec3& p) const {
    if (kind == Plane) return glm::normalize(b);
    // central differences of the distance
    const double e = 1e-6;
    glm::dvec3 g(distance(p + glm::dvec3(e, 0, 0)) - distance(p - glm::dvec3(e, 0, 0)),
                 distance(p + glm::dvec3(0, e, 0)) - distance(p - glm::dvec3(0, e, 0)),
                 distance(p + glm::dvec3(0, 0, e)) - distance(p - glm::dvec3(0, 0, e)));
    double l = glm::length(g);
    return l > 0 ? g / l : glm::dvec3(0, 1, 0);
}

void World::add_anchor(Handle h, const glm::dvec3& point, double phi, double release) {
    anchors_.push_back({h.index, point, std::clamp(phi, 0.0, 1.0), release});
}

bool World::anchored(Handle h) const {
    for (const auto& a : anchors_)
        if (a.particle == h.index) return true;
    return false;
}

std::size_t World::components() const {
    std::size_t n = 0;
    for (std::size_t i = 0; i < x_.size(); ++i)
        if (alive_[i] && parent_[i] == kNone) ++n;
    return n;
}

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
    // Eq. 5: anchors pull their particles in; one too far away lets go
    for (std::size_t k = 0; k < anchors_.size();) {
        Anchor& a = anchors_[k];
        if (glm::length(x_[a.particle] - a.point) > a.release) {
            anchors_.erase(anchors_.begin() + static_cast<std::ptrdiff_t>(k));
            continue;
        }
        x_[a.particle] += a.phi * (a.point - x_[a.particle]);
        ++k;
    }
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
        for (const auto& [i, target] : pulls_) x_[i] = target; // a dragged particle goes where it is dragged
    }
    // Eq. 17-18, with damping; then obstacles: a particle inside one is put back on its surface
    // (its radius off it), its velocity losing the normal part (or bouncing by the elasticity)
    // and some of the tangential part (friction)
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        v_[i] = fixed_[i] ? glm::dvec3(0.0) : (x_[i] - old[i]) / dt * (1.0 - settings_.damping);
        age_[i] += dt;
        if (fixed_[i]) continue;
        const double r = std::min({radii_[i].x, radii_[i].y, radii_[i].z});
        for (const auto& o : obstacles_) {
            double d = o.distance(x_[i]) - r;
            if (d >= 0) continue;
            glm::dvec3 nrm = o.normal(x_[i]);
            x_[i] -= nrm * d;
            double vn = glm::dot(v_[i], nrm);
            glm::dvec3 tangential = v_[i] - nrm * vn;
            v_[i] = tangential * (1 - o.friction) + (vn < 0 ? -vn * o.elasticity : vn) * nrm;
        }
    }
    // breaking: a connection stretched past the threshold lets its child go (section 4.3)
    if (break_threshold_ > 0) {
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t p = parent_[i];
            if (!alive_[i] || p == kNone) continue;
            double rest = glm::length(rest_x_[i] - rest_x_[p]);
            double now = glm::length(x_[i] - x_[p]);
            if (rest > 0 && std::fabs(now - rest) / rest > break_threshold_) {
                auto& siblings = children_[p];
                siblings.erase(std::remove(siblings.begin(), siblings.end(), i), siblings.end());
                parent_[i] = kNone; // the loose part keeps its own shape and falls
            }
        }
    }
    pulls_.clear();
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
