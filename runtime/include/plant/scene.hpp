// What the mesher hands to the exporters: flat triangle buffers in world space for the tubes,
// organ prototypes meshed once, and their placements. y is up (glTF's convention).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plant {

struct Material {
    glm::vec3 color{0.45f, 0.32f, 0.2f}; // linear RGB, 0..1
};

// Triangles of one material: indices[first, first + count) of the part's index buffer.
struct Primitive {
    std::uint32_t first = 0;
    std::uint32_t count = 0;
    std::uint32_t material = 0;
};

// Flat vertex and index buffers (about 30 bytes a triangle): positions, unit normals and
// texture coordinates per vertex, three indices per triangle.
struct MeshPart {
    std::vector<glm::vec3> positions;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> indices;
    std::vector<Primitive> primitives;
    std::size_t triangle_count() const { return indices.size() / 3; }
    bool empty() const { return indices.empty(); }
};

// One placement of a prototype: a rigid transform with uniform scale.
struct Instance {
    std::uint32_t prototype = 0;
    glm::mat4 transform{1.0f};
};

struct Scene {
    MeshPart tubes;                   // every generalized cylinder, in world space
    std::vector<MeshPart> prototypes; // organ shapes (leaves, flowers, spheres), in their own frame
    std::vector<std::string> prototype_names;
    std::vector<Instance> instances;
    std::vector<Material> materials;              // at least one
    glm::vec3 bounds_min{0.0f}, bounds_max{0.0f}; // of everything, instances included
    void update_bounds();
};

} // namespace plant
