// plant view's picking (docs/view.md): the page sends the point it hit in the plant's own
// coordinates and what it hit (a tube, or a placed organ and where that placement stands); the
// model finds the skeleton segment or organ that drew it at that step, then the module behind it
// in the derived string by its identity: name, identity, parameters and, for a parameter of type
// node, its decomposition graph node with where each value comes from.
#include "cmd_view.hpp"

#include "plant/graph.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <limits>

namespace plant::cli {

// What picking at one step reads: the interpreted string and what the turtle drew from it.
struct ViewPickData {
    ModuleString interpreted;
    Skeleton skeleton;
};

namespace {

double segment_distance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

nlohmann::json vec(const glm::dvec3& v) {
    return nlohmann::json::array({v.x, v.y, v.z});
}

// The skeleton's answer: the segment nearest the hit point (tubes), or the organ whose placement
// stands nearest the placement the page hit (nearest the hit point among equals).
struct Found {
    bool found = false;
    ModuleId id = 0;
    std::string drawn; // the module name the skeleton recorded
    nlohmann::json where;
    int axis = -1; // the skeleton axis of the segment (for an organ: of the segment nearest it)
};

// The nearest segment to p: its axis and point index (axis -1 when the skeleton has none).
std::pair<int, std::size_t> nearest_segment(const Skeleton& s, const glm::dvec3& p, double& best) {
    std::pair<int, std::size_t> at{-1, 0};
    best = std::numeric_limits<double>::infinity();
    for (std::size_t a = 0; a < s.axes.size(); ++a) {
        const auto& pts = s.axes[a].points;
        for (std::size_t k = 1; k < pts.size(); ++k) {
            const double d = segment_distance(p, pts[k - 1].position, pts[k].position);
            if (d < best) {
                best = d;
                at = {static_cast<int>(a), k};
            }
        }
    }
    return at;
}

Found nearest(const Skeleton& s, const ViewPick& q) {
    Found f;
    double best = std::numeric_limits<double>::infinity(), tie = best;
    if (q.kind == ViewPick::Tube) {
        const auto [axis, k] = nearest_segment(s, q.point, best);
        if (axis < 0) return f;
        const auto& pts = s.axes[static_cast<std::size_t>(axis)].points;
        f = {true,
             pts[k].id,
             std::string(s.module_name(pts[k])),
             {{"from", vec(pts[k - 1].position)}, {"to", vec(pts[k].position)}, {"distance", best}},
             axis};
        return f;
    }
    for (const SkeletonOrgan& o : s.organs) {
        const glm::dvec3 at(o.transform[3]);
        const double d = glm::length(at - q.origin), d2 = glm::length(at - q.point);
        if (d > best || (d == best && d2 >= tie)) continue;
        best = d;
        tie = d2;
        f = {true, o.id, organ_label(o.shape), {{"at", vec(at)}, {"distance", d}}};
    }
    if (f.found) f.axis = nearest_segment(s, q.origin, best).first;
    return f;
}

// The index of the module with identity `id` in `s`, or s.size().
std::size_t find_id(const ModuleString& s, ModuleId id) {
    if (!s.keep_ids || id == 0) return s.size();
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.ids[i] == id) return i;
    return s.size();
}

// Module i of `s`: its name, parameters (named when declared) and any graph node they name.
void describe(const Program& program, const Derivation& d, const ModuleString& s, std::size_t i,
              nlohmann::json& j) {
    const SymbolInfo& info = program.symbols[s.symbol(i)];
    j["module"] = info.name;
    const ModuleArgs args = s.args(i);
    nlohmann::json params = nlohmann::json::array();
    const DecompositionGraph* graph = d.run_state().graph();
    std::size_t at = 0;
    for (std::size_t k = 0; at < args.size(); ++k) {
        const ValueType type = k < info.param_types.size() ? info.param_types[k] : ValueType::Number;
        const std::size_t width = std::min(static_cast<std::size_t>(value_width(type)), args.size() - at);
        nlohmann::json p;
        p["name"] = k < info.param_names.size() ? info.param_names[k] : "#" + std::to_string(k + 1);
        p["value"] = width == 3 ? vec({args[at], args[at + 1], args[at + 2]}) : nlohmann::json(args[at]);
        if (type == ValueType::Node && graph) {
            const int node = graph->find(static_cast<std::uint64_t>(args[at]));
            if (node >= 0) {
                p["node"] = graph->path(node);
                if (!j.contains("node"))
                    j["node"] = {{"path", graph->path(node)}, {"text", graph_tree(*graph, node, false)}};
            }
        }
        params.push_back(std::move(p));
        at += width;
    }
    j["params"] = std::move(params);
}

// The graph node of the branch an axis draws: the node whose branch starts where the axis does
// (child(n, t, i, base, dir) gives the start, docs/language.md), else its parent axis's, up to the
// root. Without a placed node (a grammar that gives child() no base) the branch's node is unknown.
int axis_node(const DecompositionGraph& g, const Skeleton& s, int axis) {
    for (int a = axis; a >= 0; a = s.axes[static_cast<std::size_t>(a)].parent) {
        const auto& pts = s.axes[static_cast<std::size_t>(a)].points;
        if (s.axes[static_cast<std::size_t>(a)].parent < 0) return 0; // the first axis: the root's
        if (pts.empty()) continue;
        const glm::dvec3 start = pts.front().position;
        int best = -1;
        double best_d = 1e-6 * (1 + glm::length(start));
        for (std::size_t n = 1; n < g.size(); ++n) {
            const GraphNode& node = g.node(static_cast<int>(n));
            if (!node.placed) continue;
            const double d = glm::length(node.base - start);
            if (d <= best_d) {
                best_d = d;
                best = static_cast<int>(n);
            }
        }
        if (best >= 0) return best;
    }
    return -1;
}

} // namespace

std::string view_pick_json(const Program& program, const Derivation& d, int step,
                           std::shared_ptr<const ViewPickData>& data, const ViewPick& q) {
    if (!data) {
        auto made = std::make_shared<ViewPickData>();
        made->interpreted = d.interpreted(d.string());
        made->skeleton = build_skeleton(program, made->interpreted, turtle_options(d));
        data = std::move(made);
    }
    const Found f = nearest(data->skeleton, q);
    nlohmann::json j = {{"found", f.found}, {"step", step}};
    if (f.found) {
        j.update(f.where);
        j["module"] = f.drawn;
        if (f.id != 0) j["id"] = f.id;
        if (std::size_t i = find_id(d.string(), f.id); i < d.string().size()) {
            j["index"] = i;
            describe(program, d, d.string(), i, j);
        } else if (std::size_t k = find_id(data->interpreted, f.id); k < data->interpreted.size()) {
            j["interpreted"] = true; // made by an interpretation rule: not in the derived string
            describe(program, d, data->interpreted, k, j);
        }
        const DecompositionGraph* g = d.run_state().graph();
        if (g && g->size() > 0 && !j.contains("node") && f.axis >= 0) {
            const int node = axis_node(*g, data->skeleton, f.axis);
            if (node >= 0)
                j["node"] = {{"path", g->path(node)}, {"text", graph_tree(*g, node, false)}, {"by", "axis"}};
        }
    }
    return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

} // namespace plant::cli
