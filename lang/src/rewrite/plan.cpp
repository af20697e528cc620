// Building the rule plan (see plan.hpp): the direct templates, the context table and the
// symbol kernel's tables, once per list of rule sets.
#include "plan.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

namespace plant {

// Whether some production of `rs` names a query module (?P, ?H, ...) in its predecessor or
// context: then the turtle pass runs before each step to fill them.
bool reads_queries(const Program& p, const RuleSet& rs) {
    auto named = [&](const std::vector<PatternModule>& v) {
        for (const auto& m : v)
            if (p.symbols[m.sym].query) return true;
        return false;
    };
    for (const auto& pr : rs.productions)
        if (named(pr.strict) || named(pr.left) || named(pr.right)) return true;
    return false;
}

RulePlan::RulePlan(const Program& p, std::vector<const RuleSet*> rule_sets)
    : P(p), sets(std::move(rule_sets)) {
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
    }
    guarded_at.assign(P.symbols.size(), -1);
    for (SymbolId s = 0; s < P.symbols.size(); ++s)
        all_direct = all_direct && (!has_prod[s] || direct[s] || (!multi && build_guards(s)));
    if (all_direct) build_outcomes();
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
    if (!sequential()) build_copy_kernel();
}

// The copy kernel's tables (see copy_kernel), when every kind a string without numbers can hold
// is copied or has a direct template of the same arity that stores no numbers.
void RulePlan::build_copy_kernel() {
    const KindTable& kt = P.kinds;
    const std::size_t K = kt.kinds();
    if (K > kNoSymbol) return;
    copy_succ.assign(K, KindSucc{});
    copy_len.assign(K, 1);
    copy_fresh.assign(K, 0);
    for (std::size_t k = 0; k < K; ++k) {
        copy_succ[k].kinds[0] = static_cast<KindId>(k);
        if (kt.stored[k] != 0) continue; // never in a string without numbers
        const bool plain = k < kt.plain;
        const std::size_t sym = plain ? k : kt.symbol[k - kt.plain];
        if (sym >= has_prod.size() || !has_prod[sym]) continue; // copied
        const Production* pr = direct[sym];
        const std::uint32_t arity = plain ? 0 : kt.arity[k - kt.plain];
        if (!pr || pr->strict[0].width != arity || !pr->tmpl.stored.empty() || !pr->tmpl.holes.empty() ||
            pr->tmpl.kinds.size() > KindSucc::kMax) {
            copy_succ.clear();
            return;
        }
        const SuccessorTemplate& t = pr->tmpl;
        std::copy(t.kinds.begin(), t.kinds.end(), copy_succ[k].kinds);
        copy_len[k] = static_cast<std::uint8_t>(t.kinds.size());
        copy_fresh[k] = static_cast<std::uint8_t>(t.fresh());
        copy_longest = std::max(copy_longest, t.kinds.size());
    }
    copy_kernel = true;
}

