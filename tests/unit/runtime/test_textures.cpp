// Textures (docs/language.md, textures): `texture name = image("file")` read at compile time,
// SetTexture on the turtle's state (brackets restore it), materials by colour and texture through
// instances, flatten and split_nested, the image in glTF, and the PNG preview's flat colour.
#include "export_placement.hpp"
#include "helpers.hpp"
#include "plant/export.hpp"
#include "plant/mesh.hpp"
#include "runtime/nested_scene.hpp"
#include "runtime/parse_glb.hpp"
#include "texture_image.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

using namespace plant;
using plant::test::parse_glb;

namespace {

const std::string kBark = std::string(PLANT_SOURCE_DIR) + "/stdlib/textures/bark.png";

std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// A file in the temporary folder holding `bytes`, removed with the object.
struct TempFile {
    std::string path;
    TempFile(const std::string& name, const std::string& bytes)
        : path((std::filesystem::temp_directory_path() / name).string()) {
        std::ofstream(path, std::ios::binary) << bytes;
    }
    ~TempFile() { std::filesystem::remove(path); }
    TempFile(const TempFile&) = delete;
    TempFile& operator=(const TempFile&) = delete;
};

std::string with_bark(const std::string& rest) {
    return fmt::format("texture bark = image(\"{}\");\n{}", kBark, rest);
}

struct Built {
    std::unique_ptr<test::Compiled> compiled;
    Skeleton skeleton;
    Scene scene;
};

Built build(const std::string& grammar) {
    Built b;
    b.compiled = test::compile(grammar);
    INFO(b.compiled->rendered());
    REQUIRE(b.compiled->program);
    const Program& p = *b.compiled->program;
    Derivation d(p, {});
    d.run();
    b.skeleton = build_skeleton(p, d.interpreted(d.string()), turtle_options(d));
    MeshOptions mo;
    mo.derivation = &d;
    b.scene = build_scene(p, b.skeleton, mo);
    return b;
}

const tinygltf::Mesh& mesh_named(const tinygltf::Model& model, const std::string& name) {
    for (const auto& m : model.meshes)
        if (m.name == name) return m;
    FAIL("no mesh named " << name);
    return model.meshes.front();
}

// The bytes of image k as written into the file's buffer.
std::string image_bytes(const tinygltf::Model& model, std::size_t k) {
    const tinygltf::BufferView& v = model.bufferViews.at(std::size_t(model.images.at(k).bufferView));
    const auto& data = model.buffers.at(0).data;
    return std::string(data.begin() + long(v.byteOffset), data.begin() + long(v.byteOffset + v.byteLength));
}

const char* kLeaf = "surface leaf = polygon(vec3(0, 0, 0), vec3(0.1, 0.3, 0), vec3(0, 0.6, 0));\n";

} // namespace

TEST_CASE("a texture declaration reads its image at compile time and its name is its index") {
    auto c = test::compile(fmt::format("texture a = image(\"{0}\");\ntexture b = image(\"{0}\");\n"
                                       "axiom: F(a) F(b);",
                                       kBark));
    INFO(c->rendered());
    REQUIRE(c->program);
    const auto& t = c->program->textures;
    REQUIRE(t.size() == 2);
    CHECK(t[0].name == "a");
    CHECK(t[0].mime_type == "image/png");
    REQUIRE(t[0].bytes);
    CHECK(*t[0].bytes == file_bytes(kBark));
    CHECK(t[1].bytes == t[0].bytes); // one file, read once
    Derivation d(*c->program, {});
    d.run();
    CHECK(format_string(*c->program, d.string()) == "F(0)F(1)");
}

TEST_CASE("a texture is PNG or JPEG as its first bytes say") {
    const TempFile jpeg("plant-test-texture.jpg", std::string("\xff\xd8\xff\xe0\0\x10JFIF", 10));
    auto c = test::compile(fmt::format("texture photo = image(\"{}\");\naxiom: F;", jpeg.path));
    INFO(c->rendered());
    REQUIRE(c->program);
    CHECK(c->program->textures.at(0).mime_type == "image/jpeg");

    const TempFile text("plant-test-texture.png", "not an image at all");
    auto bad = test::compile(fmt::format("texture photo = image(\"{}\");\naxiom: F;", text.path));
    CHECK_FALSE(bad->program);
    CHECK_THAT(bad->rendered(),
               Catch::Contains("1:23: error:") && Catch::Contains("is not a PNG or JPEG image"));
}

