// One rewriting pass over the module string: matching (tree-aware context, new context,
// conditions), stochastic choice, successor templates, the direct path that writes in place.
// Private to derive.cpp, which runs it on one or several threads.
#pragma once

#include "plant/derive.hpp"
#include "plant/random.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <span>

namespace plant {

constexpr std::uint64_t kChoiceDraw = 0xffffffffULL; // draw index of the stochastic choice

// Everything one thread needs to rewrite a stretch of the string.
constexpr std::int64_t kUnknown = -2;

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
    std::vector<std::uint16_t>
        scratch; // Rewriter::run_symbols's keys, when the rewriter has no buffer for them
};

// Whether some production of `rs` names a query module (?P, ?H, ...) in its predecessor or
// context: then the turtle pass runs before each step to fill them.
inline bool reads_queries(const Program& p, const RuleSet& rs) {
    auto named = [&](const std::vector<PatternModule>& v) {
        for (const auto& m : v)
            if (p.symbols[m.sym].query) return true;
        return false;
    };
    for (const auto& pr : rs.productions)
        if (named(pr.strict) || named(pr.left) || named(pr.right)) return true;
    return false;
}

// What rewriting with a list of rule sets needs that does not depend on the string: which
// symbols have productions, which apply at once (direct), the context table. The derivation
// builds it once per list of rule sets and keeps it, not once per step.
struct RulePlan {
    RulePlan(const Program& p, std::vector<const RuleSet*> rule_sets) : P(p), sets(std::move(rule_sets)) {
        std::size_t frame = 1;
        has_prod.assign(P.symbols.size(), 0);
        for (const RuleSet* rs : sets) {
            brackets = brackets || rs->needs_brackets || rs->uses_left_new || rs->uses_right_new;
            for (const auto& pr : rs->productions) {
                frame = std::max<std::size_t>(frame, pr.frame_size);
                has_prod[pr.strict[0].sym] = 1;
                if (pr.strict.size() > 1) multi = true;
            }
            left_new = left_new || rs->uses_left_new;
            right_new = right_new || rs->uses_right_new;
            queries = queries || reads_queries(P, *rs);
        }
        frame_size = frame;
        // A symbol whose first production always applies (no condition, context or weight, one
        // predecessor module whose arguments are all bound) needs no matching: with the right
        // number of parameters, its template is applied at once.
        direct.assign(P.symbols.size(), nullptr);
        for (SymbolId s = 0; s < P.symbols.size(); ++s) {
            for (const RuleSet* rs : sets) {
                if (rs->by_symbol[s].empty()) continue;
                const Production& pr = rs->productions[rs->by_symbol[s][0]];
                bool binds_all = pr.strict.size() == 1;
                for (const auto& a : pr.strict[0].args) binds_all = binds_all && a.bind;
                if (binds_all && pr.condition.empty() && pr.weight.empty() && !pr.has_context() &&
                    !pr.has_new_context() && pr.tmpl.valid)
                    direct[s] = &pr;
                break;
            }
            all_direct = all_direct && (!has_prod[s] || direct[s]);
        }
        if (brackets && !multi && !left_new && !right_new) build_context_table();
        // Whether every symbol with productions is rewritten by a direct template or by the
        // context table: then a step needs no matching beyond a table lookup, and the output of
        // any module is bounded by the longest template (see Rewriter::run_templates).
        templated = !multi && !left_new && !right_new;
        for (SymbolId sym = 0; sym < P.symbols.size() && templated; ++sym) {
            if (!has_prod[sym]) continue;
            if (direct[sym]) {
                max_modules_out = std::max(max_modules_out, direct[sym]->tmpl.syms.size());
                max_params_out = std::max(max_params_out, direct[sym]->tmpl.params.size());
            } else if (!ctx_block.empty() && ctx_block[sym] >= 0) {
                for (const RuleSet* rs : sets)
                    for (std::uint32_t pi : rs->by_symbol[sym]) {
                        max_modules_out = std::max(max_modules_out, rs->productions[pi].tmpl.syms.size());
                        max_params_out = std::max(max_params_out, rs->productions[pi].tmpl.params.size());
                    }
            } else {
                templated = false;
            }
        }
        if (templated && max_params_out == 0 && max_modules_out <= SymbolSucc::kMax && !ctx_block.empty())
            build_symbol_kernel();
    }

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
        std::uint32_t block = 0;           // its successors start at succ_at[block]
        std::uint8_t lmask = 0, rmask = 0; // 0xff: the block is indexed by that neighbour's key
        std::uint8_t shape = 0;
        std::uint8_t key = 0; // ctx_key
    };
    bool symbol_kernel = false; // Rewriter::run_symbols can rewrite strings without parameters
    std::vector<SymbolRow> sym_rows;
    std::vector<std::uint32_t> succ_at; // blocks of indices into succs
    std::vector<SymbolSucc> succs;

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
    bool all_direct = true; // every symbol with productions has a direct template
    // Whether a step must rewrite on one thread, left to right (or right to left for `>>`).
    bool sequential() const { return multi || left_new || right_new; }
    std::size_t max_modules_out = 1; // the longest template's modules (at least 1: a copy)
    std::size_t max_params_out = 0;  // and the most parameters a template holds

  private:
    // The symbol kernel's tables. It needs every rewritten symbol to be parameterless: a direct
    // template whose pattern takes no parameters, or a context table.
    void build_symbol_kernel() {
        const std::size_t S = P.symbols.size(), K = ctx_keys;
        for (SymbolId sym = 0; sym < S; ++sym)
            if (has_prod[sym] && direct[sym] && direct[sym]->strict[0].width != 0)
                return; // a pattern with parameters
        auto add = [&](const SuccessorTemplate& t) {
            SymbolSucc su;
            std::copy(t.syms.begin(), t.syms.end(), su.syms);
            su.len = static_cast<std::uint32_t>(t.syms.size());
            su.fresh = su.len - (t.keep >= 0 ? 1 : 0);
            succs.push_back(su);
            return static_cast<std::uint32_t>(succs.size() - 1);
        };
        std::vector<std::pair<const Production*, std::uint32_t>> seen; // each production once
        auto add_production = [&](const Production& pr) {
            for (const auto& [q, at] : seen)
                if (q == &pr) return at;
            seen.emplace_back(&pr, add(pr.tmpl));
            return seen.back().second;
        };
        sym_rows.assign(S, SymbolRow{});
        for (SymbolId sym = 0; sym < S; ++sym) {
            SymbolRow& row = sym_rows[sym];
            row.shape = sym == P.symbols.close_bracket  ? kClose
                        : sym == P.symbols.open_bracket ? kOpen
                        : P.ignored[sym]                ? kIgnored
                                                        : 0;
            row.key = ctx_key[sym];
            row.block = static_cast<std::uint32_t>(succ_at.size());
            SymbolSucc self;
            self.syms[0] = sym;
            self.len = 1;
            if (!has_prod[sym]) {
                succs.push_back(self);
                succ_at.push_back(static_cast<std::uint32_t>(succs.size() - 1));
            } else if (direct[sym]) {
                succ_at.push_back(add_production(*direct[sym]));
            } else { // templated: the context table has it
                succs.push_back(self);
                const auto self_at = static_cast<std::uint32_t>(succs.size() - 1);
                row.lmask = ctx_sides[sym] & 1 ? 0xff : 0;
                row.rmask = ctx_sides[sym] & 2 ? 0xff : 0;
                for (std::size_t k = 0; k < K * K; ++k) {
                    const Production* pr = ctx_entries[static_cast<std::size_t>(ctx_block[sym]) + k];
                    succ_at.push_back(pr ? add_production(*pr) : self_at);
                }
            }
        }
        symbol_kernel = true;
    }

    // The context table. When every production of a symbol is `l < s > r -> successor` with
    // modules that carry no parameters, at most one context module a side and no condition,
    // weight or new context (ABOP's Fig. 1.31 and other signal-propagation systems), which
    // production applies depends only on the symbols of the two neighbours. A K x K table per
    // such symbol, K being the number of symbols the patterns name plus one for all others,
    // answers that with one lookup instead of trying the productions in turn.
    void build_context_table() {
        const std::size_t S = P.symbols.size();
        ctx_block.assign(S, -1);
        ctx_sides.assign(S, 0);
        ctx_key.assign(S, 0);
        std::vector<std::vector<const Production*>> cands(S);
        auto plain = [&](const PatternModule& m) {
            return m.width == 0 && m.args.empty() && m.sym != P.symbols.open_bracket &&
                   m.sym != P.symbols.close_bracket;
        };
        std::vector<SymbolId> eligible;
        for (SymbolId sym = 0; sym < S; ++sym) {
            if (!has_prod[sym] || direct[sym]) continue;
            bool ok = true;
            for (const RuleSet* rs : sets)
                for (std::uint32_t pi : rs->by_symbol[sym]) {
                    const Production& pr = rs->productions[pi];
                    ok = ok && pr.strict.size() == 1 && plain(pr.strict[0]) && pr.left.size() <= 1 &&
                         pr.right.size() <= 1 && (pr.left.empty() || plain(pr.left[0])) &&
                         (pr.right.empty() || plain(pr.right[0])) && pr.condition.empty() &&
                         pr.weight.empty() && !pr.has_new_context() && pr.tmpl.valid;
                    cands[sym].push_back(&pr);
                }
            if (!ok) continue;
            eligible.push_back(sym);
            for (const Production* pr : cands[sym]) {
                for (const auto* side : {&pr->left, &pr->right})
                    if (!side->empty() && ctx_key[(*side)[0].sym] == 0) {
                        if (ctx_keys == 255) return; // too many to tabulate: the general path it is
                        ctx_key[(*side)[0].sym] = static_cast<std::uint8_t>(ctx_keys++);
                    }
                if (!pr->left.empty()) ctx_sides[sym] |= 1;
                if (!pr->right.empty()) ctx_sides[sym] |= 2;
            }
        }
        const std::size_t K = ctx_keys;
        for (SymbolId sym : eligible) {
            ctx_block[sym] = static_cast<std::int32_t>(ctx_entries.size());
            for (std::size_t lk = 0; lk < K; ++lk)
                for (std::size_t rk = 0; rk < K; ++rk) {
                    const Production* hit = nullptr;
                    for (const Production* pr : cands[sym]) {
                        bool l = pr->left.empty() || (lk != 0 && ctx_key[pr->left[0].sym] == lk);
                        bool r = pr->right.empty() || (rk != 0 && ctx_key[pr->right[0].sym] == rk);
                        if (l && r) {
                            hit = pr;
                            break;
                        }
                    }
                    ctx_entries.push_back(hit);
                }
        }
    }
};

