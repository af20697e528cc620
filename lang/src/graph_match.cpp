// Finding nodes by path in the decomposition graph (docs/language.md, edits files and range
// matching): an edit's path component picks one child of a node by branch index and position, by
// binary search over the children sorted by index, then position (GraphNode::by_index), so a node
// with many children and many edits costs a logarithm per component, not a scan.
#include "plant/graph.hpp"

#include "plant/derive.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace plant {

namespace {
constexpr double kSamePosition = 1e-9; // positions this close are one position (as in graph.cpp)

// The first of `kids` (sorted by index, then position) at or after (index, position).
std::vector<int>::const_iterator first_at(const std::vector<GraphNode>& nodes, const std::vector<int>& kids,
                                          int index, double position, std::size_t& comparisons) {
    return std::lower_bound(kids.begin(), kids.end(), position, [&](int c, double x) {
        ++comparisons;
        const GraphNode& n = nodes[static_cast<std::size_t>(c)];
        return n.index != index ? n.index < index : n.position < x;
    });
}
} // namespace

std::string DecompositionGraph::path(int node, bool with_ranges) const {
    if (node <= 0) return "/";
    std::vector<int> chain;
    for (int k = node; k > 0; k = nodes_[static_cast<std::size_t>(k)].parent) chain.push_back(k);
    std::string out;
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
        const GraphNode& n = nodes_[static_cast<std::size_t>(*it)];
        out += "/" + format_double(n.position);
        if (n.index != 0) out += fmt::format("#{}", n.index);
        if (!with_ranges) continue;
        // halfway to the neighbouring siblings of the same index; 0 or 1 at an end (no two
        // siblings share an index and a position: they would be one node)
        double lo = 0, hi = 1;
        const auto& kids = nodes_[static_cast<std::size_t>(n.parent)].by_index;
        std::size_t unused = 0;
        const auto at = first_at(nodes_, kids, n.index, n.position, unused);
        if (at != kids.begin()) {
            const GraphNode& o = nodes_[static_cast<std::size_t>(*(at - 1))];
            if (o.index == n.index) lo = (o.position + n.position) / 2;
        }
        if (at != kids.end() && at + 1 != kids.end()) {
            const GraphNode& o = nodes_[static_cast<std::size_t>(*(at + 1))];
            if (o.index == n.index) hi = (o.position + n.position) / 2;
        }
        // to 9 decimals (0.3, not 0.30000000000000004), but never narrower than the range by more
        // than rounding noise: the written range must still hold the node's own position
        auto outward = [](double x, bool up) {
            const double r = std::round(x * 1e9) / 1e9;
            if (up ? r < x - 1e-12 : r > x + 1e-12)
                return (up ? std::ceil(x * 1e9) : std::floor(x * 1e9)) / 1e9;
            return r;
        };
        out += "[" + format_double(outward(lo, false)) + ".." + format_double(outward(hi, true)) + "]";
    }
    return out;
}

// One component (docs/language.md, range matching): the sibling at the component's own position
// (within 1e-9; the lowest when two are) always; else, with a range and range matching, the
// sibling in the range nearest that position (ties: the lower). A branch that is still where the
// edit was made keeps its edit, however the other branches of its range move.
int DecompositionGraph::match_step(int parent, const EditStep& step) const {
    const auto& kids = nodes_[static_cast<std::size_t>(parent)].by_index;
    auto same_index = [&](std::vector<int>::const_iterator it) {
        return nodes_[static_cast<std::size_t>(*it)].index == step.index;
    };
    auto pos = [&](std::vector<int>::const_iterator it) {
        return nodes_[static_cast<std::size_t>(*it)].position;
    };
    const auto exact = first_at(nodes_, kids, step.index, step.position - kSamePosition, comparisons_);
    if (exact != kids.end() && same_index(exact) && pos(exact) <= step.position + kSamePosition)
        return *exact;
    if (!step.ranged || decl_->match != GraphMatch::Range) return -1;
    // the nearest below the position and the nearest above it (nothing lies within 1e-9 of it)
    int below = -1, above = -1;
    if (exact != kids.begin() && same_index(exact - 1) && pos(exact - 1) >= step.lo - kSamePosition)
        below = *(exact - 1);
    if (exact != kids.end() && same_index(exact) && pos(exact) <= step.hi + kSamePosition) above = *exact;
    if (below < 0 || above < 0) return below < 0 ? above : below;
    const double db = step.position - nodes_[static_cast<std::size_t>(below)].position;
    const double da = nodes_[static_cast<std::size_t>(above)].position - step.position;
    return da < db - kSamePosition ? above : below;
}

// The node an edit's path names now, component by component from the root.
int DecompositionGraph::match(const GraphEdit& e) const {
    int cur = 0;
    for (const EditStep& step : e.path) {
        cur = match_step(cur, step);
        if (cur < 0) return -1;
    }
    return cur;
}

bool DecompositionGraph::orphaned(std::size_t k) const {
    if (!edits_ || k >= edits_->edits.size() || matches_[k] >= 0) return false;
    const GraphEdit& e = edits_->edits[k];
    if (e.share) return false;
    int at = 0;
    for (const EditStep& step : e.path) {
        const int next = match_step(at, step);
        if (next < 0) {
            // lost when the axis has branches of this index, none where the edit is
            const auto& kids = nodes_[static_cast<std::size_t>(at)].by_index;
            std::size_t unused = 0;
            const auto it = first_at(nodes_, kids, step.index, -1.0, unused);
            return it != kids.end() && nodes_[static_cast<std::size_t>(*it)].index == step.index;
        }
        at = next;
    }
    return false;
}

} // namespace plant
