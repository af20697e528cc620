// The derivation engine. One step: hooks, then (if some production reads query modules) a
// turtle pass, then the parallel rewrite, decomposition and cut, then hooks again.
//
// Parallel rewriting splits the old string into stretches, one per thread. When every module is
// copied or rewritten by a fixed successor, each thread's output is counted first and written in
// place into one string; otherwise each thread writes its own buffer and the buffers are joined
// by prefix sums. Random draws are keyed by the module's position in the old string and new
// identities are numbered in string order, so the result is the same for any number of threads.
#include "plant/derive.hpp"
#include "plant/environment.hpp"

#include "plant/random.hpp"
#include "plant/vm.hpp"
#include "rewriter.hpp"

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <thread>

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

Derivation::~Derivation() {
    big_pages::trim();
}

void Derivation::check_limits(const ModuleString& s) const {
    check_limits(s.size(), s.params.size());
}

void Derivation::check_limits(std::size_t modules, std::size_t params) const {
    if (modules > opt_.max_modules)
        throw RuntimeError{Span{},
                           fmt::format("step {}: the string grew past the limit of {} modules (raise it "
                                       "with --max-modules)",
                                       step_, opt_.max_modules)};
    std::size_t estimate =
        modules * (sizeof(SymbolId) + sizeof(std::uint32_t) + (current_.keep_ids ? sizeof(ModuleId) : 0)) +
        params * sizeof(double);
    if (estimate > opt_.max_bytes)
        throw RuntimeError{Span{},
                           fmt::format("step {}: the string needs about {:.1f} GiB, more than the limit of "
                                       "{:.1f} GiB",
                                       step_, estimate / double(1 << 30), opt_.max_bytes / double(1 << 30))};
}

const RulePlan& Derivation::plan_for(const std::vector<const RuleSet*>& sets) const {
    for (const auto& p : plans_)
        if (p->sets == sets) return *p;
    plans_.push_back(std::make_shared<const RulePlan>(prog_, sets));
    return *plans_.back();
}

const RulePlan& Derivation::step_plan() const {
    const int g = group_ >= 0 && group_ < static_cast<int>(prog_.groups.size()) ? group_ : -1;
    if (step_plans_.size() != prog_.groups.size() + 1) step_plans_.assign(prog_.groups.size() + 1, nullptr);
    const RulePlan*& slot = step_plans_[static_cast<std::size_t>(g + 1)];
    if (!slot) {
        std::vector<const RuleSet*> sets;
        if (g >= 0) sets.push_back(&prog_.groups[static_cast<std::size_t>(g)]);
        sets.push_back(&prog_.rules);
        slot = &plan_for(sets);
    }
    return *slot;
}

