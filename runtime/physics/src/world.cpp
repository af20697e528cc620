#define GLM_ENABLE_EXPERIMENTAL // glm::rotation (gtx/quaternion)
#include "plant/physics/world.hpp"

#include "parallel.hpp"
#include "plant/physics/light.hpp"
#include "plant/random.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <thread>

#include <glm/gtx/quaternion.hpp>

namespace plant::physics {

namespace {

constexpr double kFixedMass = 1e12; // "effectively infinite" inside group sums (docs/physics.md, root)

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

double Obstacle::distance(const glm::dvec3& p) const {
    switch (kind) {
    case Sphere:
        return glm::length(p - a) - b.x;
    case Box: {
        glm::dvec3 c = (a + b) * 0.5, h = (b - a) * 0.5, q = glm::abs(p - c) - h;
        return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    }
    case Plane:
        return glm::dot(p - a, glm::normalize(b));
    case Grid:
        return grid ? grid->sample(p - a) : 1e300;
    }
    return 1e300;
}

double DistanceGrid::sample(const glm::dvec3& p) const {
    if (d.empty()) return 1e300;
    const glm::dvec3 hi = lo + glm::dvec3(n - 1) * cell;
    const glm::dvec3 q = glm::clamp(p, lo, hi);
    const double outside = glm::length(p - q);
    const glm::dvec3 u = (q - lo) / cell;
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(u)), glm::ivec3(0), glm::max(n - 2, glm::ivec3(0)));
    const glm::dvec3 f = glm::clamp(u - glm::dvec3(c), 0.0, 1.0);
    auto at = [&](int x, int y, int z) {
        x = std::min(x, n.x - 1), y = std::min(y, n.y - 1), z = std::min(z, n.z - 1);
        return d[(static_cast<std::size_t>(z) * n.y + y) * n.x + x];
    };
    auto lerp = [](double a0, double a1, double t) { return a0 + (a1 - a0) * t; };
    const double x00 = lerp(at(c.x, c.y, c.z), at(c.x + 1, c.y, c.z), f.x);
    const double x10 = lerp(at(c.x, c.y + 1, c.z), at(c.x + 1, c.y + 1, c.z), f.x);
    const double x01 = lerp(at(c.x, c.y, c.z + 1), at(c.x + 1, c.y, c.z + 1), f.x);
    const double x11 = lerp(at(c.x, c.y + 1, c.z + 1), at(c.x + 1, c.y + 1, c.z + 1), f.x);
    return lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z) + outside;
}

