// The decomposition graph a derivation builds (Boudon et al. 2003, section 4): nodes identified by
// their paths, committed at the end of each pass, edits matched to them (by range or by exact
// position), and every node's parameters resolved by the inheritance rules of sections 2.1 and
// 2.2 (docs/language.md, decomposition graphs).
#include "plant/graph.hpp"

#include "plant/derive.hpp"
#include "plant/program.hpp"
#include "plant/random.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace plant {

namespace {
constexpr std::uint64_t kHandleMask = (std::uint64_t{1} << 52) - 1;
constexpr double kSamePosition = 1e-9; // positions this close are one position
} // namespace

const char* graph_param_kind_name(GraphParamKind k) {
    switch (k) {
    case GraphParamKind::Number:
        return "number";
    case GraphParamKind::Curve:
        return "curve";
    case GraphParamKind::Silhouette:
        return "silhouette";
    }
    return "?";
}

const char* value_status_name(ValueStatus s) {
    switch (s) {
    case ValueStatus::Explicit:
        return "explicit";
    case ValueStatus::Inherited:
        return "inherited";
    case ValueStatus::Offset:
        return "relative-offset";
    case ValueStatus::Fraction:
        return "relative-fraction";
    case ValueStatus::Shared:
        return "shared";
    }
    return "?";
}

int GraphDecl::find(std::string_view name) const {
    for (std::size_t k = 0; k < params.size(); ++k)
        if (params[k].name == name) return static_cast<int>(k);
    return -1;
}

double NodeValue::at(double t) const {
    double v = 0;
    for (const CurveTerm& term : curve) {
        const double c = (*term.curve)(t);
        v = term.op == EditOp::Set ? c : term.op == EditOp::Offset ? v + c : v * c;
    }
    return v;
}

DecompositionGraph::DecompositionGraph(const GraphDecl& decl, std::shared_ptr<const GraphEdits> edits,
                                       std::size_t max_bytes)
    : decl_(&decl), edits_(std::move(edits)), max_bytes_(max_bytes) {
    // the shares by level, in file order within a level: a node finds its level's by binary search
    if (edits_)
        for (std::size_t k = 0; k < edits_->edits.size(); ++k)
            if (edits_->edits[k].share) shares_.push_back(static_cast<int>(k));
    std::stable_sort(shares_.begin(), shares_.end(), [&](int a, int b) {
        return edits_->edits[static_cast<std::size_t>(a)].level <
               edits_->edits[static_cast<std::size_t>(b)].level;
    });
    add_node(kRoot, -1, 0, 0);
    resolve(0);
}

DecompositionGraph::DecompositionGraph(const DecompositionGraph& other)
    : decl_(other.decl_), edits_(other.edits_), nodes_(other.nodes_), by_handle_(other.by_handle_),
      values_(other.values_), matches_(other.matches_), shares_(other.shares_),
      level_first_(other.level_first_), comparisons_(other.comparisons_), resolved_(other.resolved_),
      max_bytes_(other.max_bytes_) {
    std::lock_guard lock(*other.pending_mutex_);
    pending_ = other.pending_;
}

std::uint64_t DecompositionGraph::child_handle(std::uint64_t parent, double position, int index) {
    const auto q = static_cast<std::uint64_t>(std::llround(position / kSamePosition));
    std::uint64_t h = mix64(parent * 0x9e3779b97f4a7c15ULL ^ mix64(q + 0x632be59bd9b4e019ULL) ^
                            mix64(static_cast<std::uint64_t>(index) + 0x1d8e4e27c47d124fULL));
    h &= kHandleMask;
    return h <= kRoot ? h + 2 : h;
}

std::size_t DecompositionGraph::node_bytes() const {
    // the node, its values, its entry in the handle map and a pending record while it is made
    return sizeof(GraphNode) + decl_->params.size() * sizeof(NodeValue) + sizeof(Pending) + 64;
}

