// The rule plan: what rewriting with a list of rule sets needs that does not depend on the
// string (which symbols have productions, which apply at once, the context table and the symbol
// kernel's tables). The derivation builds one per list of rule sets and keeps it.
#pragma once

#include "plant/program.hpp"

#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace plant {

// Whether some production of `rs` names a query module (?P, ?H, ...) in its predecessor or
// context: then the turtle pass runs before each step to fill them.
bool reads_queries(const Program& p, const RuleSet& rs);

// A context key of the symbol kernel (Rewriter::run_symbols; RulePlan::ctx_key). An enum rather
// than a char type: the compiler must assume a store through a char may change anything, and the
// kernel's loops would reload their pointers after each one.
enum class ContextKey : std::uint8_t {};

struct RulePlan {
    static constexpr std::uint32_t kNone = ~std::uint32_t{0};
    RulePlan(const Program& p, std::vector<const RuleSet*> rule_sets);

    // The symbol kernel's tables (see Rewriter::run_symbols). Every symbol has a row, and a
    // block of successors: one (itself when copied, its direct template) or, for a symbol of
    // the context table, one per pair of neighbour keys.
    struct SymbolSucc { // symbols padded to kMax, so that writing one is one fixed-size copy
        static constexpr std::size_t kMax = 8;
        SymbolId syms[kMax] = {};
        std::uint32_t len = 0;
        std::uint32_t fresh = 0; // modules that get new identities
    };
    static constexpr std::uint8_t kIgnored = 1, kOpen = 2, kClose = 3; // shapes; 0: context sees it
    struct SymbolRow {
        std::uint32_t block = 0;           // its successors start at succ_flat[block]
        std::uint8_t lmask = 0, rmask = 0; // 0xff: the block is indexed by that neighbour's key
        std::uint8_t shape = 0;
        std::uint8_t key = 0; // ctx_key
    };
    bool symbol_kernel = false; // Rewriter::run_symbols can rewrite strings without parameters
    std::vector<SymbolRow> sym_rows;
    std::vector<SymbolSucc> succ_flat; // each symbol's block of successors, one after another

    // The copy kernel (Engine::rewrite_copies, copies.cpp): when every module of a string
    // without numbers is copied or rewritten by a direct template that stores no numbers (ABOP's
    // Fig. 1.24), a step only copies each kind's successor kinds. Per kind of the program's
    // table: its successor padded to kMax kinds (so that writing one is one fixed-size copy),
    // its length and how many of them get new identities.
    struct KindSucc {
        static constexpr std::size_t kMax = 16;
        KindId kinds[kMax] = {};
    };
    bool copy_kernel = false;
    std::vector<KindSucc> copy_succ;
    std::vector<std::uint8_t> copy_len, copy_fresh;
    std::size_t copy_longest = 1; // the longest successor (at least 1: a copy)

    const Program& P;
    std::vector<const RuleSet*> sets;
    std::vector<std::uint8_t> has_prod;
    std::vector<const Production*> direct;
    // The context table (see build_context_table): per symbol, the offset of its K x K block in
    // ctx_entries (-1: no table), and whether its productions read the left or right neighbour.
    std::vector<std::int32_t> ctx_block;
    std::vector<std::uint8_t> ctx_sides; // bit 0: left, bit 1: right
    std::vector<std::uint8_t> ctx_key;   // per symbol: its row/column, 0 for symbols no pattern names
    std::size_t ctx_keys = 1;
    std::vector<const Production*> ctx_entries; // nullptr: no production applies
    std::size_t frame_size = 1;
    bool brackets = false, multi = false, left_new = false, right_new = false;
    bool queries = false;   // some pattern names a query module: the turtle pass fills them first
    bool templated = false; // see the end of the constructor
    bool all_direct = true; // every symbol with productions has a direct template or guards