class Rewriter {
  public:
    // `brackets`: where to build the bracket table (a buffer kept from step to step saves an
    // allocation each step); null: a buffer of the rewriter's own.
    // `whole`: run_range will be called once, for the whole string, by one thread. Then the
    // symbol kernel needs no bracket table, and keeps its right keys in `scratch`.
    Rewriter(const RulePlan& rule_plan, const ModuleString& in,
             std::vector<std::uint32_t>* brackets = nullptr, std::vector<std::uint16_t>* scratch = nullptr,
             bool whole = false)
        : plan(rule_plan), P(rule_plan.P), in(in), n(in.size()), kernel_scratch(whole ? scratch : nullptr) {
        if (whole && kernel_applies()) return;
        if (plan.brackets) {
            std::vector<std::uint32_t>& table = brackets ? *brackets : own_match;
            bracket_table(in, P.symbols.open_bracket, P.symbols.close_bracket, table);
            match = table.data();
        }
    }

    // The production the context table gives for module i, which has a table and no parameters.
    // nullptr: none applies.
    const Production* table_lookup(std::size_t i) const {
        const SymbolId sym = in.sym[i];
        std::size_t lk = 0, rk = 0;
        if (plan.ctx_sides[sym] & 1) {
            const std::int64_t j = left_step(static_cast<std::int64_t>(i) - 1);
            if (j >= 0 && in.arity(static_cast<std::size_t>(j)) == 0)
                lk = plan.ctx_key[in.sym[static_cast<std::size_t>(j)]];
        }
        if (plan.ctx_sides[sym] & 2) {
            const std::size_t j = right_step(i + 1);
            if (j < n && in.arity(j) == 0) rk = plan.ctx_key[in.sym[j]];
        }
        return plan.ctx_entries[static_cast<std::size_t>(plan.ctx_block[sym]) + lk * plan.ctx_keys + rk];
    }