glm::dvec3 Obstacle::normal(const glm::dvec3& p) const {
    if (kind == Plane) return glm::normalize(b);
    // central differences of the distance (over half a cell for a sampled grid)
    const double e = kind == Grid && grid ? grid->cell / 2 : 1e-6;
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

namespace {

// The turn by |omega| about omega as a quaternion (cos(w/2), sin(w/2) omega / w), given
// w2 = |omega|^2: cw = cos(w/2), sw = sin(w/2) / w. Warm-started, the turns are small; below
// w2 = 1e-4 the series to w^6 is exact to double precision (the next terms are below 1e-22)
// and needs neither sqrt nor sincos. A template so that frame_pair's lanes (v2) compute it with
// the same operations as the scalar code.
template <class T> void small_turn(T w2, T& cw, T& sw) {
    cw = 1.0 - w2 * (1.0 / 8.0 - w2 * (1.0 / 384.0 - w2 * (1.0 / 46080.0)));
    sw = 0.5 - w2 * (1.0 / 48.0 - w2 * (1.0 / 3840.0 - w2 * (1.0 / 645120.0)));
}
void large_turn(double w2, double& cw, double& sw) {
    const double w = std::sqrt(w2);
    cw = std::cos(0.5 * w);
    sw = std::sin(0.5 * w) / w;
}

// Müller et al. 2016, Eq. 10-12: turn R toward the columns of A about omega. Also gives R as a
// matrix: the last one computed when the iterations stop on convergence. With `have_matrix`,
// `matrix` holds q's already (a warm start from the last pass keeps it).
glm::dquat rotation_of(const glm::dmat3& A, glm::dquat q, int iterations, glm::dmat3& matrix,
                       bool have_matrix = false) {
    bool current = have_matrix; // whether `matrix` is q's
    for (int k = 0; k < iterations; ++k) {
        if (!current) matrix = glm::mat3_cast(q);
        current = true;
        glm::dvec3 omega =
            glm::cross(matrix[0], A[0]) + glm::cross(matrix[1], A[1]) + glm::cross(matrix[2], A[2]);
        double denom =
            std::fabs(glm::dot(matrix[0], A[0]) + glm::dot(matrix[1], A[1]) + glm::dot(matrix[2], A[2])) +
            1e-9;
        omega *= 1.0 / denom;
        const double w2 = glm::dot(omega, omega);
        if (!(w2 >= 1e-18)) break; // |omega| below 1e-9: converged, or nothing to match (zero A), or NaN
        double cw, sw;
        if (w2 < 1e-4)
            small_turn(w2, cw, sw);
        else
            large_turn(w2, cw, sw);
        q = glm::normalize(glm::dquat(cw, omega.x * sw, omega.y * sw, omega.z * sw) * q);
        current = false;
    }
    if (!current) matrix = glm::mat3_cast(q);
    return q;
}

// Two lanes of doubles (SSE2 on x86-64, NEON on arm64; GCC and Clang vector extensions). Each
// lane does exactly the scalar code's operations in the same order, so results do not depend on
// which groups go through here: IEEE arithmetic, division and square root round the same in a
// lane as alone, and the build forbids fusing a multiply and an add (-ffp-contract=off).
using v2 = double __attribute__((vector_size(16)));
using m2 = long long __attribute__((vector_size(16)));

inline v2 both(double a) {
    return v2{a, a};
}

struct Quat2 {
    v2 w, x, y, z;
};
struct Mat2 {
    v2 m[3][3]; // column-major, as glm: m[column][row]
};

// glm::mat3_cast, lane by lane
inline Mat2 mat3_cast2(const Quat2& q) {
    const v2 one = both(1.0), two = both(2.0);
    const v2 qxx = q.x * q.x, qyy = q.y * q.y, qzz = q.z * q.z;
    const v2 qxz = q.x * q.z, qxy = q.x * q.y, qyz = q.y * q.z;
    const v2 qwx = q.w * q.x, qwy = q.w * q.y, qwz = q.w * q.z;
    Mat2 r;
    r.m[0][0] = one - two * (qyy + qzz);
    r.m[0][1] = two * (qxy + qwz);
    r.m[0][2] = two * (qxz - qwy);
    r.m[1][0] = two * (qxy - qwz);
    r.m[1][1] = one - two * (qxx + qzz);
    r.m[1][2] = two * (qyz + qwx);
    r.m[2][0] = two * (qxz + qwy);
    r.m[2][1] = two * (qyz - qwx);
    r.m[2][2] = one - two * (qxx + qyy);
    return r;
}

} // namespace

glm::dquat extract_rotation(const glm::dmat3& A, glm::dquat q, int iterations) {
    glm::dmat3 matrix;
    return rotation_of(A, q, iterations, matrix);
}

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

Handle World::add_grown(Handle parent, const glm::dvec3& position_in, const glm::dquat& orientation_in,
                        const glm::dvec3& radii) {
    const glm::dvec3 position = position_in;
    const glm::dquat orientation = orientation_in;
    Handle h = add_particle(parent, position, orientation, radii);
    // Hädrich et al., Eq. 9-10: growth enters the rest state too. The turn taking the parent's
    // current frame to its rest frame carries the new particle's offset and orientation over.
    const std::uint32_t p = parent.index, i = h.index;
    const glm::dquat back = glm::normalize(rest_q_[p] * glm::inverse(q_[p]));
    rest_x_[i] = rest_x_[p] + back * (position - x_[p]);
    rest_q_[i] = glm::normalize(back * orientation);
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

bool World::attached(Handle h) const {
    if (!alive(h)) return false;
    std::uint32_t i = h.index;
    while (parent_[i] != kNone) i = parent_[i];
    return fixed_[i] != 0;
}

bool World::alive(Handle h) const {
    return h.index < x_.size() && generation_[h.index] == h.generation && alive_[h.index];
}

double World::stiffness(std::uint32_t i) const {
    if (settings_.fixed_stiffness >= 0) return std::min(1.0, settings_.fixed_stiffness);
    // s = t_l / t_m, clamped to [0, 1]; t_l starts at 0.2 (section 4.3)
    return std::clamp((0.2 + age_[i]) / settings_.stiffening_time, 0.0, 1.0);
}

double World::matching_mass(std::uint32_t j) const {
    return fixed_[j] ? kFixedMass : m_[j];
}

glm::dmat3 World::rest_moment(std::uint32_t j) const {
    // Eq. 15's term for one member is 0.2 m R D R̄ᵀ (docs/physics.md); this is its rest part,
    // 0.2 m D R̄ᵀ, which only growth changes
    const glm::dvec3& r = radii_[j];
    glm::dmat3 D(0.0);
    D[0][0] = r.x * r.x, D[1][1] = r.y * r.y, D[2][2] = r.z * r.z;
    return 0.2 * matching_mass(j) * D * glm::transpose(glm::mat3_cast(rest_q_[j]));
}

glm::dmat3 World::ellipsoid_moment(std::uint32_t j) const {
    return glm::mat3_cast(q_[j]) * rest_moment(j);
}

void World::group_moments(const Groups& g, std::vector<glm::dmat3>& each,
                          std::vector<glm::dmat3>& sums) const {
    const std::size_t n = x_.size();
    each.resize(n);
    sums.resize(n);
    // Eq. 15's moment R D R̄ᵀ: the rest part D R̄ᵀ (with the mass) changes only with growth and
    // is kept with the groups (step()); here only the current rotation enters
    const bool cached = !groups_stale_ && scratch_.rest_moment.size() == n;
    auto one = [&](std::size_t j) {
        if (alive_[j])
            each[j] = cached ? glm::mat3_cast(q_[j]) * scratch_.rest_moment[j]
                             : ellipsoid_moment(static_cast<std::uint32_t>(j));
    };
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        std::size_t j = b;
        if (cached) // two particles at a time, lane by lane as the line above
            for (; j + 1 < e; j += 2) {
                if (!alive_[j] || !alive_[j + 1]) {
                    one(j), one(j + 1);
                    continue;
                }
                const glm::dquat &qa = q_[j], &qb = q_[j + 1];
                const Mat2 R = mat3_cast2({v2{qa.w, qb.w}, v2{qa.x, qb.x}, v2{qa.y, qb.y}, v2{qa.z, qb.z}});
                const glm::dmat3 &ra = scratch_.rest_moment[j], &rb = scratch_.rest_moment[j + 1];
                for (int c = 0; c < 3; ++c) {
                    const v2 b0{ra[c][0], rb[c][0]}, b1{ra[c][1], rb[c][1]}, b2{ra[c][2], rb[c][2]};
                    for (int r = 0; r < 3; ++r) { // glm's mat3 * mat3
                        const v2 m = R.m[0][r] * b0 + R.m[1][r] * b1 + R.m[2][r] * b2;
                        each[j][c][r] = m[0];
                        each[j + 1][c][r] = m[1];
                    }
                }
            }
        for (; j < e; ++j) one(j);
    });
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            glm::dmat3 M(0.0);
            for (std::uint32_t k = g.start[i]; k < g.start[i + 1]; ++k) M += each[g.member[k].particle];
            sums[i] = M;
        }
    });
}

