// The PNG preview's line mode (png_camera.hpp, line_quads): skeleton segments as flat bands of
// at least a minimum width in pixels, for skeletal figures whose tubes would be hairlines.
#include "png_camera.hpp"

#include "plant/skeleton.hpp"

#include <algorithm>
#include <cmath>

namespace plant::detail {

namespace {

// Samples per world unit across the view at `p`: the orthographic scale, or focal / distance.
double samples_per_unit(const Camera& cam, const glm::dvec3& p) {
    if (!cam.perspective) return cam.scale;
    const double d = -glm::dot(p - cam.eye, cam.toward);
    return d > cam.near ? cam.focal / d : 0.0;
}

} // namespace

std::vector<ScreenQuad> line_quads(const Skeleton& skeleton, const Camera& cam, double width_scale,
                                   double min_samples) {
    std::vector<ScreenQuad> out;
    for (const SkeletonAxis& axis : skeleton.axes) {
        for (std::size_t k = 1; k < axis.points.size(); ++k) {
            const SkeletonPoint &p = axis.points[k - 1], &q = axis.points[k];
            const auto a = project(cam, p.position), b = project(cam, q.position);
            if (!a || !b || !finite3(*a) || !finite3(*b)) continue;
            const double half_a =
                0.5 * std::max(min_samples, 2 * p.radius * width_scale * samples_per_unit(cam, p.position));
            const double half_b =
                0.5 * std::max(min_samples, 2 * q.radius * width_scale * samples_per_unit(cam, q.position));
            glm::dvec2 d(b->x - a->x, b->y - a->y);
            const double len = glm::length(d);
            d = len > 1e-9 ? d / len : glm::dvec2(1, 0); // a point seen end on: a square dot
            const glm::dvec2 n(-d.y, d.x);
            const glm::dvec2 a0 = glm::dvec2(*a) - d * half_a, b0 = glm::dvec2(*b) + d * half_b;
            ScreenQuad quad{{glm::dvec3(a0 + n * half_a, a->z), glm::dvec3(b0 + n * half_b, b->z),
                             glm::dvec3(b0 - n * half_b, b->z), glm::dvec3(a0 - n * half_a, a->z)},
                            q.color};
            if (std::all_of(quad.corner.begin(), quad.corner.end(),
                            [](const glm::dvec3& c) { return finite3(c); }))
                out.push_back(quad);
        }
    }
    return out;
}

double widest_tube(const Skeleton& skeleton, const Camera& cam, double width_scale) {
    double widest = 0.0;
    for (const SkeletonAxis& axis : skeleton.axes) {
        if (axis.points.size() < 2) continue; // no tube
        for (const SkeletonPoint& p : axis.points) {
            const double w = 2 * p.radius * width_scale * samples_per_unit(cam, p.position);
            if (std::isfinite(w)) widest = std::max(widest, w);
        }
    }
    return widest;
}

} // namespace plant::detail
