// Self-shading for phototropism (Hädrich et al. 2017, Eq. 7's occlusion O): the plant's particles
// counted in a grid of cubic cells, and the count along a ray from a point toward the light. Both
// the runtime's own growth (World::grow) and the climber binding use it. The scene's obstacles
// shade too (shadow.cpp): a point whose ray toward the light enters one is in full shade.
#pragma once

#include "plant/physics/world.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <span>
#include <vector>

namespace plant::physics {

class LightGrid {
  public:
    // Counts `points` in cells of `cell` (doubled until the grid has at most 4 million cells);
    // points that are not finite are left out.
    void build(std::span<const glm::dvec3> points, double cell);
    void clear();
    // Particles in the cells a ray from p toward `to_light` (unit) passes, p's own cell left out.
    double count_toward(const glm::dvec3& p, const glm::dvec3& to_light) const;
    // Eq. 7's O: 1 - exp(-opacity * count_toward(p, to_light)), in [0, 1).
    double occlusion(const glm::dvec3& p, const glm::dvec3& to_light, double opacity) const;

  private:
    glm::dvec3 lo_{0.0};
    double cell_ = 0.1;
    glm::ivec3 n_{0};
    Array<std::uint32_t> count_; // a grid of millions of cells: in 2 MiB pages (world.hpp)
};

// Whether the ray from p toward `to_light` (unit) enters obstacle o: the paper's light includes
// the scene (its shadow maps, Hädrich et al. 2017, section 4.2). Exact for spheres, boxes and
// planes; a sampled grid is marched by its distance (at least half a cell a step, so a part
// thinner than that may let light through), at most 4096 steps. A point inside o is not shaded
// by it (the ray never enters it), nor is one whose ray only grazes a face.
bool blocks_light(const Obstacle& o, const glm::dvec3& p, const glm::dvec3& to_light);
// Whether any of the obstacles blocks the light at p.
bool in_shadow(const std::vector<Obstacle>& obstacles, const glm::dvec3& p, const glm::dvec3& to_light);

// The share of the sky (the half of the directions with y > 0, sampled by kSkyDirections fixed
// directions spread evenly over it) that no obstacle hides from p.
constexpr int kSkyDirections = 32;
double sky_visible(const std::vector<Obstacle>& obstacles, const glm::dvec3& p);
// Those directions: a Fibonacci spiral over the upper half of the sphere, direction k at height
// y = (k + 0.5) / kSkyDirections, turned by the golden angle from the one before.
const std::vector<glm::dvec3>& sky_directions();

// Eq. 7's O at p in a scene, 1 less the light p receives. With diffuse = 0: 1 where an obstacle
// blocks the light (with `obstacles_shade`), else the plant's particles counted in `grid`
// (LightGrid::occlusion). With diffuse d > 0, d of the light comes from the open sky and 1 - d from
// the light's direction: the light is (1 - O_plant) ((1 - d) direct + d sky), direct 0 or 1 as an
// obstacle blocks it and sky the share of the sky no obstacle hides (sky_visible), so a point in
// an obstacle's shadow still has the sky's light (docs/climber-growth.md, "Diffuse light"). World::grow
// and the climber's occlusion() both use it.
double scene_occlusion(const LightGrid& grid, const std::vector<Obstacle>& obstacles, bool obstacles_shade,
                       const glm::dvec3& p, const glm::dvec3& to_light, double opacity, double diffuse = 0);

} // namespace plant::physics
