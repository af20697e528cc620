// The passes a step runs over the string. Parallel rewriting splits the old string into
// stretches, one per thread. When every module is copied or rewritten by a fixed successor, each
// thread's output is counted first and written in place into one string (rewrite_direct);
// otherwise each thread writes its own buffer and the buffers are joined by prefix sums
// (rewrite_parallel). Random draws are keyed by the module's position in the old string and new
// identities are numbered in string order, so the result is the same for any number of threads.
#include "engine.hpp"

#include "plant/memory_budget.hpp"
#include "plant/streams.hpp"
#include "rewriter.hpp"
#include <plant/crew.hpp>

#include <fmt/format.h>

#include <algorithm>

namespace plant {

namespace detail {

EngineHandle::EngineHandle() : engine_(std::make_unique<Engine>()) {}
EngineHandle::EngineHandle(const EngineHandle& other) : engine_(std::make_unique<Engine>(*other.engine_)) {}
EngineHandle::~EngineHandle() = default;

} // namespace detail

namespace {

// Whether some module of `s` is the first module of a predecessor in `rs`: a pass over the
// symbols is much cheaper than a rewrite that copies the whole string unchanged.
bool any_candidate(const ModuleString& s, const RuleSet& rs) {
    for (std::size_t i = 0; i < s.size(); ++i)
        if (const SymbolId x = s.symbol(i); x < rs.by_symbol.size() && !rs.by_symbol[x].empty()) return true;
    return false;
}

// After a write sized from the counts: whether each thread's stretch ended where the next one's
// began (its bound was exact) and the identities they numbered follow on (also when no
// identities are kept: the counter moves on as on one thread); if so, cuts `out` to
// what was written (the last stretch's bound may exceed it).
bool cut_to_written(ModuleString& out, const std::vector<Rewriter::Counts>& written,
                    const std::vector<std::size_t>& m_at, const std::vector<std::size_t>& p_at,
                    const std::vector<ModuleId>& id_at) {
    const std::size_t T = written.size();
    for (std::size_t t = 0; t + 1 < T; ++t)
        if (m_at[t] + written[t].modules != m_at[t + 1] || p_at[t] + written[t].params != p_at[t + 1] ||
            id_at[t] + written[t].new_ids != id_at[t + 1])
            return false;
    const std::size_t m = m_at[T - 1] + written[T - 1].modules;
    out.kinds.resize(m);
    if (out.keep_ids) out.ids.resize(m);
    out.params.resize(p_at[T - 1] + written[T - 1].params);
    out.block_at.resize((m + ModuleString::kBlock - 1) >> ModuleString::kBlockShift);
    return true;
}

} // namespace

void Engine::check_limits(const Derivation& d, const ModuleString& s) const {
    check_limits(d, s.size(), s.params.size());
}

void Engine::check_limits(const Derivation& d, std::size_t modules, std::size_t params) const {
    auto limit = [&](std::string message) {
        RuntimeError e{RuntimeErrorKind::ModuleLimit, Span{}, std::move(message)};
        e.at_step(d.step_);
        return e;
    };
    if (modules > d.opt_.max_modules)
        throw limit(fmt::format("the string grew past the limit of {} modules (raise it with --max-modules)",
                                d.opt_.max_modules));
    // a module holds its symbol and a byte of arity (the block offsets add 4 bytes per 64
    // modules, docs/rewriting.md), its identity when kept, and its parameters
    std::size_t estimate = modules * (sizeof(SymbolId) + 1 + (d.current_.keep_ids ? sizeof(ModuleId) : 0)) +
                           modules / 16 + params * sizeof(double);
    if (estimate > d.opt_.max_bytes)
        throw limit(fmt::format("the string needs about {} MB, more than the {} MB it may take (half of "
                                "--max-memory): raise --max-memory",
                                (estimate + (1 << 20) - 1) >> 20, d.opt_.max_bytes >> 20));
}

const RulePlan& Engine::plan_for(const Program& prog, const std::vector<const RuleSet*>& sets) {
    for (const auto& p : plans)
        if (p->sets == sets) return *p;
    plans.push_back(std::make_shared<const RulePlan>(prog, sets));
    return *plans.back();
}

const RulePlan& Engine::step_plan(const Derivation& d) {
    const Program& prog = d.prog_;
    const int g = d.group_ >= 0 && d.group_ < static_cast<int>(prog.groups.size()) ? d.group_ : -1;
    if (step_plans.size() != prog.groups.size() + 1) step_plans.assign(prog.groups.size() + 1, nullptr);
    const RulePlan*& slot = step_plans[static_cast<std::size_t>(g + 1)];
    if (!slot) {
        std::vector<const RuleSet*> sets;
        if (g >= 0) sets.push_back(&prog.groups[static_cast<std::size_t>(g)]);
        sets.push_back(&prog.rules);
        slot = &plan_for(prog, sets);
    }
    return *slot;
}

void Engine::rewrite(const Derivation& d, const ModuleString& in, ModuleString& out, const RulePlan& plan,
                     std::uint64_t phase, int step_for_env) {
    const std::size_t n = in.size();
    int threads = std::max(1, d.opt_.threads);
    if (plan.sequential() || n < 20000) threads = 1;
    // The symbol kernel runs on one thread (Rewriter::run_symbols): a string it can rewrite is
    // rewritten whole, whatever the thread count.
    const bool kernel_may = plan.symbol_kernel && in.params.empty() && !in.keep_ids;
    Rewriter rw(plan, in, &brackets, &kernel_scratch, threads == 1 || kernel_may);
    if (rw.kernel_applies()) threads = 1;
    rw.set_draws(d.seed_, phase);
    auto setup = [&](Worker& w) {
        w.env.prog = &d.prog_;
        w.env.run = &d.run_;
        w.env.globals = const_cast<double*>(d.globals_.data()); // read-only during rewriting
        w.env.seed = d.seed_;
        w.env.phase = phase;
        w.env.step = step_for_env;
        w.env.max_output = d.opt_.max_modules;
        w.env.max_params = d.opt_.max_bytes / sizeof(double);
        w.env.interrupt = d.opt_.interrupt;
        w.env.max_steps = d.opt_.max_steps;
        w.env.graph_records = !interpreting; // interpretation makes no node that lives on
        if (!interpreting) {                 // (the turtle's view is not the derivation's work)
            w.env.max_work = d.opt_.max_work;
            w.env.work_limit = d.opt_.max_work - std::min(d.opt_.max_work, work);
        }
        w.out.keep_ids = in.keep_ids;
        w.out.use_kinds_of(in);
    };
    out.clear();
    out.keep_ids = in.keep_ids;
    out.use_kinds_of(in);
    // The direct path needs every module's successor to be a direct template: a plan with
    // symbols rewritten otherwise would find one in nearly every string, after counting up to it.
    // (interpretation rewrites a copy of the string and leaves the counts to the string itself)
    const bool counted = !interpreting && counts.of == in.kinds.data() && counts.size == n && !in.empty();
    if (!interpreting) forget_counts();
    if (copies_apply(plan, in)) {
        rewrite_copies(d, in, out, plan, counted);
    } else if (!plan.sequential() && plan.all_direct &&
               rewrite_direct(d, rw, in, out, plan, threads, counted, setup)) {
        // done
    } else if (threads == 1) {
        Worker w(std::move(out)); // writes into the arrays `out` has
        setup(w);
        rewrite_one_thread(d, rw, in, w, plan);
        out = std::move(w.out);
    } else {
        rewrite_parallel(d, rw, in, out, threads, setup);
    }
    if (n > 0) {
        growth = std::max(0.5, std::min(16.0, double(out.size()) / double(n)));
        param_growth =
            in.params.empty()
                ? growth
                : std::max(0.5, std::min(16.0, double(out.params.size()) / double(in.params.size())));
    }
    check_limits(d, out);
    if (!interpreting) { // the workers' instructions were added as they finished; now the modules
        work += out.size();
        if (work > d.opt_.max_work) throw_work_limit(d.opt_.max_work);
    }
}

// The whole string on one thread, which numbers new modules in string order as it writes them.
void Engine::rewrite_one_thread(const Derivation& d, Rewriter& rw, const ModuleString& in, Worker& w,
                                const RulePlan& plan) {
    const std::size_t n = in.size();
    w.env.id_base = next_id;
    // A small string reserves twice what it expects: its arrays come back as the spare two
    // steps on (see Derivation::step), and then still fit, instead of being reallocated.
    auto room = [](std::size_t want) { return want < 65536 ? 2 * want : want; };
    w.out.kinds.reserve(room(static_cast<std::size_t>(n * growth * 1.02) + 16));
    if (w.out.keep_ids) w.out.ids.reserve(w.out.kinds.capacity());
    w.out.params.reserve(room(static_cast<std::size_t>(in.params.size() * param_growth * 1.02) + 16));
    try {
        if (plan.right_new) {
            // right to left: new modules are marked, then numbered in string order
            w.env.id_base = kNewIdBit;
            rw.run_backward(w);
            w.out = rw.assemble_backward(w.out);
            ModuleId next = next_id;
            for (auto& id : w.out.ids)
                if (id & kNewIdBit) id = next++;
        } else {
            rw.run_range(w, 0, n);
        }
    } catch (const RuntimeError& e) {
        if (e.kind == RuntimeErrorKind::ModuleLimit) check_limits(d, w.out);
        throw;
    }
    next_id += w.env.new_count;
    if (!interpreting) work += w.env.work;
}

// Worker 0 writes into buffers sized for the whole output and numbers its new modules directly;
// the others' parts are appended to it afterwards, so only (T-1)/T of the string is copied a
// second time.
template <typename Setup>
void Engine::rewrite_parallel(const Derivation& d, Rewriter& rw, const ModuleString& in, ModuleString& out,
                              int threads, const Setup& setup) {
    const std::size_t n = in.size();
    std::vector<Worker> workers(static_cast<std::size_t>(threads));
    const std::string* stage = memory::Stage::current(); // (interpretation's, say, not the derivation's)
    run_on_crew(static_cast<std::size_t>(threads), [&](std::size_t part) {
        const int t = static_cast<int>(part);
        memory::InStage named(stage);
        Worker& w = workers[static_cast<std::size_t>(t)];
        setup(w);
        std::size_t b = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
        std::size_t e = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads);
        std::size_t modules = (t == 0 ? n : e - b),
                    params = in.params.size() * (e - b) / std::max<std::size_t>(n, 1);
        if (t == 0) {
            params = in.params.size();
            w.env.id_base = next_id;
        }
        w.out.kinds.reserve(static_cast<std::size_t>(modules * growth * 1.02) + 16);
        if (w.out.keep_ids) w.out.ids.reserve(w.out.kinds.capacity());
        w.out.params.reserve(static_cast<std::size_t>(params * param_growth * 1.02) + 16);
        try {
            rw.run_range(w, b, e);
        } catch (const RuntimeError& err) {
            w.error = err;
        }
    });
    std::size_t total = 0, total_params = 0;
    for (auto& w : workers) {
        if (w.error) {
            if (w.error->kind == RuntimeErrorKind::ModuleLimit) check_limits(d, w.out);
            throw *w.error;
        }
        total += w.out.size();
        total_params += w.out.params.size();
        if (!interpreting) work += w.env.work;
    }
    if (total > d.opt_.max_modules) {
        check_limits(d, total, total_params);
    }
    std::vector<std::size_t> mod_at(workers.size()), par_at(workers.size());
    std::vector<ModuleId> id_at(workers.size());
    std::size_t m = 0, p = 0;
    ModuleId ids = next_id;
    for (std::size_t t = 0; t < workers.size(); ++t) {
        mod_at[t] = m;
        par_at[t] = p;
        id_at[t] = ids;
        m += workers[t].out.size();
        p += workers[t].out.params.size();
        ids += workers[t].env.new_count;
    }
    out.swap(workers[0].out);
    const std::size_t m0 = out.size(), p0 = out.params.size(); // worker 0's part
    out.kinds.resize(total);
    if (out.keep_ids) out.ids.resize(total);
    out.params.resize(total_params);
    run_on_crew(workers.size() - 1, [&](std::size_t part) {
        const std::size_t t = part + 1;
        ModuleString& src = workers[t].out;
        std::copy(src.kinds.begin(), src.kinds.end(),
                  out.kinds.begin() + static_cast<std::ptrdiff_t>(mod_at[t]));
        std::copy(src.params.begin(), src.params.end(),
                  out.params.begin() + static_cast<std::ptrdiff_t>(par_at[t]));
        for (std::size_t i = 0; out.keep_ids && i < src.size(); ++i) {
            ModuleId id = src.ids[i];
            out.ids[mod_at[t] + i] = (id & kNewIdBit) ? id_at[t] + (id & ~kNewIdBit) : id;
        }
        ModuleString().swap(src);
    });
    out.index_from(m0, p0);
    next_id = ids;
}

