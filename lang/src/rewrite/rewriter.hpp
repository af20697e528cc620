// What the rewriting routes share: the worker a thread rewrites with, the Rewriter (one pass over
// one string under one rule plan) and the helpers its loops call for every module, kept here as
// inline functions so that each route's loop can inline them. The routes themselves live in
// their own files:
//   general.cpp    run_range: matching, conditions, stochastic choice, production bodies
//   templated.cpp  run_templates: every rewritten symbol has a template or a context table
//   direct.cpp     count_direct/write_direct: every successor is a direct template, in place
//   symbols.cpp    run_symbols: the symbol kernel, for strings without parameters
//   passes.cpp     run_backward: right to left, for productions with a right new context
//   context.cpp    the context matchers (old string, new string) and :find
// Private to the language library (and its unit tests).
#pragma once

#include "plan.hpp"
#include "plant/derive.hpp"
#include "plant/random.hpp"
#include "plant/vm.hpp"

#include <cmath>
#include <cstring>
#include <optional>
#include <span>

namespace plant {

constexpr std::int64_t kUnknown = -2;

// What write_direct needs of a module of a given kind, read with one load: its symbol's direct
// template, else its entry in RulePlan::guarded (-1: none, or a direct template); `copy`, the
// outcome of copying it when its symbol has no productions, else kPatch or kNoCopy (see
// write_direct); its symbol's first outcome (RulePlan::outcome_at); its numbers and how many of
// them are stored, and whether all of them are (its ModuleArgs are then one array). For a
// patched kind whose symbol has one guard and no draw, `one` is all that a copied run needs of
// it (Rewriter::copy_run).
struct PatchOne {
    RulePlan::Guard guard;                    // the module is rewritten where it holds,
    const RulePlan::ArgHole* moved = nullptr; // these numbers changed (RulePlan::Emit::moved)
    std::uint32_t moved_n = 0;
    std::uint32_t at = 0; // the outcome of its copy (its rewrite's is the next)
};
struct KindRow {
    static constexpr std::uint32_t kNoCopy = ~std::uint32_t{0}, kPatch = kNoCopy - 1;
    const Production* direct = nullptr;
    const PatchOne* one = nullptr;
    std::int32_t guarded = -1;
    std::uint32_t copy = kNoCopy;
    std::uint32_t at = 0;
    std::uint16_t arity = 0;
    std::uint8_t stored = 0;
    bool dense = true;
};

// Everything one thread needs to rewrite a stretch of the string.
struct Worker {
    Worker() = default;
    explicit Worker(ModuleString&& o) : out(std::move(o)) {}
    EvalEnv env;
    std::vector<double> frame;
    ModuleString out;
    std::optional<RuntimeError> error;
    // context neighbours of the module at ctx_at, found once for all its productions
    std::size_t ctx_at = ~std::size_t{0};
    std::int64_t ctx_left = kUnknown, ctx_right = kUnknown;
    BigVector<ContextKey> scratch; // Rewriter::run_symbols's keys, when the rewriter has no buffer for them
    // write_direct's snapshots, one every kSnapEvery modules read: where the output stood
    // (modules written so far), then the tally of every outcome so far (Engine::counts).
    std::vector<std::uint64_t> snaps;
    // write_direct's table of the kinds (see KindRow), and its kinds' PatchOne
    std::vector<KindRow> kind_rows;
    std::vector<PatchOne> patch_ones;
};

class Rewriter {
  public:
    // `brackets`: where to build the bracket table (a buffer kept from step to step saves an
    // allocation each step); null: a buffer of the rewriter's own.
    // `whole`: run_range will be called once, for the whole string, by one thread. Only then
    // does the symbol kernel apply (it needs no bracket table, and keeps its right keys in
    // `scratch`).
    Rewriter(const RulePlan& rule_plan, const ModuleString& in,
             std::vector<std::uint32_t>* brackets = nullptr, BigVector<ContextKey>* scratch = nullptr,
             bool whole = false);