bool DecompositionGraph::too_many(std::size_t n) const {
    return n > kMaxNodes || n * std::max<std::size_t>(decl_->params.size(), 1) > kMaxValues ||
           n * node_bytes() > max_bytes_;
}

bool DecompositionGraph::full() const {
    std::lock_guard lock(*pending_mutex_);
    return too_many(nodes_.size() + pending_.size() + 1);
}

bool DecompositionGraph::record(std::uint64_t handle, std::uint64_t parent, double position, int index,
                                const NodePlace* place) const {
    std::lock_guard lock(*pending_mutex_);
    if (pending_.count(handle) == 0) {
        if (too_many(nodes_.size() + pending_.size() + 1)) return false;
    }
    Pending fresh{parent, position, index, false, NodePlace{}};
    if (place) {
        fresh.placed = true;
        fresh.place = *place;
    }
    auto [it, added] = pending_.try_emplace(handle, fresh);
    if (added) return true;
    Pending& p = it->second;
    if (p.parent != parent || std::fabs(p.position - position) > kSamePosition || p.index != index)
        return false;
    // one node named twice with positions a rounding error apart: keep the lower position (and its
    // placement), whichever thread came first, so the graph is the same for every --threads
    if (position < p.position) {
        p.position = position;
        p.placed = fresh.placed;
        p.place = fresh.place;
    }
    return true;
}

bool DecompositionGraph::is_pending(std::uint64_t handle) const {
    std::lock_guard lock(*pending_mutex_);
    return pending_.count(handle) > 0;
}

void DecompositionGraph::add_node(std::uint64_t handle, int parent, double position, int index) {
    GraphNode n;
    n.handle = handle;
    n.parent = parent;
    n.position = position;
    n.index = index;
    n.depth = parent < 0 ? 0 : nodes_[static_cast<std::size_t>(parent)].depth + 1;
    if (n.depth > kMaxDepth)
        throw RuntimeError{
            RuntimeErrorKind::General, Span{},
            fmt::format("the decomposition graph would be deeper than {} levels (a child of {})", kMaxDepth,
                        excerpt(path(parent), 80))};
    const int k = static_cast<int>(nodes_.size());
    by_handle_[handle] = k;
    if (static_cast<std::size_t>(n.depth) == level_first_.size()) level_first_.push_back(k);
    nodes_.push_back(std::move(n));
    // (commit sorts each parent's children once, after adding a pass's nodes)
    if (parent >= 0) nodes_[static_cast<std::size_t>(parent)].children.push_back(k);
}

