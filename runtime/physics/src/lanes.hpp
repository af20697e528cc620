// Two lanes of doubles for the shape matching's hot loops, shared by frames.cpp and
// shape_matching.cpp (internal to plant_physics).
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace plant::physics {

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

// two quaternions, one a lane
inline Quat2 load2(const glm::dquat& a, const glm::dquat& b) {
    return {v2{a.w, b.w}, v2{a.x, b.x}, v2{a.y, b.y}, v2{a.z, b.z}};
}

// glm's quaternion product p * q, lane by lane
inline Quat2 mul2(const Quat2& p, const Quat2& q) {
    return {p.w * q.w - p.x * q.x - p.y * q.y - p.z * q.z, p.w * q.x + p.x * q.w + p.y * q.z - p.z * q.y,
            p.w * q.y + p.y * q.w + p.z * q.x - p.x * q.z, p.w * q.z + p.z * q.w + p.x * q.y - p.y * q.x};
}

// glm::dot of two quaternions, lane by lane
inline v2 dot2(const Quat2& a, const Quat2& b) {
    return (a.w * b.w + a.x * b.x) + (a.y * b.y + a.z * b.z);
}

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

} // namespace plant::physics