    // Whether run_range rewrites this string with the symbol kernel (run_symbols).
    bool kernel_applies() const { return plan.symbol_kernel && in.params.empty() && !in.keep_ids; }

    // Whether production `pr` (pattern, context and condition) matches at module i: the REPL's
    // :find. Binds the worker's frame.
    bool matches_at(Worker& w, std::size_t i, const Production& pr) {
        if (w.frame.size() < plan.frame_size) w.frame.assign(plan.frame_size, 0.0);
        w.env.position = i;
        w.env.draw = 0;
        w.env.id = in.id(i);
        return matches(w, i, pr);
    }

    // ---- the direct path: every module is copied or rewritten by a direct template ----------
    // Then the size of the output of any stretch is known before writing it, so the output is
    // allocated once, exactly, and each thread writes its stretch in place.
    struct Counts {
        std::size_t modules = 0, params = 0;
        ModuleId new_ids = 0;
        bool ok = true;
    };

    Counts count_direct(std::size_t b, std::size_t e) const {
        Counts c;
        for (std::size_t i = b; i < e; ++i) {
            const SymbolId s = in.sym[i];
            if (!plan.has_prod[s]) {
                ++c.modules;
                c.params += in.arity(i);
                continue;
            }
            const Production* pr = plan.direct[s];
            if (!pr || in.arity(i) != pr->strict[0].width) {
                c.ok = false;
                return c;
            }
            c.modules += pr->tmpl.syms.size();
            c.params += pr->tmpl.params.size();
            c.new_ids += pr->tmpl.syms.size() - (pr->tmpl.keep >= 0 ? 1 : 0);
        }
        return c;
    }

