// glTF 2.0 export through tinygltf.
//
// Layout of the single buffer: for each non-empty mesh part (the tubes, then each distinct placed
// prototype) four tightly packed buffer views, in this order: POSITION (vec3 float), NORMAL (vec3
// float), TEXCOORD_0 (vec2 float), indices (uint32). Every primitive of a part shares the part's
// vertex accessors and has its own index accessor, a window into the part's index view. With GPU
// instancing, each instanced node's TRANSLATION (vec3), ROTATION (vec4) and SCALE (vec3) views
// follow the meshes. All components are 4 bytes, so every view and accessor is 4-byte aligned.
// Each texture image a material uses is written once, as its file's bytes in a buffer view of its
// own (padded to 4 bytes like the others), where its material first needs it; every texture
// shares one sampler (repeat in both directions, linear filtering with mipmaps).
//
// The buffer is never gathered in memory for a .glb: the builder keeps a list of pieces (the
// scene's own arrays, padding, the few arrays made here) and writes them one after another after
// the JSON; normals are renormalized as they are written, a block at a time.
#include "plant/export.hpp"

#include "bounds.hpp"
#include "export_placement.hpp"

#include <tiny_gltf.h>

#include <glm/glm.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <optional>
#include <sstream>

namespace plant {

// ---------------------------------------------------------------------------------------------
// glTF

namespace {

std::string quoted(const std::string& s) {
    return "'" + s + "'";
}

constexpr const char* kGpuInstancing = "EXT_mesh_gpu_instancing";
constexpr int array_buffer = 34962;         // ARRAY_BUFFER
constexpr int element_array_buffer = 34963; // ELEMENT_ARRAY_BUFFER

// The double nearest to the shortest decimal that reads back as `f`: JSON then shows 0.1 for
// 0.1f instead of 0.10000000149011612. Not for accessor min and max, which must match the data.
double tidy(float f) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, f).ptr;
    double d = 0.0;
    std::from_chars(text, end, d);
    return d;
}

// The validator rejects normals that are not unit length: renormalized when written.
glm::vec3 unit_normal(glm::vec3 n) {
    const float len = glm::length(n);
    if (!(len > 1e-20f) || !std::isfinite(len)) return glm::vec3(0.0f, 1.0f, 0.0f);
    if (std::abs(len - 1.0f) > 1e-5f) n /= len;
    return n;
}

// Whether unit_normal leaves each of the `n` vec3 floats at `bytes` as it is: a squared length
// within [(1 - 1e-5)^2, (1 + 1e-5)^2], narrowed by 1e-6 each side for the rounding of the squared
// length against glm::length's (a normal near the edge takes the exact path). NaN fails.
bool all_unit(const unsigned char* bytes, std::size_t n) {
    constexpr float kLow = (1.0f - 1e-5f) * (1.0f - 1e-5f) + 1e-6f,
                    kHigh = (1.0f + 1e-5f) * (1.0f + 1e-5f) - 1e-6f;
    bool ok = true;
    for (std::size_t k = 0; k < n; ++k) {
        float v[3];
        std::memcpy(v, bytes + k * sizeof v, sizeof v);
        const float s = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        ok &= (s >= kLow) & (s <= kHigh);
    }
    return ok;
}

// A run of the buffer's bytes: borrowed from the scene (or from GltfBuilder::owned), or normals
// (vec3 floats) to renormalize on the way out.
struct Piece {
    const unsigned char* bytes;
    std::size_t size;
    bool normals;
};

constexpr unsigned char kZeros[4] = {0, 0, 0, 0};

struct GltfBuilder {
    const Scene& scene;
    const std::vector<detail::NestedGroup>& groups; // scene prototypes kept as nodes
    tinygltf::Model model;
    std::vector<int> material_index;               // scene material -> glTF material, -1 while unused
    std::vector<int> texture_index;                // scene texture -> glTF texture, -1 while unused
    std::vector<std::uint32_t> shared;             // prototype -> the first prototype with the same mesh
    std::vector<int> proto_mesh;                   // prototype -> its mesh, -1 while none (or empty)
    std::vector<bool> meshed;                      // prototype -> add_mesh was called for it
    std::vector<Piece> pieces;                     // the buffer, in order
    std::size_t length = 0;                        // the buffer's length: the pieces' sizes added up
    std::vector<std::vector<unsigned char>> owned; // bytes made here that pieces point into
    MeshPart baked;                                // the --flatten mesh, which pieces point into