void World::group_frame(std::uint32_t i, glm::dquat warm, const glm::dmat3& moment, int iterations,
                        const Groups& g, Frame& out, bool warm_matrix) const {
    // Eq. 14 with Eq. 15's ellipsoid moments (summed over the group already), positions
    // relative to the centers to keep the sums well conditioned
    const Groups::Member* from = g.member.data() + g.start[i];
    const Groups::Member* to = g.member.data() + g.start[i + 1];
    // (In local variables: written through glm's operators into `out`, every sum is stored
    // and loaded again, since `out` might alias the positions.)
    const glm::dvec3* x = x_.data();
    double cx = 0, cy = 0, cz = 0;
    for (const auto* k = from; k < to; ++k) {
        const glm::dvec3& p = x[k->particle];
        cx += k->share * p.x;
        cy += k->share * p.y;
        cz += k->share * p.z;
    }
    // A = moment + the sum of outer(x_k - c, mr_k), column j being (x_k - c) mr_k[j]
    double a00 = moment[0][0], a01 = moment[0][1], a02 = moment[0][2], a10 = moment[1][0], a11 = moment[1][1],
           a12 = moment[1][2], a20 = moment[2][0], a21 = moment[2][1], a22 = moment[2][2];
    for (const auto* k = from; k < to; ++k) {
        const glm::dvec3& p = x[k->particle];
        const double dx = p.x - cx, dy = p.y - cy, dz = p.z - cz;
        const glm::dvec3& mr = k->mr;
        a00 += dx * mr.x, a01 += dy * mr.x, a02 += dz * mr.x;
        a10 += dx * mr.y, a11 += dy * mr.y, a12 += dz * mr.y;
        a20 += dx * mr.z, a21 += dy * mr.z, a22 += dz * mr.z;
    }
    const glm::dmat3 A(a00, a01, a02, a10, a11, a12, a20, a21, a22);
    out.c = glm::dvec3(cx, cy, cz);
    out.R = rotation_of(A, warm, iterations, out.M, warm_matrix);
    out.valid = true;
}

