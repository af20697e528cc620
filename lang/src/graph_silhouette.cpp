// Silhouette values from their keyed arguments (graph_silhouette.hpp; Boudon et al. 2003,
// sections 2.4 and 3): the axis, Cescatti's six control points and two shape coefficients, and
// the control point T.
#include "graph_silhouette.hpp"

#include "compiler_internal.hpp"

#include <fmt/format.h>

#include <array>

namespace plant {

namespace {
constexpr std::array<const char*, 10> kKeys = {"axis", "top", "bottom",    "px",           "pz",
                                               "nx",   "nz",  "top_shape", "bottom_shape", "tip"};
constexpr std::size_t kMaxAxisPoints = 1000;

int key_index(const std::string& k) {
    for (std::size_t i = 0; i < kKeys.size(); ++i)
        if (k == kKeys[i]) return static_cast<int>(i);
    return -1;
}

std::optional<AxisCurve> axis_of(const ast::Expr& a, const SilhouetteEval& ev) {
    if (a.kind != ast::ExprKind::Call || (a.text != "polyline" && a.text != "bezier")) {
        ev.error(a.span,
                 "a silhouette's axis is polyline(p0, p1, ...) or bezier(p0, p1, ...) of vec3 points");
        return std::nullopt;
    }
    if (a.args.size() > kMaxAxisPoints) {
        ev.error(a.span, fmt::format("an axis has at most {} points", kMaxAxisPoints));
        return std::nullopt;
    }
    std::vector<glm::dvec3> points;
    for (const auto& p : a.args) {
        auto v = ev.vec(*p);
        if (!v) return std::nullopt;
        points.push_back(*v);
    }
    std::string error;
    AxisCurve axis = AxisCurve::make(a.text == "bezier" ? AxisCurve::Kind::Bezier : AxisCurve::Kind::Polyline,
                                     std::move(points), error);
    if (!error.empty()) {
        ev.error(a.span, error);
        return std::nullopt;
    }
    return axis;
}
} // namespace

std::shared_ptr<const Silhouette> build_silhouette(const ast::Expr& e, const SilhouetteEval& ev) {
    std::array<const ast::Expr*, kKeys.size()> given{};
    for (std::size_t i = 0; i < e.args.size(); ++i) {
        const std::string& key = i < e.keys.size() ? e.keys[i] : std::string();
        const Span at = i < e.key_spans.size() ? e.key_spans[i] : e.args[i]->span;
        const int k = key_index(key);
        if (k < 0) {
            std::vector<std::string> names(kKeys.begin(), kKeys.end());
            const std::string near = key.empty() ? std::string() : nearest_name(key, names);
            ev.error(at, key.empty()
                             ? std::string("a silhouette's arguments are named: axis:, top:, bottom:, px:, "
                                           "pz:, nx:, nz:, top_shape:, bottom_shape:, tip:")
                         : near.empty() ? fmt::format("a silhouette has no argument '{}'", key)
                                        : fmt::format("a silhouette has no argument '{}'; did you mean '{}'?",
                                                      key, near));
            return nullptr;
        }
        if (given[static_cast<std::size_t>(k)]) {
            ev.error(at, fmt::format("'{}' is given twice", key));
            return nullptr;
        }
        given[static_cast<std::size_t>(k)] = e.args[i].get();
    }
    for (std::size_t k = 0; k < 7; ++k)
        if (!given[k]) {
            ev.error(e.span,
                     fmt::format("a silhouette needs '{}:' (it takes axis, top, bottom, px, pz, nx and "
                                 "nz; top_shape, bottom_shape and tip are optional)",
                                 kKeys[k]));
            return nullptr;
        }
    auto out = std::make_shared<Silhouette>();
    auto axis = axis_of(*given[0], ev);
    if (!axis) return nullptr;
    out->axis = std::move(*axis);
    glm::dvec3 pts[6];
    for (std::size_t k = 1; k < 7; ++k) {
        auto v = ev.vec(*given[k]);
        if (!v) return nullptr;
        pts[k - 1] = *v;
    }
    double shape[2] = {2, 2};
    for (std::size_t k = 7; k < 9; ++k) {
        if (!given[k]) continue;
        auto v = ev.number(*given[k]);
        if (!v) return nullptr;
        shape[k - 7] = *v;
    }
    std::string error;
    out->envelope = Envelope::make(pts[0], pts[1], pts[2], pts[3], pts[4], pts[5], shape[0], shape[1], error);
    if (!error.empty()) {
        ev.error(e.span, error);
        return nullptr;
    }
    out->tip = out->axis.points.back();
    if (given[9]) {
        auto v = ev.vec(*given[9]);
        if (!v) return nullptr;
        out->tip = *v;
    }
    if (glm::length(out->tip - out->base()) <= 1e-12 * std::max(1.0, glm::length(out->tip))) {
        ev.error(given[9] ? given[9]->span : e.span,
                 "the tip T is at the axis's base B: BT gives the direction and size that place a child");
        return nullptr;
    }
    return out;
}

} // namespace plant