void DecompositionGraph::commit() {
    std::vector<std::pair<std::uint64_t, Pending>> fresh;
    {
        std::lock_guard lock(*pending_mutex_);
        if (pending_.empty()) return;
        fresh.assign(pending_.begin(), pending_.end());
        pending_.clear();
    }
    const std::size_t before = nodes_.size();
    if (nodes_.size() + fresh.size() > kMaxNodes)
        throw RuntimeError{RuntimeErrorKind::General, Span{},
                           fmt::format("the decomposition graph would have more than {} nodes", kMaxNodes)};
    // parents before children (by the depth among the new nodes), then by handle: the same nodes
    // in the same order on any threads, in one pass however deep the new part is
    std::sort(fresh.begin(), fresh.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    {
        std::unordered_map<std::uint64_t, std::size_t> at;
        at.reserve(fresh.size());
        for (std::size_t i = 0; i < fresh.size(); ++i) at.emplace(fresh[i].first, i);
        std::vector<std::size_t> depth(fresh.size(), SIZE_MAX);
        std::vector<std::size_t> chain;
        for (std::size_t i = 0; i < fresh.size(); ++i) {
            // walk up through new parents until one of known depth or an old parent, then unwind
            // (a cycle, which only colliding handles could make, is cut by the length bound)
            std::size_t k = i, base = 0;
            chain.clear();
            while (depth[k] == SIZE_MAX && chain.size() <= fresh.size()) {
                chain.push_back(k);
                auto up = at.find(fresh[k].second.parent);
                if (up == at.end()) break;
                if (depth[up->second] != SIZE_MAX) {
                    base = depth[up->second] + 1;
                    break;
                }
                k = up->second;
            }
            for (std::size_t j = 0; j < chain.size(); ++j) // chain[0] is i, the last the highest
                depth[chain[j]] = std::min(depth[chain[j]], base + (chain.size() - 1 - j));
        }
        std::vector<std::size_t> order(fresh.size());
        for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return depth[a] < depth[b]; });
        std::vector<std::pair<std::uint64_t, Pending>> sorted;
        sorted.reserve(fresh.size());
        for (std::size_t i : order) sorted.push_back(std::move(fresh[i]));
        fresh = std::move(sorted);
    }
    std::vector<int> touched; // parents that got children
    bool progress = true;
    while (!fresh.empty() && progress) {
        progress = false;
        std::vector<std::pair<std::uint64_t, Pending>> later;
        for (const auto& [h, p] : fresh) {
            if (int known = find(h); known >= 0) {
                const GraphNode& n = nodes_[static_cast<std::size_t>(known)];
                const bool same = n.parent >= 0 &&
                                  nodes_[static_cast<std::size_t>(n.parent)].handle == p.parent &&
                                  std::fabs(n.position - p.position) <= kSamePosition && n.index == p.index;
                if (!same)
                    throw RuntimeError{
                        RuntimeErrorKind::General, Span{},
                        fmt::format("two paths of the decomposition graph have the same handle "
                                    "({} and a child at {} of another node)",
                                    path(known), format_double(p.position))};
                progress = true;
                continue;
            }
            const int parent = find(p.parent);
            if (parent < 0) {
                later.emplace_back(h, p);
                continue;
            }
            add_node(h, parent, p.position, p.index);
            touched.push_back(parent);
            if (p.placed) { // the first call that made the node places it
                GraphNode& n = nodes_.back();
                n.placed = true;
                n.base = p.place.base;
                n.dir = p.place.dir;
                n.span = p.place.span;
            }
            progress = true;
        }
        fresh = std::move(later);
    }
    // (a parent that is never committed cannot happen: child() checks that it is a node)
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (int t : touched) {
        GraphNode& parent = nodes_[static_cast<std::size_t>(t)];
        std::sort(parent.children.begin(), parent.children.end(), [&](int a, int b) {
            const GraphNode &x = nodes_[static_cast<std::size_t>(a)],
                            &y = nodes_[static_cast<std::size_t>(b)];
            return x.position != y.position ? x.position < y.position : x.index < y.index;
        });
        parent.by_index = parent.children;
        std::stable_sort(parent.by_index.begin(), parent.by_index.end(), [&](int a, int b) {
            return nodes_[static_cast<std::size_t>(a)].index < nodes_[static_cast<std::size_t>(b)].index;
        });
    }
    resolve(before);
}

// A node's own setting of one parameter, before inheritance.
struct DecompositionGraph::Local {
    ValueStatus status = ValueStatus::Inherited;
    bool is_private = false;
    double number = 0;
    const CurveDef* curve = nullptr;
    std::shared_ptr<const Silhouette> silhouette;
    int edit = -1;
};

namespace {
void apply(DecompositionGraph::Local& l, const GraphEdit& e, int k) {
    switch (e.op) {
    case EditOp::Set:
        l.status = e.share ? ValueStatus::Shared : ValueStatus::Explicit;
        break;
    case EditOp::Offset:
        l.status = ValueStatus::Offset;
        break;
    case EditOp::Fraction:
        l.status = ValueStatus::Fraction;
        break;
    case EditOp::Inherit:
        l.status = ValueStatus::Inherited;
        break;
    case EditOp::Private:
        l.is_private = true;
        return;
    case EditOp::Public:
        l.is_private = false;
        return;
    }
    l.number = e.number;
    l.curve = e.curve.get();
    l.silhouette = e.silhouette;
    l.edit = k;
}
} // namespace

