// The derivation engine: hooks, parallel rewriting with tree-aware context, stochastic choice,
// decomposition and cut (LANGUAGE.md sections 4, 6, 7). The result depends only on the program,
// its parameters and the seed: never on the thread count.
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/module_string.hpp"
#include "plant/program.hpp"
#include "plant/run_state.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace plant {

class Rewriter;   // derive.cpp
class Derivation; // below
struct RulePlan;  // rewriter.hpp

// The environment phase of a step, implemented by the runtime (runtime's environment_phase.hpp):
// the plant as it is now meets its environments. It runs after `on before_step` and before the
// rewrite, in steps whose productions read query modules or whose program declares
// environments, and in this order: environments that hold segments are shown the modules bound
// to them and advance (a climber runs its physics; what broke off leaves the string), every
// environment sees the plant, ?E modules are answered, and ?P ?H ?U ?L modules receive the
// turtle's position, heading, up or left vector.
class EnvironmentPhase {
  public:
    virtual ~EnvironmentPhase() = default;
    virtual void run(const Derivation& derivation, RunState& state, ModuleString& string) = 0;
};

struct StepStats {
    int step = 0;
    std::size_t modules = 0;
    std::size_t bytes = 0;
    double ms = 0;
};

struct DeriveOptions {
    std::optional<int> steps;          // overrides the grammar's `derive N;`
    std::optional<std::uint64_t> seed; // overrides the grammar's `seed S;`
    int threads = 1;
    std::size_t max_modules = 50'000'000;
    std::size_t max_bytes = std::size_t{8} << 30;  // estimate of the string's memory
    EnvironmentPhase* environment_phase = nullptr; // none: environments never see the plant
    std::function<void(const StepStats&)> on_step;
    std::function<void(const std::string&)> on_print; // output of print(...) in hooks
    const std::atomic<bool>* interrupt = nullptr;     // set asynchronously to abandon a step
    // Whether the string keeps module identities (LANGUAGE.md section 6). Without them a
    // derivation writes 8 bytes less per module; they are kept anyway when the program can
    // observe them (it calls id(), or has query modules or environments).
    bool identities = true;
};

class Derivation {
  public:
    Derivation(const Program& program, DeriveOptions options);
    Derivation(const Derivation&) = default;
    Derivation& operator=(const Derivation&) = delete; // holds a reference to its program
    // Gives the memory freed strings kept for later steps back to the system (big_pages).
    ~Derivation();

    // Evaluates settings, builds the axiom (with decomposition) and runs `on start`.
    void start();
    // Runs one step with its hooks. Returns false when the derivation is over (the target step
    // count was reached or a hook said `stop;`).
    bool step();
    // Runs `on end`. Called once, after the last step.
    void finish();
    // start(), all steps, finish().
    void run();

    const ModuleString& string() const { return current_; }
    ModuleString& mutable_string() { return current_; }
    int steps_done() const { return step_; }
    int target_steps() const { return target_; }
    bool stopped() const { return stopped_; }
    std::uint64_t seed() const { return seed_; }
    double default_angle() const { return angle_; }
    double default_step() const { return step_length_; }
    double default_width() const { return width_; }
    std::vector<double>& globals() { return globals_; }
    int active_group() const { return group_; }
    void use_group(int group) { group_ = group; } // -1: none (the REPL's :use)
    void set_seed(std::uint64_t seed) { seed_ = seed; }
    ModuleId next_id() const { return next_id_; }
    const Program& program() const { return prog_; }
    // The live environments, made from the program's declarations by start().
    const RunState& run_state() const { return run_; }
    RunState& run_state() { return run_; }
    // Whether the string keeps module identities (see DeriveOptions::identities).
    bool keeps_identities() const { return current_.keep_ids; }

    // The string as the turtle sees it: interpretation rules applied (max_depth passes).
    ModuleString interpreted(const ModuleString& s) const;

  private:
    void run_hook(HookKind kind);
    void rewrite(const ModuleString& in, ModuleString& out, const RulePlan& plan, std::uint64_t phase,
                 int step_for_env) const;
    template <typename Setup>
    bool rewrite_direct(Rewriter& rw, const ModuleString& in, ModuleString& out, int threads,
                        const Setup& setup) const;
    void decompose(ModuleString& s, int step_for_env);
    void apply_cut(ModuleString& s) const;
    void check_limits(const ModuleString& s) const;
    void check_limits(std::size_t modules, std::size_t params) const;
    // The plan for rewriting with `sets`, built the first time and kept (copies share them).
    const RulePlan& plan_for(const std::vector<const RuleSet*>& sets) const;
    // The plan for a step with the active group: plan_for(group's rules, then the unnamed ones).
    const RulePlan& step_plan() const;

    const Program& prog_;
    DeriveOptions opt_;
    RunState run_; // copied with the derivation
    ModuleString current_;
    std::vector<double> globals_;
    int step_ = 0;
    int target_ = 0;
    int group_ = -1;
    bool stopped_ = false;
    bool started_ = false;
    std::uint64_t seed_ = 0;
    double angle_ = 90, step_length_ = 1, width_ = 1;
    mutable ModuleId next_id_ = 1;
    mutable double growth_ = 2.0, param_growth_ = 2.0; // last step's growth, for reserving memory
    mutable std::vector<std::shared_ptr<const RulePlan>> plans_;
    mutable std::vector<const RulePlan*> step_plans_; // per group + 1 (index 0: no group), from plans_
    mutable std::vector<std::uint32_t> brackets_;     // the bracket table, kept from step to step
    mutable std::vector<std::uint16_t>
        kernel_scratch_; // the symbol kernel's right keys (Rewriter::run_symbols)
    // The string a step replaced, when small, kept for the next step to write its output into:
    // small strings would otherwise pay a round of allocations a step. Copies start without one.
    struct Spare {
        static constexpr std::size_t kMaxBytes = std::size_t{1} << 20;
        ModuleString s;
        Spare() = default;
        Spare(const Spare&) {}
        Spare& operator=(const Spare&) { return *this; }
    };
    Spare spare_;
};

// The positions where the first production of `rules` matches in the derivation's current string
// (its pattern, context and condition): what `:find PATTERN` lists in the REPL.
std::vector<std::size_t> find_matches(const Derivation& d, const Program& program, const RuleSet& rules);

// Formats a string in ABOP notation (LANGUAGE.md section 11).
// With `max_chars`, stops after the module that passes that length (the REPL's :show).
std::string format_string(const Program& program, const ModuleString& s, bool with_ids = false,
                          std::size_t max_chars = ~std::size_t{0});
// Shortest text that reads back to the same double.
std::string format_double(double v);

} // namespace plant