    GltfBuilder(const Scene& s, const std::vector<detail::NestedGroup>& g) : scene(s), groups(g) {
        model.asset.version = "2.0";
        model.asset.generator = "plant";
        material_index.assign(std::max<std::size_t>(scene.materials.size(), 1), -1);
        texture_index.assign(scene.textures.size(), -1);
    }

    // Pads the buffer with zeros to a multiple of 4 bytes.
    void align() {
        if (model.buffers.empty()) model.buffers.emplace_back();
        if (const std::size_t pad = (4 - length % 4) % 4) {
            pieces.push_back(Piece{kZeros, pad, false});
            length += pad;
        }
    }

    // Adds `size` bytes at `bytes` as a new buffer view (4-byte aligned) and returns its index. The
    // bytes are read when the file is written: they must outlive the builder's write.
    int add_view(const void* bytes, std::size_t size, int target, bool normals = false) {
        align();
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = length;
        view.byteLength = size;
        view.target = target;
        if (size > 0) pieces.push_back(Piece{static_cast<const unsigned char*>(bytes), size, normals});
        length += size;
        model.bufferViews.push_back(std::move(view));
        return static_cast<int>(model.bufferViews.size() - 1);
    }

    // Hands the buffer's bytes to `sink`, normals renormalized a block at a time. The mesher's
    // normals are unit already: a block that unit_normal would leave as it is goes out from the
    // scene's own array, only the others through a copy.
    void write_buffer(const ByteSink& sink) const {
        std::vector<glm::vec3> block;
        for (const Piece& piece : pieces) {
            if (!piece.normals) {
                sink(piece.bytes, piece.size);
                continue;
            }
            constexpr std::size_t kBlock = 1 << 15; // 384 kB a write
            const std::size_t count = piece.size / sizeof(glm::vec3);
            for (std::size_t at = 0; at < count; at += kBlock) {
                const std::size_t n = std::min(kBlock, count - at);
                const unsigned char* from = piece.bytes + at * sizeof(glm::vec3);
                if (all_unit(from, n)) {
                    sink(from, n * sizeof(glm::vec3));
                    continue;
                }
                block.resize(kBlock);
                std::memcpy(block.data(), from, n * sizeof(glm::vec3));
                for (std::size_t k = 0; k < n; ++k) block[k] = unit_normal(block[k]);
                sink(block.data(), n * sizeof(glm::vec3));
            }
        }
    }

    int add_accessor(int view, std::size_t byte_offset, std::size_t count, int type, int component_type) {
        tinygltf::Accessor a;
        a.bufferView = view;
        a.byteOffset = byte_offset;
        a.count = count;
        a.type = type;
        a.componentType = component_type;
        model.accessors.push_back(std::move(a));
        return static_cast<int>(model.accessors.size() - 1);
    }

    int material(std::uint32_t m, const std::string& part) {
        if (scene.materials.empty() ? m != 0 : m >= scene.materials.size())
            throw ExportError("glTF export: " + part + " uses material " + std::to_string(m) +
                              " but the scene has " + std::to_string(scene.materials.size()));
        int& index = material_index[m];
        if (index >= 0) return index;
        const Material color = scene.materials.empty() ? Material{} : scene.materials[m];
        tinygltf::Material mat;
        mat.name = "material" + std::to_string(m);
        auto channel = [](float x) { return std::isfinite(x) ? tidy(std::clamp(x, 0.0f, 1.0f)) : 0.0; };
        mat.pbrMetallicRoughness.baseColorFactor = {channel(color.color.r), channel(color.color.g),
                                                    channel(color.color.b), 1.0};
        if (color.texture >= 0) { // the image replaces the colour (docs/language.md, textures)
            mat.pbrMetallicRoughness.baseColorTexture.index = texture(color.texture, part);
            mat.pbrMetallicRoughness.baseColorTexture.texCoord = 0;
            mat.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
        }
        mat.pbrMetallicRoughness.metallicFactor = 0.0;
        mat.pbrMetallicRoughness.roughnessFactor = 0.9;
        mat.doubleSided = true;
        model.materials.push_back(std::move(mat));
        index = static_cast<int>(model.materials.size() - 1);
        return index;
    }