void Derivation::rewrite(const ModuleString& in, ModuleString& out, const RulePlan& plan, std::uint64_t phase,
                         int step_for_env) const {
    const std::size_t n = in.size();
    int threads = std::max(1, opt_.threads);
    if (plan.sequential() || n < 20000) threads = 1;
    Rewriter rw(plan, in, &brackets_, &kernel_scratch_, threads == 1);
    auto setup = [&](Worker& w) {
        w.env.prog = &prog_;
        w.env.run = &run_;
        w.env.globals = const_cast<double*>(globals_.data()); // read-only during rewriting
        w.env.seed = seed_;
        w.env.phase = phase;
        w.env.step = step_for_env;
        w.env.max_output = opt_.max_modules;
        w.env.max_params = opt_.max_bytes / sizeof(double);
        w.env.interrupt = opt_.interrupt;
        w.out.keep_ids = in.keep_ids;
    };
    out.clear();
    out.keep_ids = in.keep_ids;
    // The direct path needs every module's successor to be a direct template: a plan with
    // symbols rewritten otherwise would find one in nearly every string, after counting up to it.
    if (!plan.sequential() && plan.all_direct && rewrite_direct(rw, in, out, threads, setup)) {
        // done
    } else if (threads == 1) {
        Worker w(std::move(out)); // writes into the arrays `out` has
        setup(w);
        w.env.id_base = next_id_; // one thread numbers new modules in string order directly
        // A small string reserves twice what it expects: its arrays come back as the spare two
        // steps on (see Derivation::step), and then still fit, instead of being reallocated.
        auto room = [](std::size_t want) { return want < 65536 ? 2 * want : want; };
        w.out.sym.reserve(room(static_cast<std::size_t>(n * growth_ * 1.02) + 16));
        if (w.out.keep_ids) w.out.ids.reserve(w.out.sym.capacity());
        w.out.poff.reserve(w.out.sym.capacity() + 1);
        w.out.params.reserve(room(static_cast<std::size_t>(in.params.size() * param_growth_ * 1.02) + 16));
        try {
            if (plan.right_new) {
                // right to left: new modules are marked, then numbered in string order
                w.env.id_base = kNewIdBit;
                rw.run_backward(w);
                w.out = rw.assemble_backward(w.out);
                ModuleId next = next_id_;
                for (auto& id : w.out.ids)
                    if (id & kNewIdBit) id = next++;
            } else {
                rw.run_range(w, 0, n);
            }
        } catch (const RuntimeError& e) {
            if (e.message == "module limit" || e.message == "the string outgrew the module limit")
                check_limits(w.out);
            throw;
        }
        out = std::move(w.out);
        next_id_ += w.env.new_count;
    } else {
        // Worker 0 writes into buffers sized for the whole output and numbers its new modules
        // directly; the others' parts are appended to it afterwards, so only (T-1)/T of the
        // string is copied a second time.
        std::vector<Worker> workers(static_cast<std::size_t>(threads));
        {
            std::vector<std::jthread> pool;
            for (int t = 0; t < threads; ++t) {
                pool.emplace_back([&, t] {
                    Worker& w = workers[static_cast<std::size_t>(t)];
                    setup(w);
                    std::size_t b = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
                    std::size_t e = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads);
                    std::size_t modules = (t == 0 ? n : e - b),
                                params = in.params.size() * (e - b) / std::max<std::size_t>(n, 1);
                    if (t == 0) {
                        params = in.params.size();
                        w.env.id_base = next_id_;
                    }
                    w.out.sym.reserve(static_cast<std::size_t>(modules * growth_ * 1.02) + 16);
                    if (w.out.keep_ids) w.out.ids.reserve(w.out.sym.capacity());
                    w.out.poff.reserve(w.out.sym.capacity() + 1);
                    w.out.params.reserve(static_cast<std::size_t>(params * param_growth_ * 1.02) + 16);
                    try {
                        rw.run_range(w, b, e);
                    } catch (const RuntimeError& err) {
                        w.error = err;
                    }
                });
            }
        }
        std::size_t total = 0, total_params = 0;
        for (auto& w : workers) {
            if (w.error) {
                if (w.error->message == "module limit" ||
                    w.error->message == "the string outgrew the module limit")
                    check_limits(w.out);
                throw *w.error;
            }
            total += w.out.size();
            total_params += w.out.params.size();
        }
        if (total > opt_.max_modules) {
            check_limits(total, total_params);
        }
        std::vector<std::size_t> mod_at(workers.size()), par_at(workers.size());
        std::vector<ModuleId> id_at(workers.size());
        std::size_t m = 0, p = 0;
        ModuleId ids = next_id_;
        for (std::size_t t = 0; t < workers.size(); ++t) {
            mod_at[t] = m;
            par_at[t] = p;
            id_at[t] = ids;
            m += workers[t].out.size();
            p += workers[t].out.params.size();
            ids += workers[t].env.new_count;
        }
        out.swap(workers[0].out);
        out.sym.resize(total);
        if (out.keep_ids) out.ids.resize(total);
        out.poff.resize(total + 1);
        out.params.resize(total_params);
        {
            std::vector<std::jthread> pool;
            for (std::size_t t = 1; t < workers.size(); ++t) {
                pool.emplace_back([&, t] {
                    ModuleString& src = workers[t].out;
                    std::copy(src.sym.begin(), src.sym.end(),
                              out.sym.begin() + static_cast<std::ptrdiff_t>(mod_at[t]));
                    std::copy(src.params.begin(), src.params.end(),
                              out.params.begin() + static_cast<std::ptrdiff_t>(par_at[t]));
                    for (std::size_t i = 0; i < src.size(); ++i) {
                        out.poff[mod_at[t] + i] = static_cast<std::uint32_t>(par_at[t] + src.poff[i]);
                        if (!out.keep_ids) continue;
                        ModuleId id = src.ids[i];
                        out.ids[mod_at[t] + i] = (id & kNewIdBit) ? id_at[t] + (id & ~kNewIdBit) : id;
                    }
                    ModuleString().swap(src);
                });
            }
        }
        out.poff[total] = static_cast<std::uint32_t>(total_params);
        next_id_ = ids;
    }
    if (n > 0) {
        growth_ = std::max(0.5, std::min(16.0, double(out.size()) / double(n)));
        param_growth_ =
            in.params.empty()
                ? growth_
                : std::max(0.5, std::min(16.0, double(out.params.size()) / double(in.params.size())));
    }
    check_limits(out);
}