glm::dquat World::group_rotation(std::uint32_t i) const {
    Groups g;
    build_groups(g);
    glm::dmat3 moment(0.0);
    for_group(i, [&](std::uint32_t j) { moment += ellipsoid_moment(j); });
    Frame f;
    group_frame(i, rotation_from_rest(i), moment, 20, g, f);
    return f.R;
}

void World::build_groups(Groups& g) const {
    const std::size_t n = x_.size();
    g.start.assign(n + 1, 0);
    g.member.clear();
    g.rest_center.assign(n, glm::dvec3(0.0));
    for (std::uint32_t i = 0; i < n; ++i) {
        g.start[i] = static_cast<std::uint32_t>(g.member.size());
        if (!alive_[i]) continue;
        double M = 0;
        glm::dvec3 rc(0.0);
        for_group(i, [&](std::uint32_t j) {
            const double m = matching_mass(j);
            M += m;
            rc += m * rest_x_[j];
            g.member.push_back({j, m, glm::dvec3(0.0)});
        });
        rc /= M;
        g.rest_center[i] = rc;
        for (std::size_t k = g.start[i]; k < g.member.size(); ++k) {
            auto& e = g.member[k];
            e.mr = e.share * (rest_x_[e.particle] - rc);
            e.share /= M;
        }
    }
    g.start[n] = static_cast<std::uint32_t>(g.member.size());
    // goal sources: its own group, its parent's (twice the weight), its children's (half)
    g.source_start.assign(n + 1, 0);
    g.source.clear();
    for (std::uint32_t j = 0; j < n; ++j) {
        const auto first = static_cast<std::uint32_t>(g.source.size());
        g.source_start[j] = first;
        double W = 0;
        auto add = [&](std::uint32_t i, double w) {
            if (!alive_[i]) return;
            g.source.push_back({i, w, rest_x_[j] - g.rest_center[i]});
            W += w;
        };
        // Eq. 4's weights are all j's mass times these factors; divided by their sum the mass
        // drops out (and a massless particle still has a goal)
        add(j, 1.0);
        if (parent_[j] != kNone) add(parent_[j], 2.0);
        for (std::uint32_t c : children_[j]) add(c, 0.5);
        for (std::size_t k = first; k < g.source.size(); ++k) g.source[k].weight /= W;
    }
    g.source_start[n] = static_cast<std::uint32_t>(g.source.size());
}