// Tries the direct path (see Rewriter::count_direct): count the output of each thread's stretch,
// allocate the output once, write the stretches in place. Returns false, having written
// nothing, when some module needs the general path. On one thread, a string the last rewrite
// counted (`counted`, see Engine::counts) is not read to count: its output is sized from the
// counts, and cut to what was written when that was only a bound.
template <typename Setup>
bool Engine::rewrite_direct(const Derivation& d, Rewriter& rw, const ModuleString& in, ModuleString& out,
                            const RulePlan& plan, int threads, bool counted, const Setup& setup) {
    const std::size_t n = in.size();
    const auto T = static_cast<std::size_t>(threads);
    std::vector<Rewriter::Counts> counts_at(T);
    auto bounds = [&](std::size_t t) { return std::pair{n * t / T, n * (t + 1) / T}; };
    auto parallel = [&](auto&& body) { run_on_crew(T, body); };
    std::size_t modules = 0, params = 0;
    std::vector<std::size_t> m_at(T), p_at(T);
    std::vector<ModuleId> id_at(T);
    // sized: from the counts, without reading the string (exact, or bounds when a guarded
    // symbol's outcomes differ in size; then each thread's stretch starts at a bound)
    const bool sized = counted && (T == 1 || slices_missed != &plan) &&
                       size_from_counts(plan, in, modules, params) && within_limits(d, modules, params) &&
                       (T == 1 || size_slices(plan, in, T, m_at, p_at, id_at));
    if (!sized) {
        modules = params = 0; // (size_from_counts may have left a partial sum)
        parallel([&](std::size_t t) {
            auto [b, e] = bounds(t);
            counts_at[t] = rw.count_direct(b, e);
        });
        modules_counted += n;
        for (const auto& c : counts_at) {
            if (!c.ok) return false;
            modules += c.modules;
            params += c.params;
        }
        check_limits(d, modules, params); // before allocating anything
        ModuleId ids = next_id;
        for (std::size_t t = 0, m = 0, p = 0; t < T; ++t) {
            m_at[t] = m;
            p_at[t] = p;
            id_at[t] = ids;
            m += counts_at[t].modules;
            p += counts_at[t].params;
            ids += counts_at[t].new_ids;
        }
    } else if (T == 1) {
        id_at[0] = next_id;
    }
    out.kinds.resize(modules);
    if (out.keep_ids) out.ids.resize(modules);
    out.params.resize(params);
    out.block_at.resize((modules + ModuleString::kBlock - 1) >> ModuleString::kBlockShift);
    std::vector<Worker> workers(T);
    std::vector<std::vector<std::uint64_t>> tallies(T, std::vector<std::uint64_t>(plan.outcome_tmpl.size()));
    parallel([&](std::size_t t) {
        Worker& w = workers[t];
        setup(w);
        auto [b, e] = bounds(t);
        try {
            counts_at[t] = rw.write_direct(w, b, e, out, m_at[t], p_at[t], id_at[t], tallies[t].data());
        } catch (const RuntimeError& err) {
            w.error = err;
        }
    });
    for (auto& w : workers)
        if (w.error) throw *w.error;
    if (sized && !cut_to_written(out, counts_at, m_at, p_at, id_at)) {
        slices_missed = &plan; // the stretches left gaps: count, and write again
        return rewrite_direct(d, rw, in, out, plan, threads, counted, setup);
    }
    for (auto& w : workers)
        if (!interpreting) work += w.env.work;
    next_id = id_at[T - 1] + counts_at[T - 1].new_ids;
    if (!interpreting) {
        count_outcomes(plan, tallies, counted, out);
        keep_snapshots(plan, workers, tallies, m_at);
    }
    return true;
}