    // The glTF texture of scene texture t: its image (the file's bytes in a buffer view) and the
    // one sampler, added on first use.
    int texture(int t, const std::string& part) {
        if (static_cast<std::size_t>(t) >= scene.textures.size() || !scene.textures[std::size_t(t)].bytes)
            throw ExportError("glTF export: " + part + " uses texture " + std::to_string(t) +
                              " but the scene has " + std::to_string(scene.textures.size()));
        int& index = texture_index[std::size_t(t)];
        if (index >= 0) return index;
        const Texture& given = scene.textures[std::size_t(t)];
        if (model.samplers.empty()) {
            tinygltf::Sampler sampler;
            sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
            sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
            sampler.wrapS = TINYGLTF_TEXTURE_WRAP_REPEAT;
            sampler.wrapT = TINYGLTF_TEXTURE_WRAP_REPEAT;
            model.samplers.push_back(std::move(sampler));
        }
        tinygltf::Image image;
        image.name = given.name;
        image.mimeType = given.mime_type;
        image.bufferView = add_view(given.bytes->data(), given.bytes->size(), 0);
        model.images.push_back(std::move(image));
        tinygltf::Texture tex;
        tex.name = given.name;
        tex.sampler = 0;
        tex.source = static_cast<int>(model.images.size() - 1);
        model.textures.push_back(std::move(tex));
        index = static_cast<int>(model.textures.size() - 1);
        return index;
    }

    // Adds `part` as one mesh and returns its index, or -1 when it has no triangles.
    int add_mesh(const MeshPart& part, const std::string& name) {
        const std::size_t nv = part.positions.size();
        check_mesh_part(part, "glTF export: " + name);
        if (nv > std::numeric_limits<std::uint32_t>::max())
            throw ExportError("glTF export: " + name + " has too many vertices");

        const std::vector<Primitive> prims = detail::drawn_primitives(part, "glTF export: " + name);
        if (prims.empty() || nv == 0) return -1;

        tinygltf::Mesh mesh;
        mesh.name = name;

        // POSITION, with the min and max the specification requires.
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
        if (!grow_point_bounds(part.positions.data(), nv, lo, hi))
            throw ExportError("glTF export: " + name + " has a position that is not finite");
        const int pos_view = add_view(part.positions.data(), nv * sizeof(glm::vec3), array_buffer);
        const int pos = add_accessor(pos_view, 0, nv, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT);
        model.accessors[std::size_t(pos)].minValues = {lo.x, lo.y, lo.z};
        model.accessors[std::size_t(pos)].maxValues = {hi.x, hi.y, hi.z};

        // NORMAL: renormalized as they are written (unit_normal)
        int nrm = -1;
        if (!part.normals.empty()) {
            const int view = add_view(part.normals.data(), nv * sizeof(glm::vec3), array_buffer, true);
            nrm = add_accessor(view, 0, nv, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT);
        }

        int uv = -1;
        if (!part.uvs.empty()) {
            const int view = add_view(part.uvs.data(), nv * sizeof(glm::vec2), array_buffer);
            uv = add_accessor(view, 0, nv, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT);
        }

        const int idx_view =
            add_view(part.indices.data(), part.indices.size() * sizeof(std::uint32_t), element_array_buffer);
        for (const Primitive& p : prims) {
            tinygltf::Primitive prim;
            prim.attributes["POSITION"] = pos;
            if (nrm >= 0) prim.attributes["NORMAL"] = nrm;
            if (uv >= 0) prim.attributes["TEXCOORD_0"] = uv;
            prim.indices = add_accessor(idx_view, std::size_t(p.first) * sizeof(std::uint32_t), p.count,
                                        TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
            prim.material = material(p.material, name);
            prim.mode = TINYGLTF_MODE_TRIANGLES; // tinygltf 2.7 writes -1 otherwise
            mesh.primitives.push_back(std::move(prim));
        }
        model.meshes.push_back(std::move(mesh));
        return static_cast<int>(model.meshes.size() - 1);
    }

    // Adds `node` at the scene's top level, or as a child of node `parent`.
    int add_node(tinygltf::Node node, int parent = -1) {
        model.nodes.push_back(std::move(node));
        const int index = static_cast<int>(model.nodes.size() - 1);
        if (parent < 0)
            model.scenes[0].nodes.push_back(index);
        else
            model.nodes[std::size_t(parent)].children.push_back(index);
        return index;
    }

    // Sets the node's transform: translation, rotation and scale when it is one, else the matrix.
    void place(tinygltf::Node& node, const glm::mat4& transform, const std::string& what) {
        if (const auto trs = detail::decompose(transform)) {
            node.translation = {tidy(trs->translation.x), tidy(trs->translation.y), tidy(trs->translation.z)};
            node.rotation = {trs->rotation.x, trs->rotation.y, trs->rotation.z, trs->rotation.w};
            node.scale = {tidy(trs->scale.x), tidy(trs->scale.y), tidy(trs->scale.z)};
            return;
        }
        node.matrix.resize(16);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) {
                const float x = transform[c][r];
                if (!std::isfinite(x))
                    throw ExportError("glTF export: a placement of " + what +
                                      " has a transform that is not finite");
                node.matrix[std::size_t(c * 4 + r)] = tidy(x);
            }
    }

