// The derivation's lifecycle: settings and the axiom (start), steps, hooks, the end. One step:
// hooks, then the environment phase (when some production reads query modules or the program
// declares environments), then the rewrite, decomposition and cut (the engine,
// rewrite/engine.cpp), then hooks again.
#include "plant/derive.hpp"
#include "plant/environment.hpp"
#include "plant/memory_budget.hpp"

#include "plant/streams.hpp"
#include "plant/vm.hpp"
#include "rewrite/engine.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace plant {

namespace {

// Whether anything the program does depends on module identities: id(), the query pass (which
// finds modules by identity between the turtle and the rewrite) and environments (which
// remember the modules they were told about).
bool observes_identities(const Program& p) {
    if (p.uses_id || !p.environments.empty() || reads_queries(p, p.rules)) return true;
    for (const RuleSet& g : p.groups)
        if (reads_queries(p, g)) return true;
    return false;
}

// What a step's tables take a module, besides the strings: 4 bytes of bracket table, 4 to spare
// for the workers' match tables. (The symbol kernel's keys, a BigVector, charge for themselves.)
constexpr std::size_t kTableBytesPerModule = 8;

double now_ms() {
    using namespace std::chrono;
    return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

} // namespace

// ---- Derivation ------------------------------------------------------------------------------

Derivation::Derivation(const Program& program, DeriveOptions options)
    : prog_(program), opt_(std::move(options)) {
    globals_ = prog_.global_values;
}

// Kept pages left to the process when a derivation ends: one 2 MiB page for each of two
// derivations at once, so that the next variant of a batch (or the REPL's next run) writes its
// small strings into a warm page instead of clearing a fresh one.
constexpr std::size_t kKeepAfterRun = 2 * big_pages::kHuge;

Derivation::~Derivation() {
    big_pages::trim(kKeepAfterRun);
}

ModuleId Derivation::next_id() const {
    return engine_->next_id;
}

std::uint64_t Derivation::work_done() const {
    return engine_->work;
}

std::uint64_t Derivation::modules_counted() const {
    return engine_->modules_counted;
}

void Derivation::reset_work() {
    engine_->work = 0;
}

void Derivation::limit_work(EvalEnv& env) const {
    env.max_work = opt_.max_work;
    env.work_limit = opt_.max_work - std::min(opt_.max_work, engine_->work);
}

void Derivation::charge_work(const EvalEnv& env) {
    engine_->work += env.work;
    if (engine_->work > opt_.max_work) throw_work_limit(opt_.max_work);
}

ModuleString Derivation::interpreted(const ModuleString& s) const {
    return engine_->interpreted(*this, s);
}

void Derivation::commit_graph() {
    if (DecompositionGraph* g = run_.graph()) g->commit();
}

void Derivation::run_hook(HookKind kind) {
    const auto k = static_cast<std::size_t>(kind);
    if (!prog_.has_hook[k]) return;
    EvalEnv env;
    env.graph_records = true;
    HookEffects effects;
    env.prog = &prog_;
    env.run = &run_;
    env.hook_run = &run_; // hooks alone change environments
    env.globals = globals_.data();
    env.seed = seed_;
    env.phase = stream::hook(step_, k);
    env.position = stream::kNoPosition;
    env.step = step_;
    env.effects = &effects;
    env.max_steps = opt_.max_steps;
    env.interrupt = opt_.interrupt;
    if (opt_.on_print) effects.on_print = &opt_.on_print; // each line as it is printed
    limit_work(env);
    std::vector<double> frame(std::max<std::size_t>(prog_.hook_frame[k], 1));
    try {
        plant::run(prog_.hooks[k], frame.data(), env);
        charge_work(env);
    } catch (RuntimeError& e) {
        e.step = step_;
        e.message = fmt::format("step {}, on {}: {}", step_, ast::spelling(kind), e.message);
        throw;
    }
    try {
        commit_graph();
    } catch (RuntimeError& e) {
        e.message = fmt::format("step {}, on {}: {}", step_, ast::spelling(kind), e.message);
        throw;
    }
    if (!effects.printed.empty() && opt_.on_print) opt_.on_print(effects.printed);
    if (effects.use_group != -2) group_ = effects.use_group;
    if (effects.stop) stopped_ = true;
}

namespace {

// What a setting, and the axiom after them, are evaluated with: the program, the run's state and
// globals, and the VM's budget.
EvalEnv settings_env(Derivation& d, const Program& prog) {
    EvalEnv env;
    env.prog = &prog;
    env.run = &d.run_state();
    env.globals = d.globals().data();
    env.max_steps = d.options().max_steps;
    env.interrupt = d.options().interrupt;
    env.max_work = d.options().max_work;
    env.work_limit = d.options().max_work; // (start() counts from zero)
    return env;
}

} // namespace

void Derivation::evaluate_settings() {
    // the environments as declared (a second start begins afresh); the graph gets half the
    // string's budget, at most 1 GiB (a bonsai's graph holds hundreds of nodes, not millions)
    run_ = RunState(prog_, opt_.edits ? opt_.edits : prog_.graph.edits,
                    std::min(opt_.max_bytes / 2, std::size_t{1} << 30));
    EvalEnv env = settings_env(*this, prog_);
    using Key = ast::SettingKey;
    auto setting = [&](Key key, double fallback) {
        const Code& c = prog_.setting(key);
        return c.empty() ? fallback : eval_number(c, nullptr, env);
    };
    auto where = [&](Key key) {
        const Code& c = prog_.setting(key);
        return c.spans.empty() ? Span{} : c.spans.back();
    };
    double steps = opt_.steps ? *opt_.steps : setting(Key::Derive, 0);
    if (steps < 0 || steps > 1e6 || steps != std::floor(steps))
        throw RuntimeError{
            RuntimeErrorKind::Setting, where(Key::Derive),
            fmt::format("the number of steps must be a whole number from 0 to 1000000, found {}", steps)};
    target_ = static_cast<int>(steps);
    double seed = setting(Key::Seed, 0);
    if (!(seed >= 0 && seed <= 9.0e18) || seed != std::floor(seed))
        throw RuntimeError{RuntimeErrorKind::Setting, where(Key::Seed),
                           fmt::format("the seed must be a whole number from 0 to 9e18, found {}", seed)};
    seed_ = opt_.seed ? *opt_.seed : static_cast<std::uint64_t>(seed);
    angle_ = setting(Key::Angle, 90);
    step_length_ = setting(Key::Step, 1);
    width_ = setting(Key::Width, 0.1); // a tenth of the default step: a slender branch
    if (!std::isfinite(angle_))
        throw RuntimeError{RuntimeErrorKind::Setting, where(Key::Angle),
                           fmt::format("the angle must be a finite number, found {}", angle_)};
    if (!std::isfinite(step_length_))
        throw RuntimeError{RuntimeErrorKind::Setting, where(Key::Step),
                           fmt::format("the step must be a finite number, found {}", step_length_)};
    if (!(width_ >= 0 && std::isfinite(width_)))
        throw RuntimeError{RuntimeErrorKind::Setting, where(Key::Width),
                           fmt::format("the width must be a finite number, 0 or more, found {}", width_)};
    width_scale_ = setting(Key::WidthScale, 1);
    if (!(width_scale_ > 0 && width_scale_ <= 1e6))
        throw RuntimeError{
            RuntimeErrorKind::Setting, where(Key::WidthScale),
            fmt::format("width_scale must be a number above 0 and at most 1000000, found {}", width_scale_)};
    engine_->work += env.work; // (each setting is bounded by --max-steps alone)
}

void Derivation::start() {
    engine_->work = 0;
    evaluate_settings();
    EvalEnv env = settings_env(*this, prog_);
    step_ = 0;
    stopped_ = false;
    group_ = -1;
    engine_->next_id = 1;
    engine_->forget_counts();
    // the axiom: emitted like a successor, then decomposed
    env.seed = seed_;
    env.phase = stream::kAxiom;
    ModuleString axiom;
    axiom.keep_ids = opt_.identities || observes_identities(prog_);
    axiom.use_kinds(&prog_.kinds);
    env.out = &axiom;
    env.max_output = opt_.max_modules;
    env.id_base = engine_->next_id;
    env.graph_records = true;
    try {
        plant::run(prog_.axiom, nullptr, env);
        commit_graph();
        env.work += axiom.size(); // the axiom's modules are written too
        charge_work(env);
    } catch (const RuntimeError& e) {
        if (e.kind == RuntimeErrorKind::ModuleLimit) engine_->check_limits(*this, axiom);
        throw;
    }
    engine_->next_id += env.new_count;
    current_.swap(axiom);
    try {
        engine_->decompose(*this, current_, 0);
        commit_graph();
        Engine::apply_cut(prog_, current_);
    } catch (RuntimeError& e) {
        e.at_step(0);
        throw;
    }
    started_ = true;
    run_hook(HookKind::Start);
    // The plan for the rule sets the first step uses is prepared here, with the axiom, as
    // lindenmayer.js prepares its productions when the system is made: the steps' timings
    // (plant derive --stats) are then the rewriting alone.
    engine_->step_plan(*this);
}

bool Derivation::step() {
    if (!started_) start();
    if (stopped_ || step_ >= target_) return false;
    if (opt_.interrupt && opt_.interrupt->load())
        throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
    double t0 = now_ms();
    run_hook(HookKind::BeforeStep);
    if (stopped_) return false;
    const RulePlan& plan = engine_->step_plan(*this);
    // the environment phase: the plant as it is now meets its environments, query modules are filled
    if ((plan.queries || !prog_.environments.empty()) && opt_.environment_phase) {
        engine_->forget_counts(); // the phase may edit the string in place
        opt_.environment_phase->run(*this, run_, current_);
    }
    // (moved rather than swapped: an empty ModuleString would allocate its first offset; a
    // moved-from one is only ever cleared, which restores it)
    ModuleString next(std::move(engine_->spare));
    ++step_;
    try {
        // the tables the engine keeps beside the strings for a step (the bracket table, the symbol
        // kernel's keys, the workers' match tables), charged against --max-memory before the
        // rewrite (the strings charge for themselves, see big_allocator.hpp)
        memory::Reservation tables(current_.size() * kTableBytesPerModule);
        engine_->rewrite(*this, current_, next, plan, stream::step(step_), step_);
        commit_graph();
        current_.swap(next);
        if (next.bytes() <= Engine::kMaxSpareBytes)
            engine_->spare = std::move(next); // (the spare string: see Engine::spare)
        else
            ModuleString().swap(next); // a large one is freed before decomposition
        engine_->decompose(*this, current_, step_);
        commit_graph();
        Engine::apply_cut(prog_, current_);
        memory::check_resident_between_steps(); // the backstop, for what no charge saw
    } catch (RuntimeError& e) {
        e.at_step(step_);
        throw;
    }
    run_hook(HookKind::AfterStep);
    if (opt_.on_step) opt_.on_step(StepStats{step_, current_.size(), current_.bytes(), now_ms() - t0});
    return !stopped_ && step_ < target_;
}

void Derivation::finish() {
    run_hook(HookKind::End);
}

void Derivation::run() {
    start();
    while (step()) {
    }
    finish();
    big_pages::trim(kKeepAfterRun); // what freed strings kept for later steps, but two pages, goes back
}

} // namespace plant