// A commit resolves only what it can change: the new nodes, and the nodes whose edits now match
// differently (a new sibling can take a range's edit), each with its subtree, since a value
// depends only on the node's own edits and its ancestors' values. The other nodes keep theirs.
void DecompositionGraph::resolve(std::size_t before) {
    const std::size_t N = nodes_.size(), P = decl_->params.size();
    const std::size_t E = edits_ ? edits_->edits.size() : 0;
    before = std::min(before, N);
    std::vector<char> dirty(N, 0);
    std::fill(dirty.begin() + static_cast<std::ptrdiff_t>(before), dirty.end(), 1);
    std::vector<int> matches(E, -1);
    std::vector<std::pair<int, int>> by_node; // (node, node edit), file order within a node
    for (std::size_t k = 0; k < E; ++k) {
        const GraphEdit& e = edits_->edits[k];
        if (e.share) { // its level's first node (the share applies to the whole level)
            const auto level = static_cast<std::size_t>(e.level);
            matches[k] = level < level_first_.size() ? level_first_[level] : -1;
            continue;
        }
        const int m = match(e), was = k < matches_.size() ? matches_[k] : -1;
        matches[k] = m;
        if (m != was) {
            if (was >= 0) dirty[static_cast<std::size_t>(was)] = 1;
            if (m >= 0) dirty[static_cast<std::size_t>(m)] = 1;
        }
        if (m >= 0) by_node.emplace_back(m, static_cast<int>(k));
    }
    matches_ = std::move(matches);
    std::stable_sort(by_node.begin(), by_node.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    // parents come before their children in nodes_: one pass marks the subtrees and resolves them
    for (std::size_t n = 1; n < before; ++n)
        if (dirty[static_cast<std::size_t>(nodes_[n].parent)]) dirty[n] = 1;
    values_.resize(N * P);
    std::vector<char> moved(N, 0); // placements computed anew in this call
    std::vector<NodeValue> previous;
    std::vector<Local> local;
    for (std::size_t n = 0; n < N; ++n) {
        if (!dirty[n]) continue;
        previous.clear();
        if (n < before)
            previous.assign(values_.begin() + static_cast<std::ptrdiff_t>(n * P),
                            values_.begin() + static_cast<std::ptrdiff_t>((n + 1) * P));
        resolve_node(n, by_node, local);
        place(n, previous, moved);
    }
}

int DecompositionGraph::source(int node, std::size_t p) const {
    const std::size_t P = decl_->params.size();
    while (values_[static_cast<std::size_t>(node) * P + p].is_private) // (never the root's)
        node = nodes_[static_cast<std::size_t>(node)].parent;
    return node;
}

// Node n's values from its own edits (the shares of its level, then its node edits, each in file
// order) and the values it inherits (sections 2.1 and 2.2).
void DecompositionGraph::resolve_node(std::size_t n, const std::vector<std::pair<int, int>>& by_node,
                                      std::vector<Local>& local) {
    const std::size_t P = decl_->params.size();
    const GraphNode& node = nodes_[n];
    local.assign(P, Local{});
    if (n == 0) // the root: the graph block's values, explicit
        for (std::size_t p = 0; p < P; ++p) {
            local[p].status = ValueStatus::Explicit;
            local[p].number = decl_->params[p].number;
            local[p].curve = decl_->params[p].curve.get();
            local[p].silhouette = decl_->params[p].silhouette;
        }
    auto level = [&](int k) { return edits_->edits[static_cast<std::size_t>(k)].level; };
    auto share = std::lower_bound(shares_.begin(), shares_.end(), node.depth,
                                  [&](int k, int depth) { return level(k) < depth; });
    for (; share != shares_.end() && level(*share) == node.depth; ++share) {
        const GraphEdit& e = edits_->edits[static_cast<std::size_t>(*share)];
        apply(local[static_cast<std::size_t>(e.param)], e, *share);
    }
    auto edit = std::lower_bound(by_node.begin(), by_node.end(), static_cast<int>(n),
                                 [](const auto& a, int m) { return a.first < m; });
    for (; edit != by_node.end() && edit->first == static_cast<int>(n); ++edit) {
        const GraphEdit& e = edits_->edits[static_cast<std::size_t>(edit->second)];
        apply(local[static_cast<std::size_t>(e.param)], e, edit->second);
    }
    resolved_ += P;
    const int parent = node.parent;
    for (std::size_t p = 0; p < P; ++p) {
        const Local& l = local[p];
        NodeValue v;
        v.status = l.status;
        v.is_private = n > 0 && l.is_private; // the root's are always public
        v.edit = l.edit;
        const bool own = l.status == ValueStatus::Explicit || l.status == ValueStatus::Shared;
        if (own || parent < 0) {
            v.from = static_cast<int>(n);
            v.number = l.number;
            if (l.curve) v.curve = {CurveTerm{EditOp::Set, l.curve}};
            v.silhouette = l.silhouette;
            values_[n * P + p] = std::move(v);
            continue;
        }
        const int from = source(parent, p);
        const NodeValue& inherited = values_[static_cast<std::size_t>(from) * P + p];
        // where the value was last set: past ancestors that inherited it themselves
        v.from = inherited.status == ValueStatus::Inherited ? inherited.from : from;
        v.number = inherited.number;
        v.curve = inherited.curve;
        v.silhouette = inherited.silhouette; // (a silhouette is never relative)
        if (l.status == ValueStatus::Offset) {
            v.number += l.number;
            if (l.curve) v.curve.push_back({EditOp::Offset, l.curve});
        } else if (l.status == ValueStatus::Fraction) {
            v.number *= l.number;
            if (l.curve) v.curve.push_back({EditOp::Fraction, l.curve});
        }
        if (!std::isfinite(v.number)) // e.g. `length *= 1e200` on a node that inherits another
            throw RuntimeError{RuntimeErrorKind::Arithmetic,
                               l.edit >= 0 ? edits_->edits[static_cast<std::size_t>(l.edit)].span : Span{},
                               fmt::format("'{}' at {} is not a finite number ({}) after this edit",
                                           decl_->params[p].name, path(static_cast<int>(n)),
                                           format_double(v.number))};
        values_[n * P + p] = std::move(v);
    }
}

// Places node n's silhouettes (Boudon et al. 2003, section 3, Fig. 8): the root's are in world
// coordinates; a node made by child(n, pos, index, base, dir) has B at base, BT along dir and T on
// its parent's envelope of the same parameter; any other node keeps its parent's placement.
void DecompositionGraph::place(std::size_t n, const std::vector<NodeValue>& previous,
                               std::vector<char>& moved) {
    const std::size_t P = decl_->params.size();
    const GraphNode& node = nodes_[n];
    // unchanged since the last commit: the same silhouettes here and an unchanged parent
    bool keep = !previous.empty() && (node.parent < 0 || !moved[static_cast<std::size_t>(node.parent)]);
    for (std::size_t p = 0; p < P && keep; ++p)
        keep = previous[p].silhouette == values_[n * P + p].silhouette;
    moved[n] = !keep;
    if (keep) {
        for (std::size_t p = 0; p < P; ++p) values_[n * P + p].placement = previous[p].placement;
        return;
    }
    for (std::size_t p = 0; p < P; ++p) {
        if (decl_->params[p].kind != GraphParamKind::Silhouette) continue;
        NodeValue& v = values_[n * P + p];
        if (node.parent < 0 || !v.silhouette) continue; // the identity
        const NodeValue& up = values_[static_cast<std::size_t>(node.parent) * P + p];
        if (!node.placed) {
            v.placement = up.placement;
            continue;
        }
        ChildPlacement c = place_child(*up.silhouette, up.placement, *v.silhouette, node.base, node.dir);
        if (!c.ok())
            throw RuntimeError{RuntimeErrorKind::General, node.span,
                               fmt::format("cannot place silhouette '{}' of {}: {}", decl_->params[p].name,
                                           path(static_cast<int>(n)), c.error)};
        v.placement = c.placement;
    }
}

} // namespace plant