bool Engine::within_limits(const Derivation& d, std::size_t modules, std::size_t params) const {
    try {
        check_limits(d, modules, params);
    } catch (const RuntimeError&) {
        return false;
    }
    return true;
}

void Engine::count_outcomes(const RulePlan& plan, const std::vector<std::vector<std::uint64_t>>& tallies,
                            bool counted, const ModuleString& out) {
    const std::size_t S = plan.has_prod.size();
    std::vector<std::uint64_t> modules(S, 0);
    std::vector<std::int32_t> arity(S, -2), stored(S, -2); // -2: no module yet
    auto merge = [&](std::size_t s, std::int32_t a, std::int32_t k) {
        arity[s] = arity[s] == -2 || arity[s] == a ? a : -1;
        stored[s] = stored[s] == -2 || stored[s] == k ? k : -1;
    };
    for (std::size_t o = 0; o < plan.outcome_tmpl.size(); ++o) {
        std::uint64_t c = 0;
        for (const auto& t : tallies) c += t[o];
        if (c == 0) continue;
        if (const SuccessorTemplate* t = plan.outcome_tmpl[o]) {
            for (std::size_t j = 0; j < t->syms.size(); ++j) {
                modules[t->syms[j]] += c;
                merge(t->syms[j], static_cast<std::int32_t>(t->param_end[j] - (j ? t->param_end[j - 1] : 0)),
                      t->stored_nargs[j]);
            }
        } else {
            const SymbolId s = plan.outcome_sym[o];
            modules[s] += c;
            const bool known = counted && counts.arity.size() == S;
            merge(s, known ? counts.arity[s] : -1, known ? counts.stored[s] : -1);
        }
    }
    counts.kinds.clear();
    counts.modules = std::move(modules);
    counts.arity = std::move(arity);
    counts.stored = std::move(stored);
    counts.of = out.kinds.data();
    counts.size = out.size();
}

