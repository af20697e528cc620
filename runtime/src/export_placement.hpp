// What the glTF writer needs to keep placements shared: a placement's matrix as translation,
// rotation and scale; which prototypes are the same mesh; and everything baked into world space.
#pragma once

#include "plant/scene.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plant::detail {

// M = T * R * S as glTF composes a node's (and EXT_mesh_gpu_instancing's) transform.
struct Trs {
    glm::vec3 translation{0.0f};
    glm::vec4 rotation{0.0f, 0.0f, 0.0f, 1.0f}; // unit quaternion, x y z w
    glm::vec3 scale{1.0f};                      // every component > 0
};

// How far (relative to the largest scale) the matrix rebuilt from its decomposition may be from
// the given one.
constexpr double kTrsTolerance = 1e-4;

// The decomposition of `m`, or none when `m` is not finite, its last row is not (0, 0, 0, 1), or
// its linear part is not a rotation times a positive (per-axis) scale within kTrsTolerance: a
// shear, a mirror or a collapsed axis. Then the caller writes the matrix as it is.
std::optional<Trs> decompose(const glm::mat4& m);

// For each prototype, the first prototype with exactly the same positions, normals, texture
// coordinates, indices and primitives (itself when there is none): equal prototypes are one mesh.
// Flattening copies a scene prototype's organs once per scene prototype (a leaf inside weeping
// branches of several levels of detail); this brings them back to one.
std::vector<std::uint32_t> shared_prototypes(const Scene& scene);

// A scene prototype whose placements stay nodes in the glTF file: one parent node per placement,
// whose children draw the prototype's parts with instance accessors shared by every placement
// (a forest of 100 willows writes one willow's leaf placements, not 100).
struct NestedGroup {
    std::string name;
    std::vector<glm::mat4> placements; // of the scene prototype, in the scene's frame
    // the prototype's parts: an index in the split scene's prototypes (which places none of
    // them itself) and the part's transform in the prototype's frame
    std::vector<std::pair<std::uint32_t, glm::mat4>> parts;
};

// A scene prototype stays nested when it places more parts (its tubes and organs, and theirs
// through the scene prototypes it places) than it is placed itself, and drawing every part at
// every placement would take more than kNestedFrom placements. Any other is drawn into its
// parent's placements, as flatten() does: a weeping branch placed 960 times with its 12 leaves
// becomes one instanced node of 11,520 leaves.
constexpr std::uint64_t kNestedFrom = 65536;

// The scene flattened except for the scene prototypes placed at its top level that stay nested
// (above): their parts become prototypes of the result, placed by `groups`. Throws ExportError
// (naming `what`) for a placement of a scene prototype that does not exist.
Scene split_nested(const Scene& scene, std::vector<NestedGroup>& groups, const std::string& what);

// The part's primitives as they are drawn: the whole part in material 0 when it has none, empty
// ones left out. Throws ExportError (naming `name`) for a primitive that does not fit the indices
// in whole triangles.
std::vector<Primitive> drawn_primitives(const MeshPart& part, const std::string& name);

// The tubes and every placement transformed into world space (normals by the inverse transpose)
// in one part, one primitive per material, in the order materials are first used. Throws
// ExportError (naming `what`) when the result would pass 2^32 vertices.
MeshPart bake(const Scene& scene, const char* what);

} // namespace plant::detail