// Whether some module of `s` is the first module of a predecessor in `rs`: a pass over the
// symbols is much cheaper than a rewrite that copies the whole string unchanged.
static bool any_candidate(const ModuleString& s, const RuleSet& rs) {
    for (SymbolId x : s.sym)
        if (x < rs.by_symbol.size() && !rs.by_symbol[x].empty()) return true;
    return false;
}

// Tries the direct path (see Rewriter::count_direct): count the output of each thread's stretch,
// allocate the output once, write the stretches in place. Returns false, having written
// nothing, when some module needs the general path.
template <typename Setup>
bool Derivation::rewrite_direct(Rewriter& rw, const ModuleString& in, ModuleString& out, int threads,
                                const Setup& setup) const {
    const std::size_t n = in.size();
    const auto T = static_cast<std::size_t>(threads);
    std::vector<Rewriter::Counts> counts(T);
    auto bounds = [&](std::size_t t) { return std::pair{n * t / T, n * (t + 1) / T}; };
    auto parallel = [&](auto&& body) {
        if (T == 1) {
            body(std::size_t{0});
            return;
        }
        std::vector<std::jthread> pool;
        for (std::size_t t = 0; t < T; ++t) pool.emplace_back([&body, t] { body(t); });
    };
    parallel([&](std::size_t t) {
        auto [b, e] = bounds(t);
        counts[t] = rw.count_direct(b, e);
    });
    std::size_t modules = 0, params = 0;
    for (const auto& c : counts) {
        if (!c.ok) return false;
        modules += c.modules;
        params += c.params;
    }
    check_limits(modules, params); // before allocating anything
    out.sym.resize(modules);
    if (out.keep_ids) out.ids.resize(modules);
    out.poff.resize(modules + 1);
    out.params.resize(params);
    out.poff[0] = 0;
    std::vector<Worker> workers(T);
    std::vector<std::size_t> m_at(T), p_at(T);
    std::vector<ModuleId> id_at(T);
    ModuleId ids = next_id_;
    for (std::size_t t = 0, m = 0, p = 0; t < T; ++t) {
        m_at[t] = m;
        p_at[t] = p;
        id_at[t] = ids;
        m += counts[t].modules;
        p += counts[t].params;
        ids += counts[t].new_ids;
    }
    parallel([&](std::size_t t) {
        Worker& w = workers[t];
        setup(w);
        auto [b, e] = bounds(t);
        try {
            rw.write_direct(w, b, e, out, m_at[t], p_at[t], id_at[t]);
        } catch (const RuntimeError& err) {
            w.error = err;
        }
    });
    for (auto& w : workers)
        if (w.error) throw *w.error;
    next_id_ = ids;
    return true;
}

