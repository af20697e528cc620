// glTF export of placements: GPU instancing by default, plain nodes, everything baked; the
// decomposition of placement matrices (runtime/src/export_placement.hpp).
#include "export_placement.hpp"
#include "plant/export.hpp"
#include "runtime/nested_scene.hpp"
#include "runtime/parse_glb.hpp"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <tiny_gltf.h>

#include <cstring>
#include <limits>
#include <set>
#include <string>

using namespace plant;
using plant::test::parse_glb;

namespace {

const tinygltf::Node* node_named(const tinygltf::Model& model, const std::string& name) {
    for (const auto& node : model.nodes)
        if (node.name == name) return &node;
    return nullptr;
}

int instanced_nodes(const tinygltf::Model& model) {
    int n = 0;
    for (const auto& node : model.nodes) n += node.extensions.count("EXT_mesh_gpu_instancing") ? 1 : 0;
    return n;
}

// Element k of a float accessor of `width` components.
glm::vec4 element(const tinygltf::Model& model, int accessor, std::size_t k, int width) {
    const auto& a = model.accessors[std::size_t(accessor)];
    const auto& view = model.bufferViews[std::size_t(a.bufferView)];
    const auto& data = model.buffers[std::size_t(view.buffer)].data;
    glm::vec4 v(0.0f);
    std::memcpy(&v[0], data.data() + view.byteOffset + a.byteOffset + k * std::size_t(width) * 4,
                std::size_t(width) * 4);
    return v;
}

int attribute(const tinygltf::Node& node, const char* name) {
    return node.extensions.at("EXT_mesh_gpu_instancing").Get("attributes").Get(name).GetNumberAsInt();
}

} // namespace

TEST_CASE("glTF keeps each mesh of a nested scene once: instanced nodes, plain nodes or baked",
          "[export][gltf]") {
    const Scene scene = test::nested_scene();

    // ground, odd box, trunk, long and short branch, and the leaf of both branch lengths once
    const tinygltf::Model gpu = parse_glb(scene, GltfLayout::GpuInstancing);
    CHECK(gpu.meshes.size() == 6);
    // the ground; the odd box instanced once and plain twice (sheared, mirrored); one instanced
    // node each for the trunks, the two branch lengths and the leaves
    CHECK(gpu.nodes.size() == 8);
    CHECK(instanced_nodes(gpu) == 5);
    CHECK(gpu.extensionsUsed == std::vector<std::string>{"EXT_mesh_gpu_instancing"});
    CHECK(gpu.extensionsRequired.empty()); // viewers without it draw each mesh once
    const tinygltf::Node* leaf = node_named(gpu, "tree/long/leaf");
    REQUIRE(leaf);
    const int n = test::kNestedLeaves;
    CHECK(gpu.accessors[std::size_t(attribute(*leaf, "TRANSLATION"))].count == std::size_t(n));
    CHECK(gpu.accessors[std::size_t(attribute(*leaf, "ROTATION"))].count == std::size_t(n));
    CHECK(gpu.accessors[std::size_t(attribute(*leaf, "SCALE"))].count == std::size_t(n));

    // the leaves' TRS give back the flattened scene's transforms, in order
    const Scene flat = flatten(scene);
    std::vector<glm::mat4> leaf_transforms;
    for (const Instance& inst : flat.instances)
        if (flat.prototype_names[inst.prototype].ends_with("/leaf"))
            leaf_transforms.push_back(inst.transform);
    REQUIRE(leaf_transforms.size() == std::size_t(n));
    for (std::size_t k : {std::size_t(0), std::size_t(50), std::size_t(n - 1)}) {
        const glm::vec4 t = element(gpu, attribute(*leaf, "TRANSLATION"), k, 3);
        const glm::vec4 r = element(gpu, attribute(*leaf, "ROTATION"), k, 4);
        const glm::vec4 s = element(gpu, attribute(*leaf, "SCALE"), k, 3);
        CHECK(glm::length(r) == Approx(1.0f).margin(1e-5));
        const glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(t)) *
                            glm::mat4_cast(glm::quat(r.w, r.x, r.y, r.z)) *
                            glm::scale(glm::mat4(1.0f), glm::vec3(s));
        for (int c = 0; c < 4; ++c)
            for (int row = 0; row < 4; ++row)
                CHECK(m[c][row] == Approx(leaf_transforms[k][c][row]).margin(1e-4));
    }

    // --no-gpu-instancing: the same meshes, one plain node per placement
    const tinygltf::Model nodes = parse_glb(scene, GltfLayout::Nodes);
    CHECK(nodes.meshes.size() == 6);
    CHECK(nodes.nodes.size() == 1 + 3 + 2 + 16 + std::size_t(n));
    CHECK(instanced_nodes(nodes) == 0);
    CHECK(nodes.extensionsUsed.empty());

    // --flatten: one world-space mesh
    const tinygltf::Model baked = parse_glb(scene, GltfLayout::Baked);
    CHECK(baked.meshes.size() == 1);
    CHECK(baked.nodes.size() == 1);
    CHECK(baked.extensionsUsed.empty());
    std::size_t triangles = flat.tubes.triangle_count(), baked_triangles = 0;
    for (const Instance& inst : flat.instances) triangles += flat.prototypes[inst.prototype].triangle_count();
    for (const auto& prim : baked.meshes[0].primitives)
        baked_triangles += baked.accessors[std::size_t(prim.indices)].count / 3;
    CHECK(baked_triangles == triangles);
    CHECK(baked.meshes[0].primitives.size() == 4); // one per color: grey, two browns, green
}

