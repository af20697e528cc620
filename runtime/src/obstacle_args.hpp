// Obstacle shapes written as environment arguments, read the same way by the `obstacles` and
// `climber` kinds (internal to plant_runtime):
//
//   sphere: vec3, sphere_radius: r     box_min: vec3, box_max: vec3
//   plane_point: vec3, plane_normal: vec3
//
// Shapes pair up in the order they are written: each sphere with the next sphere_radius, each
// box_min with the next box_max, each plane_point with the next plane_normal. Repeat a pair
// for more shapes. A `mesh: "file"` argument is checked here and loaded by the kind.
#pragma once

#include "plant/environment.hpp"
#include "plant/physics/world.hpp"

#include <glm/glm.hpp>

#include <string>
#include <string_view>
#include <vector>

namespace plant {

class ObstacleArgs {
  public:
    // `kind` prefixes the errors ("obstacles", "climber").
    explicit ObstacleArgs(const char* kind) : kind_(kind) {}
    // Whether `key` names a shape argument (not `mesh`).
    static bool is_shape(std::string_view key);
    // Takes one shape argument; false with `error` set when its type is wrong.
    bool read(const EnvArg& arg, std::string& error);
    // Checks a `mesh` argument is a quoted file name; false with `error` set when not.
    bool mesh(const EnvArg& arg, std::string& error) const;
    // Every sphere has its radius, every box_min its box_max, every plane_point its normal.
    bool paired(std::string& error) const;
    // The shapes in the order spheres, boxes, planes (what `move(k, ...)` numbers), with the
    // physics' default friction and elasticity; false with `error` set for a zero normal.
    bool shapes(std::vector<physics::Obstacle>& out, std::string& error) const;

  private:
    const char* kind_;
    std::vector<glm::dvec3> centers_, box_min_, box_max_, plane_point_, plane_normal_;
    std::vector<double> radii_;
};

} // namespace plant
