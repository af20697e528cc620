// The orientations after the last length and bending sweep (docs/physics.md, "Length and
// bending"): each particle turned by the shortest rotation that lays its rest direction, as its
// rotation from rest carries it, along its link now, so the heading a grammar reads and grows
// along is the stem's direction and the twist about it is kept. A particle's turn reads only its
// own orientation and link, so this runs after the sweep instead of inside its serial chain, on
// any number of threads, and two particles at a time lane by lane (lanes.hpp) with exactly the
// scalar code's operations: the results are the same bit for bit as one particle at a time.
#include "plant/physics/world.hpp"

#include "lanes.hpp"
#include "parallel.hpp"

#include <cmath>

namespace plant::physics {

namespace {

// the shortest rotation taking unit a to unit b, as a quaternion
glm::dquat rotation_between(const glm::dvec3& a, const glm::dvec3& b) {
    const double c = glm::dot(a, b);
    if (c < -1 + 1e-9) {
        const glm::dvec3 k =
            glm::normalize(glm::cross(a, std::fabs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
        return glm::dquat(0, k.x, k.y, k.z);
    }
    const glm::dvec3 k = glm::cross(a, b);
    return glm::normalize(glm::dquat(1 + c, k.x, k.y, k.z));
}

constexpr double kOpposite = -1 + 1e-9; // rotation_between's half turn, left to the scalar code

// glm's quaternion product p * q, lane by lane
Quat2 mul(const Quat2& p, const Quat2& q) {
    return {p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
            p.w * q.y + p.y * q.w + p.z * q.x - p.x * q.z, p.w * q.z + p.z * q.w + p.x * q.y - p.y * q.x};
}

// glm::dot of two quaternions
v2 dot4(const Quat2& a, const Quat2& b) {
    return (a.w * b.w + a.x * b.x) + (a.y * b.y + a.z * b.z);
}

// glm::normalize of a quaternion, but for a zero length (glm's answer is the identity there):
// `degenerate` says whether a lane had one, for the caller to redo it alone
Quat2 normalize4(const Quat2& q, bool& degenerate) {
    const v2 len2 = dot4(q, q);
    const v2 len{std::sqrt(len2[0]), std::sqrt(len2[1])};
    if (!(len[0] > 0) || !(len[1] > 0)) degenerate = true;
    const v2 over = both(1.0) / len;
    return {q.w * over, q.x * over, q.y * over, q.z * over};
}

Quat2 load(const glm::dquat& a, const glm::dquat& b) {
    return {v2{a.w, b.w}, v2{a.x, b.x}, v2{a.y, b.y}, v2{a.z, b.z}};
}

} // namespace

void World::orient_one(std::uint32_t i) {
    const glm::dvec3 axis = glm::normalize(rotation_from_rest(i) * scratch_.rest_dir[i]);
    q_[i] = glm::normalize(rotation_between(axis, scratch_.dir[i]) * q_[i]);
}

void World::orient_pair(std::uint32_t i, std::uint32_t j) {
    // orient_one for i and j, lane by lane
    const Quat2 q = load(q_[i], q_[j]);
    const Quat2 r = load(rest_q_[i], rest_q_[j]);
    // rotation_from_rest: normalize(q * inverse(rest)), inverse being conjugate / dot
    const v2 rr = dot4(r, r);
    const Quat2 inv{r.w / rr, (-r.x) / rr, (-r.y) / rr, (-r.z) / rr};
    bool degenerate = false;
    const Quat2 from_rest = normalize4(mul(q, inv), degenerate);
    // the rest direction carried by it (glm's quaternion times vector), normalized
    const glm::dvec3 &ra = scratch_.rest_dir[i], &rb = scratch_.rest_dir[j];
    const v2 vx{ra.x, rb.x}, vy{ra.y, rb.y}, vz{ra.z, rb.z};
    const v2 &Qx = from_rest.x, &Qy = from_rest.y, &Qz = from_rest.z, &Qw = from_rest.w;
    const v2 ux = Qy * vz - vy * Qz, uy = Qz * vx - vz * Qx, uz = Qx * vy - vx * Qy;
    const v2 uux = Qy * uz - uy * Qz, uuy = Qz * ux - uz * Qx, uuz = Qx * uy - ux * Qy;
    const v2 two = both(2.0);
    const v2 cx = vx + ((ux * Qw) + uux) * two, cy = vy + ((uy * Qw) + uuy) * two, cz = vz + ((uz * Qw) + uuz) * two;
    const v2 c2 = (cx * cx + cy * cy) + cz * cz;
    const v2 inv_len = both(1.0) / v2{std::sqrt(c2[0]), std::sqrt(c2[1])};
    const v2 ax = cx * inv_len, ay = cy * inv_len, az = cz * inv_len;
    // rotation_between(axis, dir)
    const glm::dvec3 &da = scratch_.dir[i], &db = scratch_.dir[j];
    const v2 dx{da.x, db.x}, dy{da.y, db.y}, dz{da.z, db.z};
    const v2 c = (ax * dx + ay * dy) + az * dz;
    if (degenerate || !(c[0] >= kOpposite) || !(c[1] >= kOpposite)) { // rare: one at a time
        orient_one(i), orient_one(j);
        return;
    }
    const Quat2 turn{both(1.0) + c, ay * dz - dy * az, az * dx - dz * ax, ax * dy - dx * ay};
    const Quat2 unit_turn = normalize4(turn, degenerate);
    const Quat2 out = normalize4(mul(unit_turn, q), degenerate);
    if (degenerate) {
        orient_one(i), orient_one(j);
        return;
    }
    q_[i] = glm::dquat(out.w[0], out.x[0], out.y[0], out.z[0]);
    q_[j] = glm::dquat(out.w[1], out.x[1], out.y[1], out.z[1]);
}

void World::orient_along_links() {
    const auto& list = scratch_.oriented;
    parallel_ranges(list.size(), settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        std::size_t k = b;
        for (; k + 1 < e; k += 2) orient_pair(list[k], list[k + 1]);
        if (k < e) orient_one(list[k]);
    });
}

} // namespace plant::physics