TEST_CASE("SetTexture sets the texture of what follows, and brackets restore it") {
    const Built b = build(with_bark(
        std::string(kLeaf) + "axiom: SetTexture(bark) F [ SetTexture(-1) F ~leaf ] F ~leaf SetTexture F;"));
    REQUIRE(b.skeleton.axes.size() == 2);
    std::vector<int> trunk, branch, organs;
    for (const auto& p : b.skeleton.axes[0].points) trunk.push_back(p.texture);
    for (const auto& p : b.skeleton.axes[1].points) branch.push_back(p.texture);
    for (const auto& o : b.skeleton.organs) organs.push_back(o.texture);
    CHECK(trunk == std::vector<int>{0, 0, 0, -1});
    CHECK(branch == std::vector<int>{-1, -1});
    CHECK(organs == std::vector<int>{-1, 0}); // a leaf placed under a texture carries it
    // the trunk's tube: one material with the texture, one without; the leaves: one prototype each
    std::set<int> textures;
    for (const Primitive& p : b.scene.tubes.primitives)
        textures.insert(b.scene.materials.at(p.material).texture);
    CHECK(textures == std::set<int>{-1, 0});
    CHECK(b.scene.prototypes.size() == 2);
    REQUIRE(b.scene.textures.size() == 1);
    CHECK(b.scene.textures[0].name == "bark");
}

TEST_CASE("SetTexture of a texture the grammar does not declare is a runtime error") {
    for (const char* axiom : {"F SetTexture(1) F", "SetTexture(0.5) F", "SetTexture(-2) F"}) {
        auto c = test::compile(with_bark(fmt::format("axiom: {};", axiom)));
        REQUIRE(c->program);
        Derivation d(*c->program, {});
        d.run();
        try {
            build_skeleton(*c->program, d.interpreted(d.string()), turtle_options(d));
            FAIL("no error for " << axiom);
        } catch (const RuntimeError& e) {
            CHECK(e.kind == RuntimeErrorKind::Turtle);
            CHECK_THAT(e.message, Catch::Contains("('SetTexture') of the string sets texture") &&
                                      Catch::Contains("declares only texture 0"));
        }
    }
}

TEST_CASE("a textured trunk in glTF: the image once with the file's bytes, the leaf keeps its colour") {
    const Built b = build(with_bark(std::string(kLeaf) +
                                    "axiom: SetTexture(bark) !(0.3) F(2) [ SetTexture(-1) ;(1) ~leaf ] F "
                                    "[ - F ] F;"));
    for (GltfLayout layout : {GltfLayout::GpuInstancing, GltfLayout::Nodes, GltfLayout::Baked}) {
        const tinygltf::Model model = parse_glb(b.scene, layout);
        REQUIRE(model.images.size() == 1);
        REQUIRE(model.textures.size() == 1);
        REQUIRE(model.samplers.size() == 1);
        CHECK(model.images[0].mimeType == "image/png");
        CHECK(image_bytes(model, 0) == file_bytes(kBark));
        CHECK(model.samplers[0].wrapS == TINYGLTF_TEXTURE_WRAP_REPEAT);
        CHECK(model.samplers[0].wrapT == TINYGLTF_TEXTURE_WRAP_REPEAT);
        int textured = 0, green = 0;
        for (const auto& m : model.materials) {
            const auto& pbr = m.pbrMetallicRoughness;
            if (pbr.baseColorTexture.index >= 0) {
                ++textured;
                CHECK(pbr.baseColorTexture.index == 0);
                CHECK(pbr.baseColorFactor == std::vector<double>{1, 1, 1, 1});
            } else if (pbr.baseColorFactor == std::vector<double>{0.2, 0.55, 0.18, 1}) {
                ++green;
            }
        }
        CHECK(textured == 1);
        CHECK(green == 1);
        if (layout != GltfLayout::Baked) {
            const auto& tubes = mesh_named(model, "tubes");
            REQUIRE(tubes.primitives.size() == 1);
            CHECK(model.materials.at(std::size_t(tubes.primitives[0].material))
                      .pbrMetallicRoughness.baseColorTexture.index == 0);
            CHECK(tubes.primitives[0].attributes.count("TEXCOORD_0") == 1);
            const auto& leaf = mesh_named(model, "leaf");
            CHECK(model.materials.at(std::size_t(leaf.primitives.at(0).material))
                      .pbrMetallicRoughness.baseColorTexture.index == -1);
        }
    }
}