    // A plain node placing `mesh` by the instance's matrix.
    void add_matrix_node(int mesh, const glm::mat4& transform, int parent = -1) {
        tinygltf::Node node;
        node.mesh = mesh;
        node.matrix.resize(16);
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) {
                const float x = transform[c][r];
                if (!std::isfinite(x))
                    throw ExportError("glTF export: an instance of " + model.meshes[std::size_t(mesh)].name +
                                      " has a transform that is not finite");
                node.matrix[std::size_t(c * 4 + r)] = tidy(x);
            }
        add_node(std::move(node), parent);
    }

    template <class T> int add_instance_accessor(const std::vector<T>& values, int type) {
        const auto* p = reinterpret_cast<const unsigned char*>(values.data());
        const std::vector<unsigned char>& kept = owned.emplace_back(p, p + values.size() * sizeof(T));
        const int view = add_view(kept.data(), kept.size(), 0);
        return add_accessor(view, 0, values.size(), type, TINYGLTF_COMPONENT_TYPE_FLOAT);
    }

    // Instance accessors for `placements` (EXT_mesh_gpu_instancing's attributes), or none when
    // no placement is a rotation times a positive scale; those that are not go to `plain`.
    std::optional<tinygltf::Value> instance_attributes(const std::vector<const glm::mat4*>& placements,
                                                       std::vector<const glm::mat4*>& plain) {
        std::vector<glm::vec3> translation, scale;
        std::vector<glm::vec4> rotation;
        for (const glm::mat4* m : placements) {
            if (const auto trs = detail::decompose(*m)) {
                translation.push_back(trs->translation);
                rotation.push_back(trs->rotation);
                scale.push_back(trs->scale);
            } else {
                plain.push_back(m);
            }
        }
        if (translation.empty()) return std::nullopt;
        tinygltf::Value::Object attributes;
        attributes["TRANSLATION"] = tinygltf::Value(add_instance_accessor(translation, TINYGLTF_TYPE_VEC3));
        attributes["ROTATION"] = tinygltf::Value(add_instance_accessor(rotation, TINYGLTF_TYPE_VEC4));
        attributes["SCALE"] = tinygltf::Value(add_instance_accessor(scale, TINYGLTF_TYPE_VEC3));
        tinygltf::Value::Object extension;
        extension["attributes"] = tinygltf::Value(std::move(attributes));
        if (model.extensionsUsed.empty()) model.extensionsUsed.push_back(kGpuInstancing);
        return tinygltf::Value(std::move(extension));
    }

    void add_instanced_node(int mesh, const tinygltf::Value& extension, int parent = -1) {
        tinygltf::Node node;
        node.name = model.meshes[std::size_t(mesh)].name;
        node.mesh = mesh;
        node.extensions[kGpuInstancing] = extension;
        add_node(std::move(node), parent);
    }

    // One node drawing `mesh` at every placement (EXT_mesh_gpu_instancing); a placement that is not
    // a rotation times a positive scale gets a plain node instead.
    void add_instanced(int mesh, const std::vector<const glm::mat4*>& placements) {
        std::vector<const glm::mat4*> plain;
        if (const auto extension = instance_attributes(placements, plain))
            add_instanced_node(mesh, *extension);
        for (const glm::mat4* m : plain) add_matrix_node(mesh, *m);
    }

    // The mesh of prototype k (the first prototype with the same mesh, meshed once), or -1.
    int mesh_of(std::uint32_t k) {
        k = shared[k];
        if (!meshed[k]) {
            meshed[k] = true;
            proto_mesh[k] = add_mesh(scene.prototypes[k], prototype_name(k));
        }
        return proto_mesh[k];
    }

    // A nested scene prototype: its parts' meshes and instance accessors written once, then a
    // node per placement whose children draw them.
    void add_group(const detail::NestedGroup& group) {
        std::vector<int> meshes;                              // in the order first drawn
        std::map<int, std::vector<const glm::mat4*>> by_mesh; // mesh -> its transforms in the group
        for (const auto& [proto, transform] : group.parts) {
            const int mesh = mesh_of(proto);
            if (mesh < 0) continue;
            auto [it, added] = by_mesh.try_emplace(mesh);
            if (added) meshes.push_back(mesh);
            it->second.push_back(&transform);
        }
        std::vector<std::pair<int, tinygltf::Value>> instanced;
        std::vector<std::pair<int, const glm::mat4*>> plain;
        for (int mesh : meshes) {
            std::vector<const glm::mat4*> rest;
            if (by_mesh[mesh].size() == 1) { // drawn once (the tubes): a plain child node
                plain.emplace_back(mesh, by_mesh[mesh][0]);
                continue;
            }
            if (auto extension = instance_attributes(by_mesh[mesh], rest))
                instanced.emplace_back(mesh, std::move(*extension));
            for (const glm::mat4* m : rest) plain.emplace_back(mesh, m);
        }
        for (const glm::mat4& placement : group.placements) {
            tinygltf::Node node;
            node.name = group.name;
            place(node, placement, group.name);
            const int parent = add_node(std::move(node));
            for (const auto& [mesh, extension] : instanced) add_instanced_node(mesh, extension, parent);
            for (const auto& [mesh, m] : plain) {
                tinygltf::Node child;
                child.name = model.meshes[std::size_t(mesh)].name;
                child.mesh = mesh;
                if (*m != glm::mat4(1.0f)) place(child, *m, child.name);
                add_node(std::move(child), parent);
            }
        }
    }

    std::string prototype_name(std::size_t i) const {
        return i < scene.prototype_names.size() && !scene.prototype_names[i].empty()
                   ? scene.prototype_names[i]
                   : "prototype" + std::to_string(i);
    }

    void build(GltfLayout layout) {
        model.scenes.emplace_back();
        model.scenes[0].name = "plant";
        model.defaultScene = 0;

        if (layout == GltfLayout::Baked) {
            baked = detail::bake(scene, "glTF export");
            const int mesh = add_mesh(baked, "plant");
            if (mesh >= 0) {
                tinygltf::Node node;
                node.name = "plant";
                node.mesh = mesh;
                add_node(std::move(node));
            }
        } else {
            const int tubes = add_mesh(scene.tubes, "tubes");
            if (tubes >= 0) {
                tinygltf::Node node;
                node.name = "tubes";
                node.mesh = tubes;
                add_node(std::move(node));
            }
            add_placements(layout);
        }

        if (!model.buffers.empty()) align();
    }

    // The JSON of a .glb: tinygltf's, serialized with an empty buffer whose byteLength is then
    // set. The key cannot occur elsewhere: strings in the JSON have their quotes escaped.
    std::string glb_json(const std::string& path) const {
        std::ostringstream out(std::ios::out | std::ios::binary);
        tinygltf::TinyGLTF gltf;
        if (!gltf.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/false, /*writeBinary=*/true) || !out)
            throw ExportError("cannot write " + quoted(path) + ": glTF serialization failed");
        const std::string glb = std::move(out).str();
        std::uint32_t chunk = 0; // after the 12-byte header: the JSON chunk's length, then its type
        if (glb.size() >= 20) std::memcpy(&chunk, glb.data() + 12, 4);
        std::string json = glb.substr(std::min<std::size_t>(20, glb.size()), chunk);
        while (!json.empty() && json.back() == ' ') json.pop_back(); // the chunk's padding
        if (model.buffers.empty()) return json;
        const std::string empty = R"("buffers":[{"byteLength":0}])";
        const std::size_t at = json.find(empty);
        if (at == std::string::npos)
            throw ExportError("cannot write " + quoted(path) + ": glTF serialization gave no buffer");
        json.replace(at, empty.size(), R"("buffers":[{"byteLength":)" + std::to_string(length) + "}]");
        return json;
    }

    // A .glb: header, JSON chunk (padded with spaces), binary chunk (when the buffer has bytes).
    void write_glb(const std::string& path, const ByteSink& sink) const {
        std::string json = glb_json(path);
        json.append((4 - json.size() % 4) % 4, ' ');
        const std::uint64_t total = 12 + 8 + json.size() + (length > 0 ? 8 + length : 0);
        if (total > std::numeric_limits<std::uint32_t>::max())
            throw ExportError("cannot write " + quoted(path) +
                              ": the scene is too large for a .glb file (over 4 GB)");
        // little-endian, as the format is (the machines plant builds on are)
        const std::uint32_t head[5] = {0x46546C67, 2, std::uint32_t(total), std::uint32_t(json.size()),
                                       0x4E4F534A};
        sink(head, sizeof head);
        sink(json.data(), json.size());
        if (length == 0) return;
        const std::uint32_t bin[2] = {std::uint32_t(length), 0x004E4942};
        sink(bin, sizeof bin);
        write_buffer(sink);
    }

    // The placed prototypes, each distinct one meshed once, and their placements.
    void add_placements(GltfLayout layout) {
        shared = detail::shared_prototypes(scene);
        proto_mesh.assign(scene.prototypes.size(), -1);
        meshed.assign(scene.prototypes.size(), false);
        // placements by mesh, in the order meshes are first placed
        std::vector<std::vector<const glm::mat4*>> placements;
        for (const Instance& inst : scene.instances) {
            const int mesh = mesh_of(inst.prototype);
            if (mesh < 0) continue;
            if (layout == GltfLayout::Nodes) {
                add_matrix_node(mesh, inst.transform);
                continue;
            }
            if (placements.size() <= std::size_t(mesh)) placements.resize(std::size_t(mesh) + 1);
            placements[std::size_t(mesh)].push_back(&inst.transform);
        }
        for (std::size_t mesh = 0; mesh < placements.size(); ++mesh)
            if (!placements[mesh].empty()) add_instanced(static_cast<int>(mesh), placements[mesh]);
        for (const detail::NestedGroup& group : groups) add_group(group);
    }
};

} // namespace

