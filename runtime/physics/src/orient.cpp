// The orientations after the last shape-matching pass and after the last length and bending
// sweep. After the pass (blend_orientations), each free particle's orientation goes as far
// toward its group's rotation of its rest orientation as `passes` blends by its stiffness s would
// take it: a normalized linear blend on the short arc, by 1 - (1 - s)^passes. The steps are
// small, where it and slerp agree to second order, and it needs no trigonometry. After the sweep
// (orient_along_links; docs/physics.md, "Length and bending"), each particle is turned by the
// shortest rotation that lays its rest direction, as its rotation from rest carries it, along its
// link now, so the heading a grammar reads and grows along is the stem's direction and the twist
// about it is kept. A particle's turn reads only its own orientation and link, so this runs after
// the sweep instead of inside its serial chain, on any number of threads, and two particles at a
// time lane by lane (lanes.hpp) with exactly the scalar code's operations: the results are the
// same bit for bit as one particle at a time. The blend, too, reads only the particle's own state
// and its group's frame, and runs the same way.
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

// glm::normalize of a quaternion, but for a zero length (glm's answer is the identity there):
// `degenerate` says whether a lane had one, for the caller to redo it alone
Quat2 normalize2(const Quat2& q, bool& degenerate) {
    const v2 len2 = dot2(q, q);
    const v2 len{std::sqrt(len2[0]), std::sqrt(len2[1])};
    if (!(len[0] > 0) || !(len[1] > 0)) degenerate = true;
    const v2 over = both(1.0) / len;
    return {q.w * over, q.x * over, q.y * over, q.z * over};
}

} // namespace

void World::orient_one(std::uint32_t i) {
    const glm::dvec3 axis = glm::normalize(rotation_from_rest(i) * scratch_.rest_dir[i]);
    q_[i] = glm::normalize(rotation_between(axis, scratch_.dir[i]) * q_[i]);
}

void World::orient_pair(std::uint32_t i, std::uint32_t j) {
    // orient_one for i and j, lane by lane
    const Quat2 q = load2(q_[i], q_[j]);
    const Quat2 r = load2(rest_q_[i], rest_q_[j]);
    // rotation_from_rest: normalize(q * inverse(rest)), inverse being conjugate / dot
    const v2 rr = dot2(r, r);
    const Quat2 inv{r.w / rr, (-r.x) / rr, (-r.y) / rr, (-r.z) / rr};
    bool degenerate = false;
    const Quat2 from_rest = normalize2(mul2(q, inv), degenerate);
    // the rest direction carried by it (glm's quaternion times vector), normalized
    const glm::dvec3 &ra = scratch_.rest_dir[i], &rb = scratch_.rest_dir[j];
    const v2 vx{ra.x, rb.x}, vy{ra.y, rb.y}, vz{ra.z, rb.z};
    const v2 &Qx = from_rest.x, &Qy = from_rest.y, &Qz = from_rest.z, &Qw = from_rest.w;
    const v2 ux = Qy * vz - vy * Qz, uy = Qz * vx - vz * Qx, uz = Qx * vy - vx * Qy;
    const v2 uux = Qy * uz - uy * Qz, uuy = Qz * ux - uz * Qx, uuz = Qx * uy - ux * Qy;
    const v2 two = both(2.0);
    const v2 cx = vx + ((ux * Qw) + uux) * two, cy = vy + ((uy * Qw) + uuy) * two,
             cz = vz + ((uz * Qw) + uuz) * two;
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
    const Quat2 unit_turn = normalize2(turn, degenerate);
    const Quat2 out = normalize2(mul2(unit_turn, q), degenerate);
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

void World::blend_one(std::uint32_t i) {
    const int passes = settings_.iterations;
    const double st = scratch_.stiffness[i];
    double rest = 1.0; // (1 - s)^passes, by multiplying: pow() costs more than the rest of the blend
    for (int k = 0; k < passes; ++k) rest *= 1.0 - st;
    const double so = 1.0 - rest;
    glm::dquat target = glm::normalize(scratch_.frames[i].R * rest_q_[i]);
    if (glm::dot(q_[i], target) < 0) target = -target;
    q_[i] = glm::normalize(q_[i] * (1.0 - so) + target * so);
}

void World::blend_pair(std::uint32_t i, std::uint32_t j) {
    // blend_one for i and j, lane by lane
    const int passes = settings_.iterations;
    const v2 st{scratch_.stiffness[i], scratch_.stiffness[j]};
    v2 rest = both(1.0);
    for (int k = 0; k < passes; ++k) rest *= both(1.0) - st;
    const v2 so = both(1.0) - rest, keep = both(1.0) - so;
    bool degenerate = false;
    Quat2 target = normalize2(
        mul2(load2(scratch_.frames[i].R, scratch_.frames[j].R), load2(rest_q_[i], rest_q_[j])), degenerate);
    const Quat2 q = load2(q_[i], q_[j]);
    const v2 along = dot2(q, target);
    for (int l = 0; l < 2; ++l)
        if (along[l] < 0) { // -target, lane by lane (negated, as glm does, not multiplied by -1)
            target.w[l] = -target.w[l], target.x[l] = -target.x[l];
            target.y[l] = -target.y[l], target.z[l] = -target.z[l];
        }
    const Quat2 mix{q.w * keep + target.w * so, q.x * keep + target.x * so, q.y * keep + target.y * so,
                    q.z * keep + target.z * so};
    const Quat2 out = normalize2(mix, degenerate);
    if (degenerate) { // a zero quaternion, which glm normalizes to the identity: one at a time
        blend_one(i), blend_one(j);
        return;
    }
    q_[i] = glm::dquat(out.w[0], out.x[0], out.y[0], out.z[0]);
    q_[j] = glm::dquat(out.w[1], out.x[1], out.y[1], out.z[1]);
}

void World::blend_orientations() {
    const std::size_t n = x_.size();
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        std::uint32_t waiting = kNone; // the first of a pair
        for (std::size_t k = b; k < e; ++k) {
            const auto i = static_cast<std::uint32_t>(k);
            if (!alive_[i] || fixed_[i]) continue;
            if (waiting == kNone) {
                waiting = i;
                continue;
            }
            blend_pair(waiting, i);
            waiting = kNone;
        }
        if (waiting != kNone) blend_one(waiting);
    });
}

} // namespace plant::physics
