// From skeleton to triangles: one generalized cylinder per axis, organ prototypes meshed once.
#pragma once

#include "plant/derive.hpp"
#include "plant/scene.hpp"
#include "plant/skeleton.hpp"

#include <functional>
#include <optional>

namespace plant {

struct MeshOptions {
    int sides = 8;                // vertices per ring
    double width_scale = 1.0;     // drawn radii are the skeleton's times this (`width_scale`)
    double sharp_bend_deg = 45.0; // past this a joint is rounded with extra rings
    double tip_taper = 0.35;      // radius of the last ring, as a fraction of the axis radius there
    bool continue_axes = true;    // an axis's tube goes on into a child axis (see tube_paths)
    // Where the viewer stands (plant run --camera): with the grammar's `param depth_unit`, each
    // instance placement's view depth comes from its distance to it (docs/language.md, level of
    // detail). None: every placement has the program's own view_depth.
    std::optional<glm::dvec3> camera;
    // Instances (docs/language.md, instances): the outer derivation, whose seed and limits (module
    // count, instructions, interrupt) each instance's derivation takes; none: seed 0, default
    // limits. The memory all instance derivations and their flattened geometry may take (0: 4 GB),
    // and how many distinct instance derivations a scene may need.
    const Derivation* derivation = nullptr;
    std::uint64_t max_memory = 0;
    std::size_t max_instance_derivations = 10000;
};

// The points one tube runs through, in order.
using TubePath = std::vector<const SkeletonPoint*>;

// The tubes of a skeleton. Each axis is one tube, except that an axis that ends where a child
// axis begins, with the child's first segment turning from its last one by no more than
// sharp_bend_deg, goes on into that child (the straightest one when several qualify): the
// sympodial case, where an apex stops and a lateral takes over. The joint is the child's first
// point, so the radius narrows to the child's there. Without this, a sympodial tree (ABOP
// Fig. 2.7) is one tube per segment, each with a hidden tapered tip inside the next.
std::vector<TubePath> tube_paths(const Skeleton& skeleton, const MeshOptions& options);

// Appends one tube to `part`, with primitives grouped by `material_of` (a (color, texture) ->
// material index map the caller keeps across tubes; the texture is SkeletonPoint::texture). Rings
// are shared between consecutive segments; frames are parallel-transported from the first point's
// left vector. Texture coordinates: u runs around the ring from 0 to 1, v is the arc length along
// the axis in world units.
void mesh_tube(const TubePath& path, const MeshOptions& options, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&, int)>& material_of);
// The same with materials by colour alone (textures ignored).
void mesh_tube(const TubePath& path, const MeshOptions& options, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&)>& material_of);

// The whole scene: tubes, prototypes for every surface (and @O spheres) used, instances, and
// each instance the turtle placed derived and meshed once per (instance, arguments, view depth)
// as a scene prototype, placed by transform (instances.cpp). Throws RuntimeError when a surface
// cannot be loaded, and when instances would take more than the options allow.
Scene build_scene(const Program& program, const Skeleton& skeleton, const MeshOptions& options);

// Reads every mesh file the program's `surface s = load("...");` declarations name, its instances'
// bodies' included, each file once, as meshing them would, and throws the RuntimeError meshing
// would throw (kind Input for a file refused as unsafe or malformed). `plant check` runs it, so
// that a file `plant run` would refuse is reported without growing the plant; it reads surfaces
// the plant never places too, which `plant run` does not.
void check_surface_files(const Program& program);

} // namespace plant
