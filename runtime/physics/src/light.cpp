#include "plant/physics/light.hpp"

#include "cells.hpp"

#include <cmath>

namespace plant::physics {

void LightGrid::clear() {
    count_.clear();
    n_ = glm::ivec3(0);
}

void LightGrid::build(std::span<const glm::dvec3> points, double cell) {
    clear();
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& p : points) {
        if (!finite(p)) continue;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    if (!(lo.x <= hi.x) || !(cell > 0)) return; // no point with a finite position
    glm::dvec3 n = glm::floor((hi - lo) / cell) + 1.0;
    while (n.x * n.y * n.z > 4e6) {
        cell *= 2;
        n = glm::floor((hi - lo) / cell) + 1.0;
    }
    if (!finite(n)) return;
    cell_ = cell;
    lo_ = lo;
    n_ = glm::ivec3(n);
    count_.assign(static_cast<std::size_t>(n_.x) * n_.y * n_.z, 0);
    for (const auto& p : points) {
        if (!finite(p)) continue;
        glm::ivec3 c = cell_index((p - lo) / cell, glm::ivec3(0), n_ - 1);
        ++count_[(static_cast<std::size_t>(c.z) * n_.y + c.y) * n_.x + c.x];
    }
}

double LightGrid::count_toward(const glm::dvec3& p, const glm::dvec3& dir) const {
    if (count_.empty() || !finite(p) || !finite(dir)) return 0;
    const double cell = cell_;
    glm::dvec3 q = p;
    // outside the grid, own matches no cell of it whether clamped to just past it or not
    const glm::ivec3 own = cell_index((p - lo_) / cell, glm::ivec3(-1), n_);
    double count = 0;
    glm::ivec3 last = own;
    const glm::dvec3 extent = glm::dvec3(n_) * cell;
    // half-cell steps along the ray, each cell counted once
    for (int k = 0; k < 4 * (n_.x + n_.y + n_.z); ++k) {
        q += dir * (cell * 0.5);
        const glm::dvec3 rel = q - lo_;
        if (rel.x < 0 || rel.y < 0 || rel.z < 0 || rel.x >= extent.x || rel.y >= extent.y ||
            rel.z >= extent.z) {
            // outside the grid: nothing more in the way once moving away from it
            const bool leaving = (rel.x < 0 && dir.x <= 0) || (rel.y < 0 && dir.y <= 0) ||
                                 (rel.z < 0 && dir.z <= 0) || (rel.x >= extent.x && dir.x >= 0) ||
                                 (rel.y >= extent.y && dir.y >= 0) || (rel.z >= extent.z && dir.z >= 0);
            if (leaving) break;
            continue;
        }
        const glm::ivec3 c = cell_index(rel / cell, glm::ivec3(0), n_ - 1);
        if (c == own || c == last) continue;
        last = c;
        count += count_[(static_cast<std::size_t>(c.z) * n_.y + c.y) * n_.x + c.x];
    }
    return count;
}

double LightGrid::occlusion(const glm::dvec3& p, const glm::dvec3& to_light, double opacity) const {
    return 1.0 - std::exp(-opacity * count_toward(p, to_light));
}

} // namespace plant::physics
