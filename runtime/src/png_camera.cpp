// The PNG preview's cameras (png_camera.hpp).
#include "png_camera.hpp"

#include "plant/skeleton.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace plant::detail {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kAzimuthDeg = 40.0;   // the 3/4 view: swung this far from the front (+z) toward +x
constexpr double kElevationDeg = 24.0; // and raised this far above the horizon
constexpr double kMargin = 0.05;       // of the image size, on each side

glm::dvec3 iso_toward() {
    const double az = kAzimuthDeg * kPi / 180.0, el = kElevationDeg * kPi / 180.0;
    return {std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az)};
}

} // namespace

bool finite3(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

namespace {

Box part_box(const MeshPart& part) {
    Box box;
    for (const glm::vec3& p : part.positions) box.add(glm::dvec3(p));
    return box;
}

} // namespace

Box framing_box(const Scene& scene) {
    Box given;
    given.lo = glm::dvec3(scene.bounds_min);
    given.hi = glm::dvec3(scene.bounds_max);
    if (finite3(given.lo) && finite3(given.hi) && given.valid() && given.lo != given.hi) return given;

    Box box = part_box(scene.tubes);
    std::vector<Box> protos;
    protos.reserve(scene.prototypes.size());
    for (const MeshPart& proto : scene.prototypes) protos.push_back(part_box(proto));
    for (const Instance& inst : scene.instances) {
        if (inst.prototype >= protos.size() || !protos[inst.prototype].valid()) continue;
        const Box& pb = protos[inst.prototype];
        const glm::dmat4 m(inst.transform);
        for (int corner = 0; corner < 8; ++corner) {
            glm::dvec3 p((corner & 1) ? pb.hi.x : pb.lo.x, (corner & 2) ? pb.hi.y : pb.lo.y,
                         (corner & 4) ? pb.hi.z : pb.lo.z);
            box.add(glm::dvec3(m * glm::dvec4(p, 1.0)));
        }
    }
    if (box.valid()) return box;
    if (finite3(given.lo) && finite3(given.hi) && given.valid()) return given;
    Box origin;
    origin.lo = origin.hi = glm::dvec3(0.0);
    return origin;
}

namespace {

void aim(Camera& cam, const glm::dvec3& toward) {
    cam.toward = toward;
    const glm::dvec3 forward = -cam.toward;
    // looking straight up or down, -z is up on the image (the back of the scene at the top)
    const glm::dvec3 up_hint = std::abs(forward.y) > 0.999 ? glm::dvec3(0, 0, -1) : glm::dvec3(0, 1, 0);
    cam.right = glm::normalize(glm::cross(forward, up_hint));
    cam.up = glm::cross(cam.right, forward);
    cam.light = glm::normalize(0.55 * cam.toward + 0.75 * glm::dvec3(0, 1, 0) - 0.4 * cam.right);
}

Camera make_camera(const Scene& scene, int width, int height, const glm::dvec3& toward) {
    Camera cam;
    aim(cam, toward);

    const Box box = framing_box(scene);
    cam.center = 0.5 * (box.lo + box.hi);
    const glm::dvec3 half = 0.5 * (box.hi - box.lo);
    // The projection of a box is symmetric about the projected center: its half-size along a
    // screen axis a is sum |a_i| * half_i.
    const double hw =
        std::abs(cam.right.x) * half.x + std::abs(cam.right.y) * half.y + std::abs(cam.right.z) * half.z;
    const double hh = std::abs(cam.up.x) * half.x + std::abs(cam.up.y) * half.y + std::abs(cam.up.z) * half.z;
    const double avail_w = 0.5 * width * (1.0 - 2.0 * kMargin);
    const double avail_h = 0.5 * height * (1.0 - 2.0 * kMargin);
    double scale = std::numeric_limits<double>::infinity();
    if (hw > 0.0) scale = std::min(scale, avail_w / hw);
    if (hh > 0.0) scale = std::min(scale, avail_h / hh);
    if (!std::isfinite(scale) || scale <= 0.0) scale = 1.0; // a point: nothing has any area
    cam.scale = scale;
    cam.cx = 0.5 * width;
    cam.cy = 0.5 * height;
    return cam;
}

// A perspective camera at view.eye looking at view.target (default: the centre of the scene's
// bounds), its view angle the narrowest that shows every corner of the bounds in front of it,
// kept between kMinViewDeg and kMaxViewDeg across the image's shorter side.
Camera make_perspective_camera(const Scene& scene, int width, int height, const PngView& view) {
    constexpr double kMinViewDeg = 10.0, kMaxViewDeg = 100.0, kFallbackViewDeg = 60.0;
    Camera cam;
    cam.perspective = true;
    cam.eye = view.eye;
    const Box box = framing_box(scene);
    const glm::dvec3 target = view.target.value_or(0.5 * (box.lo + box.hi));
    glm::dvec3 toward = cam.eye - target;
    const double distance = glm::length(toward);
    if (distance > 0.0 && std::isfinite(distance)) {
        aim(cam, toward / distance);
    } else { // the camera at the point it looks at: look the default 3/4 way
        aim(cam, iso_toward());
    }
    const double size = glm::length(box.hi - box.lo);
    cam.near = std::isfinite(size) && size > 0.0 ? 1e-4 * size : 1e-6;

    double need_x = 0.0, need_y = 0.0; // the largest |x / d| and |y / d| of the corners in front
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec3 p((corner & 1) ? box.hi.x : box.lo.x, (corner & 2) ? box.hi.y : box.lo.y,
                           (corner & 4) ? box.hi.z : box.lo.z);
        const glm::dvec3 v = p - cam.eye;
        const double d = -glm::dot(v, cam.toward);
        if (!(d > cam.near)) continue;
        need_x = std::max(need_x, std::abs(glm::dot(v, cam.right)) / d);
        need_y = std::max(need_y, std::abs(glm::dot(v, cam.up)) / d);
    }
    double focal = std::numeric_limits<double>::infinity();
    if (need_x > 0.0) focal = std::min(focal, 0.5 * width * (1.0 - 2.0 * kMargin) / need_x);
    if (need_y > 0.0) focal = std::min(focal, 0.5 * height * (1.0 - 2.0 * kMargin) / need_y);
    const double half = 0.5 * std::min(width, height);
    auto focal_for = [&](double view_deg) { return half / std::tan(0.5 * view_deg * kPi / 180.0); };
    if (!std::isfinite(focal)) focal = focal_for(kFallbackViewDeg);
    cam.focal = std::clamp(focal, focal_for(kMaxViewDeg), focal_for(kMinViewDeg));
    cam.cx = 0.5 * width;
    cam.cy = 0.5 * height;
    return cam;
}

// The extent of what the turtle drew (axis points and organ positions), or of the scene's
// bounds without a skeleton.
Box drawn_box(const Scene& scene, const Skeleton* skeleton) {
    if (!skeleton) return framing_box(scene);
    Box box;
    for (const auto& axis : skeleton->axes)
        for (const auto& p : axis.points) box.add(p.position);
    for (const auto& organ : skeleton->organs) box.add(glm::dvec3(organ.transform[3]));
    return box.valid() ? box : framing_box(scene);
}

} // namespace