void World::frame_pair(const std::uint32_t (&group)[2], const std::vector<glm::dmat3>& moments,
                       const Groups& g, std::vector<Frame>& frames) const {
    // group_frame with one rotation iteration from the last pass's frame, for two groups with
    // the same number of members at once (equal counts: no lane needs padding)
    const Groups::Member* from[2] = {g.member.data() + g.start[group[0]],
                                     g.member.data() + g.start[group[1]]};
    const std::uint32_t count = g.start[group[0] + 1] - g.start[group[0]];
    const glm::dvec3* x = x_.data();
    v2 cx = both(0), cy = both(0), cz = both(0);
    for (std::uint32_t k = 0; k < count; ++k) {
        const Groups::Member &a = from[0][k], &b = from[1][k];
        const glm::dvec3 &pa = x[a.particle], &pb = x[b.particle];
        const v2 share{a.share, b.share};
        cx += share * v2{pa.x, pb.x};
        cy += share * v2{pa.y, pb.y};
        cz += share * v2{pa.z, pb.z};
    }
    v2 A[3][3];
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) A[c][r] = v2{moments[group[0]][c][r], moments[group[1]][c][r]};
    for (std::uint32_t k = 0; k < count; ++k) {
        const Groups::Member &a = from[0][k], &b = from[1][k];
        const glm::dvec3 &pa = x[a.particle], &pb = x[b.particle];
        const v2 d[3] = {v2{pa.x, pb.x} - cx, v2{pa.y, pb.y} - cy, v2{pa.z, pb.z} - cz};
        const v2 mr[3] = {v2{a.mr.x, b.mr.x}, v2{a.mr.y, b.mr.y}, v2{a.mr.z, b.mr.z}};
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) A[c][r] += d[r] * mr[c];
    }
    // rotation_of, one iteration, warm-started from the frames' rotations and their matrices
    Frame* f[2] = {&frames[group[0]], &frames[group[1]]};
    Quat2 q{v2{f[0]->R.w, f[1]->R.w}, v2{f[0]->R.x, f[1]->R.x}, v2{f[0]->R.y, f[1]->R.y},
            v2{f[0]->R.z, f[1]->R.z}};
    Mat2 M;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) M.m[c][r] = v2{f[0]->M[c][r], f[1]->M[c][r]};
    v2 omega[3] = {both(0), both(0), both(0)};
    v2 dots = both(0);
    for (int c = 0; c < 3; ++c) {
        const v2* m = M.m[c];
        const v2* a = A[c];
        // glm::cross(m, a), summed column after column as (c0 + c1) + c2
        const v2 cr[3] = {m[1] * a[2] - a[1] * m[2], m[2] * a[0] - a[2] * m[0], m[0] * a[1] - a[0] * m[1]};
        const v2 dt = (m[0] * a[0] + m[1] * a[1]) + m[2] * a[2];
        for (int r = 0; r < 3; ++r) omega[r] = c == 0 ? cr[r] : omega[r] + cr[r];
        dots = c == 0 ? dt : dots + dt;
    }
    const v2 denom = v2{std::fabs(dots[0]), std::fabs(dots[1])} + both(1e-9);
    const v2 inv = both(1.0) / denom;
    for (auto& o : omega) o *= inv;
    const v2 w2 = (omega[0] * omega[0] + omega[1] * omega[1]) + omega[2] * omega[2];
    const m2 turn = w2 >= both(1e-18); // false: converged or NaN, the lane keeps its frame
    Quat2 n{};
    Mat2 nm{};
    v2 len{};
    if (turn[0] || turn[1]) {
        v2 cw, sw;
        small_turn(w2, cw, sw);
        for (int l = 0; l < 2; ++l)
            if (turn[l] && !(w2[l] < 1e-4)) large_turn(w2[l], cw[l], sw[l]); // as rotation_of
        const Quat2 p{cw, omega[0] * sw, omega[1] * sw, omega[2] * sw};
        // p * q as glm multiplies quaternions, then glm::normalize
        n = {p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
             p.w * q.y + p.y * q.w + p.z * q.x - p.x * q.z, p.w * q.z + p.z * q.w + p.x * q.y - p.y * q.x};
        const v2 len2 = (n.w * n.w + n.x * n.x) + (n.y * n.y + n.z * n.z);
        len = v2{std::sqrt(len2[0]), std::sqrt(len2[1])};
        const v2 one_over = both(1.0) / len;
        n = {n.w * one_over, n.x * one_over, n.y * one_over, n.z * one_over};
        nm = mat3_cast2(n);
    }
    for (int l = 0; l < 2; ++l) {
        Frame& out = *f[l];
        out.c = glm::dvec3(cx[l], cy[l], cz[l]);
        out.valid = true;
        if (!turn[l]) continue;
        if (len[l] <= 0) { // glm::normalize's answer to a zero quaternion (a NaN length stays NaN, as there)
            out.R = glm::dquat(1, 0, 0, 0);
            out.M = glm::mat3_cast(out.R);
            continue;
        }
        out.R = glm::dquat(n.w[l], n.x[l], n.y[l], n.z[l]);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) out.M[c][r] = nm.m[c][r][l];
    }
}

