// Closed triangle meshes as obstacles: loading (any format OpenMesh reads) and signed distance.
// Shared by the `obstacles` and `climber` environments (internal to plant_runtime).
#pragma once

#include "plant/physics/world.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace plant {

struct Triangle {
    glm::dvec3 a, b, c, n; // corners and unit normal (outward for a closed mesh wound outward)
};

// Reads a mesh and triangulates it. `who` prefixes the error ("obstacles", "climber"). Throws
// InputError when the file is unsafe or malformed (mesh_file.hpp).
bool load_triangles(const std::string& path, std::vector<Triangle>& out, const char* who, std::string& error);

// Ericson, Real-Time Collision Detection, 5.1.5: the point of a triangle nearest to p.
glm::dvec3 closest_on_triangle(const glm::dvec3& p, const Triangle& t);

// Distance from p to the nearest triangle, negative on the inner side of that triangle's face.
double signed_distance(const std::vector<Triangle>& mesh, const glm::dvec3& p);

// signed_distance through a bounding-volume hierarchy (distance_grid.cpp): the same value, bit
// for bit, as the loop over every triangle, found by looking only at nearby triangles.
class TriangleTree {
  public:
    explicit TriangleTree(const std::vector<Triangle>& mesh);
    double signed_distance(const glm::dvec3& p) const;

  private:
    struct Node {
        glm::dvec3 lo, hi;
        std::uint32_t first = 0, count = 0; // a leaf's triangles in order_; count 0: an inner node
        std::uint32_t left = 0, right = 0;
    };
    std::uint32_t build(std::uint32_t first, std::uint32_t count, std::vector<glm::dvec3>& centres);
    const std::vector<Triangle>& mesh_;
    std::vector<Node> nodes_;
    std::vector<std::uint32_t> order_;
    double window_ = 0; // triangles this much farther than the nearest are replayed too
};

// Samples signed_distance on a grid of `cell` spacing over the mesh's box grown by `margin`
// (at most `max_points` samples: the cell grows to fit), for the particle runtime. Null when the
// box is not finite (corners or a margin near the largest double).
std::shared_ptr<const physics::DistanceGrid> distance_grid(const std::vector<Triangle>& mesh, double cell,
                                                           double margin, std::size_t max_points = 1u << 20);

// Appends triangles showing an obstacle: a box's six faces, a sphere, a plane as a square around
// the plant's box [lo, hi] (0.8 of its diagonal across). A sampled grid shows nothing here (its mesh does).
void obstacle_triangles(const physics::Obstacle& o, const glm::dvec3& lo, const glm::dvec3& hi,
                        std::vector<glm::dvec3>& out);

} // namespace plant