void Engine::decompose(const Derivation& d, ModuleString& s, int step_for_env) {
    const Program& prog = d.prog_;
    if (prog.decompose.empty()) return;
    std::vector<const RuleSet*> sets{&prog.decompose};
    for (int pass = 0; pass < prog.decompose.max_depth; ++pass) {
        if (!any_candidate(s, prog.decompose)) break;
        ModuleString next;
        ModuleId before = next_id;
        rewrite(d, s, next, plan_for(prog, sets), stream::decompose(step_for_env, pass), step_for_env);
        bool changed = next_id != before || !next.same_modules(s);
        s.swap(next);
        if (!changed) break;
    }
}

void Engine::apply_cut(const Program& prog, ModuleString& s) {
    if (!prog.uses_cut) return;
    const SymbolId cut = prog.symbols.cut, open = prog.symbols.open_bracket,
                   close = prog.symbols.close_bracket;
    bool any = false;
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.symbol(i) == cut) {
            any = true;
            break;
        }
    if (!any) return;
    cut_branches(s, open, close, [&](std::size_t i) { return s.symbol(i) == cut; });
}

ModuleString Engine::interpreted(const Derivation& d, const ModuleString& s) {
    const Program& prog = d.prog_;
    ModuleString cur = s;
    if (prog.interpret.empty()) return cur;
    std::vector<const RuleSet*> sets{&prog.interpret};
    ModuleId saved = next_id;
    interpreting = true;
    struct Reset {
        bool& flag;
        ~Reset() { flag = false; }
    } reset{interpreting};
    for (int pass = 0; pass < prog.interpret.max_depth; ++pass) {
        if (!any_candidate(cur, prog.interpret)) break;
        ModuleString next;
        rewrite(d, cur, next, plan_for(prog, sets), stream::interpret(d.step_, pass), d.step_);
        bool changed = !cur.same_modules(next);
        cur.swap(next);
        if (!changed) break;
    }
    next_id = saved; // interpretation never creates modules that live on
    return cur;
}

} // namespace plant