void World::match_shapes(std::vector<Frame>& frames, const std::vector<glm::dmat3>& moments, int iterations,
                         const Groups& g) const {
    const std::size_t n = x_.size();
    frames.resize(n);
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        // groups warm-started with one iteration go two at a time (frame_pair), paired by their
        // number of members: a group waits in `pending` for a partner of its size
        constexpr std::uint32_t kMaxPaired = 8, kNoGroup = ~0u;
        std::uint32_t pending[kMaxPaired + 1];
        std::fill(std::begin(pending), std::end(pending), kNoGroup);
        for (std::size_t k = b; k < e; ++k) {
            const auto i = static_cast<std::uint32_t>(k);
            if (!alive_[i]) continue;
            // warm start from the last pass's rotation when there is one, else from the
            // particle's own rotation from rest; the last pass's matrix goes with its rotation
            const bool last = frames[i].valid;
            const std::uint32_t size = g.start[i + 1] - g.start[i];
            if (last && iterations == 1 && size <= kMaxPaired) {
                if (pending[size] == kNoGroup) {
                    pending[size] = i;
                } else {
                    frame_pair({pending[size], i}, moments, g, frames);
                    pending[size] = kNoGroup;
                }
                continue;
            }
            const glm::dquat warm = last ? frames[i].R : rotation_from_rest(i);
            group_frame(i, warm, moments[i], iterations, g, frames[i], last);
        }
        for (std::uint32_t i : pending)
            if (i != kNoGroup) group_frame(i, frames[i].R, moments[i], iterations, g, frames[i], true);
    });
}

glm::dvec3 World::goal_of(std::uint32_t j, const std::vector<Frame>& frames, const Groups& g) const {
    // Eq. 3: the target of particle j in group i is R_i (x̄_j - c̄_i) + c_i; Eq. 4: j's goal is
    // their mass-weighted mean over the groups j belongs to (its own, its parent's, its
    // children's), its parent's group counting twice as much as its own and its children's half.
    // The weights are divided by their sum already (build_groups); a particle always has its
    // own group.
    double sx = 0, sy = 0, sz = 0; // in local variables, as in group_frame
    const Groups::Source* end = g.source.data() + g.source_start[j + 1];
    for (const auto* k = g.source.data() + g.source_start[j]; k < end; ++k) {
        const Frame& f = frames[k->group];
        const glm::dvec3& o = k->offset;
        // glm's M * o + c, column by column
        const double gx = f.M[0][0] * o.x + f.M[1][0] * o.y + f.M[2][0] * o.z + f.c.x;
        const double gy = f.M[0][1] * o.x + f.M[1][1] * o.y + f.M[2][1] * o.z + f.c.y;
        const double gz = f.M[0][2] * o.x + f.M[1][2] * o.y + f.M[2][2] * o.z + f.c.z;
        sx += k->weight * gx;
        sy += k->weight * gy;
        sz += k->weight * gz;
    }
    return {sx, sy, sz};
}

std::vector<glm::dvec3> World::goals() const {
    std::vector<Frame> frames;
    std::vector<glm::dmat3> each, moments;
    Groups groups;
    build_groups(groups);
    group_moments(groups, each, moments);
    match_shapes(frames, moments, 20, groups);
    std::vector<glm::dvec3> goal(x_.size());
    for (std::uint32_t j = 0; j < x_.size(); ++j) goal[j] = goal_of(j, frames, groups);
    return goal;
}

