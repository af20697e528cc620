// The general route: every module is matched against its symbol's productions in turn
// (pattern, context, condition), weighted productions are drawn from (cpfg semantics), and the
// successor is written by its template or by running the production's body. run_range also
// hands whole stretches to the faster routes when the plan and the string allow them.
#include "rewriter.hpp"

#include "plant/streams.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace plant {

Rewriter::Rewriter(const RulePlan& rule_plan, const ModuleString& in, std::vector<std::uint32_t>* brackets,
                   BigVector<ContextKey>* scratch, bool whole)
    : plan(rule_plan), P(rule_plan.P), in(in), n(in.size()), whole(whole),
      kernel_scratch(whole ? scratch : nullptr) {
    table_kinds = whole && plan.symbol_kernel && in.params.empty() && in.has_table_kinds();
    if (kernel_applies()) return;
    if (plan.brackets) {
        std::vector<std::uint32_t>& table = brackets ? *brackets : own_match;
        bracket_table(in, P.symbols.open_bracket, P.symbols.close_bracket, table);
        match = table.data();
    }
}

// The internal signal that a worker's output passed the limits; the derivation turns it into the
// message that names the limit (Derivation's check_limits, in engine.cpp).
void Rewriter::limit_error() const {
    throw RuntimeError{RuntimeErrorKind::ModuleLimit, Span{}, "module limit"};
}

void Rewriter::hole_error(const SuccessorTemplate& t, std::size_t h, double value) const {
    std::size_t j = 0;
    while (t.param_end[j] <= t.holes[h]) ++j;
    std::uint32_t k = t.holes[h] - (j ? t.param_end[j - 1] : 0);
    throw RuntimeError{RuntimeErrorKind::Arithmetic, t.hole_spans[h],
                       fmt::format("parameter {} of '{}' is {}", k + 1, P.symbols[t.syms[j]].name,
                                   std::isnan(value) ? "NaN" : "infinite")};
}

// Rewrites modules [b, e) into w.out.
void Rewriter::run_range(Worker& w, std::size_t b, std::size_t e) {
    if (kernel_applies()) { // then [b, e) is the whole string
        run_symbols(w);
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
        if (!plan.has_prod[in.symbol(i)]) {
            std::size_t j = i + 1;
            while (j < e && !plan.has_prod[in.symbol(j)]) ++j;
            w.out.append_range(in, i, j);
            i = j;
            if (w.out.size() > w.env.max_output || w.out.params.size() > w.env.max_params) limit_error();
            continue;
        }
        if (const Production* pr = plan.direct[in.symbol(i)]; pr && in.arity(i) == pr->strict[0].width) {
            if (!pr->tmpl.holes.empty()) {
                bind_args(w, i, in.params.data() + in.offset(i), pr->strict[0]);
                w.env.position = i;
                w.env.draw = 0;
                w.env.id = in.id(i);
            }
            apply_template(w, i, *pr);
            ++i;
            continue;
        }
        if (!plan.ctx_block.empty() && plan.ctx_block[in.symbol(i)] >= 0 && in.arity(i) == 0) {
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

// Tries the productions for module i; returns the number of modules consumed (0: none applied).
std::size_t Rewriter::apply(Worker& w, std::size_t i) {
    EvalEnv& env = w.env;
    env.position = i;
    env.draw = 0;
    env.id = in.id(i);
    const SymbolId sym = in.symbol(i);
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
std::size_t Rewriter::apply_template(Worker& w, std::size_t i, const Production& pr) {
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
        const double* p = t.stored.data();
        for (std::size_t j = 0; j < m; p += t.stored_nargs[j], ++j) {
            const ModuleId id = static_cast<int>(j) == t.keep ? in.id(i) : env.id_base + env.new_count++;
            out.push_kind(t.kinds[j], p, t.stored_nargs[j], id);
        }
        if (out.size() > env.max_output) limit_error();
        return 1;
    }
    const std::size_t m0 = out.kinds.size();
    const std::size_t p0 = out.params.size();
    out.kinds.resize(m0 + m);
    if (out.keep_ids) out.ids.resize(m0 + m);
    out.params.resize(p0 + t.stored.size());
    std::copy(t.kinds.begin(), t.kinds.end(), out.kinds.begin() + static_cast<std::ptrdiff_t>(m0));
    double* pp = out.params.data() + p0;
    std::copy(t.stored.begin(), t.stored.end(), pp);
    for (std::size_t h = 0; h < t.holes.size(); ++h) pp[t.stored_holes[h]] = values[h];
    out.index_from(m0, p0);
    if (out.keep_ids) {
        ModuleId* ids = out.ids.data() + m0;
        for (std::size_t j = 0; j < m; ++j)
            ids[j] = static_cast<int>(j) == t.keep ? in.ids[i] : env.id_base + env.new_count++;
    } else {
        env.new_count += t.fresh();
    }
    if (out.size() > env.max_output) limit_error();
    return 1;
}

std::size_t Rewriter::run_body(Worker& w, std::size_t i, const Production& pr) {
    if (pr.tmpl.valid) return apply_template(w, i, pr);
    EvalEnv& env = w.env;
    SymbolId keep_syms[32];
    ModuleId keep_ids[32];
    const std::size_t k = std::min<std::size_t>(pr.strict.size(), 32);
    for (std::size_t m = 0; m < k; ++m) {
        keep_syms[m] = in.symbol(i + m);
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
    w.out.truncate(mark);
    return 0;
}

// cpfg semantics: all applicable weighted productions of the module, one drawn by weight.
std::size_t Rewriter::choose(Worker& w, std::size_t i, std::size_t set0, std::size_t cand0,
                             std::size_t length) {
    struct Option {
        const Production* pr;
        double weight;
    };
    Option options[64];
    std::size_t count = 0;
    double total = 0;
    const SymbolId sym = in.symbol(i);
    for (std::size_t si = set0; si < plan.sets.size(); ++si) {
        const auto& cands = plan.sets[si]->by_symbol[sym];
        for (std::size_t ci = si == set0 ? cand0 : 0; ci < cands.size(); ++ci) {
            const Production& pr = plan.sets[si]->productions[cands[ci]];
            if (pr.weight.empty() || (length && pr.strict.size() != length) || !matches(w, i, pr)) continue;
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
    // Weights near the largest double can sum to infinity: then they are all divided by the
    // largest first (a scale of 1 changes no weight, so ordinary weights draw as they always did).
    double scale = 1;
    if (!std::isfinite(total)) {
        double largest = 0;
        for (std::size_t k = 0; k < count; ++k) largest = std::max(largest, options[k].weight);
        scale = 1 / largest;
        total = 0;
        for (std::size_t k = 0; k < count; ++k) total += options[k].weight * scale;
    }
    double u = random_unit(random_bits(w.env.seed, w.env.phase, i, stream::kChoiceDraw)) * total;
    std::size_t pick = count - 1;
    for (std::size_t k = 0; k < count; ++k) {
        const double weight = options[k].weight * scale;
        if (u < weight) {
            pick = k;
            break;
        }
        u -= weight;
    }
    const Production& pr = *options[pick].pr;
    w.env.draw = 0;
    matches(w, i, pr); // bind the chosen production's names again
    return run_body(w, i, pr);
}

} // namespace plant
