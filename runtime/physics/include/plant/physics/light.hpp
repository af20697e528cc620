// Self-shading for phototropism (Hädrich et al. 2017, Eq. 7's occlusion O): the plant's particles
// counted in a grid of cubic cells, and the count along a ray from a point toward the light. Both
// the runtime's own growth (World::grow) and the climber binding use it.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace plant::physics {

class LightGrid {
  public:
    // Counts `points` in cells of `cell` (doubled until the grid has at most 4 million cells);
    // points that are not finite are left out.
    void build(const std::vector<glm::dvec3>& points, double cell);
    void clear();
    // Particles in the cells a ray from p toward `to_light` (unit) passes, p's own cell left out.
    double count_toward(const glm::dvec3& p, const glm::dvec3& to_light) const;
    // Eq. 7's O: 1 - exp(-opacity * count_toward(p, to_light)), in [0, 1).
    double occlusion(const glm::dvec3& p, const glm::dvec3& to_light, double opacity) const;

  private:
    glm::dvec3 lo_{0.0};
    double cell_ = 0.1;
    glm::ivec3 n_{0};
    std::vector<std::uint32_t> count_;
};

} // namespace plant::physics
