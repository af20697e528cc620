// Writes the hand-made nested scene of the export tests (tests/unit/runtime/nested_scene.hpp) as
// glTF, for the node checks in tests/gltf/instances.sh:
//   gltf_nested_scene DIR
// DIR/nested.glb (GPU instancing), DIR/nested.nodes.glb (plain nodes), DIR/nested.flat.glb
// (baked) and DIR/nested.gltf (JSON, GPU instancing); DIR/forest.glb and DIR/forest.nodes.glb, a
// forest whose trees stay nodes (GPU instancing) and the same with plain nodes.
#include "runtime/nested_scene.hpp"
#include "plant/export.hpp"

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: gltf_nested_scene DIR\n");
        return 64;
    }
    const std::string dir = argv[1];
    try {
        const plant::Scene scene = plant::test::nested_scene();
        using plant::GltfContainer, plant::GltfLayout;
        plant::write_gltf(scene, dir + "/nested.glb", GltfContainer::Binary, GltfLayout::GpuInstancing);
        plant::write_gltf(scene, dir + "/nested.nodes.glb", GltfContainer::Binary, GltfLayout::Nodes);
        plant::write_gltf(scene, dir + "/nested.flat.glb", GltfContainer::Binary, GltfLayout::Baked);
        plant::write_gltf(scene, dir + "/nested.gltf", GltfContainer::Json, GltfLayout::GpuInstancing);
        // 70 trees of 1,000 leaves: each tree stays a node, its leaf placements written once
        const plant::Scene forest = plant::test::forest_scene(70, 1000);
        plant::write_gltf(forest, dir + "/forest.glb", GltfContainer::Binary, GltfLayout::GpuInstancing);
        plant::write_gltf(forest, dir + "/forest.nodes.glb", GltfContainer::Binary, GltfLayout::Nodes);
    } catch (const plant::ExportError& e) {
        std::fprintf(stderr, "gltf_nested_scene: %s\n", e.what());
        return 73;
    }
    return 0;
}