namespace {

// `c op x` as `x mirrored(op) c`.
Op mirrored(Op op) {
    switch (op) {
    case Op::Lt:
        return Op::Gt;
    case Op::Le:
        return Op::Ge;
    case Op::Gt:
        return Op::Lt;
    case Op::Ge:
        return Op::Le;
    default: // Eq, Ne
        return op;
    }
}

// The guard a production's condition and weight make (see RulePlan::Guard), or nothing when
// they are not of the simple forms.
std::optional<RulePlan::Guard> guard_of(const Production& pr) {
    const PatternModule& pm = pr.strict[0];
    RulePlan::Guard g;
    g.pr = &pr;
    const Code& c = pr.condition;
    if (!c.empty()) {
        if (c.instrs.size() != 4 || c.instrs[3].op != Op::Halt || c.instrs[3].n != 1) return std::nullopt;
        const Op op = c.instrs[2].op;
        if (op != Op::Lt && op != Op::Le && op != Op::Gt && op != Op::Ge && op != Op::Eq && op != Op::Ne)
            return std::nullopt;
        const Instr *load = &c.instrs[0], *k = &c.instrs[1];
        bool swapped = false; // `constant OP parameter`
        if (load->op == Op::Const) {
            std::swap(load, k);
            swapped = true;
        }
        if (load->op != Op::LoadLocal || load->n != 1 || k->op != Op::Const) return std::nullopt;
        const auto slot = static_cast<std::uint32_t>(load->a);
        std::uint32_t at = 0;
        bool found = false;
        for (const auto& pa : pm.args) {
            if (pa.slot <= slot && slot < pa.slot + static_cast<std::uint32_t>(pa.width)) {
                g.param = at + (slot - pa.slot);
                found = true;
                break;
            }
            at += pa.width;
        }
        if (!found) return std::nullopt;
        // `x OP c` as an interval of x, the parameter, and whether it is the outside: a strict
        // bound is the next double inward (nothing is between), NaN where nothing is inward (x
        // < -inf), so that a NaN parameter or constant compares as IEEE says
        const double cst = c.consts[static_cast<std::size_t>(k->a)];
        constexpr double inf = std::numeric_limits<double>::infinity();
        const double nan = std::numeric_limits<double>::quiet_NaN();
        auto below = [&](double v) { return v == -inf ? nan : std::nextafter(v, -inf); };
        auto above = [&](double v) { return v == inf ? nan : std::nextafter(v, inf); };
        const Op o = swapped ? mirrored(op) : op; // as `x o c`
        g.negate = o == Op::Ne;
        g.lo = o == Op::Lt || o == Op::Le ? -inf : o == Op::Gt ? above(cst) : cst;
        g.hi = o == Op::Gt || o == Op::Ge ? inf : o == Op::Lt ? below(cst) : cst;
    }
    const Code& w = pr.weight;
    if (!w.empty()) {
        if (w.instrs.size() != 2 || w.instrs[0].op != Op::Const || w.instrs[1].op != Op::Halt ||
            w.instrs[1].n != 1)
            return std::nullopt;
        g.weight = w.consts[static_cast<std::size_t>(w.instrs[0].a)];
        if (!(g.weight >= 0) || !std::isfinite(g.weight)) return std::nullopt; // the general path says why
    }
    return g;
}

} // namespace

// Whether every production of `sym` makes a guard; then they are recorded as its guards.
bool RulePlan::build_guards(SymbolId sym) {
    std::vector<Guard> gs;
    std::uint32_t width = 0;
    for (const RuleSet* rs : sets)
        for (std::uint32_t pi : rs->by_symbol[sym]) {
            const Production& pr = rs->productions[pi];
            bool binds_all = pr.strict.size() == 1;
            for (const auto& a : pr.strict[0].args) binds_all = binds_all && a.bind;
            if (!binds_all || pr.has_context() || pr.has_new_context() || !pr.tmpl.valid) return false;
            if (!gs.empty() && pr.strict[0].width != width) return false;
            width = pr.strict[0].width;
            std::optional<Guard> g = guard_of(pr);
            if (!g) return false;
            gs.push_back(*g);
        }
    if (gs.empty() || gs.size() > 64) return false;
    Guarded entry;
    entry.first = static_cast<std::uint32_t>(guards.size());
    entry.count = static_cast<std::uint32_t>(gs.size());
    entry.width = width;
    // (a module of sym stores all its numbers unless some template gives it a kind of constants;
    // its plain kinds, of any arity, store them all)
    entry.uniform = true;
    for (std::size_t k = 0; k < P.kinds.size(); ++k)
        if (P.kinds.symbol[k] == sym && P.kinds.layout_at[k] != KindTable::kAllStored) entry.uniform = false;
    for (const Guard& g : gs) {
        const SuccessorTemplate& t = g.pr->tmpl;
        entry.uniform = entry.uniform && t.syms.size() == 1 && t.stored.size() == width && t.keep == 0;
    }
    guarded_at[sym] = static_cast<std::int32_t>(guarded.size());
    guards.insert(guards.end(), gs.begin(), gs.end());
    build_picks(entry);
    guarded.push_back(entry);
    return true;
}