void Derivation::decompose(ModuleString& s, int step_for_env) {
    if (prog_.decompose.empty()) return;
    std::vector<const RuleSet*> sets{&prog_.decompose};
    for (int pass = 0; pass < prog_.decompose.max_depth; ++pass) {
        if (!any_candidate(s, prog_.decompose)) break;
        ModuleString next;
        ModuleId before = next_id_;
        rewrite(s, next, plan_for(sets),
                (static_cast<std::uint64_t>(step_for_env) << 16) | static_cast<std::uint64_t>(pass + 1),
                step_for_env);
        bool changed =
            next_id_ != before || next.size() != s.size() || next.sym != s.sym || next.params != s.params;
        s.swap(next);
        if (!changed) break;
    }
}

void Derivation::apply_cut(ModuleString& s) const {
    if (!prog_.uses_cut) return;
    const SymbolId cut = prog_.symbols.cut, open = prog_.symbols.open_bracket,
                   close = prog_.symbols.close_bracket;
    bool any = false;
    for (SymbolId x : s.sym)
        if (x == cut) {
            any = true;
            break;
        }
    if (!any) return;
    cut_branches(s, open, close, [&](std::size_t i) { return s.sym[i] == cut; });
}

ModuleString Derivation::interpreted(const ModuleString& s) const {
    ModuleString cur = s;
    if (prog_.interpret.empty()) return cur;
    std::vector<const RuleSet*> sets{&prog_.interpret};
    ModuleId saved = next_id_;
    for (int pass = 0; pass < prog_.interpret.max_depth; ++pass) {
        if (!any_candidate(cur, prog_.interpret)) break;
        ModuleString next;
        rewrite(cur, next, plan_for(sets),
                (static_cast<std::uint64_t>(step_) << 16) | 0x8000u | static_cast<std::uint64_t>(pass),
                step_);
        bool changed = next.sym != cur.sym || next.params != cur.params;
        cur.swap(next);
        if (!changed) break;
    }
    next_id_ = saved; // interpretation never creates modules that live on
    return cur;
}

void Derivation::run_hook(HookKind kind) {
    const auto k = static_cast<std::size_t>(kind);
    if (!prog_.has_hook[k]) return;
    EvalEnv env;
    HookEffects effects;
    env.prog = &prog_;
    env.run = &run_;
    env.hook_run = &run_; // hooks alone change environments
    env.globals = globals_.data();
    env.seed = seed_;
    env.phase = (static_cast<std::uint64_t>(step_) << 16) | (0xF000u + k);
    env.position = ~std::uint64_t{0};
    env.step = step_;
    env.effects = &effects;
    std::vector<double> frame(std::max<std::size_t>(prog_.hook_frame[k], 1));
    try {
        plant::run(prog_.hooks[k], frame.data(), env);
    } catch (RuntimeError& e) {
        static const char* names[] = {"on start", "on before_step", "on after_step", "on end"};
        e.message = fmt::format("step {}, {}: {}", step_, names[k], e.message);
        throw;
    }
    if (!effects.printed.empty() && opt_.on_print) opt_.on_print(effects.printed);
    if (effects.use_group != -2) group_ = effects.use_group;
    if (effects.stop) stopped_ = true;
}

