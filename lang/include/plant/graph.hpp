// Decomposition graphs (docs/language.md, decomposition graphs; Boudon, Prusinkiewicz, Federl,
// Godin and Karwowski 2003, sections 2.1, 2.2 and 4): the parameters a grammar declares in its
// `graph { }` block, the edits read from an edits file, and the graph a derivation builds while
// it runs, with each node's parameters resolved through inheritance.
//
// The declaration and the edits never change once made; the graph is run state (RunState): a
// derivation owns it, copying the derivation copies it, and start() makes it anew.
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/silhouette.hpp"
#include "plant/source.hpp"

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace plant {

struct CurveDef;
struct Program;

// What a graph parameter holds: a number, a curve (a function of t) or a silhouette (an axis, an
// envelope and the control point T, placed in each node by child(n, pos, index, base, dir)).
enum class GraphParamKind : std::uint8_t { Number, Curve, Silhouette };
const char* graph_param_kind_name(GraphParamKind k);

// How an edit's path finds its node when the branches have moved (DESIGN: range matching is
// ours, section 6 of the paper proposes it; single is the paper's exact-position matching).
enum class GraphMatch : std::uint8_t { Range, Single };

struct GraphParamDecl {
    std::string name;
    GraphParamKind kind = GraphParamKind::Number;
    double number = 0;                            // the root's default (Number)
    std::shared_ptr<const CurveDef> curve;        // the root's default (Curve)
    std::shared_ptr<const Silhouette> silhouette; // the root's default (Silhouette)
    Span span;
};

struct GraphEdits;

// `graph [match range|single] { ... }` and `edits "file";` as compiled.
struct GraphDecl {
    bool declared = false;
    GraphMatch match = GraphMatch::Range;
    std::vector<GraphParamDecl> params;
    std::string edits_path; // the default edits file, resolved; empty: none
    Span edits_span;
    Span span;
    // The edits the program was given when it was loaded (plant's --edits, or the default file);
    // DeriveOptions::edits overrides them for one derivation. Null: none.
    std::shared_ptr<const GraphEdits> edits;
    int find(std::string_view name) const;
};

// ---- edits ---------------------------------------------------------------------------------

enum class EditOp : std::uint8_t { Set, Offset, Fraction, Inherit, Private, Public };

// One component of an edit's path: POSITION[#INDEX][[LO..HI]].
struct EditStep {
    double position = 0;
    int index = 0;
    bool ranged = false;
    double lo = 0, hi = 0;
};

struct GraphEdit {
    Span span;                  // the whole line
    bool share = false;         // `share LEVEL NAME = VALUE`
    int level = 0;              // share: the depth it applies to
    std::vector<EditStep> path; // node edits: empty is the root
    int param = -1;             // in GraphDecl::params
    EditOp op = EditOp::Set;
    double number = 0;
    std::shared_ptr<const CurveDef> curve;
    std::shared_ptr<const Silhouette> silhouette;
    std::string value_text; // the value as written (for listings)
};

struct GraphEdits {
    std::vector<GraphEdit> edits;
};

// Reads an edits file already added to `sources` as `file_id`: one edit a line (DESIGN17, the
// edits file format). Values are evaluated with the program's params and consts. Errors go to
// `diags` with their line and column; returns null when there was any.
std::shared_ptr<const GraphEdits> parse_edits(const Program& program, const SourceManager& sources,
                                              std::uint32_t file_id, Diagnostics& diags);

// The path of an edit as written in an edits file ("/0.25[0..0.375]/0.5#1").
std::string edit_path_text(const GraphEdit& e);

// A node path spelled as in an edits file ("/", "/0.25#1/0.5", "/0.25[0..0.5]"); none when it is
// not one.
std::optional<std::vector<EditStep>> parse_node_path(const std::string& text);

// ---- the graph -----------------------------------------------------------------------------

struct GraphNode {
    std::uint64_t handle = 0;
    int parent = -1; // index in the graph's node list; -1 for the root
    double position = 0;
    int index = 0;
    int depth = 0;
    std::vector<int> children; // by position, then index
    // the same children by index, then position: edit matching finds a component's sibling by
    // binary search here (DecompositionGraph::match), not by scanning every child
    std::vector<int> by_index;
    // child(n, pos, index, base, dir): where the branch starts and which way it points, for the
    // placement of the node's silhouettes (Fig. 8); the call's span for errors
    bool placed = false;
    glm::dvec3 base{0.0}, dir{0.0};
    Span span;
};

// Where child(n, pos, index, base, dir) puts a new node's silhouettes.
struct NodePlace {
    glm::dvec3 base{0.0}, dir{0.0};
    Span span;
};

// How a node's value of a parameter came about.
enum class ValueStatus : std::uint8_t { Explicit, Inherited, Offset, Fraction, Shared };
const char* value_status_name(ValueStatus s);

// A resolved curve: the fold of its terms from the first (Set) on, pointwise in t.
struct CurveTerm {
    EditOp op = EditOp::Set; // Set, Offset (sum) or Fraction (product)
    const CurveDef* curve = nullptr;
};

struct NodeValue {
    ValueStatus status = ValueStatus::Inherited;
    bool is_private = false;
    int from = 0;  // the node the inherited part comes from (itself when explicit)
    int edit = -1; // the edit that set the status or value, -1: none
    double number = 0;
    std::vector<CurveTerm> curve;
    std::shared_ptr<const Silhouette> silhouette; // own coordinates (explicit or inherited)
    Placement placement;                          // own coordinates to world (Fig. 8)
    double at(double t) const;
    PlacedSilhouette placed() const { return {silhouette.get(), placement}; }
};

class DecompositionGraph {
  public:
    // The root handle; children's handles are hashes of their paths (child_handle).
    static constexpr std::uint64_t kRoot = 1;
    // A bound on the nodes of one graph: a runaway grammar stops with a runtime error.
    static constexpr std::size_t kMaxNodes = 1'000'000;
    // A bound on nodes times parameters: the resolved values a graph holds.
    static constexpr std::size_t kMaxValues = 20'000'000;
    // A bound on the depth (a path's components): a plant's branching orders are a handful, and
    // listings print every node's path whole.
    static constexpr int kMaxDepth = 100;

    // What one node costs in memory, all its values included (the bound max_bytes applies).
    std::size_t node_bytes() const;

    // `max_bytes`: the memory the nodes and their values may take (a derivation gives its
    // graph the string's budget, half of plant run's --max-memory); record() refuses past it.
    DecompositionGraph(const GraphDecl& decl, std::shared_ptr<const GraphEdits> edits,
                       std::size_t max_bytes = std::size_t{4} << 30);
    DecompositionGraph(const DecompositionGraph& other);
    DecompositionGraph& operator=(const DecompositionGraph&) = delete;

    // The handle of the child of `parent` at `position` with branch `index`: a 52-bit hash,
    // exactly representable in a double (so a node is one module parameter).
    static std::uint64_t child_handle(std::uint64_t parent, double position, int index);

    // The node with this handle, -1 if none is committed.
    int find(std::uint64_t handle) const {
        auto it = by_handle_.find(handle);
        return it == by_handle_.end() ? -1 : it->second;
    }
    // Records a child made during a pass (from any thread); committed by commit(). False when
    // the handle is already recorded for another path (a hash collision).
    bool record(std::uint64_t handle, std::uint64_t parent, double position, int index,
                const NodePlace* place = nullptr) const;
    // Whether `handle` was recorded in this pass and is not committed yet.
    bool is_pending(std::uint64_t handle) const;
    // Whether one more node would pass kMaxNodes, kMaxValues or the memory bound (record() then
    // refuses it); max_bytes() is that bound.
    bool full() const;
    std::size_t max_bytes() const { return max_bytes_; }
    // Commits the nodes recorded since the last commit (sorted by path, so the result does not
    // depend on the threads), then matches the edits again and resolves and places the values of
    // the new nodes and of the nodes an edit now matches differently, with their subtrees (the
    // other nodes' values cannot have changed). Throws RuntimeError (kind General) on a hash
    // collision, too many nodes or a silhouette that cannot be placed (at the child() call that
    // made the node).
    void commit();

    std::size_t size() const { return nodes_.size(); }
    const GraphNode& node(int k) const { return nodes_[static_cast<std::size_t>(k)]; }
    const GraphDecl& decl() const { return *decl_; }
    const NodeValue& value(int node, int param) const {
        return values_[static_cast<std::size_t>(node) * decl_->params.size() +
                       static_cast<std::size_t>(param)];
    }
    // The node's path: "/", "/0.25", "/0.5#1/0.3"; with ranges, each component's binding range
    // (halfway to the neighbouring siblings of the same index) as `:save` writes it.
    std::string path(int node, bool with_ranges = false) const;
    const GraphEdits* edits() const { return edits_.get(); }
    // Per edit: the node it applies to (a share: its level's first node), -1 when dormant.
    const std::vector<int>& matches() const { return matches_; }
    // Siblings compared while matching edit paths since the graph was made (for tests: matching
    // is a binary search per path component, not a scan of the siblings).
    std::size_t match_comparisons() const { return comparisons_; }
    // Node values computed since the graph was made: a commit resolves its new nodes and the
    // subtrees of nodes whose edits changed, not the whole graph (for tests).
    std::size_t resolved_values() const { return resolved_; }
    // Whether dormant edit k lost its node: the path stops at a node whose axis has branches of
    // the component's index, none at the position (not an axis that has not grown yet). The
    // REPL drops such edits under single-position matching (the paper's Fig. 10 c).
    bool orphaned(std::size_t k) const;

    struct Local; // a node's own setting of one parameter, before inheritance (graph.cpp)

  private:
    struct Pending {
        std::uint64_t parent;
        double position;
        int index;
        bool placed = false;
        NodePlace place;
    };
    int match(const GraphEdit& e) const;
    // The child of `parent` with branch `index` that an edit component names (docs/language.md,
    // range matching), -1 when none.
    int match_step(int parent, const EditStep& step) const;
    // Matches the edits again, then resolves the nodes from `before` on and every node whose
    // edits changed, with their subtrees (nodes before `before` were resolved by an earlier call).
    void resolve(std::size_t before);
    // Node n's values from its own edits (`by_node`: the node edits by node; `local`: scratch).
    void resolve_node(std::size_t n, const std::vector<std::pair<int, int>>& by_node,
                      std::vector<Local>& local);
    // The node whose value of parameter p the children of `node` inherit: the nearest of node
    // and its ancestors where p is public.
    int source(int node, std::size_t p) const;
    void place(std::size_t node, const std::vector<NodeValue>& previous, std::vector<char>& moved);
    void add_node(std::uint64_t handle, int parent, double position, int index);

    const GraphDecl* decl_;
    std::shared_ptr<const GraphEdits> edits_;
    std::vector<GraphNode> nodes_;
    std::unordered_map<std::uint64_t, int> by_handle_;
    std::vector<NodeValue> values_; // nodes x params
    std::vector<int> matches_;
    std::vector<int> shares_;      // the share edits, in file order
    std::vector<int> level_first_; // per depth, the first node made at it
    mutable std::size_t comparisons_ = 0;
    std::size_t resolved_ = 0;
    bool too_many(std::size_t nodes) const; // (with pending_mutex_ held)
    std::size_t max_bytes_ = std::size_t{4} << 30;
    mutable std::unique_ptr<std::mutex> pending_mutex_ = std::make_unique<std::mutex>();
    mutable std::unordered_map<std::uint64_t, Pending> pending_;
};

} // namespace plant
