// Graph built-ins and parameter reads for the VM (graph_ops.hpp; docs/language.md,
// decomposition graphs). A node is its handle, one double; child() records a new node for the
// end of the pass (DecompositionGraph::commit) and reads see only committed nodes.
#include "graph_ops.hpp"

#include "plant/derive.hpp"
#include "plant/graph.hpp"
#include "plant/run_state.hpp"

#include <fmt/format.h>

#include <cmath>

namespace plant {

namespace {

constexpr double kMaxHandle = 4503599627370495.0; // 2^52 - 1
constexpr double kMaxIndex = 1e6;

bool as_handle(double v, std::uint64_t& h) {
    if (!(v >= 0 && v <= kMaxHandle) || v != std::floor(v)) return false;
    h = static_cast<std::uint64_t>(v);
    return true;
}

// The committed node `v` names, or an error message.
std::string committed(const DecompositionGraph& g, double v, int& node) {
    std::uint64_t h = 0;
    node = as_handle(v, h) ? g.find(h) : -1;
    if (node >= 0) return {};
    if (as_handle(v, h) && g.is_pending(h)) // recorded in this pass, not yet committed
        return "this node was made in the current pass: read it from the next step "
               "(nodes are committed when a pass ends)";
    return fmt::format("{} is not a node of the decomposition graph", format_double(v));
}

std::string make_child(const DecompositionGraph& g, const double* a, bool with_index, bool records, double& r,
                       const NodePlace* place = nullptr) {
    std::uint64_t parent = 0;
    const bool parent_ok = as_handle(a[0], parent) && (g.find(parent) >= 0 || g.is_pending(parent));
    if (!parent_ok) return fmt::format("{} is not a node of the decomposition graph", format_double(a[0]));
    const double pos = a[1];
    if (!(pos >= 0 && pos <= 1))
        return fmt::format("a child's position along its parent's axis is from 0 to 1, found {}",
                           format_double(pos));
    const double idx = with_index ? a[2] : 0;
    if (!(idx >= 0 && idx <= kMaxIndex) || idx != std::floor(idx))
        return fmt::format("a child's branch index is a whole number from 0 to 1000000, found {}",
                           format_double(idx));
    const int index = static_cast<int>(idx);
    if (const int up = g.find(parent); up >= 0 && g.node(up).depth >= DecompositionGraph::kMaxDepth)
        return fmt::format("the decomposition graph would be deeper than {} levels (a child of {})",
                           DecompositionGraph::kMaxDepth, excerpt(g.path(up), 80));
    const std::uint64_t h = DecompositionGraph::child_handle(parent, pos, index);
    r = static_cast<double>(h);
    if (int known = g.find(h); known >= 0) {
        const GraphNode& n = g.node(known);
        if (n.parent >= 0 && g.node(n.parent).handle == parent && std::fabs(n.position - pos) <= 1e-9 &&
            n.index == index)
            return {};
        return fmt::format("two paths of the decomposition graph have the same handle: {} and a child at "
                           "{} of another node",
                           g.path(known), format_double(pos));
    }
    if (place) { // the parent's silhouettes must be there to place the child's in (Fig. 8)
        const int up = g.find(parent);
        if (up < 0)
            return "the parent node was made in the current pass: place its children from the next step "
                   "(nodes are committed when a pass ends)";
        for (std::size_t p = 0; p < g.decl().params.size(); ++p) {
            if (g.decl().params[p].kind != GraphParamKind::Silhouette) continue;
            const NodeValue& v = g.value(up, static_cast<int>(p));
            // the branching point inside the parent's envelope (the ray's reach is checked when
            // the node is committed, with this call's span)
            const double level = v.placed().level(place->base);
            if (!(level <= 1.0 + 1e-9))
                return fmt::format(
                    "cannot place silhouette '{}': the branching point lies outside the parent's "
                    "envelope (level {:.6g}, at most 1 inside): place branches on the part of the "
                    "axis inside it",
                    g.decl().params[p].name, level);
        }
    }
    if (records && !g.record(h, parent, pos, index, place))
        return g.full()
                   ? fmt::format("the decomposition graph would have more than {} nodes, {} values (nodes "
                                 "times parameters) or {} MB of memory (a quarter of the "
                                 "command's --max-memory, at most 1024 MB)",
                                 DecompositionGraph::kMaxNodes, DecompositionGraph::kMaxValues,
                                 g.max_bytes() >> 20)
                   : "two paths of the decomposition graph made in this pass have the same handle";
    return {};
}

} // namespace

std::string graph_builtin(BuiltinId id, const double* a, double* r, const EvalEnv& env) {
    const DecompositionGraph* g = env.run ? env.run->graph() : nullptr;
    if (!g) return "the decomposition graph exists only while the plant is derived";
    int node = -1;
    switch (id) {
    case BuiltinId::Root:
        r[0] = static_cast<double>(DecompositionGraph::kRoot);
        return {};
    case BuiltinId::Child:
        return make_child(*g, a, false, env.graph_records, r[0]);
    case BuiltinId::ChildIndex:
        return make_child(*g, a, true, env.graph_records, r[0]);
    case BuiltinId::Depth:
    case BuiltinId::Position:
    case BuiltinId::BranchIndex: {
        if (std::string e = committed(*g, a[0], node); !e.empty()) return e;
        const GraphNode& n = g->node(node);
        r[0] = id == BuiltinId::Depth ? n.depth : id == BuiltinId::Position ? n.position : n.index;
        return {};
    }
    default:
        return "not a graph built-in";
    }
}

std::string graph_place(const double* a, double* r, const EvalEnv& env, Span span) {
    const DecompositionGraph* g = env.run ? env.run->graph() : nullptr;
    if (!g) return "the decomposition graph exists only while the plant is derived";
    NodePlace place;
    place.base = {a[3], a[4], a[5]};
    place.dir = {a[6], a[7], a[8]};
    place.span = span;
    return make_child(*g, a, true, env.graph_records, r[0], &place);
}

namespace {
constexpr ValueType N = ValueType::Number, V = ValueType::Vec3, B = ValueType::Bool, X = ValueType::Void;
constexpr SilhouetteMethodInfo kMethods[] = {
    {"level", SilhouetteMethod::Level, 1, {V, X}, N, "how far out p is: below 1 inside, 1 on the envelope"},
    {"contains", SilhouetteMethod::Contains, 1, {V, X}, B, "p inside the envelope"},
    {"reach",
     SilhouetteMethod::Reach,
     2,
     {V, V},
     N,
     "the distance from p along the unit d to the envelope, 0 when p is outside"},
    {"axis", SilhouetteMethod::Axis, 1, {N, X}, V, "the point at t of the placed axis"},
    {"heading", SilhouetteMethod::Heading, 1, {N, X}, V, "the unit tangent at t of the placed axis"},
    {"base", SilhouetteMethod::Base, 0, {X, X}, V, "the placed base B"},
    {"tip", SilhouetteMethod::Tip, 0, {X, X}, V, "the placed control point T"},
    {"scale", SilhouetteMethod::Scale, 0, {X, X}, N, "the placement's scale"},
};
} // namespace

std::span<const SilhouetteMethodInfo> silhouette_methods() {
    return kMethods;
}

std::string graph_shape(int param, std::size_t method, const double* a, double* r, const EvalEnv& env) {
    const DecompositionGraph* g = env.run ? env.run->graph() : nullptr;
    if (!g) return "the decomposition graph exists only while the plant is derived";
    int node = -1;
    if (std::string e = committed(*g, a[0], node); !e.empty()) return e;
    const PlacedSilhouette s = g->value(node, param).placed();
    const glm::dvec3 p{a[1], a[2], a[3]};
    auto put = [&](const glm::dvec3& v) {
        r[0] = v.x;
        r[1] = v.y;
        r[2] = v.z;
    };
    switch (kMethods[method].id) {
    case SilhouetteMethod::Level:
        r[0] = s.level(p);
        break;
    case SilhouetteMethod::Contains:
        r[0] = s.contains(p) ? 1 : 0;
        break;
    case SilhouetteMethod::Reach: {
        const glm::dvec3 d{a[4], a[5], a[6]};
        r[0] = s.reach(p, d);
        break;
    }
    case SilhouetteMethod::Axis:
        put(s.axis(a[1]));
        break;
    case SilhouetteMethod::Heading:
        put(s.heading(a[1]));
        break;
    case SilhouetteMethod::Base:
        put(s.base());
        break;
    case SilhouetteMethod::Tip:
        put(s.tip());
        break;
    case SilhouetteMethod::Scale:
        r[0] = s.placement.scale;
        break;
    }
    return {};
}

std::string graph_read(int param, bool curve, const double* a, double* r, const EvalEnv& env) {
    const DecompositionGraph* g = env.run ? env.run->graph() : nullptr;
    if (!g) return "the decomposition graph exists only while the plant is derived";
    int node = -1;
    if (std::string e = committed(*g, a[0], node); !e.empty()) return e;
    const NodeValue& v = g->value(node, param);
    r[0] = curve ? v.at(a[1]) : v.number;
    return {};
}

} // namespace plant
