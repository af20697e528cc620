#include "helpers.hpp"
#include "plant/export.hpp"
#include "plant/export_text.hpp"
#include "plant/mesh.hpp"
#include "plant/raster.hpp"

#include <catch2/catch.hpp>

#include <glm/gtc/matrix_transform.hpp>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <streambuf>
#include <unistd.h>

using namespace plant;

namespace {

Scene scene_of(const std::string& grammar) {
    auto c = test::compile(grammar);
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Skeleton sk = build_skeleton(*c->program, d.interpreted(d.string()), turtle_options(d));
    return build_scene(*c->program, sk, MeshOptions{});
}

// Bounding box of the pixels that are not background.
struct Box {
    int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    int count = 0;
};
Box drawn(const Image& img) {
    Box b;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const std::uint8_t* p = &img.rgb[static_cast<std::size_t>((y * img.width + x) * 3)];
            if (p[0] > 245 && p[1] > 245 && p[2] > 245) continue;
            ++b.count;
            b.x0 = std::min(b.x0, x), b.x1 = std::max(b.x1, x);
            b.y0 = std::min(b.y0, y), b.y1 = std::max(b.y1, y);
        }
    return b;
}

} // namespace

TEST_CASE("the PNG preview frames the plant: drawn, centred, not clipped", "[export][png]") {
    // a tall trunk with a side branch: taller than wide
    Scene s = scene_of("width 0.3; axiom: F F F [ +(60) F F ] F;");
    Image img = render_scene(s, 200, 200);
    REQUIRE(img.rgb.size() == 200u * 200u * 3u);
    Box b = drawn(img);
    CHECK(b.count > 500); // not blank
    CHECK(b.x0 > 0);      // not clipped on any side
    CHECK(b.y0 > 0);
    CHECK(b.x1 < 199);
    CHECK(b.y1 < 199);
    CHECK(b.y1 - b.y0 > 150); // framed on the bounding box: the plant fills the height
    CHECK(std::abs((b.x0 + b.x1) / 2 - 100) < 40);
}

TEST_CASE("an empty scene renders a blank image", "[export][png]") {
    Scene s = scene_of("axiom: +;");
    Image img = render_scene(s, 64, 32);
    CHECK(drawn(img).count == 0);
}

TEST_CASE("writers leave no partial file when they fail", "[export]") {
    Scene s = scene_of("axiom: F;");
    CHECK_THROWS_AS(write_gltf(s, "/nonexistent-dir/x.glb", GltfContainer::Binary), ExportError);
    CHECK_THROWS_AS(write_mesh_file(s, "/nonexistent-dir/x.obj", MeshFileFormat::Obj), ExportError);
    CHECK(!std::filesystem::exists("/nonexistent-dir"));
}

namespace {

// A stream buffer that takes `room` bytes and then refuses, as a string stream does when it cannot
// grow: the stream that writes to it goes bad.
class FullBuffer : public std::streambuf {
  public:
    explicit FullBuffer(std::size_t room) : room_(room) {}
    std::size_t taken = 0;

  protected:
    int_type overflow(int_type c) override {
        if (taken >= room_ || traits_type::eq_int_type(c, traits_type::eof())) return traits_type::eof();
        ++taken;
        return c;
    }
    std::streamsize xsputn(const char*, std::streamsize n) override {
        const auto k = std::min<std::streamsize>(n, static_cast<std::streamsize>(room_ - taken));
        taken += static_cast<std::size_t>(k);
        return k;
    }

  private:
    std::size_t room_;
};

} // namespace

TEST_CASE("a mesh file the stream cannot take in full is an error, not a shorter file", "[export][mesh]") {
    Scene s = scene_of("axiom: F F [ + F ] F;");
    for (MeshFileFormat f : {MeshFileFormat::Obj, MeshFileFormat::Ply, MeshFileFormat::Off}) {
        std::ostringstream whole;
        write_mesh_stream(s, f, "x", whole); // the whole file fits
        REQUIRE(whole.str().size() > 200);
        FullBuffer full(100);
        std::ostream out(&full);
        CHECK_THROWS_AS(write_mesh_stream(s, f, "x", out), ExportError);
        CHECK(full.taken == 100);
    }
}

TEST_CASE("the skeleton JSON lists axes with points and organs with matrices", "[export]") {
    auto c = test::compile(
        "surface s = polygon(vec3(0,0,0), vec3(1,0,0), vec3(0,1,0)); axiom: F [ + F ~s(1) ] F;");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Skeleton sk = build_skeleton(*c->program, d.string(), TurtleOptions{});
    std::string json = skeleton_json(sk);
    CHECK(json.rfind("{\"format\":\"plant-skeleton\",\"version\":1,\"axes\":[", 0) == 0);
    CHECK(json.find("\"parent\":0") != std::string::npos); // the branch's parent is the main axis
    CHECK(json.find("\"shape\":\"s\"") != std::string::npos);
    CHECK(json.find("\"module\":\"F\"") != std::string::npos);
}