    // The production the context table gives for module i, which has a table and no parameters.
    // nullptr: none applies.
    const Production* table_lookup(std::size_t i) const {
        const SymbolId sym = in.symbol(i);
        std::size_t lk = 0, rk = 0;
        if (plan.ctx_sides[sym] & 1) {
            const std::int64_t j = left_step(static_cast<std::int64_t>(i) - 1);
            if (j >= 0 && in.arity(static_cast<std::size_t>(j)) == 0)
                lk = plan.ctx_key[in.symbol(static_cast<std::size_t>(j))];
        }
        if (plan.ctx_sides[sym] & 2) {
            const std::size_t j = right_step(i + 1);
            if (j < n && in.arity(j) == 0) rk = plan.ctx_key[in.symbol(j)];
        }
        return plan.ctx_entries[static_cast<std::size_t>(plan.ctx_block[sym]) + lk * plan.ctx_keys + rk];
    }

    // Whether run_range rewrites this string with the symbol kernel (run_symbols): one thread
    // over the whole string (its tables are the symbols': not for a string with kinds of
    // constant numbers).
    bool kernel_applies() const {
        return whole && plan.symbol_kernel && in.params.empty() && !in.keep_ids && !table_kinds;
    }

    // Whether production `pr` (pattern, context and condition) matches at module i: the REPL's
    // :find. Binds the worker's frame.
    bool matches_at(Worker& w, std::size_t i, const Production& pr);

    // Rewrites modules [b, e) into w.out (general.cpp), by the fastest route the plan and the
    // string allow.
    void run_range(Worker& w, std::size_t b, std::size_t e);

    // ---- the direct path (direct.cpp): every module is copied or rewritten by a direct template
    // Then the size of the output of any stretch is known before writing it, so the output is
    // allocated once, exactly, and each thread writes its stretch in place.
    struct Counts {
        std::size_t modules = 0, params = 0;
        ModuleId new_ids = 0;
        bool ok = true;
    };
    Counts count_direct(std::size_t b, std::size_t e) const;
    // How often write_direct records its snapshot (Worker::snaps), in modules read.
    static constexpr std::size_t kSnapEvery = 8192;
    // Writes the output of modules [b, e) at module m_at and parameter p_at of `out`, whose
    // arrays are large enough; new identities are numbered from id_at. Adds each module's
    // outcome to `tally` (indexed as RulePlan::outcome_at). Returns what it wrote.
    Counts write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out, std::size_t m_at,
                        std::size_t p_at, ModuleId id_at, std::uint64_t* tally);

    // The production a guarded symbol's module i gets (see RulePlan::Guarded), decided as
    // apply() and choose() would decide it: its guard's index among the symbol's, or -1 when
    // none applies and the module is copied. x: module i's numbers (an array when all are
    // stored, else its ModuleArgs), `arity` of them.
    template <typename Numbers>
    std::int32_t pick_guarded(std::size_t i, const Numbers& x, std::uint32_t arity,
                              const RulePlan::Guarded& g) const;
    [[gnu::noinline]] std::int32_t pick_unlisted(std::size_t i, const ModuleArgs& a,
                                                 const RulePlan::Guarded& g) const;
    // The seed and phase of the step's random draws (weighted choice on the direct path).
    void set_draws(std::uint64_t seed, std::uint64_t phase) { draw_phase = random_phase(seed, phase); }

    // ---- backward processing for `>>` (passes.cpp)
    void run_backward(Worker& w);
    ModuleString assemble_backward(const ModuleString& pieces) const;

