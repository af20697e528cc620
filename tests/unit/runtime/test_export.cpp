#include "helpers.hpp"
#include "plant/export.hpp"
#include "plant/export_text.hpp"
#include "plant/mesh.hpp"
#include "plant/raster.hpp"

#include <catch2/catch.hpp>

#include <filesystem>

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
    CHECK_THROWS_AS(write_gltf(s, "/nonexistent-dir/x.glb"), ExportError);
    CHECK_THROWS_AS(write_mesh_file(s, "/tmp/plant-test.xyz"), ExportError);
    CHECK(!std::filesystem::exists("/tmp/plant-test.xyz"));
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