    // Guarded symbols (see build_guards): every production of the symbol has one predecessor
    // module that binds all its arguments, a template, no context, a condition `parameter OP
    // constant` or none, and a constant weight or none. Which production applies (or none, and
    // the module is copied) is then decided without the stack machine, on the direct path.
    struct Guard {
        const Production* pr = nullptr;
        std::uint32_t param = 0; // the module's parameter the condition compares (if any)
        double weight = -1;      // below 0: not weighted
        // The condition as an interval: it holds where (lo <= x && x <= hi) != negate, for x
        // the parameter (see guard_of); without a condition, lo is NaN and negate set: always
        double lo = std::numeric_limits<double>::quiet_NaN(), hi = 0;
        bool negate = true;
        bool holds(double x) const { return ((x >= lo) & (x <= hi)) != negate; }
        std::uint32_t test = 0; // its interval among its symbol's tests (kNone: it always holds)
    };
    // The distinct intervals of a symbol's guards (see build_picks): several conditions often
    // share one (`l >= 0.5` in two productions, `l < 0.5` in a third), and the table of
    // outcomes is indexed by which of these hold, each tested once.
    struct Test {
        std::uint32_t param = 0;
        double lo = 0, hi = 0;
        bool inside(double x) const { return (x >= lo) & (x <= hi); }
    };
    struct Guarded {
        std::uint32_t first = 0, count = 0; // its guards, in the order apply() tries them
        std::uint32_t width = 0;            // the parameters every pattern of the symbol takes
        bool uniform = false;               // every outcome (a production or the copy) writes as much
        // Up to kPickBits distinct intervals (`tests` from tests_first on): the entry in
        // `picks` of the first of its 2^tests_n outcomes, indexed by which intervals hold the
        // parameter they test (bit k: test k's); -1 for more.
        std::int32_t picks = -1;
        std::uint32_t tests_first = 0, tests_n = 0;
    };
    std::vector<std::int32_t> guarded_at; // per symbol: its entry in `guarded`, or -1
    std::vector<Guarded> guarded;
    std::vector<Guard> guards;
    std::vector<Test> tests;
    // What a guarded module becomes when a given set of its conditions holds (see
    // Rewriter::pick_guarded): the one guard that applies (`only`, among the symbol's), none
    // (kNone, no options), or a draw among the options from `first` on in `pick_options`, by
    // the weights there (each already scaled, and `total` their sum, as Rewriter::choose
    // computes them).
    static constexpr std::uint32_t kPickBits = 6;
    struct Pick {
        std::uint32_t only = kNone;
        std::uint32_t first = 0, count = 0;
        double total = 0;
    };
    struct PickOption {
        std::uint32_t guard = 0; // among the symbol's
        double weight = 0;
    };
    std::vector<Pick> picks;
    std::vector<PickOption> pick_options;
    // The outcomes a module can have on the direct path, which the writer tallies so that the
    // next step knows its output's size without a counting pass (see Engine::StringCounts):
    // outcome_at[s] is the copy of a module of symbol s, outcome_at[s] + 1 + k its direct
    // template (k = 0) or its k-th guard.
    std::vector<std::uint32_t> outcome_at;
    std::vector<const SuccessorTemplate*> outcome_tmpl; // nullptr: the copy
    std::vector<SymbolId> outcome_sym;
    // Per outcome, how the direct writer computes its template's numbers without binding the
    // frame (Rewriter::put_args): when every computed number is one of the module's own, times
    // or plus a constant (SuccessorTemplate::affine), each number's source among the module's
    // numbers, its place among the stored ones and its constant, from args_first on in `args`.
    // The number is x * mul + add for x the source, one expression for the three forms, each
    // exact: x * c + (-0.0) is x * c (a zero keeps its sign), x * 1 + c is x + c, x * 1 + (-0.0)
    // is x (docs/rewriting.md, "The direct path").
    struct ArgHole {
        std::uint32_t from = 0; // the predecessor's number it reads
        std::uint32_t to = 0;   // its place among the template's stored numbers
        double mul = 1, add = -0.0;
    };
    std::vector<std::int32_t> outcome_args; // its first entry in `args`; -1: run the frame
    std::vector<ArgHole> args;
    // Per outcome whose numbers are affine, what Rewriter::put_affine writes, read from one
    // place: the template's kinds and stored numbers (nullptr when every one is computed), its
    // holes from holes_at on in `args`, and the modules that get new identities.
    // For an outcome that writes one module of its predecessor's symbol with every stored
    // number a hole, the holes that change a number when that module is rewritten in place (a
    // patched module, Rewriter::copy_run): from moved_at on in `moved`, moved_n of them. A hole
    // that takes the number at its own place unchanged (x * 1 + (-0.0)) keeps it as copied.
    struct Emit {
        const KindId* kinds = nullptr;
        const double* stored = nullptr;
        std::uint32_t m = 0, stored_n = 0, holes_at = 0, holes_n = 0, fresh = 0;
        std::int32_t keep = -1;
        std::uint32_t moved_at = 0, moved_n = 0;
    };
    std::vector<Emit> emits;
    std::vector<ArgHole> moved;
    // Whether a step must rewrite on one thread, left to right (or right to left for `>>`).
    bool sequential() const { return multi || left_new || right_new; }
    std::size_t max_modules_out = 1; // the longest template's modules (at least 1: a copy)
    std::size_t max_params_out = 0;  // and the most parameters a template holds

  private:
    void build_symbol_kernel();
    void build_copy_kernel();
    bool build_guards(SymbolId sym);
    void build_picks(Guarded& g);
    void build_outcomes();
    std::int32_t add_args(const Production& pr);
    void build_context_table();
};

} // namespace plant
