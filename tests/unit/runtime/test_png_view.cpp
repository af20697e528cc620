// The PNG preview from a camera the user places (plant run --camera, --look-at): perspective,
// aimed at a point, placements of nested scenes drawn.
#include "plant/export.hpp"
#include "plant/raster.hpp"
#include "runtime/nested_scene.hpp"

#include <catch2/catch.hpp>

using namespace plant;

namespace {

struct Drawn {
    int count = 0;
    double cx = 0.0, cy = 0.0; // centroid of the drawn pixels
};

Drawn drawn(const Image& img) {
    Drawn d;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const std::uint8_t* p = &img.rgb[std::size_t((y * img.width + x) * 3)];
            if (p[0] > 245 && p[1] > 245 && p[2] > 245) continue;
            ++d.count;
            d.cx += x;
            d.cy += y;
        }
    if (d.count > 0) {
        d.cx /= d.count;
        d.cy /= d.count;
    }
    return d;
}

// Pixels where red or blue clearly dominates.
int pixels_of(const Image& img, int channel) {
    int n = 0;
    for (std::size_t k = 0; k + 2 < img.rgb.size(); k += 3)
        if (img.rgb[k + std::size_t(channel)] > 100 && img.rgb[k + std::size_t(2 - channel)] < 60) ++n;
    return n;
}

} // namespace

TEST_CASE("a camera views a nested scene in perspective from where it stands", "[export][png]") {
    const Scene scene = test::nested_scene();
    const PngView side{glm::dvec3(0, 8, 40), std::nullopt};
    const Image from_side = render_scene(scene, 96, 96, side);
    const Drawn d = drawn(from_side);
    CHECK(d.count > 500);            // the trees show
    CHECK(std::abs(d.cx - 48) < 20); // looking at the centre of the bounds by default
    const bool same_as_flat = render_scene(flatten(scene), 96, 96, side).rgb == from_side.rgb;
    CHECK(same_as_flat);                                     // placed scenes are drawn where they are placed
    CHECK(render_scene(scene, 96, 96).rgb != from_side.rgb); // not the default 3/4 view
    const Image from_top = render_scene(scene, 96, 96, PngView{glm::dvec3(0, 60, 0), std::nullopt});
    CHECK(drawn(from_top).count > 500);
    CHECK(from_top.rgb != from_side.rgb);

    // looking at a point right of the centre moves the scene left
    const Drawn aimed_right = drawn(render_scene(scene, 96, 96, PngView{side.eye, glm::dvec3(8, 5, 0)}));
    CHECK(aimed_right.cx < d.cx - 5);
    // looking away, nothing is in view
    CHECK(drawn(render_scene(scene, 96, 96, PngView{side.eye, glm::dvec3(0, 8, 80)})).count == 0);
}

TEST_CASE("a perspective camera draws near things larger and clips what is behind it", "[export][png]") {
    Scene scene;
    scene.materials = {Material{{0.9f, 0.05f, 0.05f}}, Material{{0.05f, 0.05f, 0.9f}}};
    scene.prototypes = {test::box_part(glm::vec3(1.0f), 0), test::box_part(glm::vec3(1.0f), 1)};
    scene.instances = {Instance{0, glm::translate(glm::mat4(1.0f), glm::vec3(-2, 0, 0))},
                       Instance{1, glm::translate(glm::mat4(1.0f), glm::vec3(2, 0, -30))}};
    scene.update_bounds();
    // the camera beside the near red box, looking past it toward the far blue one
    const PngView view{glm::dvec3(0, 0, 8), glm::dvec3(0, 0, -15)};
    const Image img = render_scene(scene, 128, 128, view);
    const int red = pixels_of(img, 0), blue = pixels_of(img, 2);
    CHECK(blue > 10);
    CHECK(red > 4 * blue); // same size, four times nearer
    // a camera inside the red box, and a camera at the point it looks at: no crash
    CHECK_NOTHROW(render_scene(scene, 64, 64, PngView{glm::dvec3(-2, 0, 0), glm::dvec3(2, 0, -30)}));
    CHECK_NOTHROW(render_scene(scene, 64, 64, PngView{glm::dvec3(1, 1, 1), glm::dvec3(1, 1, 1)}));
}
