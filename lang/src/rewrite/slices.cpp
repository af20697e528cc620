// Sizing the direct path's output from what the last step's writers counted (Engine::counts),
// instead of reading the string once more: the whole output (one thread), and where each of
// several threads writes its stretch (from the writers' snapshots, Worker::snaps). See
// docs/rewriting.md, "The direct path".
#include "engine.hpp"
#include "rewriter.hpp"

#include <algorithm>

namespace plant {

bool Engine::size_from_counts(const RulePlan& plan, const ModuleString& in, std::size_t& modules,
                              std::size_t& params) const {
    std::size_t new_ids = 0;
    return size_from(plan, counts.modules, in.params.size(), modules, params, new_ids);
}

bool Engine::size_from(const RulePlan& plan, const std::vector<std::uint64_t>& per_symbol,
                       std::size_t params_in, std::size_t& modules, std::size_t& params,
                       std::size_t& new_ids) const {
    modules = 0;
    new_ids = 0;
    params = params_in;
    const std::size_t S = plan.has_prod.size();
    if (counts.modules.size() != S || per_symbol.size() != S) return false;
    for (std::size_t s = 0; s < S; ++s) {
        const std::uint64_t c = per_symbol[s];
        if (c == 0) continue;
        if (!plan.has_prod[s]) {
            modules += c;
        } else if (const Production* pr = plan.direct[s]) {
            if (counts.arity[s] != static_cast<std::int32_t>(pr->strict[0].width) || counts.stored[s] < 0)
                return false;
            modules += c * pr->tmpl.syms.size();
            params += c * pr->tmpl.stored.size();
            params -= c * static_cast<std::size_t>(counts.stored[s]);
            new_ids += c * pr->tmpl.fresh();
        } else {
            const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(plan.guarded_at[s])];
            std::size_t most_m = 1, most_p = 0, most_new = 0; // (the copy's own parameters are in params_in)
            if (!g.uniform)
                for (std::uint32_t k = 0; k < g.count; ++k) {
                    const SuccessorTemplate& t = plan.guards[g.first + k].pr->tmpl;
                    most_m = std::max(most_m, t.syms.size());
                    most_p = std::max(most_p, t.stored.size());
                    most_new = std::max(most_new, t.fresh());
                }
            modules += c * most_m;
            new_ids += c * most_new;
            if (!g.uniform && counts.stored[s] >= 0) { // exact when every module has a template
                const auto own = static_cast<std::size_t>(counts.stored[s]);
                params += c * std::max(most_p, own) - c * own;
            } else {
                params += c * most_p;
            }
        }
    }
    return true;
}

bool Engine::size_slices(const RulePlan& plan, const ModuleString& in, std::size_t T,
                         std::vector<std::size_t>& m_at, std::vector<std::size_t>& p_at,
                         std::vector<ModuleId>& id_at) {
    // (no snapshots: every stretch of the last write was shorter than Rewriter::kSnapEvery; the
    // symbols before each start are then counted from the string's start)
    const RulePlan* sp = counts.snap_plan;
    if (!sp) return false;
    const std::size_t n = in.size(), S = plan.has_prod.size(), O = sp->outcome_tmpl.size();
    const SymbolReader sym_of = in.symbols();
    std::vector<std::uint64_t> per_symbol(S);
    std::size_t counted = 0;
    m_at.assign(T, 0);
    p_at.assign(T, 0);
    id_at.assign(T, next_id);
    for (std::size_t t = 1; t < T; ++t) {
        // the modules before thread t's stretch: the last snapshot at or before its start, and
        // the symbols from there on counted
        const std::size_t start = n * t / T;
        const auto up = std::upper_bound(counts.snap_pos.begin(), counts.snap_pos.end(), start);
        std::fill(per_symbol.begin(), per_symbol.end(), 0);
        std::size_t from = 0;
        if (up != counts.snap_pos.begin()) {
            const auto j = static_cast<std::size_t>(up - counts.snap_pos.begin()) - 1;
            from = counts.snap_pos[j];
            const std::uint64_t* tally = counts.snap_tally.data() + j * O;
            for (std::size_t o = 0; o < O; ++o) {
                if (tally[o] == 0) continue;
                if (const SuccessorTemplate* tm = sp->outcome_tmpl[o])
                    for (const SymbolId x : tm->syms) per_symbol[x] += tally[o];
                else
                    per_symbol[sp->outcome_sym[o]] += tally[o];
            }
        }
        for (std::size_t i = from; i < start; ++i) ++per_symbol[sym_of(i)];
        counted += start - from;
        std::size_t modules = 0, params = 0, new_ids = 0;
        if (!size_from(plan, per_symbol, in.offset(start), modules, params, new_ids)) return false;
        m_at[t] = modules;
        p_at[t] = params;
        id_at[t] = next_id + new_ids;
    }
    modules_counted += counted;
    return true;
}

void Engine::keep_snapshots(const RulePlan& plan, const std::vector<Worker>& workers,
                            const std::vector<std::vector<std::uint64_t>>& tallies,
                            const std::vector<std::size_t>& m_at) {
    const std::size_t O = plan.outcome_tmpl.size();
    counts.snap_pos.clear();
    counts.snap_tally.clear();
    counts.snap_plan = &plan;
    std::vector<std::uint64_t> before(O, 0); // the outcomes of the threads before this one
    for (std::size_t t = 0; t < workers.size(); ++t) {
        const std::vector<std::uint64_t>& snaps = workers[t].snaps;
        for (std::size_t at = 0; at + O + 1 <= snaps.size(); at += O + 1) {
            counts.snap_pos.push_back(m_at[t] + static_cast<std::size_t>(snaps[at]));
            for (std::size_t o = 0; o < O; ++o) counts.snap_tally.push_back(before[o] + snaps[at + 1 + o]);
        }
        for (std::size_t o = 0; o < O; ++o) before[o] += tallies[t][o];
    }
}

} // namespace plant
