// PNG previews that look like the book's figures (issue 20, items 10 and 11): a 2-D figure is
// drawn face-on with its right angles right and its aspect ratio kept, skeletal figures in lines
// at least a pixel wide, and `width_scale` turning ABOP's pixel widths into a tree, not a blob.
#include "helpers.hpp"
#include "plant/export.hpp"
#include "plant/mesh.hpp"
#include "plant/raster.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

using namespace plant;

namespace {

struct Figure {
    std::unique_ptr<test::Compiled> compiled;
    std::unique_ptr<Derivation> derivation;
    Skeleton skeleton;
    Scene scene;
};

Figure figure(const std::string& name, std::optional<double> width_scale = std::nullopt) {
    std::ifstream in(std::string(PLANT_SOURCE_DIR) + "/grammars/abop/" + name + ".plant");
    std::stringstream text;
    text << in.rdbuf();
    Figure f;
    f.compiled = test::compile(text.str());
    REQUIRE(f.compiled->program);
    f.derivation = std::make_unique<Derivation>(*f.compiled->program, DeriveOptions{});
    f.derivation->run();
    const Derivation& d = *f.derivation;
    f.skeleton = build_skeleton(*f.compiled->program, d.interpreted(d.string()), turtle_options(d));
    MeshOptions mo;
    mo.width_scale = width_scale.value_or(d.width_scale());
    f.scene = build_scene(*f.compiled->program, f.skeleton, mo);
    return f;
}

PngOptions options_of(const Figure& f, PngViewKind view = PngViewKind::Auto) {
    PngOptions o;
    o.view = view;
    o.skeleton = &f.skeleton;
    o.lines = PngLines::Auto;
    o.width_scale = f.derivation->width_scale();
    return o;
}

bool drawn(const Image& img, int x, int y) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return false;
    const std::uint8_t* p = &img.rgb[std::size_t((y * img.width + x) * 3)];
    return !(p[0] > 245 && p[1] > 245 && p[2] > 245);
}

struct Pixels {
    int count = 0, x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
    double aspect() const { return double(x1 - x0 + 1) / double(y1 - y0 + 1); }
};

Pixels pixels(const Image& img) {
    Pixels p;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (drawn(img, x, y)) {
                ++p.count;
                p.x0 = std::min(p.x0, x);
                p.x1 = std::max(p.x1, x);
                p.y0 = std::min(p.y0, y);
                p.y1 = std::max(p.y1, y);
            }
    return p;
}

// The skeleton's extent across (x) over its extent up (y): what a face-on figure's aspect is.
double skeleton_aspect(const Skeleton& sk) {
    double lx = 1e300, hx = -1e300, ly = 1e300, hy = -1e300;
    for (const auto& a : sk.axes)
        for (const auto& p : a.points) {
            lx = std::min(lx, p.position.x);
            hx = std::max(hx, p.position.x);
            ly = std::min(ly, p.position.y);
            hy = std::max(hy, p.position.y);
        }
    return (hx - lx) / (hy - ly);
}

// The edge directions of the drawn pixels: the share of the image's gradient (Sobel, on how
// dark each pixel is) whose direction is within 10 degrees of horizontal or vertical. Near 1
// for a figure of axis-aligned lines seen face-on; much less when its squares come out as
// parallelograms, whose slanted edges have slanted gradients.
double axis_aligned_share(const Image& img) {
    auto dark = [&](int x, int y) {
        if (x < 0 || y < 0 || x >= img.width || y >= img.height) return 0.0;
        const std::uint8_t* p = &img.rgb[std::size_t((y * img.width + x) * 3)];
        return 255.0 - (p[0] + p[1] + p[2]) / 3.0;
    };
    double aligned = 0, all = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const double gx = dark(x + 1, y - 1) + 2 * dark(x + 1, y) + dark(x + 1, y + 1) -
                              dark(x - 1, y - 1) - 2 * dark(x - 1, y) - dark(x - 1, y + 1);
            const double gy = dark(x - 1, y + 1) + 2 * dark(x, y + 1) + dark(x + 1, y + 1) -
                              dark(x - 1, y - 1) - 2 * dark(x, y - 1) - dark(x + 1, y - 1);
            const double m = std::hypot(gx, gy);
            if (m < 1e-9) continue;
            all += m;
            const double off = std::min(std::abs(gx), std::abs(gy)) / m; // sin of the angle to an axis
            if (off < std::sin(10.0 * 3.14159265358979 / 180.0)) aligned += m;
        }
    return all > 0 ? aligned / all : 0.0;
}

} // namespace

