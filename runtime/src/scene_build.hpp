// The parts of build_scene: scene.cpp meshes one skeleton, instances.cpp derives and places the
// instances it names.
#pragma once

#include "plant/mesh.hpp"

namespace plant::detail {

// The tubes and organ prototypes of one skeleton, in its own frame; its instance organs are left
// to the caller. Bounds are not set.
Scene mesh_skeleton(const Program& program, const Skeleton& skeleton, const MeshOptions& options);

// Throws RuntimeError when the scene's bounds pass the range of single-precision numbers.
void check_single_precision(const Scene& scene);

} // namespace plant::detail