    // Writes the output of modules [b, e) at module m_at and parameter p_at of `out`, whose
    // arrays are already sized; new identities are numbered from id_at.
    // Identities are written only when `out` keeps them (Ids, a template argument so that the
    // loop has no test for it).
    void write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out, std::size_t m_at,
                      std::size_t p_at, ModuleId id_at) {
        if (out.keep_ids)
            write_direct<true>(w, b, e, out, m_at, p_at, id_at);
        else
            write_direct<false>(w, b, e, out, m_at, p_at, id_at);
    }
    template <bool Ids>
    void write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out, std::size_t m_at,
                      std::size_t p_at, ModuleId id_at) {
        w.frame.assign(plan.frame_size, 0.0);
        SymbolId* S = out.sym.data() + m_at;
        ModuleId* ID = Ids ? out.ids.data() + m_at : nullptr;
        std::uint32_t* PO = out.poff.data() + m_at + 1; // poff[m_at] is the previous stretch's end
        double* PA = out.params.data() + p_at;
        std::size_t p = p_at;
        double values[256];
        std::size_t i = b;
        std::size_t next_check = b + 65536;
        while (i < e) {
            if (i >= next_check) { // a long step can be interrupted (Ctrl-C in the REPL)
                next_check = i + 65536;
                if (w.env.interrupt && w.env.interrupt->load()) throw RuntimeError{Span{}, "interrupted"};
            }
            if (!plan.has_prod[in.sym[i]]) { // a run of modules without productions: copy it
                std::size_t j = i + 1;
                while (j < e && !plan.has_prod[in.sym[j]]) ++j;
                const std::size_t n = j - i;
                const std::uint32_t pb = in.poff[i], pe = in.poff[j];
                const auto shift = static_cast<std::uint32_t>(p - pb); // wraps around on purpose
                if (n <= 8 && pe - pb <= 8) {
                    // the usual run between two rewritten modules is a few turtle symbols: plain
                    // loops beat three library calls
                    for (std::size_t k = 0; k < n; ++k) {
                        S[k] = in.sym[i + k];
                        if constexpr (Ids) ID[k] = in.ids[i + k];
                        PO[k] = in.poff[i + 1 + k] + shift;
                    }
                    for (std::uint32_t k = 0; k < pe - pb; ++k) PA[k] = in.params[pb + k];
                } else {
                    std::memcpy(S, in.sym.data() + i, n * sizeof(SymbolId));
                    if constexpr (Ids) std::memcpy(ID, in.ids.data() + i, n * sizeof(ModuleId));
                    if (pe > pb) std::memcpy(PA, in.params.data() + pb, (pe - pb) * sizeof(double));
                    for (std::size_t k = 0; k < n; ++k) PO[k] = in.poff[i + 1 + k] + shift;
                }
                S += n;
                if constexpr (Ids) ID += n;
                PO += n;
                PA += pe - pb;
                p += pe - pb;
                i = j;
                continue;
            }
            const Production& pr = *plan.direct[in.sym[i]];
            const SuccessorTemplate& t = pr.tmpl;
            if (!t.holes.empty()) {
                const double* a = in.args(i);
                for (const auto& pa : pr.strict[0].args) {
                    for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + k] = a[k];
                    a += pa.width;
                }
                w.env.position = i;
                w.env.draw = 0;
                w.env.id = in.id(i);
                w.env.out = nullptr;
                compute_holes(w, t, values);
                check_holes(t, values);
            }
            const std::size_t m = t.syms.size();
            put_template<Ids>(t, values, p, Ids ? in.ids[i] : 0, id_at, S, PO, PA, ID);
            if constexpr (Ids) ID += m;
            S += m;
            PO += m;
            PA += t.params.size();
            p += t.params.size();
            ++i;
        }
    }

    // Writes successor template t, its computed numbers in `values`, at S, PO, PA and ID, its
    // parameters starting at parameter p of the output. Module t.keep gets the identity `kept`
    // (the predecessor's), the others new ones counted on from `next_new`. Identities are
    // written only when Ids.
    template <bool Ids>
    static void put_template(const SuccessorTemplate& t, const double* values, std::size_t p, ModuleId kept,
                             ModuleId& next_new, SymbolId* S, std::uint32_t* PO, double* PA, ModuleId* ID) {
        const std::size_t m = t.syms.size();
        if (m != 0) std::memcpy(S, t.syms.data(), m * sizeof(SymbolId));
        // An erasing or parameterless successor has no parameter storage;
        // memcpy with a null source is undefined even for zero bytes.
        if (!t.params.empty()) std::memcpy(PA, t.params.data(), t.params.size() * sizeof(double));
        for (std::size_t h = 0; h < t.holes.size(); ++h) PA[t.holes[h]] = values[h];
        const auto p32 = static_cast<std::uint32_t>(p);
        for (std::size_t j = 0; j < m; ++j) PO[j] = p32 + t.param_end[j];
        if constexpr (Ids) {
            for (std::size_t j = 0; j < m; ++j) ID[j] = static_cast<int>(j) == t.keep ? kept : next_new++;
        } else {
            next_new += m - (t.keep >= 0 ? 1 : 0);
        }
    }

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

    void check_holes(const SuccessorTemplate& t, const double* values) const {
        for (std::size_t h = 0; h < t.holes.size(); ++h) {
            if (std::isfinite(values[h])) continue;
            std::size_t j = 0;
            while (t.param_end[j] <= t.holes[h]) ++j;
            std::uint32_t k = t.holes[h] - (j ? t.param_end[j - 1] : 0);
            throw RuntimeError{t.hole_spans[h],
                               fmt::format("parameter {} of '{}' is {}", k + 1, P.symbols[t.syms[j]].name,
                                           std::isnan(values[h]) ? "NaN" : "infinite")};
        }
    }

    // Rewrites modules [b, e) into w.out.
    void run_range(Worker& w, std::size_t b, std::size_t e) {
        if (kernel_applies()) {
            if (match)
                run_symbols<false>(w, b, e);
            else
                run_symbols<true>(w, b, e); // the whole string, with no bracket table
            return;
        }
        if (plan.templated) {
            if (w.out.keep_ids)
                run_templates<true>(w, b, e);
            else
                run_templates<false>(w, b, e);
            return;
        }
        w.frame.assign(plan.frame_size, 0.0);
        std::size_t i = b;
        while (i < e) {
            if (!plan.has_prod[in.sym[i]]) {
                std::size_t j = i + 1;
                while (j < e && !plan.has_prod[in.sym[j]]) ++j;
                w.out.append_range(in, i, j);
                i = j;
                if (w.out.size() > w.env.max_output || w.out.params.size() > w.env.max_params) limit_error(w);
                continue;
            }
            if (const Production* pr = plan.direct[in.sym[i]]; pr && in.arity(i) == pr->strict[0].width) {
                if (!pr->tmpl.holes.empty()) {
                    const double* a = in.args(i);
                    for (const auto& pa : pr->strict[0].args) {
                        for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + k] = a[k];
                        a += pa.width;
                    }
                    w.env.position = i;
                    w.env.draw = 0;
                    w.env.id = in.id(i);
                }
                apply_template(w, i, *pr);
                ++i;
                continue;
            }
            if (!plan.ctx_block.empty() && plan.ctx_block[in.sym[i]] >= 0 && in.arity(i) == 0) {
                if (const Production* pr = table_lookup(i)) {
                    w.env.position = i;
                    w.env.draw = 0;
                    w.env.id = in.id(i);
                    apply_template(w, i, *pr);
                } else {
                    w.out.append_range(in, i, i + 1);
                }
                ++i;
                continue;
            }
            std::size_t used = apply(w, i);
            if (used == 0) {
                w.out.append_range(in, i, i + 1);
                used = 1;
            }
            i += used;
        }
    }

    // run_range for a templated plan (every rewritten symbol has a direct template or a context
    // table). The output is written through plain pointers into arrays opened up to their
    // capacity (which the derivation reserved from the last step's growth), checked once per
    // module against the longest template, and cut to what was written at the end. A module that
    // needs matching after all (its parameter count differs from the pattern's) goes through
    // apply() with the arrays at their true size.
    template <bool Ids> void run_templates(Worker& w, std::size_t b, std::size_t e) {
        w.frame.assign(plan.frame_size, 0.0);
        ModuleString& out = w.out;
        EvalEnv& env = w.env;
        const std::size_t Mmax = plan.max_modules_out, Pmax = plan.max_params_out;
        double values[256];
        std::size_t m = out.size(), p = out.params.size();
        std::size_t mcap = 0, pcap = 0;
        SymbolId* S = nullptr;
        std::uint32_t* PO = nullptr; // PO[m]: where module m's parameters end
        double* PA = nullptr;
        ModuleId* ID = nullptr;
        auto open = [&](std::size_t need_m, std::size_t need_p) {
            mcap = std::max({out.sym.capacity(), need_m, 2 * m});
            pcap = std::max({out.params.capacity(), need_p, 2 * p});
            out.sym.resize(mcap);
            if constexpr (Ids) out.ids.resize(mcap);
            out.poff.resize(mcap + 1);
            out.params.resize(pcap);
            S = out.sym.data();
            PO = out.poff.data() + 1;
            PA = out.params.data();
            if constexpr (Ids) ID = out.ids.data();
        };
        auto close = [&] {
            out.sym.resize(m);
            if constexpr (Ids) out.ids.resize(m);
            out.poff.resize(m + 1);
            out.params.resize(p);
        };
        // The room left is checked for a run of modules at a time rather than per module: a
        // module writes at most `per_module` modules and, copied, its own parameters or,
        // rewritten, at most Pmax, so the next k modules fit in `per_module` k modules and their
        // own parameters plus Pmax k. A run is as long as the room opened lets it be (the arrays
        // grow only when not even one module fits), and it ends at `next_check`, where the
        // interrupt and the limits are looked at too.
        const std::size_t per_module = std::max<std::size_t>(Mmax, 1);
        std::size_t next_limits = b + 65536, next_check = b;
        std::size_t i = b;
        auto run_length = [&] {
            std::size_t k = std::min({e - i, next_limits - i, std::size_t{4096}, (mcap - m) / per_module});
            while (k > 0 && p + (in.poff[i + k] - in.poff[i]) + Pmax * k > pcap) k /= 2;
            return k;
        };
        open(m + per_module, p + Pmax);
        while (i < e) {
            if (i >= next_check) {
                if (i >= next_limits) {
                    next_limits = i + 65536;
                    if (env.interrupt && env.interrupt->load()) throw RuntimeError{Span{}, "interrupted"};
                    if (m > env.max_output || p > env.max_params) {
                        close();
                        limit_error(w);
                    }
                }
                std::size_t k = run_length();
                if (k == 0) {
                    open(m + per_module, p + (in.poff[i + 1] - in.poff[i]) + Pmax);
                    k = run_length(); // at least 1 now
                }
                next_check = i + k;
            }
            const SymbolId sym = in.sym[i];
            const std::uint32_t arity = in.poff[i + 1] - in.poff[i];
            const Production* pr = nullptr;
            if (plan.has_prod[sym]) {
                pr = plan.direct[sym];
                if (pr && arity == pr->strict[0].width) {
                    if (!pr->tmpl.holes.empty()) {
                        const double* a = in.params.data() + in.poff[i];
                        for (const auto& pa : pr->strict[0].args) {
                            for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + k] = a[k];
                            a += pa.width;
                        }
                    }
                } else if (!pr && arity == 0) {
                    pr = table_lookup(i); // nullptr: no production applies, the module is copied
                } else {                  // matching after all, with the arrays at their true size
                    close();
                    std::size_t used = apply(w, i);
                    if (used == 0) {
                        out.append_range(in, i, i + 1);
                        used = 1;
                    }
                    i += used;
                    m = out.size();
                    p = out.params.size();
                    open(m + per_module, p + Pmax);
                    next_check = i; // room is made again from here
                    continue;
                }
            }
            if (!pr) { // copied as it is
                S[m] = sym;
                if constexpr (Ids) ID[m] = in.ids[i];
                for (std::uint32_t k = in.poff[i]; k < in.poff[i + 1]; ++k) PA[p++] = in.params[k];
                PO[m] = static_cast<std::uint32_t>(p);
                ++m;
                ++i;
                continue;
            }
            const SuccessorTemplate& t = pr->tmpl;
            if (!t.holes.empty()) {
                env.position = i;
                env.draw = 0;
                env.id = Ids ? in.ids[i] : 0;
                env.out = nullptr;
                compute_holes(w, t, values);
                check_holes(t, values);
            }
            ModuleId next_new = env.id_base + env.new_count;
            put_template<Ids>(t, values, p, Ids ? in.ids[i] : 0, next_new, S + m, PO + m, PA + p,
                              Ids ? ID + m : nullptr);
            env.new_count = next_new - env.id_base;
            m += t.syms.size();
            p += t.params.size();
            ++i;
        }
        close();
        if (out.size() > env.max_output || out.params.size() > env.max_params) limit_error(w);
    }

    // run_range for strings without parameters or identities under a plan with a symbol kernel
    // (parameterless context-sensitive systems such as ABOP's Fig. 1.31). A module's successor
    // comes from its symbol's block: itself, its direct template, or the context table's entry
    // for its neighbours' keys; it is written as one fixed-size copy of padded symbols, and
    // parameter offsets are all zero. Neighbours are carried along rather than searched for:
    // - the left key: the key of the last module context sees, saved at each '[' and taken back
    //   at its ']' (left_step settles a ']' whose '[' lies before b);
    // - over the whole string (Whole), the right keys come from one right-to-left pass that does
    //   the same mirrored, and there is no bracket table; on a stretch, right_step finds them.
    template <bool Whole> void run_symbols(Worker& w, std::size_t b, std::size_t e) {
        using Plan = RulePlan;
        ModuleString& out = w.out;
        EvalEnv& env = w.env;
        const SymbolId* in_sym = in.sym.data();
        const Plan::SymbolRow* rows = plan.sym_rows.data();
        const std::uint32_t* succ_at = plan.succ_at.data();
        const Plan::SymbolSucc* succs = plan.succs.data();
        const std::size_t K = plan.ctx_keys;
        const std::size_t Mmax = plan.max_modules_out;
        constexpr std::size_t kPad = Plan::SymbolSucc::kMax;
        auto key_of = [&](std::int64_t j) -> std::size_t { return j < 0 ? 0 : rows[in_sym[j]].key; };

        // The right-to-left pass: the key of the last module context sees, saved at each ']'
        // and taken back at its '[' (going leftwards, a branch is entered at its ']'). A bracket
        // without a partner has none.
        // Both passes keep their saved keys on `stack`, which is as deep as the stretch is long.
        const std::uint16_t* rkey = nullptr;
        std::uint16_t* stack = nullptr;
        if constexpr (Whole) {
            std::vector<std::uint16_t>& scratch = kernel_scratch ? *kernel_scratch : w.scratch;
            scratch.resize(2 * n + 1);
            std::uint16_t* keys = scratch.data();
            stack = keys + n;
            std::uint16_t right = 0;
            std::size_t depth = 0;
            for (std::size_t j = n; j-- > 0;) {
                const Plan::SymbolRow r = rows[in_sym[j]];
                keys[j] = right;
                if (r.shape == 0) {
                    right = r.key;
                } else if (r.shape == Plan::kClose) {
                    stack[depth++] = right;
                    right = 0;
                } else if (r.shape == Plan::kOpen) {
                    right = depth ? stack[--depth] : 0;
                }
            }
            rkey = keys;
        } else {
            w.scratch.resize(e - b + 1);
            stack = w.scratch.data();
        }

        const std::size_t p_end = out.params.size(); // every module written here has none
        std::size_t m = out.size();
        std::size_t left = b > 0 ? key_of(left_step(static_cast<std::int64_t>(b) - 1)) : 0;
        std::size_t depth = 0; // the left keys at the open '['s are on the stack
        std::uint64_t fresh = 0;
        std::size_t i = b, next_check = b + 65536;
        out.sym.resize(std::max(out.sym.capacity(), m)); // the room reserved is written in place
        while (i < e) {
            // the modules that fit: each writes at most Mmax, and a copy writes kPad
            std::size_t room = out.sym.size() >= m + kPad ? (out.sym.size() - m - kPad) / Mmax : 0;
            if (room == 0) {
                out.sym.resize(std::max(m + Mmax + kPad, 2 * out.sym.size()));
                continue;
            }
            if (i >= next_check) {
                next_check = i + 65536;
                if (env.interrupt && env.interrupt->load()) throw RuntimeError{Span{}, "interrupted"};
                if (m > env.max_output) {
                    out.sym.resize(m);
                    limit_error(w);
                }
            }
            const std::size_t stop = std::min({e, i + room, next_check});
            SymbolId* S = out.sym.data();
            for (; i < stop; ++i) {
                const Plan::SymbolRow row = rows[in_sym[i]];
                std::size_t at = row.block;
                if constexpr (Whole) {
                    at += (left & row.lmask) * K + (rkey[i] & row.rmask);
                } else if (row.lmask | row.rmask) {
                    const std::size_t j = row.rmask ? right_step(i + 1) : n;
                    at += (left & row.lmask) * K + (j < n ? rows[in_sym[j]].key : 0);
                }
                const Plan::SymbolSucc& su = succs[succ_at[at]];
                std::memcpy(S + m, su.syms, sizeof su.syms);
                m += su.len;
                fresh += su.fresh;
                if (row.shape == 0) {
                    left = row.key;
                } else if (row.shape == Plan::kOpen) {
                    stack[depth++] = static_cast<std::uint16_t>(left);
                } else if (row.shape == Plan::kClose) {
                    if (depth == 0) // a branch opened before b, or never
                        left = Whole ? 0 : key_of(left_step(static_cast<std::int64_t>(i)));
                    else
                        left = stack[--depth];
                }
            }
        }
        if (m > env.max_output) {
            out.sym.resize(m);
            limit_error(w);
        }
        out.sym.resize(m);
        const std::size_t m0 = out.poff.size();
        out.poff.resize(m + 1);
        std::fill(out.poff.begin() + static_cast<std::ptrdiff_t>(m0), out.poff.end(),
                  static_cast<std::uint32_t>(p_end));
        env.new_count += static_cast<ModuleId>(fresh);
    }

    // Backward processing for `>>`: modules right to left; each successor becomes a piece and
    // the new string to the right is the pieces made so far, newest first.
    void run_backward(Worker& w) {
        w.frame.assign(plan.frame_size, 0.0);
        piece_starts.clear();
        // Going right to left, a predecessor is found by its last module.
        std::vector<std::vector<std::pair<std::size_t, std::size_t>>> by_last(P.symbols.size());
        for (std::size_t si = 0; si < plan.sets.size(); ++si)
            for (std::size_t pi = 0; pi < plan.sets[si]->productions.size(); ++pi)
                by_last[plan.sets[si]->productions[pi].strict.back().sym].emplace_back(si, pi);
        std::size_t k = n;
        while (k-- > 0) {
            piece_starts.push_back(w.out.size());
            std::size_t used = 0;
            for (const auto& [si, pi] : by_last[in.sym[k]]) {
                const Production& pr = plan.sets[si]->productions[pi];
                const std::size_t len = pr.strict.size();
                if (len > k + 1) continue;
                const std::size_t start = k + 1 - len;
                w.env.position = start;
                w.env.draw = 0;
                w.env.id = in.id(start);
                if (!matches(w, start, pr)) continue;
                if (!pr.weight.empty()) {
                    const auto& cands = plan.sets[si]->by_symbol[pr.strict[0].sym];
                    std::size_t ci = 0;
                    while (ci < cands.size() && cands[ci] != pi) ++ci;
                    used = choose(w, start, si, ci, len); // only predecessors that end at k
                } else {
                    used = run_body(w, start, pr);
                }
                if (used) break;
            }
            if (used == 0) {
                w.out.append_range(in, k, k + 1);
            } else {
                k -= used - 1; // the predecessor's other modules are consumed too
            }
        }
        piece_starts.push_back(w.out.size());
    }

    ModuleString assemble_backward(const ModuleString& pieces) const {
        ModuleString out;
        out.keep_ids = pieces.keep_ids;
        for (std::size_t p = piece_starts.size() - 1; p-- > 0;)
            out.append_range(pieces, piece_starts[p], piece_starts[p + 1]);
        return out;
    }

  private:
    [[noreturn]] void limit_error(Worker& w) const {
        (void)w;
        throw RuntimeError{Span{}, "module limit"};
    }

    bool match_module(std::size_t j, const PatternModule& pm, double* frame) const {
        return match_in(in, j, pm, frame);
    }

    // The next module of a left context at or before j: a ']' skips its whole branch, a '['
    // is stepped over to the parent, ignored modules are stepped over. -1 when there is none.
    std::int64_t left_step(std::int64_t j) const {
        while (j >= 0) {
            SymbolId s = in.sym[static_cast<std::size_t>(j)];
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
            SymbolId s = in.sym[j];
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

    bool match_right(std::size_t e, std::span<const PatternModule> pats, double* frame) const {
        std::size_t j = e;
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        for (const auto& p : pats) {
            if (p.sym == open) {
                while (j < n && P.ignored[in.sym[j]]) ++j;
                if (j >= n || in.sym[j] != open) return false;
                ++j;
                continue;
            }
            if (p.sym == close) { // skip the rest of the current branch
                while (j < n && in.sym[j] != close) {
                    if (in.sym[j] == open) {
                        if (match[j] >= n) return false;
                        j = match[j] + 1;
                    } else {
                        ++j;
                    }
                }
                if (j >= n) return false;
                ++j;
                continue;
            }
            j = right_step(j);
            if (j >= n || !match_module(j, p, frame)) return false;
            ++j;
        }
        return true;
    }

    // Left context in the new string (forward processing): the output made so far.
    bool match_left_new(const ModuleString& out, const std::vector<PatternModule>& pats,
                        double* frame) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        auto j = static_cast<std::int64_t>(out.size()) - 1;
        for (std::size_t k = pats.size(); k-- > 0;) {
            for (;;) {
                if (j < 0) return false;
                SymbolId s = out.sym[static_cast<std::size_t>(j)];
                if (s == close) { // skip the whole preceding branch
                    int depth = 0;
                    for (; j >= 0; --j) {
                        SymbolId t = out.sym[static_cast<std::size_t>(j)];
                        if (t == close)
                            ++depth;
                        else if (t == open && --depth == 0)
                            break;
                    }
                    if (j < 0) return false;
                    --j;
                } else if (s == open || P.ignored[s]) {
                    --j;
                } else {
                    break;
                }
            }
            if (!match_in(out, static_cast<std::size_t>(j), pats[k], frame)) return false;
            --j;
        }
        return true;
    }

    // Walks the new string to the right of the module being rewritten in backward processing:
    // the pieces made so far, the newest (the right neighbour's successor) first.
    struct PieceIter {
        const std::vector<std::size_t>& ps;
        std::size_t p = 0, i = 0;
        bool valid = false;
        explicit PieceIter(const std::vector<std::size_t>& starts) : ps(starts) {
            if (ps.size() >= 2) {
                p = ps.size() - 2;
                i = ps[p];
                valid = true;
                normalize();
            }
        }
        void normalize() {
            while (valid && i >= ps[p + 1]) {
                if (p == 0) {
                    valid = false;
                    break;
                }
                --p;
                i = ps[p];
            }
        }
        void next() {
            ++i;
            normalize();
        }
    };

    bool match_right_new(const ModuleString& out, const std::vector<PatternModule>& pats,
                         double* frame) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        PieceIter it(piece_starts);
        for (const auto& pat : pats) {
            for (;;) {
                if (!it.valid) return false;
                SymbolId s = out.sym[it.i];
                if (s == open && pat.sym != open) { // skip the lateral branch
                    int depth = 0;
                    for (; it.valid; it.next()) {
                        SymbolId t = out.sym[it.i];
                        if (t == open)
                            ++depth;
                        else if (t == close && --depth == 0)
                            break;
                    }
                    if (!it.valid) return false;
                    it.next();
                } else if (s == close && pat.sym != close) {
                    return false;
                } else if (s != open && s != close && P.ignored[s]) {
                    it.next();
                } else {
                    break;
                }
            }
            if (!match_in(out, it.i, pat, frame)) return false;
            it.next();
        }
        return true;
    }

    bool match_in(const ModuleString& s, std::size_t j, const PatternModule& pm, double* frame) const {
        if (s.sym[j] != pm.sym || s.arity(j) != pm.width) return false;
        const double* a = s.args(j);
        for (const auto& pa : pm.args) {
            if (pa.bind) {
                for (int k = 0; k < pa.width; ++k) frame[pa.slot + k] = a[k];
            } else if (!std::isnan(pa.value) && a[0] != pa.value) {
                return false;
            }
            a += pa.width;
        }
        return true;
    }

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

    // Tries the productions for module i; returns the number of modules consumed (0: none applied).
    std::size_t apply(Worker& w, std::size_t i) {
        EvalEnv& env = w.env;
        env.position = i;
        env.draw = 0;
        env.id = in.id(i);
        const SymbolId sym = in.sym[i];
        for (std::size_t si = 0; si < plan.sets.size(); ++si) {
            const RuleSet& rs = *plan.sets[si];
            const auto& cands = rs.by_symbol[sym];
            for (std::size_t ci = 0; ci < cands.size(); ++ci) {
                const Production& pr = rs.productions[cands[ci]];
                if (!matches(w, i, pr)) continue;
                if (!pr.weight.empty()) return choose(w, i, si, ci);
                if (std::size_t used = run_body(w, i, pr)) return used;
            }
        }
        return 0;
    }

    // The fast path of run_body for arrow-form successors (see SuccessorTemplate).
    std::size_t apply_template(Worker& w, std::size_t i, const Production& pr) {
        const SuccessorTemplate& t = pr.tmpl;
        ModuleString& out = w.out;
        EvalEnv& env = w.env;
        double values[256];
        if (!t.holes.empty()) {
            env.out = nullptr;
            compute_holes(w, t, values);
            check_holes(t, values);
        }
        const std::size_t m = t.syms.size();
        if (m <= 4 && t.holes.empty()) { // short constant successors: plain appends
            for (std::size_t j = 0; j < m; ++j) {
                out.sym.push_back(t.syms[j]);
                for (std::uint32_t k = j ? t.param_end[j - 1] : 0; k < t.param_end[j]; ++k)
                    out.params.push_back(t.params[k]);
                out.poff.push_back(static_cast<std::uint32_t>(out.params.size()));
                const ModuleId id = static_cast<int>(j) == t.keep ? in.id(i) : env.id_base + env.new_count++;
                if (out.keep_ids) out.ids.push_back(id);
            }
            if (out.size() > env.max_output) throw RuntimeError{Span{}, "module limit"};
            return 1;
        }
        const std::size_t m0 = out.sym.size();
        const std::size_t p0 = out.params.size();
        out.sym.resize(m0 + m);
        if (out.keep_ids) out.ids.resize(m0 + m);
        out.poff.resize(m0 + m + 1);
        out.params.resize(p0 + t.params.size());
        std::copy(t.syms.begin(), t.syms.end(), out.sym.begin() + static_cast<std::ptrdiff_t>(m0));
        double* pp = out.params.data() + p0;
        std::copy(t.params.begin(), t.params.end(), pp);
        for (std::size_t h = 0; h < t.holes.size(); ++h) pp[t.holes[h]] = values[h];
        std::uint32_t* po = out.poff.data() + m0 + 1;
        const auto base = static_cast<std::uint32_t>(p0);
        for (std::size_t j = 0; j < m; ++j) po[j] = base + t.param_end[j];
        if (out.keep_ids) {
            ModuleId* ids = out.ids.data() + m0;
            for (std::size_t j = 0; j < m; ++j)
                ids[j] = static_cast<int>(j) == t.keep ? in.ids[i] : env.id_base + env.new_count++;
        } else {
            env.new_count += m - (t.keep >= 0 ? 1 : 0);
        }
        if (out.size() > env.max_output) throw RuntimeError{Span{}, "module limit"};
        return 1;
    }

    std::size_t run_body(Worker& w, std::size_t i, const Production& pr) {
        if (pr.tmpl.valid) return apply_template(w, i, pr);
        EvalEnv& env = w.env;
        SymbolId keep_syms[32];
        ModuleId keep_ids[32];
        const std::size_t k = std::min<std::size_t>(pr.strict.size(), 32);
        for (std::size_t m = 0; m < k; ++m) {
            keep_syms[m] = in.sym[i + m];
            keep_ids[m] = in.id(i + m);
        }
        env.keep_syms = keep_syms;
        env.keep_ids = keep_ids;
        env.keep_count = static_cast<std::uint32_t>(k);
        env.keep_used = 0;
        env.produced = false;
        env.out = &w.out;
        const std::size_t mark = w.out.size();
        RunStatus st = run(pr.body, w.frame.data(), env);
        env.keep_count = 0;
        if (st == RunStatus::Produced || env.produced) return pr.strict.size();
        // not applied: drop anything a partial body emitted
        w.out.sym.resize(mark);
        if (w.out.keep_ids) w.out.ids.resize(mark);
        w.out.params.resize(w.out.poff[mark]);
        w.out.poff.resize(mark + 1);
        return 0;
    }

    // cpfg semantics: all applicable weighted productions of the module, one drawn by weight.
    std::size_t choose(Worker& w, std::size_t i, std::size_t set0, std::size_t cand0,
                       std::size_t length = 0) {
        struct Option {
            const Production* pr;
            double weight;
        };
        Option options[64];
        std::size_t count = 0;
        double total = 0;
        const SymbolId sym = in.sym[i];
        for (std::size_t si = set0; si < plan.sets.size(); ++si) {
            const auto& cands = plan.sets[si]->by_symbol[sym];
            for (std::size_t ci = si == set0 ? cand0 : 0; ci < cands.size(); ++ci) {
                const Production& pr = plan.sets[si]->productions[cands[ci]];
                if (pr.weight.empty() || (length && pr.strict.size() != length) || !matches(w, i, pr))
                    continue;
                double wt = eval_number(pr.weight, w.frame.data(), w.env);
                if (!(wt >= 0) || !std::isfinite(wt))
                    throw RuntimeError{
                        pr.weight.spans.empty() ? pr.span : pr.weight.spans.back(),
                        fmt::format("a production weight must be a finite number >= 0, found {}", wt)};
                if (wt == 0 || count == 64) continue;
                options[count++] = {&pr, wt};
                total += wt;
            }
        }
        if (count == 0) return 0;
        double u = random_unit(random_bits(w.env.seed, w.env.phase, i, kChoiceDraw)) * total;
        std::size_t pick = count - 1;
        for (std::size_t k = 0; k < count; ++k) {
            if (u < options[k].weight) {
                pick = k;
                break;
            }
            u -= options[k].weight;
        }
        const Production& pr = *options[pick].pr;
        w.env.draw = 0;
        matches(w, i, pr); // bind the chosen production's names again
        return run_body(w, i, pr);
    }

    const RulePlan& plan;
    const Program& P;
    const ModuleString& in;
    const std::size_t n;
    std::vector<std::uint32_t> own_match;
    std::vector<std::uint16_t>* kernel_scratch = nullptr; // run_symbols's right keys, kept from step to step
    const std::uint32_t* match = nullptr;                 // the bracket table (see bracket_table)
    std::vector<std::size_t> piece_starts;
};

} // namespace plant