  private:
    template <bool Ids>
    std::size_t copy_run(const KindRow* rows, std::size_t i, std::size_t e, std::size_t q, KindId* S,
                         double* PA, ModuleId* ID, std::uint64_t* tally, std::uint32_t& np) const;
    template <bool Ids>
    Counts write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out, std::size_t m_at,
                        std::size_t p_at, ModuleId id_at, std::uint64_t* tally);
    template <bool Ids> void run_templates(Worker& w, std::size_t b, std::size_t e);
    void run_symbols(Worker& w);

    // general.cpp: trying productions, running their successors
    std::size_t apply(Worker& w, std::size_t i);
    std::size_t apply_template(Worker& w, std::size_t i, const Production& pr);
    std::size_t run_body(Worker& w, std::size_t i, const Production& pr);
    std::size_t choose(Worker& w, std::size_t i, std::size_t set0, std::size_t cand0, std::size_t length = 0);
    [[noreturn]] void limit_error() const;
    [[noreturn]] void hole_error(const SuccessorTemplate& t, std::size_t h, double value) const;

    // Writes successor template t, its computed numbers in `values`, at S (kinds), PA and ID:
    // its kinds and stored numbers (SuccessorTemplate::kinds). Module t.keep gets the identity
    // `kept` (the predecessor's), the others new ones counted on from `next_new`. Identities are
    // written only when Ids. The caller indexes the parameters (ModuleString::index_range) once
    // the stretch is written.
    template <bool Ids>
    static void put_template(const SuccessorTemplate& t, const double* values, ModuleId kept,
                             ModuleId& next_new, KindId* S, double* PA, ModuleId* ID) {
        const std::size_t m = t.syms.size();
        if (m != 0) std::memcpy(S, t.kinds.data(), m * sizeof(KindId));
        // An erasing or parameterless successor has no parameter storage;
        // memcpy with a null source is undefined even for zero bytes.
        // (none is when every stored number is computed, the usual case)
        if (t.stored.size() != t.holes.size())
            std::memcpy(PA, t.stored.data(), t.stored.size() * sizeof(double));
        for (std::size_t h = 0; h < t.holes.size(); ++h) PA[t.stored_holes[h]] = values[h];
        if constexpr (Ids) {
            for (std::size_t j = 0; j < m; ++j) ID[j] = static_cast<int>(j) == t.keep ? kept : next_new++;
        } else {
            next_new += t.fresh();
        }
    }

    // Copies m kinds without a library call for the short lengths templates have: two
    // overlapping fixed-size copies cover any length between a size and its double.
    static void copy_kinds(KindId* to, const KindId* from, std::size_t m) {
        static_assert(sizeof(KindId) == 2, "the size classes below assume 2-byte kinds");
        auto two = [&](auto block) {
            constexpr std::size_t w = sizeof(block) / sizeof(KindId);
            std::memcpy(&block, from, sizeof block);
            std::memcpy(to, &block, sizeof block);
            std::memcpy(&block, from + m - w, sizeof block);
            std::memcpy(to + m - w, &block, sizeof block);
        };
        struct Sixteen {
            std::uint64_t a, b;
        };
        if (m > 16)
            std::memcpy(to, from, m * sizeof(KindId));
        else if (m >= 8)
            two(Sixteen{});
        else if (m >= 4)
            two(std::uint64_t{});
        else if (m >= 2)
            two(std::uint32_t{});
        else if (m == 1)
            to[0] = from[0];
    }

    // put_template for a template whose numbers are affine functions of the predecessor's own
    // (RulePlan::outcome_args), outcome o with RulePlan::Emit em: each computed from `x` (the
    // module's numbers) and written in its place, without the frame. Numbers that are not
    // finite are an error, as with check_holes; the test is folded into the loop (check_holes
    // reads back values just stored one by one, which the processor cannot forward to its
    // paired loads).
    template <bool Ids, typename Numbers>
    void put_affine(std::uint32_t o, const RulePlan::Emit& em, const Numbers& x, ModuleId kept,
                    ModuleId& next_new, KindId* S, double* PA, ModuleId* ID) const {
        copy_kinds(S, em.kinds, em.m);
        if (em.stored) std::memcpy(PA, em.stored, em.stored_n * sizeof(double));
        put_numbers(o, em, x, PA);
        if constexpr (Ids) {
            for (std::uint32_t j = 0; j < em.m; ++j)
                ID[j] = static_cast<int>(j) == em.keep ? kept : next_new++;
        } else {
            next_new += em.fresh;
        }
    }
    // Writes x[from] * mul + add for each of the n holes at hs into PA; returns whether all are
    // certainly finite: their sum is not finite when a number is not (inf - inf and NaN are
    // NaN), or, rarely, when finite numbers overflow it.
    template <typename Numbers>
    static bool put_holes(const RulePlan::ArgHole* hs, std::uint32_t n, const Numbers& x, double* PA) {
        double sum = 0;
        for (std::uint32_t h = 0; h < n; ++h) {
            const double v = x[hs[h].from] * hs[h].mul + hs[h].add;
            sum += v;
            PA[hs[h].to] = v;
        }
        return sum - sum == 0;
    }
    // put_numbers for a module rewritten in place (RulePlan::Emit::moved): only the numbers
    // that change. A number that is not finite is reported by put_numbers, as it would be.
    void put_moved(const PatchOne& one, const double* x, double* PA) const {
        if (!put_holes(one.moved, one.moved_n, x, PA)) [[unlikely]] {
            const std::uint32_t o = one.at + 1;
            put_numbers(o, plan.emits[o], x, PA);
        }
    }
    // put_affine's computed numbers alone, from x (the module's numbers: an array, or its
    // ModuleArgs), into PA; when put_holes cannot vouch for them, the numbers themselves are
    // looked at and the first that is not finite reported.
    template <typename Numbers>
    void put_numbers(std::uint32_t o, const RulePlan::Emit& em, const Numbers& x, double* PA) const {
        const RulePlan::ArgHole* hs = plan.args.data() + em.holes_at;
        if (!put_holes(hs, em.holes_n, x, PA)) [[unlikely]]
            for (std::uint32_t h = 0; h < em.holes_n; ++h)
                if (!std::isfinite(PA[hs[h].to])) hole_error(*plan.outcome_tmpl[o], h, PA[hs[h].to]);
    }

    // Binds the numbers of module i, whose stored ones start at `at`, to the names of pattern
    // module pm (which binds all of them) in w.frame.
    void bind_args(Worker& w, std::size_t i, const double* at, const PatternModule& pm) const {
        const ModuleArgs a = in.args_at(i, at);
        std::size_t from = 0;
        for (const auto& pa : pm.args) {
            for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + static_cast<std::size_t>(k)] = a[from + k];
            from += static_cast<std::size_t>(pa.width);
        }
    }

    // The numbers a template computes (its holes), from the bound frame.
    void compute_holes(Worker& w, const SuccessorTemplate& t, double* values) const {
        if (t.affine.empty()) {
            run(t.values, w.frame.data(), w.env, values);
            return;
        }
        const double* f = w.frame.data();
        for (std::size_t h = 0; h < t.affine.size(); ++h) {
            const auto& a = t.affine[h];
            values[h] = a.kind == a.Copy  ? f[a.slot]
                        : a.kind == a.Mul ? f[a.slot] * a.constant
                                          : f[a.slot] + a.constant;
        }
    }

    // One test for all the numbers: x * 0 is NaN exactly when x is infinite or NaN, and a NaN
    // makes the sum NaN. Only then are they looked at one by one, to name the first.
    void check_holes(const SuccessorTemplate& t, const double* values) const {
        double sum = 0;
        for (std::size_t h = 0; h < t.holes.size(); ++h) sum += values[h] * 0.0;
        if (sum == sum) [[likely]]
            return;
        for (std::size_t h = 0; h < t.holes.size(); ++h)
            if (!std::isfinite(values[h])) hole_error(t, h, values[h]);
    }

    // ---- context matching: the walks every route takes per module (the longer matchers, for
    // several context modules and for the new string, are in context.cpp)

    bool match_in(const ModuleString& s, std::size_t j, const PatternModule& pm, double* frame) const {
        if (s.symbol(j) != pm.sym || s.arity(j) != pm.width) return false;
        const ModuleArgs a = s.args(j);
        std::size_t at = 0;
        for (const auto& pa : pm.args) {
            if (pa.bind) {
                for (int k = 0; k < pa.width; ++k) frame[pa.slot + k] = a[at + k];
            } else if (!std::isnan(pa.value) && a[at] != pa.value) {
                return false;
            }
            at += pa.width;
        }
        return true;
    }

    bool match_module(std::size_t j, const PatternModule& pm, double* frame) const {
        return match_in(in, j, pm, frame);
    }

    // The next module of a left context at or before j: a ']' skips its whole branch, a '['
    // is stepped over to the parent, ignored modules are stepped over. -1 when there is none.
    std::int64_t left_step(std::int64_t j) const {
        while (j >= 0) {
            SymbolId s = in.symbol(static_cast<std::size_t>(j));
            if (s == P.symbols.close_bracket) {
                std::uint32_t m = match[static_cast<std::size_t>(j)];
                if (m >= n) return -1;
                j = static_cast<std::int64_t>(m) - 1;
            } else if (s == P.symbols.open_bracket || P.ignored[s]) {
                --j;
            } else {
                return j;
            }
        }
        return -1;
    }

    // Matches the left context whose last module is at j (as found by left_step).
    bool match_left_from(std::int64_t j, const std::vector<PatternModule>& pats, double* frame) const {
        for (std::size_t k = pats.size(); k-- > 0;) {
            if (j < 0 || !match_module(static_cast<std::size_t>(j), pats[k], frame)) return false;
            if (k > 0) j = left_step(j - 1);
        }
        return true;
    }

    // The next module of a right context at or after j, for a pattern module that is not a
    // bracket: lateral branches are skipped, the end of the branch ends the context. n if none.
    std::size_t right_step(std::size_t j) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        while (j < n) {
            SymbolId s = in.symbol(j);
            if (s == open) {
                if (match[j] >= n) return n;
                j = match[j] + 1;
            } else if (s == close) {
                return n;
            } else if (P.ignored[s]) {
                ++j;
            } else {
                return j;
            }
        }
        return n;
    }

    // context.cpp
    bool match_right(std::size_t e, std::span<const PatternModule> pats, double* frame) const;
    bool match_left_new(const ModuleString& out, const std::vector<PatternModule>& pats, double* frame) const;
    bool match_right_new(const ModuleString& out, const std::vector<PatternModule>& pats,
                         double* frame) const;

    // Pattern, context and condition. Binds the frame.
    bool matches(Worker& w, std::size_t i, const Production& pr) {
        double* frame = w.frame.data();
        for (std::size_t k = 0; k < pr.strict.size(); ++k)
            if (i + k >= n || !match_module(i + k, pr.strict[k], frame)) return false;
        if (!pr.left.empty() || !pr.right.empty()) {
            // the neighbours found by scanning are the same for every production tried at i
            if (w.ctx_at != i) {
                w.ctx_at = i;
                w.ctx_left = kUnknown;
                w.ctx_right = kUnknown;
            }
            if (!pr.left.empty()) {
                if (w.ctx_left == kUnknown) w.ctx_left = left_step(static_cast<std::int64_t>(i) - 1);
                if (!match_left_from(w.ctx_left, pr.left, frame)) return false;
            }
            if (!pr.right.empty()) {
                const std::size_t e = i + pr.strict.size();
                if (pr.strict.size() == 1 && pr.right[0].sym != P.symbols.open_bracket &&
                    pr.right[0].sym != P.symbols.close_bracket) {
                    if (w.ctx_right == kUnknown) w.ctx_right = static_cast<std::int64_t>(right_step(e));
                    if (static_cast<std::size_t>(w.ctx_right) >= n ||
                        !match_module(static_cast<std::size_t>(w.ctx_right), pr.right[0], frame))
                        return false;
                    if (pr.right.size() > 1 &&
                        !match_right(static_cast<std::size_t>(w.ctx_right) + 1,
                                     std::span<const PatternModule>(pr.right).subspan(1), frame))
                        return false;
                } else if (!match_right(e, pr.right, frame)) {
                    return false;
                }
            }
        }
        if (!pr.left_new.empty() && !match_left_new(w.out, pr.left_new, frame)) return false;
        if (!pr.right_new.empty() && !match_right_new(w.out, pr.right_new, frame)) return false;
        if (!pr.condition.empty() && eval_number(pr.condition, frame, w.env) == 0) return false;
        return true;
    }

    std::uint64_t draw_phase = random_phase(0, 0); // see set_draws

    const RulePlan& plan;
    const Program& P;
    const ModuleString& in;
    bool table_kinds = false; // some module of `in` has a kind of constant numbers
    const std::size_t n;
    const bool whole; // see the constructor
    std::vector<std::uint32_t> own_match;
    BigVector<ContextKey>* kernel_scratch = nullptr; // run_symbols's right keys, kept from step to step
    const std::uint32_t* match = nullptr;            // the bracket table (see bracket_table)
    std::vector<std::size_t> piece_starts; // run_backward: where each piece of the new string starts
};

} // namespace plant
