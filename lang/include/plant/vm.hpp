// The stack machine that runs compiled expressions, production bodies, functions and hooks.
#pragma once

#include "plant/program.hpp"

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace plant {

// What a hook asked for while it ran.
struct HookEffects {
    int use_group = -2; // -2: unchanged, -1: none, else group index
    bool stop = false;
    // Each print() line is handed to `on_print` as it is made when that is set (so a hook that
    // prints in a long loop shows its output and holds none); otherwise it is kept in `printed`.
    const std::function<void(const std::string&)>* on_print = nullptr;
    std::string printed;
};

// The default of EvalEnv::max_steps (--max-steps): 500 times what the busiest shipped grammar or
// test uses in one evaluation (about 390,000), above a loop stopped at 10 million turns (about
// 10 instructions a turn), and a runaway evaluation stops within a second.
inline constexpr std::uint64_t kDefaultMaxSteps = 200'000'000;

// The default of DeriveOptions::max_work (--max-work): the work a whole derivation may do, counted
// as VM instructions plus modules written (docs/language.md, "One work budget per run"). The
// busiest shipped grammar or benchmark does about 1.9e7; 1e11 is a few minutes of running, not days.
inline constexpr std::uint64_t kDefaultMaxWork = 100'000'000'000;

// Throws the RuntimeError (kind WorkLimit, no position) for a run past `max_work`: the same
// words on any thread count, so the message names no module.
[[noreturn]] void throw_work_limit(std::uint64_t max_work);

// Marks an identity as "new in this step"; the engine replaces it with a real identity after
// the step so identities do not depend on how the string was split between threads.
inline constexpr ModuleId kNewIdBit = ModuleId{1} << 63;

class RunState;

struct EvalEnv {
    const Program* prog = nullptr;
    // The derivation's environments (run_state.hpp): method calls read them. Null for constants
    // the compiler evaluates, which see the environments as declared.
    const RunState* run = nullptr;
    // The same, non-null only while a hook runs (one thread): edit methods change them.
    RunState* hook_run = nullptr;
    double* globals = nullptr;
    std::uint64_t seed = 0;
    std::uint64_t phase = 0;    // derivation step and pass
    std::uint64_t position = 0; // index of the module in the string being rewritten
    std::uint32_t draw = 0;     // random draws made so far for this module
    int step = 0;
    ModuleId id = 0;
    std::size_t max_output = ~std::size_t{0}; // module limit of the output
    std::size_t max_params = ~std::size_t{0}; // parameter limit of the output
    const std::atomic<bool>* interrupt = nullptr;

    // The evaluation budget ("fuel"): run() called from outside the VM (a hook, a production's
    // condition, weight, successor values or body, a setting, a constant) may execute at most
    // max_steps instructions, the functions it calls included; the interrupt is looked at every
    // kStepSlice instructions of it. steps_left and slice belong to run().
    std::uint64_t max_steps = kDefaultMaxSteps;
    std::uint64_t steps_left = 0; // of the running evaluation, beyond the current slice
    std::int64_t slice = 0;       // instructions left in the current slice
    int function = -1;            // the function being run, -1: none (for messages)
    // The run's work budget (DeriveOptions::max_work): `work` counts the instructions run() has
    // executed with this env, over all its evaluations; an evaluation stops once `work` passes
    // `work_limit` (looked at every kStepSlice instructions and when each evaluation ends, so
    // the hot loop pays nothing). max_work is the run's whole budget, for the message.
    std::uint64_t work = 0;
    std::uint64_t work_limit = ~std::uint64_t{0};
    std::uint64_t max_work = ~std::uint64_t{0};

    // Output of production bodies.
    ModuleString* out = nullptr;
    const SymbolId* keep_syms = nullptr; // predecessor modules whose identities may be kept
    const ModuleId* keep_ids = nullptr;
    std::uint32_t keep_count = 0;
    std::uint32_t keep_used = 0;  // bit mask
    ModuleId new_count = 0;       // new modules emitted by this chunk so far
    ModuleId id_base = kNewIdBit; // a new module's identity is id_base + new_count
    bool produced = false;

    // Whether child() records new nodes of the decomposition graph: in the rewrite, decomposition,
    // the axiom and hooks, not in interpretation (which changes nothing that lives on).
    bool graph_records = false;

    HookEffects* effects = nullptr; // non-null only while a hook runs
    int call_depth = 0;
    std::vector<double> arena; // operand stacks and frames of nested calls
    std::size_t arena_top = 0;

    EvalEnv() = default;
};

enum class RunStatus { Finished, Produced };

// Runs `code` with `frame` as locals. The value of an expression (up to three doubles) is copied
// to `result` when non-null. Throws RuntimeError on division by zero, NaN or infinity reaching a
// module parameter, runaway recursion and the like.
RunStatus run(const Code& code, double* frame, EvalEnv& env, double* result = nullptr);

// Replaces common instruction sequences by single instructions. Only straight-line code
// (no jumps) is changed, so no jump target moves.
void fuse(Code& code);

// Convenience for code that yields one number.
double eval_number(const Code& code, double* frame, EvalEnv& env);

// The operand stack along every path through `code`, from the opcode table's stack effects
// (opcodes.hpp): the most numbers it can hold at once, or the first instruction that could pop
// more than is there or jump out of the code. A check for tests and debugging; run() trusts the
// compiler.
struct StackCheck {
    bool ok = true;
    int max_depth = 0;
    std::size_t pc = 0; // the offending instruction when !ok
    std::string error;
};
StackCheck check_stack(const Code& code);

// One line per instruction: index, opcode name, operands a, n, b.
std::string disassemble(const Code& code);

} // namespace plant
