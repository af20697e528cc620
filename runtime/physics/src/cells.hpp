// Grid cells of positions that may be far away or not a number (internal to plant_physics).
#pragma once

#include "plant/grid_cell.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace plant::physics {

inline bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

using plant::cell_index; // (plant/grid_cell.hpp) floor(u) as an int clamped to [lo, hi], NaN to lo

inline glm::ivec3 cell_index(const glm::dvec3& u, const glm::ivec3& lo, const glm::ivec3& hi) {
    return glm::ivec3(cell_index(u.x, lo.x, hi.x), cell_index(u.y, lo.y, hi.y), cell_index(u.z, lo.z, hi.z));
}

// floor(u) as a 64-bit cell coordinate for a hashed grid, u first clamped to 2^52 cells either
// way (NaN to the top), so the conversion and a neighbour's c + 1 stay in range for a particle
// blown far away; nearer ones are not changed. Floor by truncation and correction: the baseline
// x86-64 has no rounding instruction, and std::floor is a call.
inline std::int64_t far_floor(double u) {
    constexpr double far = 0x1p52;
    u = u < far ? (u > -far ? u : -far) : far;
    const auto t = static_cast<std::int64_t>(u);
    return t - static_cast<std::int64_t>(static_cast<double>(t) > u);
}

// A hashed grid cell's key: one term per axis, xor-ed (the particle contacts combine the terms
// of neighbouring cells themselves). Multiplied as unsigned numbers, which wrap where a signed
// product would overflow and give the same bits where it does not.
inline std::uint64_t cell_term_x(std::int64_t x) {
    return static_cast<std::uint64_t>(x) * 73856093u;
}
inline std::uint64_t cell_term_y(std::int64_t y) {
    return static_cast<std::uint64_t>(y) * 19349663u;
}
inline std::uint64_t cell_term_z(std::int64_t z) {
    return static_cast<std::uint64_t>(z) * 83492791u;
}
inline std::uint64_t cell_hash(const glm::i64vec3& c) {
    return cell_term_x(c.x) ^ cell_term_y(c.y) ^ cell_term_z(c.z);
}

// The size past which an element stays out of a hashed grid whose cells are sized from the
// largest one (docs/physics.md, "Plant-plant collision"): 64 times a typical size, the median of
// at most 65 of `count` elements offered in order, every (count / 64)-th from the first. A grammar
// may give a segment a radius of up to 1e6 m; one such element would make the grid one cell.
class OversizedLimit {
  public:
    explicit OversizedLimit(std::size_t count) : stride_(count / 64 > 1 ? count / 64 : 1) {}
    void offer(double size) {
        if (seen_++ % stride_ == 0 && sampled_ < 65) sample_[sampled_++] = size;
    }
    // +infinity when nothing was offered
    double limit() {
        if (sampled_ == 0) return HUGE_VAL;
        std::nth_element(sample_, sample_ + sampled_ / 2, sample_ + sampled_);
        return 64 * sample_[sampled_ / 2];
    }

  private:
    std::size_t stride_, seen_ = 0, sampled_ = 0;
    double sample_[65];
};

} // namespace plant::physics