void World::step() {
    using clock = std::chrono::steady_clock;
    const auto t_start = clock::now();
    double collision_ms = 0;
    const double dt = settings_.dt;
    const std::size_t n = x_.size();
    std::vector<glm::dvec3>& old = scratch_.old;
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
    // Shape matching on the predictions. Small overlapping groups pass a correction on by one
    // particle per pass, so a chain needs several passes to hold its shape; the positions move
    // in every pass, the orientations once, after the last. The ellipsoid moments (Eq. 15) read
    // only the orientations, so they are summed per group once a step. The scratch is kept
    // across steps: no allocation in a step, and each group's rotation is warm-started from the
    // last pass, also the previous step's.
    auto& frames = scratch_.frames;
    if (groups_stale_) { // kept from the last step when nothing grew, broke or was cut
        auto& rest_moments = scratch_.rest_moment;
        rest_moments.resize(n);
        for (std::size_t j = 0; j < n; ++j)
            if (alive_[j]) rest_moments[j] = rest_moment(static_cast<std::uint32_t>(j));
        build_groups(scratch_.groups);
        groups_stale_ = false;
    }
    auto& stiff = scratch_.stiffness; // ages change only after the passes
    stiff.resize(n);
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) stiff[i] = stiffness(static_cast<std::uint32_t>(i));
    });
    group_moments(scratch_.groups, scratch_.moments, scratch_.group_moment);
    const int passes = settings_.iterations;
    for (int it = 0; it < passes; ++it) {
        match_shapes(frames, scratch_.group_moment, settings_.rotation_iterations, scratch_.groups);
        // each particle's goal, and the move toward it: the goals read only the frames, so a
        // particle can move as soon as its own goal is known
        parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
            for (std::size_t i = b; i < e; ++i) {
                if (!alive_[i]) continue;
                if (fixed_[i]) {
                    x_[i] = rest_x_[i];
                    continue;
                }
                // x'_g = x_p + s (x_g - x_p) (section 4.3)
                const double st = stiff[i];
                const glm::dvec3 goal = goal_of(static_cast<std::uint32_t>(i), frames, scratch_.groups);
                x_[i] = x_[i] + st * (goal - x_[i]);
                if (it + 1 < passes) continue;
                // after the last pass, the orientation goes as far toward its goal as `passes`
                // blends by s would take it: a normalized linear blend on the short arc. The
                // steps are small, where it and slerp agree to second order, and it needs no
                // trigonometry.
                double rest =
                    1.0; // (1 - s)^passes, by multiplying: pow() costs more than the rest of the blend
                for (int k = 0; k < passes; ++k) rest *= 1.0 - st;
                const double so = 1.0 - rest;
                glm::dquat target = glm::normalize(frames[i].R * rest_q_[i]);
                if (glm::dot(q_[i], target) < 0) target = -target;
                q_[i] = glm::normalize(q_[i] * (1.0 - so) + target * so);
            }
        });
        for (const auto& [i, target] : pulls_) x_[i] = target; // a dragged particle goes where it is dragged
    }
    auto t0 = clock::now();
    if (settings_.collisions) separate_particles();
    collision_ms += std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    // Eq. 17-18, with damping; then obstacles: a particle inside one is put back on its surface
    // (its radius off it), its velocity losing the normal part (or bouncing by the elasticity)
    // and some of the tangential part (friction)
    t0 = clock::now();
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
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
    });
    collision_ms += std::chrono::duration<double, std::milli>(clock::now() - t0).count();
    // breaking: a connection stretched past the threshold lets its child go (section 4.3)
    if (break_threshold_ > 0) {
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
    pulls_.clear();
    times_.collision = collision_ms;
    times_.dynamics =
        std::chrono::duration<double, std::milli>(clock::now() - t_start).count() - collision_ms;
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
            std::vector<glm::dvec3> points;
            for (std::size_t k = 0; k < n; ++k)
                if (alive_[k]) points.push_back(x_[k]);
            shade.build(points, g.light_cell);
            shade_counted = true;
        }
        return shade.occlusion(p, glm::normalize(g.to_light), g.opacity);
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
        glm::dvec3 pos = x_[i] + f * g.segment_length;
        for (const auto& o : obstacles_) // never grow into an obstacle
            if (o.distance(pos) < radii_[i].x) pos -= o.normal(pos) * (o.distance(pos) - radii_[i].x);
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
            add_grown(parent, x_[i] + lf * g.segment_length, heading_to(lf), radii_[i] * g.falloff);
            ++laterals_[i];
        }
    }
}

