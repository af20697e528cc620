// The derivation: hooks, parallel rewriting with tree-aware context, stochastic choice,
// decomposition and cut (docs/language.md: productions, module identity, hooks and groups).
// The result depends only on the program, its parameters and the seed: never on the thread count.
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/module_string.hpp"
#include "plant/program.hpp"
#include "plant/run_state.hpp"
#include "plant/vm.hpp"

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace plant {

class Derivation; // below
struct Engine;    // the rewriting engine's state (lang/src/rewrite/engine.hpp)

namespace detail {
// Owns a derivation's engine state. A copy gets what a copied derivation keeps (see Engine's copy
// constructor): the rule plans, shared; the identity counter; no buffers and no spare string.
class EngineHandle {
  public:
    EngineHandle();
    EngineHandle(const EngineHandle& other);
    EngineHandle& operator=(const EngineHandle&) = delete;
    ~EngineHandle();
    // Non-const from a const derivation: the engine's caches (rule plans built on first use,
    // scratch buffers) fill as a const Derivation is read, as in interpreted(). They change no
    // result, but one derivation must not be read from two threads at once.
    Engine* operator->() const { return engine_.get(); }
    Engine& operator*() const { return *engine_; }

  private:
    std::unique_ptr<Engine> engine_;
};
} // namespace detail

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
    // Instructions one evaluation may run (a hook call; a production's condition, weight or
    // body for one module; a setting): the VM's budget (vm.hpp, EvalEnv::max_steps).
    std::uint64_t max_steps = kDefaultMaxSteps;
    // The work the whole derivation may do, from start() on (--max-work): every VM instruction of
    // its settings, axiom, hooks, productions and decomposition, plus every module its rewrites
    // and decomposition write (docs/language.md, "One work budget per run"). Past it: a
    // RuntimeError of kind WorkLimit naming the step (and the hook), the same on any thread count.
    std::uint64_t max_work = kDefaultMaxWork;
    // Whether the string keeps module identities (docs/language.md, module identity). Without them a
    // derivation writes 8 bytes less per module; they are kept anyway when the program can
    // observe them (it calls id(), or has query modules or environments).
    bool identities = true;
    // The edits applied to the decomposition graph (docs/language.md, decomposition graphs); null:
    // none. Read with parse_edits (graph.hpp); ignored when the program declares no graph.
    std::shared_ptr<const GraphEdits> edits;
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
    // The first part of start(): evaluates the settings (derive, seed, angle, step, width,
    // width_scale) and checks their ranges, throwing a RuntimeError at the setting otherwise.
    // `plant check` calls it alone, so that it refuses what `derive` would.
    void evaluate_settings();
    // Runs one step with its hooks. Returns false when the derivation is over (the target step
    // count was reached or a hook said `stop;`).
    bool step();
    // Runs `on end`. Called once, after the last step.
    void finish();
    // start(), all steps, finish().
    void run();

    const ModuleString& string() const { return current_; }
    int steps_done() const { return step_; }
    int target_steps() const { return target_; }
    bool stopped() const { return stopped_; }
    std::uint64_t seed() const { return seed_; }
    double default_angle() const { return angle_; }
    double default_step() const { return step_length_; }
    double default_width() const { return width_; }
    // The grammar's `width_scale`: what the mesher multiplies drawn widths by (1 when not set).
    double width_scale() const { return width_scale_; }
    std::vector<double>& globals() { return globals_; }
    const std::vector<double>& globals() const { return globals_; }
    int active_group() const { return group_; }
    void use_group(int group) { group_ = group; } // -1: none (the REPL's :use)
    ModuleId next_id() const;
    // The work done since start() (see DeriveOptions::max_work).
    std::uint64_t work_done() const;
    // The modules the direct path read only to size its output, since the derivation was made
    // (a measure for tests: the counts carried from step to step should keep it small).
    std::uint64_t modules_counted() const;
    // Starts a fresh work budget without changing the derivation (the REPL: one per command).
    void reset_work();
    const Program& program() const { return prog_; }
    const DeriveOptions& options() const { return opt_; }
    // The live environments, made from the program's declarations by start().
    const RunState& run_state() const { return run_; }
    RunState& run_state() { return run_; }
    // Whether the string keeps module identities (see DeriveOptions::identities).
    bool keeps_identities() const { return current_.keep_ids; }

    // The string as the turtle sees it: interpretation rules applied (max_depth passes).
    ModuleString interpreted(const ModuleString& s) const;

  private:
    friend struct Engine; // reads the program, options, settings and string it rewrites

    void run_hook(HookKind kind);
    // Adds the instructions `env` ran to the run's work, stopping past --max-work.
    void charge_work(const EvalEnv& env);
    // What an evaluation of the derivation's own (a setting, the axiom, a hook) may still run.
    void limit_work(EvalEnv& env) const;
    // Commits the graph nodes made in the pass that just ended (no-op without a graph).
    void commit_graph();

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
    double angle_ = 90, step_length_ = 1, width_ = 1, width_scale_ = 1;
    detail::EngineHandle engine_; // the rule plans, the identity counter, buffers kept between steps
};

// The positions where the first production of `rules` matches in the derivation's current string
// (its pattern, context and condition): what `:find PATTERN` lists in the REPL.
std::vector<std::size_t> find_matches(const Derivation& d, const Program& program, const RuleSet& rules);

// Formats a string in ABOP notation (docs/language.md, printing strings).
// With `max_chars`, stops after the module that passes that length (the REPL's :show).
std::string format_string(const Program& program, const ModuleString& s, bool with_ids = false,
                          std::size_t max_chars = ~std::size_t{0});
// Shortest text that reads back to the same double.
std::string format_double(double v);

} // namespace plant