void gltf_to(const Scene& scene, GltfContainer container, const std::string& path, GltfLayout layout,
             const ByteSink& sink) {
    // With GPU instancing, scene prototypes holding many parts stay nodes (export_placement.hpp);
    // the other layouts draw everything into one level.
    Scene flat, storage;
    std::vector<detail::NestedGroup> groups;
    const Scene* drawn = &scene;
    if (layout == GltfLayout::GpuInstancing && scene.nested()) {
        flat = detail::split_nested(scene, groups, "glTF export");
        drawn = &flat;
    }
    GltfBuilder builder(exported_scene(*drawn, storage, "glTF export"), groups);
    builder.build(layout);
    if (container == GltfContainer::Binary) {
        builder.write_glb(path, sink);
        return;
    }
    // .gltf: the buffer is embedded in the JSON as a data URI, so it is gathered first
    if (!builder.model.buffers.empty()) {
        auto& data = builder.model.buffers[0].data;
        data.reserve(builder.length);
        builder.write_buffer([&](const void* bytes, std::size_t size) {
            const auto* p = static_cast<const unsigned char*>(bytes);
            data.insert(data.end(), p, p + size);
        });
    }
    std::ostringstream out(std::ios::out | std::ios::binary);
    tinygltf::TinyGLTF gltf;
    if (!gltf.WriteGltfSceneToStream(&builder.model, out, /*prettyPrint=*/true, /*writeBinary=*/false) ||
        !out)
        throw ExportError("cannot write " + quoted(path) + ": glTF serialization failed");
    builder.model = tinygltf::Model{};
    const std::string text = std::move(out).str();
    sink(text.data(), text.size());
}

std::string gltf_bytes(const Scene& scene, GltfContainer container, const std::string& path,
                       GltfLayout layout) {
    std::string bytes;
    gltf_to(scene, container, path, layout,
            [&](const void* data, std::size_t size) { bytes.append(static_cast<const char*>(data), size); });
    return bytes;
}

void write_gltf(const Scene& scene, const std::string& path, GltfContainer container, GltfLayout layout) {
    write_file_atomically(path, gltf_bytes(scene, container, path, layout));
}

} // namespace plant
