// Reading back a GLB plant wrote, for the export tests: tinygltf parses it, and a parse failure
// fails the test with tinygltf's message.
#pragma once

#include "plant/export.hpp"

#include <catch2/catch.hpp>
#include <tiny_gltf.h>

#include <string>

namespace plant::test {

inline tinygltf::Model parse_glb(const std::string& bytes) {
    tinygltf::TinyGLTF loader;
    tinygltf::Model model;
    std::string err, warn;
    const bool ok =
        loader.LoadBinaryFromMemory(&model, &err, &warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                    static_cast<unsigned>(bytes.size()));
    INFO(err);
    REQUIRE(ok);
    return model;
}

inline tinygltf::Model parse_glb(const Scene& scene, GltfLayout layout) {
    return parse_glb(gltf_bytes(scene, GltfContainer::Binary, "test.glb", layout));
}

} // namespace plant::test