// The table of what a guarded module becomes for each set of its conditions that hold (see
// Pick), when it has few enough guards. The same choice as Rewriter::choose makes: the first
// guard that holds applies; when it is weighted, a draw among it and the weighted guards after
// it that hold, zero weights left out, with the weights scaled down together when their sum
// overflows.
void RulePlan::build_picks(Guarded& g) {
    // the distinct intervals (bit for bit); a guard without a condition (an interval that holds
    // nothing, negated: lo is NaN) needs none
    Guard* gs = guards.data() + g.first;
    std::vector<Test> ts;
    for (std::uint32_t k = 0; k < g.count; ++k) {
        Guard& q = gs[k];
        if (std::isnan(q.lo) && q.negate) {
            q.test = kNone;
            continue;
        }
        const Test t{q.param, q.lo, q.hi};
        std::uint32_t j = 0;
        while (j < ts.size() &&
               !(ts[j].param == t.param &&
                 std::bit_cast<std::uint64_t>(ts[j].lo) == std::bit_cast<std::uint64_t>(t.lo) &&
                 std::bit_cast<std::uint64_t>(ts[j].hi) == std::bit_cast<std::uint64_t>(t.hi)))
            ++j;
        if (j == ts.size()) ts.push_back(t);
        q.test = j;
    }
    if (ts.size() > kPickBits) return;
    g.tests_first = static_cast<std::uint32_t>(tests.size());
    g.tests_n = static_cast<std::uint32_t>(ts.size());
    tests.insert(tests.end(), ts.begin(), ts.end());
    g.picks = static_cast<std::int32_t>(picks.size());
    for (std::uint32_t inside = 0; inside < (1u << g.tests_n); ++inside) {
        // which guards hold (bit k: guard k's) when the intervals in `inside` hold their parameters
        std::uint64_t mask = 0;
        for (std::uint32_t k = 0; k < g.count; ++k)
            if (gs[k].test == kNone || (inside >> gs[k].test & 1) != gs[k].negate)
                mask |= std::uint64_t{1} << k;
        Pick pk;
        std::uint32_t k = 0;
        while (k < g.count && !(mask >> k & 1)) ++k;
        if (k < g.count && gs[k].weight < 0) {
            pk.only = k;
        } else if (k < g.count) {
            pk.first = static_cast<std::uint32_t>(pick_options.size());
            for (std::uint32_t j = k; j < g.count; ++j) {
                if (gs[j].weight < 0 || !(mask >> j & 1) || gs[j].weight == 0) continue;
                pick_options.push_back({j, gs[j].weight});
                pk.total += gs[j].weight;
            }
            pk.count = static_cast<std::uint32_t>(pick_options.size()) - pk.first;
            if (!std::isfinite(pk.total)) {
                double largest = 0;
                for (std::uint32_t j = 0; j < pk.count; ++j)
                    largest = std::max(largest, pick_options[pk.first + j].weight);
                const double scale = 1 / largest;
                pk.total = 0;
                for (std::uint32_t j = 0; j < pk.count; ++j) {
                    PickOption& o = pick_options[pk.first + j];
                    o.weight *= scale;
                    pk.total += o.weight;
                }
            }
        }
        picks.push_back(pk);
    }
}

void RulePlan::build_outcomes() {
    auto add = [&](const Production* pr, SymbolId s) {
        outcome_tmpl.push_back(pr ? &pr->tmpl : nullptr);
        outcome_sym.push_back(s);
        outcome_args.push_back(pr ? add_args(*pr) : -1);
    };
    for (SymbolId s = 0; s < P.symbols.size(); ++s) {
        outcome_at.push_back(static_cast<std::uint32_t>(outcome_tmpl.size()));
        add(nullptr, s);
        if (!has_prod[s]) continue;
        if (direct[s]) {
            add(direct[s], s);
            continue;
        }
        const Guarded& g = guarded[static_cast<std::size_t>(guarded_at[s])];
        for (std::uint32_t k = 0; k < g.count; ++k) add(guards[g.first + k].pr, s);
    }
    emits.resize(outcome_tmpl.size());
    for (std::size_t o = 0; o < outcome_tmpl.size(); ++o) {
        const SuccessorTemplate* t = outcome_tmpl[o];
        if (!t || outcome_args[o] < 0) continue;
        Emit& em = emits[o];
        em.kinds = t->kinds.data();
        em.m = static_cast<std::uint32_t>(t->syms.size());
        em.stored_n = static_cast<std::uint32_t>(t->stored.size());
        em.holes_n = static_cast<std::uint32_t>(t->holes.size());
        em.stored = em.stored_n != em.holes_n ? t->stored.data() : nullptr;
        em.holes_at = static_cast<std::uint32_t>(outcome_args[o]);
        em.fresh = static_cast<std::uint32_t>(t->fresh());
        em.keep = t->keep;
        em.moved_at = static_cast<std::uint32_t>(moved.size());
        if (em.m != 1 || em.stored || outcome_sym[o] != t->syms[0]) continue;
        for (std::uint32_t h = 0; h < em.holes_n; ++h) {
            const ArgHole& a = args[em.holes_at + h];
            if (a.from != a.to || a.mul != 1 || a.add != 0 || !std::signbit(a.add)) moved.push_back(a);
        }
        em.moved_n = static_cast<std::uint32_t>(moved.size()) - em.moved_at;
    }
}