PngViewKind view_of(const Scene& scene, const PngOptions& options) {
    if (options.camera) return PngViewKind::Iso;
    if (options.view != PngViewKind::Auto) return options.view;
    // flat: the extent along one axis at most a thousandth of the largest (docs: README.md)
    const Box box = drawn_box(scene, options.skeleton);
    const glm::dvec3 e = box.hi - box.lo;
    const double largest = std::max({e.x, e.y, e.z});
    if (!(largest > 0.0) || !std::isfinite(largest)) return PngViewKind::Iso;
    constexpr double kFlat = 1e-3;
    if (e.z <= kFlat * largest) return PngViewKind::Front;
    if (e.x <= kFlat * largest) return PngViewKind::Side;
    if (e.y <= kFlat * largest) return PngViewKind::Top;
    return PngViewKind::Iso;
}

Camera png_camera(const Scene& scene, int width, int height, const PngOptions& options) {
    if (options.camera) return make_perspective_camera(scene, width, height, *options.camera);
    switch (view_of(scene, options)) {
    case PngViewKind::Front:
        return make_camera(scene, width, height, glm::dvec3(0, 0, 1));
    case PngViewKind::Top:
        return make_camera(scene, width, height, glm::dvec3(0, 1, 0));
    case PngViewKind::Side:
        return make_camera(scene, width, height, glm::dvec3(1, 0, 0));
    default:
        return make_camera(scene, width, height, iso_toward());
    }
}

std::optional<glm::dvec3> project(const Camera& cam, const glm::dvec3& p) {
    if (cam.perspective) {
        const glm::dvec3 v = p - cam.eye;
        const double d = -glm::dot(v, cam.toward);
        if (!(d >= cam.near)) return std::nullopt;
        return glm::dvec3(cam.cx + cam.focal * glm::dot(v, cam.right) / d,
                          cam.cy - cam.focal * glm::dot(v, cam.up) / d, 1.0 / d);
    }
    const glm::dvec3 v = p - cam.center;
    return glm::dvec3(cam.cx + cam.scale * glm::dot(v, cam.right), cam.cy - cam.scale * glm::dot(v, cam.up),
                      glm::dot(v, cam.toward));
}

} // namespace plant::detail
