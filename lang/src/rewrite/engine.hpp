// The rewriting engine as a derivation drives it: its state (the rule plans, the identity
// counter, the buffers kept from step to step) and the passes a step runs over the string
// (the rewrite on one or several threads, decomposition, cut, interpretation). Private to the
// language library; the Derivation holds one through detail::EngineHandle.
#pragma once

#include "plan.hpp"
#include "plant/derive.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace plant {

class Rewriter;
struct Worker;

struct Engine {
    Engine() = default;
    // What a copied derivation keeps: the rule plans (shared, they never change), the identity
    // counter and the growth estimates. The buffers are scratch, rebuilt by every rewrite, and
    // the spare string is not copied: copies start without one.
    Engine(const Engine& o)
        : next_id(o.next_id), work(o.work), growth(o.growth), param_growth(o.param_growth), plans(o.plans),
          step_plans(o.step_plans) {}
    Engine& operator=(const Engine&) = delete;

    // Rewrites `in` into `out` under `plan`, its random draws from stream `phase`; environments
    // see `step_for_env` as the step.
    void rewrite(const Derivation& d, const ModuleString& in, ModuleString& out, const RulePlan& plan,
                 std::uint64_t phase, int step_for_env);
    // The decomposition rules, applied until nothing changes (at most their max_depth passes).
    void decompose(const Derivation& d, ModuleString& s, int step_for_env);
    // Removes the branches cut by '%'.
    static void apply_cut(const Program& prog, ModuleString& s);
    // The string as the turtle sees it (Derivation::interpreted).
    ModuleString interpreted(const Derivation& d, const ModuleString& s);
    // Throws the error that names the limit the string passes (--max-modules, --max-bytes).
    void check_limits(const Derivation& d, const ModuleString& s) const;
    void check_limits(const Derivation& d, std::size_t modules, std::size_t params) const;

    // The plan for rewriting with `sets`, built the first time and kept (copies share them).
    const RulePlan& plan_for(const Program& prog, const std::vector<const RuleSet*>& sets);
    // The plan for a step with the active group: plan_for(group's rules, then the unnamed ones).
    const RulePlan& step_plan(const Derivation& d);

    ModuleId next_id = 1;                    // the identity the next new module gets
    std::uint64_t work = 0;                  // the run's work so far (DeriveOptions::max_work)
    bool interpreting = false;               // within interpreted(): child() records no node
    double growth = 2.0, param_growth = 2.0; // last step's growth, for reserving memory
    std::vector<std::shared_ptr<const RulePlan>> plans;
    std::vector<const RulePlan*> step_plans; // per group + 1 (index 0: no group), from plans
    std::vector<std::uint32_t> brackets;     // the bracket table, kept from step to step
    BigVector<ContextKey> kernel_scratch;    // the symbol kernel's right keys (Rewriter::run_symbols)
    // The string a step replaced, when small, kept for the next step to write its output into:
    // small strings would otherwise pay a round of allocations a step.
    ModuleString spare;
    static constexpr std::size_t kMaxSpareBytes = std::size_t{1} << 20;

    // What the last rewrite on the direct path learnt of the string it wrote, from the outcomes
    // its writers tallied: the modules of each symbol and the parameters they all carry. The
    // next rewrite of that string on one thread sizes its output from them instead of reading
    // the string once more to count (see rewrite_direct). They describe the string whose
    // symbols start at `of` and that has `size` modules, as long as nothing else changes it:
    // every rewrite forgets them first, and so does the derivation before its environment
    // phase, which edits the string in place.
    struct StringCounts {
        std::vector<std::uint64_t> modules; // per symbol
        std::vector<std::int32_t> arity;    // per symbol: what every module has; -1 they differ or unknown
        std::vector<std::int32_t> stored;   // per symbol: the numbers every module stores; -1 likewise
        // per kind, when the copy kernel wrote the string (Engine::rewrite_copies); else empty
        std::vector<std::uint64_t> kinds;
        // Snapshots the direct path's writers took as they wrote the string (Worker::snaps):
        // at module snap_pos[j], the outcomes of snap_plan so far were snap_tally[j * outcomes
        // + o], counted from the string's start. From them a step on several threads finds where
        // each thread writes without reading the whole string (Engine::size_slices).
        std::vector<std::size_t> snap_pos; // ascending
        std::vector<std::uint64_t> snap_tally;
        const RulePlan* snap_plan = nullptr;
        const SymbolId* of = nullptr;
        std::size_t size = 0;
    } counts;
    // The plan under which a step on several threads found its stretches' sizes from the counts
    // only bounds that the writers did not fill (a guarded symbol copied): later steps under it
    // count instead (another plan, after a group switch, tries the counts again).
    const RulePlan* slices_missed = nullptr;
    std::uint64_t modules_counted = 0; // read only to size an output (Derivation::modules_counted)
    void forget_counts() { counts.of = nullptr; }

  private:
    // The copy kernel (RulePlan::copy_kernel, copies.cpp): whether it applies to `in`, and the
    // rewrite by it.
    static bool copies_apply(const RulePlan& plan, const ModuleString& in);
    void rewrite_copies(const Derivation& d, const ModuleString& in, ModuleString& out, const RulePlan& plan,
                        bool counted);
    void rewrite_one_thread(const Derivation& d, Rewriter& rw, const ModuleString& in, Worker& w,
                            const RulePlan& plan);
    template <typename Setup>
    void rewrite_parallel(const Derivation& d, Rewriter& rw, const ModuleString& in, ModuleString& out,
                          int threads, const Setup& setup);
    template <typename Setup>
    bool rewrite_direct(const Derivation& d, Rewriter& rw, const ModuleString& in, ModuleString& out,
                        const RulePlan& plan, int threads, bool counted, const Setup& setup);
    // The size of the output of `in`, a string `counts` describes, on the direct path: exact
    // unless a guarded symbol may be copied or rewritten, then at most that. False when
    // unknown (a symbol's modules may not all have the width its template takes).
    bool size_from_counts(const RulePlan& plan, const ModuleString& in, std::size_t& modules,
                          std::size_t& params) const;
    // The same for modules whose symbols are counted in `per_symbol` (the string's own arities,
    // `counts`) and which store `params_in` numbers; also the new identities, at most.
    bool size_from(const RulePlan& plan, const std::vector<std::uint64_t>& per_symbol, std::size_t params_in,
                   std::size_t& modules, std::size_t& params, std::size_t& new_ids) const;
    // slices.cpp: where each of T threads writes the output of its stretch of `in`, a string
    // `counts` describes, from the snapshots: exact or bounds as size_from_counts. False when
    // the counts cannot size the output.
    bool size_slices(const RulePlan& plan, const ModuleString& in, std::size_t T,
                     std::vector<std::size_t>& m_at, std::vector<std::size_t>& p_at,
                     std::vector<ModuleId>& id_at);
    // Keeps the writers' snapshots in `counts` (after count_outcomes), thread t's output
    // having started at module m_at[t].
    void keep_snapshots(const RulePlan& plan, const std::vector<Worker>& workers,
                        const std::vector<std::vector<std::uint64_t>>& tallies,
                        const std::vector<std::size_t>& m_at);
    // Makes `counts` describe `out` from the outcomes the writers tallied.
    void count_outcomes(const RulePlan& plan, const std::vector<std::vector<std::uint64_t>>& tallies,
                        bool counted, const ModuleString& out);
    bool within_limits(const Derivation& d, std::size_t modules, std::size_t params) const;
};

} // namespace plant
