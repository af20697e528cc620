// A grid's cell coordinate for a point that may lie far outside the grid or not be a number
// (header only; the physics library's grids and the runtime's environments share it).
#pragma once

#include <cmath>

namespace plant {

// floor(u) as an int, clamped to [lo, hi]. The clamp happens before the conversion, so a point
// far away cannot overflow it (converting a double beyond int's range is undefined); NaN goes to
// lo. Within the range this is exactly clamp(int(floor(u)), lo, hi).
inline int cell_index(double u, int lo, int hi) {
    const double f = std::floor(u);
    return f >= lo ? (f <= hi ? static_cast<int>(f) : hi) : lo;
}

} // namespace plant
