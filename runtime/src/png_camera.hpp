// The PNG preview's cameras: the orthographic views (front, top, side, 3/4) framed on the
// scene's bounds, and the perspective camera the user places (plant run --view, --camera).
#pragma once

#include "plant/export.hpp"
#include "plant/scene.hpp"

#include <glm/glm.hpp>

#include <array>
#include <limits>
#include <optional>
#include <vector>

namespace plant {
struct Skeleton;
}

namespace plant::detail {

bool finite3(const glm::dvec3& v);

struct Box {
    glm::dvec3 lo{std::numeric_limits<double>::infinity()};
    glm::dvec3 hi{-std::numeric_limits<double>::infinity()};
    void add(const glm::dvec3& p) {
        if (!finite3(p)) return;
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    bool valid() const { return lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z; }
};

// The scene's own bounds, unless they are unusable (non-finite, inverted, or a single point
// while there is geometry, e.g. update_bounds() was not called): then bounds of the geometry,
// instances through their prototypes' transformed boxes.
Box framing_box(const Scene& scene);

// A camera in supersampled screen space: x right, y down, in samples; depth grows toward the
// viewer. Orthographic: a point p lands at (cx, cy) + scale * (right . (p - center), -up . (p -
// center)), depth toward . p.
struct Camera {
    glm::dvec3 center{0.0};
    glm::dvec3 right{1, 0, 0}, up{0, 1, 0}, toward{0, 0, 1}; // toward = from the scene to the eye
    glm::dvec3 light{0, 1, 0};                               // unit, toward the light
    double scale = 1.0;                                      // samples per world unit
    double cx = 0.0, cy = 0.0;                               // screen position of `center`
    // A perspective camera (plant run --camera) sees from `eye` along -toward: a point at view
    // coordinates (x, y, d) = (right, up, -toward) . (p - eye) lands at (cx + focal x / d,
    // cy - focal y / d), with depth 1 / d; only d >= near is drawn.
    bool perspective = false;
    glm::dvec3 eye{0.0};
    double focal = 1.0; // samples per unit of x / d
    double near = 0.0;
};

// The view `options` ask for, Auto made definite (plant/export.hpp, PngViewKind).
PngViewKind view_of(const Scene& scene, const PngOptions& options);
// The camera of `options` for an image of width x height samples.
Camera png_camera(const Scene& scene, int width, int height, const PngOptions& options);
// Where `p` lands: screen x, y in samples and depth (larger nearer); none behind a perspective camera.
std::optional<glm::dvec3> project(const Camera& cam, const glm::dvec3& p);

// A skeleton segment as the line mode draws it: a flat band in screen space (x, y in samples,
// depth), corners in order around it, in the colour of the segment's end point.
struct ScreenQuad {
    std::array<glm::dvec3, 4> corner;
    glm::vec3 color;
};

// The bands of every segment of `skeleton` (png_lines.cpp): each as wide as the segment's tube
// (radius times width_scale, projected) but at least `min_samples` samples, with square caps
// half as long as it is wide so that consecutive segments join without a notch.
std::vector<ScreenQuad> line_quads(const Skeleton& skeleton, const Camera& cam, double width_scale,
                                   double min_samples);
// The widest drawn tube of `skeleton` in samples across, seen by `cam`.
double widest_tube(const Skeleton& skeleton, const Camera& cam, double width_scale);

} // namespace plant::detail