TEST_CASE("Fig. 1.9a is drawn face-on in lines, its right angles right and its aspect kept") {
    const Figure f = figure("fig1_9a");
    const PngOptions o = options_of(f);
    CHECK(resolved_view(f.scene, o) == PngViewKind::Front); // flat in z: face-on by default
    const Image img = render_scene(f.scene, 1200, 900, o);
    const Pixels p = pixels(img);
    REQUIRE(p.count > 1000);
    CHECK(p.aspect() == Approx(skeleton_aspect(f.skeleton)).epsilon(0.1));
    CHECK(axis_aligned_share(img) > 0.6); // 0.67 measured

    // through the same camera, every segment is horizontal or vertical and as long as any other
    // (the squares stay squares)
    double shortest = 1e300, longest = 0;
    for (const auto& axis : f.skeleton.axes)
        for (std::size_t k = 1; k < axis.points.size(); ++k) {
            const auto a = project_to_image(f.scene, 1200, 900, o, axis.points[k - 1].position);
            const auto b = project_to_image(f.scene, 1200, 900, o, axis.points[k].position);
            REQUIRE((a && b));
            const glm::dvec2 d = *b - *a;
            const double len = glm::length(d);
            if (len < 1e-9) continue;
            CHECK(std::min(std::abs(d.x), std::abs(d.y)) / len < 1e-6);
            shortest = std::min(shortest, len);
            longest = std::max(longest, len);
        }
    CHECK(longest / shortest == Approx(1.0).epsilon(1e-6));

    // the 3/4 view skews it: the measures above tell the two apart
    const Image iso = render_scene(f.scene, 1200, 900, options_of(f, PngViewKind::Iso));
    CHECK(axis_aligned_share(iso) < 0.45); // 0.35 measured
    // at 400 x 300 the tubes are hairlines (under a pixel): Auto draws lines, which draw more
    PngOptions tubes = o, lines = o;
    tubes.lines = PngLines::Tubes;
    lines.lines = PngLines::Lines;
    const int small_lines = pixels(render_scene(f.scene, 400, 300, lines)).count;
    CHECK(pixels(render_scene(f.scene, 400, 300, tubes)).count < small_lines / 2);
    CHECK(render_scene(f.scene, 400, 300, o).rgb == render_scene(f.scene, 400, 300, lines).rgb);
}

TEST_CASE("Fig. 2.6a from the front has the skeleton's aspect, and width_scale makes it a tree") {
    const Figure f = figure("fig2_6a");
    CHECK(f.derivation->width_scale() == Approx(0.02)); // the grammar sets it
    const PngOptions o = options_of(f, PngViewKind::Front);
    const Pixels p = pixels(render_scene(f.scene, 400, 400, o));
    REQUIRE(p.count > 1000);
    CHECK(p.aspect() == Approx(skeleton_aspect(f.skeleton)).epsilon(0.1));
    CHECK(resolved_view(f.scene, options_of(f)) == PngViewKind::Iso); // a tree in 3-D

    // with ABOP's widths taken as model units the trunk (10 wide for a height of 6.5) is a blob:
    // the bounds are the trunk's, and the drawn pixels cover a good part of the box
    const Figure blob = figure("fig2_6a", 1.0);
    CHECK(blob.scene.bounds_max.x - blob.scene.bounds_min.x > 9.0);
    CHECK(f.scene.bounds_max.x - f.scene.bounds_min.x < 4.0);
    const Pixels b = pixels(render_scene(blob.scene, 400, 400, options_of(blob, PngViewKind::Front)));
    const auto fill = [](const Pixels& q) {
        return double(q.count) / (double(q.x1 - q.x0 + 1) * double(q.y1 - q.y0 + 1));
    };
    CHECK(fill(b) > 0.4);
    CHECK(fill(p) < 0.25);
}