void Derivation::start() {
    run_ = RunState(prog_); // the environments as declared: a second start begins afresh
    EvalEnv env;
    env.prog = &prog_;
    env.run = &run_;
    env.globals = globals_.data();
    auto setting = [&](const Code& c, double fallback) {
        return c.empty() ? fallback : eval_number(c, nullptr, env);
    };
    double steps = opt_.steps ? *opt_.steps : setting(prog_.setting_derive, 0);
    if (steps < 0 || steps > 1e6 || steps != std::floor(steps))
        throw RuntimeError{
            prog_.setting_derive.spans.empty() ? Span{} : prog_.setting_derive.spans.back(),
            fmt::format("the number of steps must be a whole number from 0 to 1000000, found {}", steps)};
    target_ = static_cast<int>(steps);
    double seed = setting(prog_.setting_seed, 0);
    if (!(seed >= 0 && seed < 9.0e18) || seed != std::floor(seed))
        throw RuntimeError{prog_.setting_seed.spans.empty() ? Span{} : prog_.setting_seed.spans.back(),
                           fmt::format("the seed must be a whole number from 0 to 9e18, found {}", seed)};
    seed_ = opt_.seed ? *opt_.seed : static_cast<std::uint64_t>(seed);
    angle_ = setting(prog_.setting_angle, 90);
    step_length_ = setting(prog_.setting_step, 1);
    width_ = setting(prog_.setting_width, 0.1); // a tenth of the default step: a slender branch
    step_ = 0;
    stopped_ = false;
    group_ = -1;
    next_id_ = 1;
    // the axiom: emitted like a successor, then decomposed
    env.seed = seed_;
    env.phase = 0xFFFF0000ULL;
    ModuleString axiom;
    axiom.keep_ids = opt_.identities || observes_identities(prog_);
    env.out = &axiom;
    env.max_output = opt_.max_modules;
    env.id_base = next_id_;
    try {
        plant::run(prog_.axiom, nullptr, env);
    } catch (const RuntimeError& e) {
        if (e.message == "the string outgrew the module limit") check_limits(axiom);
        throw;
    }
    next_id_ += env.new_count;
    current_.swap(axiom);
    try {
        decompose(current_, 0);
        apply_cut(current_);
    } catch (RuntimeError& e) {
        if (e.message.rfind("step ", 0) != 0) e.message = "step 0: " + e.message;
        throw;
    }
    started_ = true;
    run_hook(HookKind::Start);
    // The plan for the rule sets the first step uses is prepared here, with the axiom, as
    // lindenmayer.js prepares its productions when the system is made: the steps' timings
    // (plant derive --stats) are then the rewriting alone.
    (void)step_plan();
}

bool Derivation::step() {
    if (!started_) start();
    if (stopped_ || step_ >= target_) return false;
    if (opt_.interrupt && opt_.interrupt->load()) throw RuntimeError{Span{}, "interrupted"};
    double t0 = now_ms();
    run_hook(HookKind::BeforeStep);
    if (stopped_) return false;
    const RulePlan& plan = step_plan();
    // the environment phase: the plant as it is now meets its environments, query modules are filled
    if ((plan.queries || !prog_.environments.empty()) && opt_.environment_phase)
        opt_.environment_phase->run(*this, run_, current_);
    // (moved rather than swapped: an empty ModuleString would allocate its first offset; a
    // moved-from one is only ever cleared, which restores it)
    ModuleString next(std::move(spare_.s));
    ++step_;
    try {
        rewrite(current_, next, plan, static_cast<std::uint64_t>(step_) << 16, step_);
        current_.swap(next);
        if (next.bytes() <= Spare::kMaxBytes)
            spare_.s = std::move(next);
        else
            ModuleString().swap(next); // a large one is freed before decomposition
        decompose(current_, step_);
        apply_cut(current_);
    } catch (RuntimeError& e) {
        if (e.message.rfind("step ", 0) != 0) e.message = fmt::format("step {}: {}", step_, e.message);
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
    big_pages::trim(); // the pages freed strings kept for later steps go back to the system
}

std::vector<std::size_t> find_matches(const Derivation& d, const Program& program, const RuleSet& rules) {
    std::vector<std::size_t> out;
    if (rules.productions.empty()) return out;
    const ModuleString& s = d.string();
    RulePlan plan(program, {&rules});
    Rewriter rw(plan, s);
    Worker w;
    w.env.prog = &program;
    // another program (the REPL's :find compiles one) sees its environments as declared
    w.env.run = &program == &d.program() ? &d.run_state() : nullptr;
    std::vector<double> globals = const_cast<Derivation&>(d).globals();
    w.env.globals = globals.data();
    w.env.seed = d.seed();
    w.env.step = d.steps_done();
    const Production& pr = rules.productions[0];
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.sym[i] == pr.strict[0].sym && rw.matches_at(w, i, pr)) out.push_back(i);
    return out;
}

} // namespace plant