namespace {

std::string file_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

TEST_CASE("a scene placed as a prototype is flattened by its transforms for every writer", "[export][mesh]") {
    auto inner = std::make_shared<Scene>(scene_of("axiom: ;(2) F @O(0.5);"));
    REQUIRE(inner->prototypes.size() == 1);
    Scene outer = scene_of("axiom: F;"); // a tube of its own, in the bark color
    const std::size_t outer_materials = outer.materials.size();
    outer.scene_prototypes.push_back(inner);
    outer.scene_prototype_names.push_back("sprig");
    const glm::mat4 right = glm::translate(glm::mat4(1.0f), glm::vec3(10, 0, 0));
    const glm::mat4 up_twice =
        glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(0, 5, 0)), glm::vec3(2.0f));
    outer.scene_instances = {Instance{0, right}, Instance{0, up_twice}};
    outer.update_bounds();

    const Scene flat = flatten(outer);
    CHECK(!flat.nested());
    // the inner tubes and sphere become two prototypes, placed twice each
    REQUIRE(flat.prototypes.size() == 2);
    CHECK(flat.prototype_names == std::vector<std::string>{"sprig/tubes", "sprig/@O"});
    REQUIRE(flat.instances.size() == 4);
    CHECK(flat.instances[0].prototype == 0);
    CHECK(flat.instances[0].transform == right);
    CHECK(flat.instances[1].transform == right * inner->instances[0].transform);
    CHECK(flat.instances[2].transform == up_twice);
    CHECK(flat.tubes.positions == outer.tubes.positions);
    // the inner red joins the outer materials, and the primitives point at it
    CHECK(flat.materials.size() == outer_materials + 1);
    CHECK(flat.materials[flat.prototypes[0].primitives[0].material].color ==
          inner->materials[inner->tubes.primitives[0].material].color);
    // bounds: the first copy reaches x = 10 + inner max, the second y = 5 + 2 * inner max
    CHECK(flat.bounds_max.x == Approx(10 + inner->bounds_max.x));
    CHECK(flat.bounds_max.y == Approx(5 + 2 * inner->bounds_max.y));
    CHECK(outer.bounds_min == flat.bounds_min);
    CHECK(outer.bounds_max == flat.bounds_max);
    // a scene that places no scene comes back as it was
    CHECK(flatten(*inner).instances.size() == inner->instances.size());
    CHECK(flatten(*inner).prototype_names == inner->prototype_names);

    // every writer draws the flattened scene
    const std::string dir = (std::filesystem::temp_directory_path() / "plant-nested-test").string();
    std::filesystem::create_directories(dir);
    for (const char* ext : {".obj", ".glb"}) {
        const std::string a = dir + "/nested" + ext, b = dir + "/flat" + ext;
        if (std::string(ext) == ".obj") {
            write_mesh_file(outer, a, MeshFileFormat::Obj);
            write_mesh_file(flat, b, MeshFileFormat::Obj);
        } else {
            write_gltf(outer, a, GltfContainer::Binary);
            write_gltf(flat, b, GltfContainer::Binary);
        }
        CHECK(!file_bytes(a).empty());
        const bool same_bytes = file_bytes(a) == file_bytes(b);
        CHECK(same_bytes);
    }
    const Image nested_image = render_scene(outer, 64, 48), flat_image = render_scene(flat, 64, 48);
    const bool same_pixels = nested_image.rgb == flat_image.rgb;
    CHECK(same_pixels);
    CHECK(nested_image.rgb != render_scene(scene_of("axiom: F;"), 64, 48).rgb); // the placed scenes show

    // a placement of a scene prototype that is not there is an export error
    outer.scene_instances.push_back(Instance{3, right});
    CHECK_THROWS_AS(write_gltf(outer, dir + "/broken.glb", GltfContainer::Binary), ExportError);
    std::filesystem::remove_all(dir);
}

TEST_CASE("a finished file takes the place of the old one in one step, leaving no temporary file",
          "[export][replace]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("plant-replace-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    auto write = [](const fs::path& p, const std::string& text) { std::ofstream(p) << text; };
    auto read = [](const fs::path& p) {
        std::ifstream in(p);
        return std::string(std::istreambuf_iterator<char>(in), {});
    };
    const fs::path target = dir / "x.glb", temp = dir / ".x.glb.tmp";

    // over an existing file: the new contents, and the old ones gone with the temporary name;
    // a reader that opened the old file still reads the old contents
    write(target, "old");
    std::ifstream reader(target);
    write(temp, "new");
    CHECK(replace_file(temp.c_str(), target.c_str()) == 0);
    CHECK(read(target) == "new");
    CHECK(!fs::exists(temp));
    CHECK(std::string(std::istreambuf_iterator<char>(reader), {}) == "old");
    CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 1);

    // where nothing was: a rename
    write(temp, "fresh");
    CHECK(replace_file(temp.c_str(), (dir / "y.glb").c_str()) == 0);
    CHECK(read(dir / "y.glb") == "fresh");
    CHECK(!fs::exists(temp));

    // a folder in the way is an error, and both stay as they were
    fs::create_directories(dir / "z.glb");
    write(temp, "kept");
    CHECK(replace_file(temp.c_str(), (dir / "z.glb").c_str()) != 0);
    CHECK(fs::is_directory(dir / "z.glb"));
    CHECK(read(temp) == "kept");
    fs::remove_all(dir);
}