// Section 5.2: plants collide with each other and with themselves. Particles are spheres of
// their thinnest radius; two that overlap and are not joined (parent and child, or children of
// one parent) move apart along the line between them, half each (all of it when the other is a
// fixed root), as Müller and Chentanez 2011 resolve contacts. The pushes are gathered per
// particle from the positions before any moves, so the result does not depend on the order or
// the thread count.
void World::separate_particles() {
    const std::size_t n = x_.size();
    auto& thin = scratch_.thin;
    thin.assign(n, 0.0);
    double reach = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (alive_[i]) {
            thin[i] = std::min({radii_[i].x, radii_[i].y, radii_[i].z});
            reach = std::max(reach, 2 * thin[i]);
        }
    if (reach <= 0 || n < 2) return;
    const double cell = 2 * reach; // twice the widest contact: a 2 x 2 x 2 block of cells holds every partner
    // a cell's key: one term per axis, xor-ed
    auto term_x = [](std::int64_t x) { return static_cast<std::uint64_t>(x * 73856093); };
    auto term_y = [](std::int64_t y) { return static_cast<std::uint64_t>(y * 19349663); };
    auto term_z = [](std::int64_t z) { return static_cast<std::uint64_t>(z * 83492791); };
    auto hash = [&](const glm::i64vec3& c) { return term_x(c.x) ^ term_y(c.y) ^ term_z(c.z); };
    // each particle's cell, once: floor by truncation and correction (the baseline x86-64 has
    // no rounding instruction, and std::floor is a call)
    auto floor_of = [](double u) {
        const auto t = static_cast<std::int64_t>(u);
        return t - static_cast<std::int64_t>(static_cast<double>(t) > u);
    };
    // an open-addressing table from a cell's key to its run of particles in `members` (in index
    // order), built by counting: no sort. A slot holds the key and the run's bounds together, so
    // a lookup touches one cache line.
    std::size_t size = 16;
    while (size < 4 * n) size *= 2; // a quarter full at most: short probes
    auto& table = scratch_.table;   // begin == end: an empty slot
    table.assign(size, Cell{});
    auto& slot_of = scratch_.slot_of;
    slot_of.assign(n, ~0u);
    auto& cell_of = scratch_.cell_of;
    cell_of.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        const glm::dvec3 u = x_[i] / cell;
        cell_of[i] = glm::i64vec3(floor_of(u.x), floor_of(u.y), floor_of(u.z));
        const std::uint64_t k = hash(cell_of[i]);
        std::size_t slot = k & (size - 1);
        while (table[slot].end != 0 && table[slot].key != k) slot = (slot + 1) & (size - 1);
        table[slot].key = k;
        ++table[slot].end; // counts, for now
        slot_of[i] = static_cast<std::uint32_t>(slot);
    }
    std::uint32_t running = 0;
    for (Cell& c : table) { // counts to runs; `end` is the fill cursor below
        const std::uint32_t count = c.end;
        c.begin = c.end = running;
        running += count;
    }
    auto& members = scratch_.members;
    members.resize(running);
    for (std::uint32_t i = 0; i < n; ++i)
        if (slot_of[i] != ~0u) members[table[slot_of[i]].end++] = i;
    auto& push = scratch_.push;
    push.assign(n, glm::dvec3(0.0));
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            if (!alive_[i] || fixed_[i]) continue;
            const double ri = thin[i];
            const glm::dvec3 xi = x_[i];
            // only the 2 x 2 x 2 block of cells on the side of each axis the particle is nearer
            // to can hold a partner
            const glm::i64vec3 c = cell_of[i];
            const glm::dvec3 frac = xi / cell - glm::dvec3(c);
            const glm::i64vec3 side(frac.x < 0.5 ? -1 : 1, frac.y < 0.5 ? -1 : 1, frac.z < 0.5 ? -1 : 1);
            // the hash's three terms for the two cells along each axis
            const std::uint64_t hx[2] = {term_x(c.x), term_x(c.x + side.x)};
            const std::uint64_t hy[2] = {term_y(c.y), term_y(c.y + side.y)};
            const std::uint64_t hz[2] = {term_z(c.z), term_z(c.z + side.z)};
            // the block's eight keys, z slowest (the order the pushes are summed in)
            std::uint64_t keys[8];
            for (int q = 0; q < 8; ++q) keys[q] = hx[q & 1] ^ hy[(q >> 1) & 1] ^ hz[q >> 2];
            glm::dvec3 pushed(0.0);
            for (const std::uint64_t k : keys) {
                std::size_t slot = k & (size - 1);
                while (table[slot].end != table[slot].begin && table[slot].key != k)
                    slot = (slot + 1) & (size - 1);
                const Cell& run = table[slot];
                for (std::uint32_t at = run.begin; at < run.end; ++at) {
                    const std::uint32_t j = members[at];
                    const glm::dvec3 d = xi - x_[j];
                    const double dist2 = glm::dot(d, d), want = ri + thin[j];
                    if (dist2 >= want * want || dist2 < 1e-24) continue; // apart, or itself
                    // joined particles (parent and child, children of one parent) do not collide
                    const std::uint32_t pi = parent_[i], pj = parent_[j];
                    if (pi == j || pj == i || (pi != kNone && pi == pj)) continue;
                    const double dist = std::sqrt(dist2);
                    pushed += d / dist * ((want - dist) * (fixed_[j] ? 1.0 : 0.5));
                }
            }
            push[i] = pushed;
        }
    });
    for (std::size_t i = 0; i < n; ++i) x_[i] += push[i];
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