TEST_CASE("a placement that is not a rotation times a positive scale keeps a plain node", "[export][gltf]") {
    const Scene scene = test::nested_scene();
    const tinygltf::Model gpu = parse_glb(scene, GltfLayout::GpuInstancing);
    const tinygltf::Node* odd = node_named(gpu, "odd");
    REQUIRE(odd);
    CHECK(gpu.accessors[std::size_t(attribute(*odd, "TRANSLATION"))].count == 1);
    std::vector<const tinygltf::Node*> plain;
    for (const auto& node : gpu.nodes)
        if (node.mesh == odd->mesh && !node.extensions.count("EXT_mesh_gpu_instancing"))
            plain.push_back(&node);
    REQUIRE(plain.size() == 2);
    for (int k = 0; k < 2; ++k) { // the shear and the mirror, as given
        const glm::mat4& given = scene.instances[std::size_t(k + 1)].transform;
        REQUIRE(plain[std::size_t(k)]->matrix.size() == 16);
        for (int i = 0; i < 16; ++i)
            CHECK(plain[std::size_t(k)]->matrix[std::size_t(i)] == Approx(given[i / 4][i % 4]));
    }
}

TEST_CASE("placement matrices decompose into translation, unit rotation and positive scale",
          "[export][gltf]") {
    glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(1, 2, 3));
    m = glm::rotate(m, 1.2f, glm::normalize(glm::vec3(1, 2, -1)));
    m = glm::scale(m, glm::vec3(0.5f, 0.5f, 0.5f));
    const auto trs = detail::decompose(m);
    REQUIRE(trs);
    CHECK(trs->translation == glm::vec3(1, 2, 3));
    CHECK(glm::length(trs->rotation) == Approx(1.0f).margin(1e-6));
    CHECK(trs->rotation.w >= 0.0f);
    CHECK(trs->scale.x == Approx(0.5f));
    // per-axis scales are a rotation times a positive scale too
    CHECK(detail::decompose(glm::scale(glm::mat4(1.0f), glm::vec3(1, 2, 3))));

    glm::mat4 shear(1.0f);
    shear[1][0] = 0.01f;
    CHECK(!detail::decompose(shear));
    CHECK(!detail::decompose(glm::scale(glm::mat4(1.0f), glm::vec3(1, -1, 1)))); // a mirror
    CHECK(!detail::decompose(glm::scale(glm::mat4(1.0f), glm::vec3(1, 0, 1))));  // a collapsed axis
    glm::mat4 projective(1.0f);
    projective[0][3] = 0.5f;
    CHECK(!detail::decompose(projective));
    glm::mat4 nan(1.0f);
    nan[3][0] = std::numeric_limits<float>::quiet_NaN();
    CHECK(!detail::decompose(nan));
    // within the tolerance: float noise from composing turtle frames
    glm::mat4 noisy = glm::rotate(glm::mat4(1.0f), 0.7f, glm::vec3(0, 1, 0));
    noisy[0][1] += 1e-6f;
    CHECK(detail::decompose(noisy));
}

TEST_CASE("a placement that is not finite is an export error, never a wrong file", "[export][gltf]") {
    Scene scene = test::nested_scene();
    scene.instances[0].transform[3][0] = std::numeric_limits<float>::infinity();
    for (GltfLayout layout : {GltfLayout::GpuInstancing, GltfLayout::Nodes})
        CHECK_THROWS_AS(gltf_bytes(scene, GltfContainer::Binary, "x.glb", layout), ExportError);
}

