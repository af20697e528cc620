// Silhouettes and their placement (Boudon et al. 2003, sections 2.4 and 3): see silhouette.hpp.
#include "plant/silhouette.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

namespace plant {

namespace {

constexpr double kOutside = 1e300;

bool all_finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// v turned about the unit axis k by the angle whose cosine and sine are c and s (Rodrigues).
glm::dvec3 turn(const glm::dvec3& v, const glm::dvec3& k, double c, double s) {
    return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1 - c);
}

glm::dmat3 rotation_about(const glm::dvec3& k, double c, double s) {
    return glm::dmat3(turn({1, 0, 0}, k, c, s), turn({0, 1, 0}, k, c, s), turn({0, 0, 1}, k, c, s));
}

} // namespace

// ---- the envelope ------------------------------------------------------------------------------

Envelope Envelope::make(const glm::dvec3& top, const glm::dvec3& bottom, const glm::dvec3& px,
                        const glm::dvec3& pz, const glm::dvec3& nx, const glm::dvec3& nz, double c_top,
                        double c_bottom, std::string& error) {
    Envelope e;
    e.top = top;
    e.bottom = bottom;
    const glm::dvec3 side[4] = {px, pz, nx, nz};
    const double rad[4] = {px.x - bottom.x, pz.z - bottom.z, bottom.x - nx.x, bottom.z - nz.z};
    for (int k = 0; k < 4; ++k) {
        e.radius[k] = rad[k];
        e.height[k] = side[k].y;
        if (!(rad[k] > 0) || e.height[k] >= top.y || e.height[k] <= bottom.y) {
            error = "each widest point lies on its own side of the axis through the bottom point, "
                    "between the bottom and the top";
            return e;
        }
    }
    e.c_top = c_top;
    e.c_bottom = c_bottom;
    if (!(c_top > 0) || !(c_bottom > 0)) error = "the shape coefficients must be positive";
    return e;
}

double Envelope::level(const glm::dvec3& p) const {
    if (!all_finite(p)) return kOutside;
    const double dx = p.x - bottom.x, dz = p.z - bottom.z;
    const double r = std::hypot(dx, dz);
    double theta = std::atan2(dz, dx);
    if (theta < 0) theta += 2 * std::numbers::pi;
    const int q = std::min(3, static_cast<int>(theta / (std::numbers::pi / 2)));
    const double phi = theta - q * std::numbers::pi / 2; // angle within the quadrant
    const double a = radius[q], b = radius[(q + 1) % 4];
    const double c = std::cos(phi), s = std::sin(phi);
    const double R = a * b / std::sqrt((b * c) * (b * c) + (a * s) * (a * s)); // quarter ellipse
    const double Y = height[q] * c * c + height[(q + 1) % 4] * s * s;
    if (p.y >= Y) {
        if (p.y > top.y) return kOutside;
        double h = std::max(top.y - Y, 1e-12);
        return std::pow(std::pow(r / R, c_top) + std::pow((p.y - Y) / h, c_top), 1 / c_top);
    }
    if (p.y < bottom.y) return kOutside;
    double h = std::max(Y - bottom.y, 1e-12);
    return std::pow(std::pow(r / R, c_bottom) + std::pow((Y - p.y) / h, c_bottom), 1 / c_bottom);
}

glm::dvec3 Envelope::lo() const {
    return {bottom.x - radius[2], bottom.y, bottom.z - radius[3]};
}

glm::dvec3 Envelope::hi() const {
    return {bottom.x + radius[0], top.y, bottom.z + radius[1]};
}

glm::dvec3 Envelope::control_point(int k) const {
    const glm::dvec3 b = bottom;
    switch (k) {
    case 0:
        return {b.x, top.y, b.z};
    case 1:
        return b;
    case 2:
        return {b.x + radius[0], height[0], b.z};
    case 3:
        return {b.x, height[1], b.z + radius[1]};
    case 4:
        return {b.x - radius[2], height[2], b.z};
    default:
        return {b.x, height[3], b.z - radius[3]};
    }
}

namespace {

// The last reaches computed on this thread, keyed on every bit of the envelope and the ray.
// reach() is a pure function costing about 170 evaluations of level(); a REPL or `plant view`
// edit derives the whole plant again, and every silhouette the edit does not touch asks the same
// questions as before (docs/bonsai.md, "Time"). A hit returns the very double computed before.
class ReachMemo {
  public:
    static constexpr std::size_t kSlots = 1024; // direct-mapped: about 200 KB a thread
    using Key = std::array<std::uint64_t, 22>;
    // a field added to Envelope must be added to the key
    static_assert(sizeof(Envelope) == 16 * sizeof(double));

