// The .glb writer hands the file to its sink piece by piece (gltf_to): the scene's arrays go out
// as they are, never gathered, and normals are renormalized on the way, a block at a time.
#include "parse_glb.hpp"

#include "plant/export.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>

using namespace plant;

namespace {

// A strip of quads with `n` vertices whose normals are twice unit length, but for the first (zero)
// and the last (not finite).
Scene strip(std::size_t n) {
    Scene s;
    MeshPart& t = s.tubes;
    for (std::size_t k = 0; k < n; ++k) {
        const float x = float(k / 2), y = float(k % 2);
        t.positions.emplace_back(x, y, 0.0f);
        t.normals.emplace_back(0.0f, 0.0f, 2.0f);
        t.uvs.emplace_back(x, y);
    }
    t.normals.front() = glm::vec3(0.0f);
    t.normals.back() = glm::vec3(std::numeric_limits<float>::quiet_NaN());
    for (std::uint32_t k = 0; k + 3 < n; k += 2)
        t.indices.insert(t.indices.end(), {k, k + 1, k + 3, k, k + 3, k + 2});
    t.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(t.indices.size()), 0});
    s.materials.push_back(Material{});
    s.update_bounds();
    return s;
}

} // namespace

TEST_CASE("a .glb goes to the sink straight from the scene's arrays", "[export][gltf]") {
    const Scene s = strip(70'001); // normals over more than two blocks of 32768
    std::string file;
    bool positions_borrowed = false;
    std::size_t pieces = 0;
    gltf_to(s, GltfContainer::Binary, "x.glb", GltfLayout::GpuInstancing,
            [&](const void* data, std::size_t size) {
                ++pieces;
                positions_borrowed =
                    positions_borrowed || data == static_cast<const void*>(s.tubes.positions.data());
                file.append(static_cast<const char*>(data), size);
            });
    CHECK(positions_borrowed); // not a copy
    CHECK(pieces > 4);
    CHECK(file == gltf_bytes(s, GltfContainer::Binary, "x.glb"));
    std::uint32_t total = 0;
    std::memcpy(&total, file.data() + 8, 4);
    CHECK(total == file.size());

    const tinygltf::Model m = test::parse_glb(file);
    REQUIRE(m.meshes.size() == 1);
    const tinygltf::Accessor& a = m.accessors[std::size_t(m.meshes[0].primitives[0].attributes.at("NORMAL"))];
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    REQUIRE(a.count == s.tubes.normals.size());
    std::vector<glm::vec3> normals(a.count);
    std::memcpy(normals.data(), m.buffers[0].data.data() + v.byteOffset, a.count * sizeof(glm::vec3));
    CHECK(normals.front() == glm::vec3(0.0f, 1.0f, 0.0f)); // zero: a default
    CHECK(normals.back() == glm::vec3(0.0f, 1.0f, 0.0f));  // not finite: a default
    std::size_t unit = 0;
    for (std::size_t k = 1; k + 1 < normals.size(); ++k) unit += normals[k] == glm::vec3(0.0f, 0.0f, 1.0f);
    CHECK(unit == normals.size() - 2);
    CHECK(s.tubes.normals[1] == glm::vec3(0.0f, 0.0f, 2.0f)); // the scene's own are left alone
}

TEST_CASE("a .gltf holds the same buffer as the .glb", "[export][gltf]") {
    const Scene s = strip(5'000);
    const tinygltf::Model binary = test::parse_glb(gltf_bytes(s, GltfContainer::Binary, "x.glb"));
    const std::string text = gltf_bytes(s, GltfContainer::Json, "x.gltf");
    tinygltf::TinyGLTF loader;
    tinygltf::Model json;
    std::string err, warn;
    REQUIRE(
        loader.LoadASCIIFromString(&json, &err, &warn, text.data(), static_cast<unsigned>(text.size()), ""));
    REQUIRE(json.buffers.size() == 1);
    CHECK(json.buffers[0].data == binary.buffers[0].data);
}

TEST_CASE("unit normals go out from the scene's array, a block with one that is not through a copy",
          "[export][gltf]") {
    Scene s = strip(70'001);
    for (glm::vec3& n : s.tubes.normals) n = glm::vec3(0.0f, 0.0f, 1.0f);
    s.tubes.normals[2 * 32768 + 5] = glm::vec3(0.0f, 0.0f, 1.00003f);  // past unit_normal's 1e-5
    s.tubes.normals[2 * 32768 + 6] = glm::vec3(0.0f, 0.0f, 1.000004f); // within it: kept as it is
    const auto* first = static_cast<const void*>(s.tubes.normals.data());
    const auto* third = static_cast<const void*>(s.tubes.normals.data() + 2 * 32768);
    bool first_borrowed = false, third_borrowed = false;
    std::string file;
    gltf_to(s, GltfContainer::Binary, "x.glb", GltfLayout::GpuInstancing,
            [&](const void* data, std::size_t size) {
                first_borrowed = first_borrowed || data == first;
                third_borrowed = third_borrowed || data == third;
                file.append(static_cast<const char*>(data), size);
            });
    CHECK(first_borrowed);
    CHECK_FALSE(third_borrowed);
    const tinygltf::Model m = test::parse_glb(file);
    const tinygltf::Accessor& a = m.accessors[std::size_t(m.meshes[0].primitives[0].attributes.at("NORMAL"))];
    const tinygltf::BufferView& v = m.bufferViews[std::size_t(a.bufferView)];
    std::vector<glm::vec3> normals(a.count);
    std::memcpy(normals.data(), m.buffers[0].data.data() + v.byteOffset, a.count * sizeof(glm::vec3));
    CHECK(normals[2 * 32768 + 5] == glm::vec3(0.0f, 0.0f, 1.0f));
    CHECK(normals[2 * 32768 + 6] == glm::vec3(0.0f, 0.0f, 1.000004f));
    CHECK(normals[2 * 32768 + 7] == glm::vec3(0.0f, 0.0f, 1.0f));
}