TEST_CASE("prototypes with the same content are one mesh", "[export][gltf]") {
    Scene scene;
    scene.materials = {Material{}};
    scene.prototypes = {test::leaf_part(0), test::box_part(glm::vec3(1.0f), 0), test::leaf_part(0)};
    scene.prototype_names = {"a", "box", "b"};
    scene.instances = {Instance{0, glm::mat4(1.0f)}, Instance{1, glm::mat4(1.0f)},
                       Instance{2, glm::translate(glm::mat4(1.0f), glm::vec3(3, 0, 0))}};
    CHECK(detail::shared_prototypes(scene) == std::vector<std::uint32_t>{0, 1, 0});
    const tinygltf::Model gpu = parse_glb(scene, GltfLayout::GpuInstancing);
    CHECK(gpu.meshes.size() == 2);
    REQUIRE(node_named(gpu, "a"));
    CHECK(gpu.accessors[std::size_t(attribute(*node_named(gpu, "a"), "TRANSLATION"))].count == 2);
    scene.prototypes[2].positions[1].x += 0.5f; // no longer the same
    CHECK(detail::shared_prototypes(scene) == std::vector<std::uint32_t>{0, 1, 2});
}

namespace {

glm::mat4 node_matrix(const tinygltf::Node& node) {
    if (!node.matrix.empty()) {
        glm::mat4 m;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) m[c][r] = float(node.matrix[std::size_t(c * 4 + r)]);
        return m;
    }
    glm::mat4 m(1.0f);
    if (!node.translation.empty())
        m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
    if (!node.rotation.empty())
        m *= glm::mat4_cast(glm::quat(float(node.rotation[3]), float(node.rotation[0]),
                                      float(node.rotation[1]), float(node.rotation[2])));
    if (!node.scale.empty()) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

} // namespace

TEST_CASE("a scene prototype with many parts placed a few times stays one node per placement, its "
          "instance accessors shared",
          "[export][gltf]") {
    const Scene scene = test::forest_scene(100, 1000); // 100 x 1,001 parts: past kNestedFrom
    const tinygltf::Model gpu = parse_glb(scene, GltfLayout::GpuInstancing);
    CHECK(gpu.meshes.size() == 2); // trunk and leaf
    CHECK(gpu.scenes[0].nodes.size() == 100);
    int leaf_nodes = 0;
    std::set<int> translations;
    const Scene flat = flatten(scene);
    for (std::size_t t = 0; t < gpu.scenes[0].nodes.size(); ++t) {
        const tinygltf::Node& tree = gpu.nodes[std::size_t(gpu.scenes[0].nodes[t])];
        CHECK(tree.name == "tree");
        CHECK(tree.matrix.empty()); // a rigid placement is written as translation, rotation, scale
        REQUIRE(tree.children.size() == 2);
        for (int child : tree.children) {
            const tinygltf::Node& c = gpu.nodes[std::size_t(child)];
            if (!c.extensions.count("EXT_mesh_gpu_instancing")) continue;
            ++leaf_nodes;
            translations.insert(attribute(c, "TRANSLATION"));
            CHECK(gpu.accessors[std::size_t(attribute(c, "TRANSLATION"))].count == 1000);
            // leaf k of tree t, in the world: as flatten() places it
            for (std::size_t k : {std::size_t(0), std::size_t(517), std::size_t(999)}) {
                const glm::vec4 tr = element(gpu, attribute(c, "TRANSLATION"), k, 3);
                const glm::vec4 q = element(gpu, attribute(c, "ROTATION"), k, 4);
                const glm::vec4 sc = element(gpu, attribute(c, "SCALE"), k, 3);
                const glm::mat4 local = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(tr)) *
                                                       glm::mat4_cast(glm::quat(q.w, q.x, q.y, q.z)),
                                                   glm::vec3(sc));
                const glm::mat4 world = node_matrix(tree) * local;
                // flatten() lists each tree's tubes, then its 1,000 leaves
                const glm::mat4& want = flat.instances[t * 1001 + 1 + k].transform;
                for (int col = 0; col < 4; ++col)
                    for (int row = 0; row < 4; ++row)
                        CHECK(world[col][row] == Approx(want[col][row]).margin(1e-4));
            }
        }
    }
    CHECK(leaf_nodes == 100);
    CHECK(translations.size() == 1); // one accessor for every tree's leaves

    // a tree placed a few times with few parts is drawn into one level, as before
    const tinygltf::Model small = parse_glb(test::forest_scene(3, 20), GltfLayout::GpuInstancing);
    CHECK(small.scenes[0].nodes.size() == 2); // an instanced trunk node, an instanced leaf node
}