    static Key key(const Envelope& e, const glm::dvec3& p, const glm::dvec3& d) {
        const double v[22] = {e.top.x,     e.top.y,     e.top.z,     e.bottom.x,  e.bottom.y,  e.bottom.z,
                              e.radius[0], e.radius[1], e.radius[2], e.radius[3], e.height[0], e.height[1],
                              e.height[2], e.height[3], e.c_top,     e.c_bottom,  p.x,         p.y,
                              p.z,         d.x,         d.y,         d.z};
        Key k;
        std::memcpy(k.data(), v, sizeof v);
        return k;
    }
    const double* find(const Key& k) const {
        const Slot& s = slots_[slot_of(k)];
        return s.used && s.key == k ? &s.value : nullptr;
    }
    void put(const Key& k, double value) { slots_[slot_of(k)] = Slot{true, k, value}; }

  private:
    struct Slot {
        bool used = false;
        Key key{};
        double value = 0;
    };
    static std::size_t slot_of(const Key& k) {
        std::uint64_t h = 1469598103934665603ull; // FNV-1a over the words
        for (std::uint64_t w : k) h = (h ^ w) * 1099511628211ull;
        return static_cast<std::size_t>(h ^ (h >> 29)) % kSlots;
    }
    std::vector<Slot> slots_ = std::vector<Slot>(kSlots);
};

} // namespace

double Envelope::reach(const glm::dvec3& p, const glm::dvec3& d) const {
    thread_local ReachMemo memo;
    const ReachMemo::Key k = ReachMemo::key(*this, p, d);
    if (const double* hit = memo.find(k)) return *hit;
    const double r = reach_uncached(p, d);
    memo.put(k, r);
    return r;
}

double Envelope::reach_uncached(const glm::dvec3& p, const glm::dvec3& d) const {
    const double len = glm::length(d);
    if (!all_finite(p) || !all_finite(d) || !(len > 0) || !std::isfinite(len) || level(p) > 1.0) return 0;
    const glm::dvec3 u = d / len;
    // where the ray leaves the envelope's box: beyond it every point is outside
    const glm::dvec3 lo_ = lo(), hi_ = hi();
    double s_max = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 3; ++i) {
        if (u[i] > 0) s_max = std::min(s_max, (hi_[i] - p[i]) / u[i]);
        if (u[i] < 0) s_max = std::min(s_max, (lo_[i] - p[i]) / u[i]);
    }
    if (!(s_max > 0) || !std::isfinite(s_max)) return 0;
    constexpr int kSamples = 128;
    double inside = 0, outside = -1;
    for (int k = 1; k <= kSamples; ++k) {
        const double s = s_max * k / kSamples;
        if (level(p + u * s) > 1.0) {
            outside = s;
            break;
        }
        inside = s;
    }
    if (outside < 0) return s_max; // inside to the box's face: it leaves there
    // bisect [inside, outside] to 1e-14 of the chord (at most 64 halvings)
    for (int k = 0; k < 64 && outside - inside > 1e-14 * s_max; ++k) {
        const double mid = 0.5 * (inside + outside);
        (level(p + u * mid) > 1.0 ? outside : inside) = mid;
    }
    return inside;
}

// ---- the axis ---------------------------------------------------------------------------------

AxisCurve AxisCurve::make(Kind kind, std::vector<glm::dvec3> points, std::string& error) {
    AxisCurve c;
    c.kind = kind;
    c.points = std::move(points);
    if (c.points.size() < 2) {
        error = "an axis needs at least two points";
        return c;
    }
    if (!std::all_of(c.points.begin(), c.points.end(), all_finite)) {
        error = "an axis point is not finite";
        return c;
    }
    if (!(c.length() > 0)) error = "an axis needs two different points";
    return c;
}

double AxisCurve::length() const {
    double total = 0;
    for (std::size_t k = 1; k < points.size(); ++k) total += glm::length(points[k] - points[k - 1]);
    return total;
}

glm::dvec3 AxisCurve::point(double t) const {
    if (points.empty()) return glm::dvec3(0.0);
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    if (kind == Kind::Bezier) {
        std::vector<glm::dvec3> q = points; // de Casteljau
        for (std::size_t n = q.size(); n > 1; --n)
            for (std::size_t k = 0; k + 1 < n; ++k) q[k] = q[k] + (q[k + 1] - q[k]) * t;
        return q[0];
    }
    const double total = length();
    if (!(total > 0)) return points[0];
    double want = t * total;
    for (std::size_t k = 1; k < points.size(); ++k) {
        const double seg = glm::length(points[k] - points[k - 1]);
        if (want <= seg && seg > 0) return points[k - 1] + (points[k] - points[k - 1]) * (want / seg);
        want -= seg;
    }
    return points.back();
}