TEST_CASE("a textured instance keeps its texture in its scene prototype, flattened and in glTF") {
    const Built b = build(with_bark(std::string(kLeaf) + R"(
instance Twig(n) {
    axiom: SetTexture(bark) F(n) [ SetTexture(-1) ;(1) ~leaf ];
}
axiom: ;(1) F Twig(1) [ + Twig(2) ];)"));
    REQUIRE(b.scene.nested());
    const std::string* bytes = b.compiled->program->textures.at(0).bytes.get();
    for (const auto& proto : b.scene.scene_prototypes) {
        REQUIRE(proto->textures.size() == 1);
        CHECK(proto->textures[0].bytes.get() == bytes);
    }
    const Scene flat = flatten(b.scene);
    REQUIRE(flat.textures.size() == 1);
    CHECK(flat.textures[0].bytes.get() == bytes);
    int textured = 0;
    for (const Material& m : flat.materials) textured += m.texture == 0 ? 1 : 0;
    CHECK(textured == 1);              // the twigs of both lengths share one material
    CHECK(flat.materials.size() == 2); // and the twigs' leaves share the outer tube's green
    const tinygltf::Model model = parse_glb(b.scene, GltfLayout::GpuInstancing);
    REQUIRE(model.images.size() == 1);
    CHECK(image_bytes(model, 0) == file_bytes(kBark));
    const auto& twig = mesh_named(model, "Twig(1)/tubes");
    CHECK(model.materials.at(std::size_t(twig.primitives.at(0).material))
              .pbrMetallicRoughness.baseColorTexture.index == 0);
}

TEST_CASE("split_nested keeps a nested scene prototype's texture") {
    // a prototype placed twice with more parts than kNestedFrom / 2 stays a node per placement
    auto inner = std::make_shared<Scene>();
    inner->textures = {Texture{"bark", "image/png", std::make_shared<const std::string>(file_bytes(kBark))}};
    inner->materials = {Material{{0.5f, 0.5f, 0.5f}, 0}, Material{{0.2f, 0.6f, 0.2f}, -1}};
    inner->tubes = test::box_part({0.1f, 1.0f, 0.1f}, 0);
    inner->prototypes = {test::leaf_part(1)};
    inner->prototype_names = {"leaf"};
    inner->instances.assign(detail::kNestedFrom / 2 + 1, Instance{0, glm::mat4(1.0f)});
    inner->update_bounds();
    Scene outer;
    outer.materials = {Material{{0.5f, 0.5f, 0.5f}, -1}}; // the same colour, without the texture
    outer.scene_prototypes = {inner};
    outer.scene_prototype_names = {"tree"};
    outer.scene_instances = {Instance{0, glm::mat4(1.0f)},
                             Instance{0, glm::translate(glm::mat4(1.0f), glm::vec3(3, 0, 0))}};
    outer.update_bounds();
    std::vector<detail::NestedGroup> groups;
    const Scene split = detail::split_nested(outer, groups, "test");
    REQUIRE(groups.size() == 1);
    REQUIRE(split.textures.size() == 1);
    CHECK(split.textures[0].bytes == inner->textures[0].bytes);
    REQUIRE(split.materials.size() == 3);
    CHECK(split.materials[0].texture == -1); // the outer material stays untextured
    const MeshPart& tubes = split.prototypes.at(groups[0].parts.at(0).first);
    CHECK(split.materials.at(tubes.primitives.at(0).material).texture == 0);
    const tinygltf::Model model = parse_glb(outer, GltfLayout::GpuInstancing);
    REQUIRE(model.images.size() == 1);
    CHECK(mesh_named(model, "tree/tubes").primitives.at(0).material >= 0);
    CHECK(model.materials.at(std::size_t(mesh_named(model, "tree/tubes").primitives.at(0).material))
              .pbrMetallicRoughness.baseColorTexture.index == 0);
}

TEST_CASE("an instance body's texture replaces the outer one of the same name") {
    const TempFile other("plant-test-other.png", std::string("\x89PNG\r\n\x1a\n", 8) + "other bytes");
    auto c = test::compile(with_bark(fmt::format(R"(instance Twig() {{
    texture bark = image("{}");
    axiom: SetTexture(bark) F;
}}
axiom: SetTexture(bark) F Twig;)",
                                                 other.path)));
    INFO(c->rendered());
    REQUIRE(c->program);
    const Program& body = *c->program->instances->at(0).program;
    REQUIRE(body.textures.size() == 1);
    CHECK(*body.textures[0].bytes == std::string("\x89PNG\r\n\x1a\n", 8) + "other bytes");
    CHECK(*c->program->textures.at(0).bytes == file_bytes(kBark));
}

TEST_CASE("the PNG preview draws a textured material in its image's average colour") {
    Scene scene;
    scene.textures = {Texture{"bark", "image/png", std::make_shared<const std::string>(file_bytes(kBark))},
                      Texture{"broken", "image/png", std::make_shared<const std::string>("\x89PNG")}};
    scene.materials = {Material{{0.0f, 0.0f, 1.0f}, 0}, Material{{0.0f, 1.0f, 0.0f}, -1},
                       Material{{1.0f, 0.0f, 0.0f}, 1}};
    const std::vector<glm::vec3> colors = detail::flat_colors(scene);
    REQUIRE(colors.size() == 3);
    // bark: brown, red over green over blue, not the material's blue
    CHECK(colors[0].r > colors[0].g);
    CHECK(colors[0].g > colors[0].b);
    CHECK(colors[0].r < 0.5f);
    CHECK(colors[1] == glm::vec3(0.0f, 1.0f, 0.0f));
    CHECK(colors[2] == glm::vec3(1.0f, 0.0f, 0.0f)); // an image that cannot be decoded: the colour
}
