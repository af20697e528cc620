// From skeleton to triangles: one generalized cylinder per axis, organ prototypes meshed once.
#pragma once

#include "plant/scene.hpp"
#include "plant/skeleton.hpp"

#include <functional>

namespace plant {

struct MeshOptions {
    int sides = 8;                // vertices per ring
    double sharp_bend_deg = 45.0; // past this a joint is rounded with extra rings
    double tip_taper = 0.35;      // radius of the last ring, as a fraction of the axis radius there
};

// Appends the tube of one axis to `part`, with primitives grouped by `material_of` (a color ->
// material index map the caller keeps across axes). Rings are shared between consecutive
// segments; frames are parallel-transported from the first point's left vector.
void mesh_axis(const SkeletonAxis& axis, const MeshOptions& options, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&)>& material_of);

// The whole scene: tubes, prototypes for every surface (and @O spheres) used, instances.
// Throws RuntimeError when a surface cannot be loaded.
Scene build_scene(const Program& program, const Skeleton& skeleton, const MeshOptions& options);

} // namespace plant