glm::dvec3 AxisCurve::heading(double t) const {
    t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
    const glm::dvec3 chord = points.size() > 1 ? points.back() - points.front() : glm::dvec3(0, 1, 0);
    auto unit_or = [&](const glm::dvec3& v, const glm::dvec3& fallback) {
        const double l = glm::length(v);
        return l > 1e-300 && std::isfinite(l) ? v / l : fallback;
    };
    const glm::dvec3 fallback = unit_or(chord, glm::dvec3(0, 1, 0));
    if (points.size() < 2) return fallback;
    if (kind == Kind::Polyline) {
        // the segment holding t (at a corner, the one after it)
        const double total = length();
        double want = t * total;
        for (std::size_t k = 1; k < points.size(); ++k) {
            const glm::dvec3 d = points[k] - points[k - 1];
            const double seg = glm::length(d);
            if (seg > 0 && (want < seg || k + 1 == points.size())) return d / seg;
            want -= seg;
        }
        return fallback;
    }
    // the derivative of the Bezier curve: the curve of the control polygon's differences
    std::vector<glm::dvec3> q;
    for (std::size_t k = 1; k < points.size(); ++k) q.push_back(points[k] - points[k - 1]);
    for (std::size_t n = q.size(); n > 1; --n)
        for (std::size_t k = 0; k + 1 < n; ++k) q[k] = q[k] + (q[k + 1] - q[k]) * t;
    const double scale = std::max(length(), 1e-300);
    if (glm::length(q[0]) > 1e-12 * scale) return glm::normalize(q[0]);
    // a vanishing derivative (repeated control points): the direction the curve moves in there
    const double dt = 1e-6;
    const glm::dvec3 step = t + dt <= 1 ? point(t + dt) - point(t) : point(t) - point(t - dt);
    return unit_or(step, fallback);
}

// ---- placement --------------------------------------------------------------------------------

glm::dmat3 minimal_rotation(const glm::dvec3& a, const glm::dvec3& b, const glm::dmat3& frame) {
    const double c = glm::dot(a, b);
    const glm::dvec3 k = glm::cross(a, b);
    const double s = glm::length(k);
    if (s > 1e-9) return rotation_about(k / s, c, s);
    if (c > 0) return glm::dmat3(1.0);
    // b is (nearly) -a: a half turn about the frame's axis most nearly perpendicular to a,
    // then the small rotation from -a onto b
    int best = 0;
    for (int i = 1; i < 3; ++i)
        if (std::abs(glm::dot(frame[i], a)) < std::abs(glm::dot(frame[best], a))) best = i;
    const glm::dvec3 n = glm::normalize(frame[best] - a * glm::dot(frame[best], a));
    const glm::dmat3 half = rotation_about(n, -1, 0);
    const glm::dvec3 k2 = glm::cross(-a, b);
    const double s2 = glm::length(k2);
    if (s2 > 0) return rotation_about(k2 / s2, glm::dot(-a, b), s2) * half;
    return half;
}

double PlacedSilhouette::reach(const glm::dvec3& p, const glm::dvec3& d) const {
    return silhouette->envelope.reach(placement.to_local(p), placement.direction_to_local(d)) *
           placement.scale;
}

ChildPlacement place_child(const Silhouette& parent, const Placement& parent_placement,
                           const Silhouette& child, const glm::dvec3& base, const glm::dvec3& dir) {
    ChildPlacement out;
    const double dir_len = glm::length(dir);
    if (!all_finite(base) || !all_finite(dir)) {
        out.error = "the branching point and the branch direction must be finite";
        return out;
    }
    if (!(dir_len > 1e-12)) {
        out.error = "the branch direction is zero: give a direction to place the child along";
        return out;
    }
    if (!(parent_placement.scale > 0) || !std::isfinite(parent_placement.scale)) {
        out.error = "the parent's placement has no size";
        return out;
    }
    const PlacedSilhouette placed{&parent, parent_placement};
    const double level = placed.level(base);
    if (level > 1.0 + 1e-9) {
        out.error = fmt::format("the branching point lies outside the parent's envelope (level {:.6g}, at "
                                "most 1 inside): place branches on the part of the axis inside it",
                                level);
        return out;
    }
    const glm::dvec3 bt = child.tip - child.base();
    const double bt_len = glm::length(bt);
    if (!all_finite(bt) || !(bt_len > 1e-12 * std::max(1.0, glm::length(child.tip)))) {
        out.error = "the child's tip T is at its base B: BT has no direction to place it by";
        return out;
    }
    const glm::dvec3 u = dir / dir_len;
    out.reach = placed.reach(base, u);
    if (!(out.reach > 0)) {
        out.error = "the ray from the branching point along the branch direction leaves the parent's "
                    "envelope at once: turn the branch inward";
        return out;
    }
    const glm::dmat3& r0 = parent_placement.rotation;
    const glm::dvec3 a = glm::normalize(r0 * bt);
    out.placement.rotation = minimal_rotation(a, u, r0) * r0;
    out.placement.scale = out.reach / bt_len;
    out.placement.translation = base - out.placement.scale * (out.placement.rotation * child.base());
    return out;
}

} // namespace plant
