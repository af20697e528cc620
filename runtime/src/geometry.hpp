// Small geometry helpers the runtime's files share (internal to plant_runtime): Rodrigues'
// rotation and three numbers read as a vector.
#pragma once

#include <glm/glm.hpp>

#include <cmath>

namespace plant {

// v rotated about the unit axis k by the angle whose cosine and sine are c and s, right-handed
// (Rodrigues' formula).
inline glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& k, double c, double s) {
    return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1 - c);
}

// v rotated about the unit axis k by phi radians, right-handed.
inline glm::dvec3 rotate(const glm::dvec3& v, const glm::dvec3& k, double phi) {
    return rotate(v, k, std::cos(phi), std::sin(phi));
}

// The three numbers at a (module parameters, method arguments) as a vector.
// n made unit length, or up (0, 1, 0) when it has none (zero, tiny or not finite): a normal a
// mesh file can always carry.
inline glm::vec3 unit_or_up(glm::vec3 n) {
    const float len = glm::length(n);
    if (!(len > 1e-20f) || !std::isfinite(len)) return {0.0f, 1.0f, 0.0f};
    return n / len;
}

inline glm::dvec3 vec(const double* a) {
    return {a[0], a[1], a[2]};
}

} // namespace plant