// The entries of `args` for production pr's template (see outcome_args), or -1 when one of its
// numbers is not an affine function of one of the module's own.
std::int32_t RulePlan::add_args(const Production& pr) {
    const SuccessorTemplate& t = pr.tmpl;
    if (t.affine.size() != t.holes.size()) return -1;
    const auto first = static_cast<std::int32_t>(args.size());
    for (std::size_t h = 0; h < t.affine.size(); ++h) {
        const SuccessorTemplate::Affine& a = t.affine[h];
        // the module's number bound to the slot (bind_args writes them in order: the last wins)
        std::int64_t from = -1;
        std::uint32_t at = 0;
        for (const auto& pa : pr.strict[0].args) {
            if (pa.slot <= a.slot && a.slot < pa.slot + static_cast<std::uint32_t>(pa.width))
                from = at + (a.slot - pa.slot);
            at += static_cast<std::uint32_t>(pa.width);
        }
        if (from < 0) {
            args.resize(static_cast<std::size_t>(first));
            return -1;
        }
        ArgHole hole;
        hole.from = static_cast<std::uint32_t>(from);
        hole.to = t.stored_holes[h];
        if (a.kind == SuccessorTemplate::Affine::Add) hole.add = a.constant;
        if (a.kind == SuccessorTemplate::Affine::Mul) hole.mul = a.constant;
        args.push_back(hole);
    }
    return first;
}

// The symbol kernel's tables. It needs every rewritten symbol to be parameterless: a direct
// template whose pattern takes no parameters, or a context table.
void RulePlan::build_symbol_kernel() {
    const std::size_t S = P.symbols.size(), K = ctx_keys;
    for (SymbolId sym = 0; sym < S; ++sym)
        if (has_prod[sym] && direct[sym] && direct[sym]->strict[0].width != 0)
            return; // a pattern with parameters
    // built as distinct successors (succs) and each block's indices into them (succ_at), then
    // flattened into succ_flat, which is all the kernel reads
    std::vector<SymbolSucc> succs;
    std::vector<std::uint32_t> succ_at;
    auto add = [&](const SuccessorTemplate& t) {
        SymbolSucc su;
        std::copy(t.syms.begin(), t.syms.end(), su.syms);
        su.len = static_cast<std::uint32_t>(t.syms.size());
        su.fresh = static_cast<std::uint32_t>(t.fresh());
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
    succ_flat.reserve(succ_at.size());
    for (std::uint32_t at : succ_at) succ_flat.push_back(succs[at]);
    symbol_kernel = true;
}

// The context table. When every production of a symbol is `l < s > r -> successor` with
// modules that carry no parameters, at most one context module a side and no condition,
// weight or new context (ABOP's Fig. 1.31 and other signal-propagation systems), which
// production applies depends only on the symbols of the two neighbours. A K x K table per
// such symbol, K being the number of symbols the patterns name plus one for all others,
// answers that with one lookup instead of trying the productions in turn.
void RulePlan::build_context_table() {
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
                     (pr.right.empty() || plain(pr.right[0])) && pr.condition.empty() && pr.weight.empty() &&
                     !pr.has_new_context() && pr.tmpl.valid;
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

} // namespace plant
