// Grid cells of positions that may be far away or not a number (internal to plant_physics).
#pragma once

#include <glm/glm.hpp>

#include <cmath>

namespace plant::physics {

inline bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// floor(u) as an int, clamped to [lo, hi]. The clamp happens before the conversion, so a
// particle blown far away cannot overflow it (converting a double beyond int's range is
// undefined); NaN goes to lo. Within the range this is exactly clamp(int(floor(u)), lo, hi).
inline int cell_index(double u, int lo, int hi) {
    const double f = std::floor(u);
    return f >= lo ? (f <= hi ? static_cast<int>(f) : hi) : lo;
}

inline glm::ivec3 cell_index(const glm::dvec3& u, const glm::ivec3& lo, const glm::ivec3& hi) {
    return glm::ivec3(cell_index(u.x, lo.x, hi.x), cell_index(u.y, lo.y, hi.y), cell_index(u.z, lo.z, hi.z));
}

} // namespace plant::physics
