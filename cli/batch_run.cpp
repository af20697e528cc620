// Running a batch (docs/batch.md): a pool of threads takes the shard's variants in order, each
// a Derivation of its own over a Program compiled once per --grid tuple and shared (a Program is
// not changed by deriving: every derivation clones its environments into its own RunState).
#include "batch.hpp"
#include "batch_manifest.hpp"
#include "batch_progress.hpp"
#include "pending_files.hpp"

#include "plant/environment_phase.hpp"
#include "plant/export.hpp"
#include "plant/memory_budget.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <malloc.h>
#include <map>
#include <thread>
#include <unistd.h>

namespace plant::cli {

namespace {

std::atomic<bool> g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

void on_stop(int sig) {
    g_signal = sig;
    g_stop.store(true);
}

// SIGINT, SIGTERM and SIGHUP (as SIGTERM) only set g_stop while a batch runs: the workers stop at their next
// look, abandon the variants under way (PendingFiles removes their files) and the batch ends by the signal
// after writing the manifest of the variants done. A signal ignored when plant started (a background job of a
// script: nohup, `&`) stays ignored.
class StopOnSignal {
  public:
    StopOnSignal() {
        struct sigaction sa {};
        sa.sa_handler = on_stop;
        sigemptyset(&sa.sa_mask);
        for (auto [sig, old] : {std::pair{SIGINT, &old_int_}, {SIGTERM, &old_term_}, {SIGHUP, &old_hup_}}) {
            sigaction(sig, nullptr, old);
            if ((old->sa_flags & SA_SIGINFO) || old->sa_handler != SIG_IGN) sigaction(sig, &sa, nullptr);
        }
        PendingFiles::share_signals(&g_stop);
    }
    ~StopOnSignal() {
        PendingFiles::share_signals(nullptr);
        sigaction(SIGINT, &old_int_, nullptr);
        sigaction(SIGTERM, &old_term_, nullptr);
        sigaction(SIGHUP, &old_hup_, nullptr);
    }
    StopOnSignal(const StopOnSignal&) = delete;
    StopOnSignal& operator=(const StopOnSignal&) = delete;

  private:
    struct sigaction old_int_ {
    }, old_term_{}, old_hup_{};
};

struct Compiled {
    SourceManager sources;
    std::unique_ptr<Program> program; // null: the messages say why
    std::string messages;
    int exit_code = kOk;
};

// The line of a diagnostic a manifest row keeps: the first error's "file:line:col: error: ...".
std::string first_error(const std::string& rendered) {
    std::size_t at = rendered.find(": error: ");
    at = at == std::string::npos ? 0 : rendered.rfind('\n', at);
    at = at == std::string::npos ? 0 : at + (rendered[at] == '\n');
    return rendered.substr(at, rendered.find('\n', at) - at);
}

// The programs of the --grid tuples, compiled when a variant first needs one and kept while
// variants of nearby tuples may still ask (variants are taken in order, and tuple-major).
class Programs {
  public:
    Programs(const BatchJob& job, std::size_t keep) : job_(job), keep_(keep) {}

    std::shared_ptr<const Compiled> get(std::uint64_t tuple) {
        std::lock_guard lock(mutex_); // compiles one at a time
        if (auto it = cache_.find(tuple); it != cache_.end()) return it->second;
        auto c = std::make_shared<Compiled>();
        GrammarOptions g = job_.grammar;
        g.color = false;
        const auto at = job_.plan.value_indices(tuple);
        for (std::size_t k = 0; k < at.size(); ++k)
            g.defines.push_back(job_.plan.axes[k].name + "=" + job_.plan.axes[k].values[at[k]]);
        c->program = load_program(g, c->sources, c->exit_code, &c->messages);
        if (cache_.size() >= keep_) cache_.erase(cache_.begin());
        cache_.emplace(tuple, c);
        return c;
    }

  private:
    const BatchJob& job_;
    std::size_t keep_;
    std::mutex mutex_;
    std::map<std::uint64_t, std::shared_ptr<const Compiled>> cache_;
};

struct Shared {
    const BatchJob& job;
    Programs& programs;
    ManifestWriter& manifest;
    Progress& progress;
    int jobs; // variants running at once, each with a 1/jobs share of --max-memory
};

// What a variant stopped by the memory budget, or by its string's share of it, is told besides:
// that its share is a part of --max-memory, and how to give it more.
std::string share_hint(const RuntimeError& e, int jobs) {
    const bool memory =
        e.kind == RuntimeErrorKind::Memory ||
        (e.kind == RuntimeErrorKind::ModuleLimit && e.message.find("--max-memory") != std::string::npos);
    if (!memory || jobs < 2) return "";
    return fmt::format(
        " (with --jobs {0} each variant has a 1/{0} share of --max-memory: lower --jobs or raise "
        "--max-memory)",
        jobs);
}

DeriveOptions variant_options(const BatchJob& job, std::uint64_t n, Progress& progress) {
    DeriveOptions opt = derive_options(job.grammar);
    if (auto seed = job.plan.seed_of(n)) opt.seed = seed;
    opt.threads = job.grammar.threads > 0 ? job.grammar.threads : 1; // the variants fill the cores
    opt.interrupt = &g_stop;
    opt.on_print = [&progress, n](const std::string& text) {
        progress.print(fmt::format("variant {}: {}", n, escape_controls(text, true)));
    };
    return opt;
}

// Derives, meshes and writes variant n into `row`. Returns false when it was interrupted.
bool run_variant(Shared& s, std::uint64_t n, ManifestRow& row) {
    const BatchPlan& plan = s.job.plan;
    row.n = n;
    row.seed = plan.seed_of(n);
    const auto at = plan.value_indices(plan.tuple_of(n));
    for (std::size_t k = 0; k < at.size(); ++k) row.params.push_back(plan.axes[k].values[at[k]]);
    const auto compiled = s.programs.get(plan.tuple_of(n));
    if (!compiled->program) {
        row.status = "grammar_error";
        row.message = first_error(compiled->messages);
        return true;
    }
    TurtleEnvironmentPhase phase; // the environments live in the derivation's RunState
    DeriveOptions opt = variant_options(s.job, n, s.progress);
    opt.environment_phase = &phase;
    Derivation d(*compiled->program, opt);
    try {
        d.run();
        row.seed = d.seed();
        std::vector<std::string> paths;
        for (const auto& o : s.job.outputs) paths.push_back(expand_template(o, plan, n, d.seed()));
        const OutputSummary summary = write_outputs(*compiled->program, d, paths, s.job.output);
        row.outputs = std::move(paths);
        row.modules = d.string().size();
        row.triangles = summary.triangles;
    } catch (const RuntimeError& e) {
        if (e.kind == RuntimeErrorKind::Interrupted || g_stop.load()) return false;
        row.status = "runtime_error";
        row.message =
            first_error(render(Diagnostic{Severity::Error, e.span, e.message + share_hint(e, s.jobs), {}},
                               compiled->sources, false));
    } catch (const ExportError& e) {
        if (g_stop.load()) return false;
        row.status = "output_error";
        row.message = escape_controls(e.what());
    } catch (const std::bad_alloc&) {
        row.status = "runtime_error";
        row.message = "out of memory (lower --jobs, --max-modules or the derivation length)";
    }
    return true;
}

void worker(Shared& s, std::atomic<std::uint64_t>& next) {
    const std::uint64_t count = s.job.plan.shard_size();
    for (std::uint64_t i; !g_stop.load() && (i = next.fetch_add(1)) < count;) {
        const auto t0 = std::chrono::steady_clock::now();
        ManifestRow row;
        try {
            if (!run_variant(s, s.job.plan.variant(i), row)) break;
        } catch (const std::exception& e) { // a thread must not end by an exception
            row.status = "runtime_error";
            row.message = fmt::format("internal error: {}", escape_controls(e.what()));
        }
        row.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (row.status != "ok")
            s.progress.print(fmt::format("plant: variant {}{}: {}", row.n,
                                         row.seed ? fmt::format(" (seed {})", *row.seed) : "", row.message));
        s.progress.done(row.status == "ok");
        s.manifest.add(i, std::move(row));
    }
}

// Runs the workers, drawing the progress bar until they are done.
void run_pool(Shared& s, int jobs) {
    std::atomic<std::uint64_t> next{0};
    std::mutex mutex;
    std::condition_variable cv;
    int running = jobs;
    std::vector<std::thread> threads;
    for (int k = 0; k < jobs; ++k)
        threads.emplace_back([&] {
            worker(s, next);
            std::lock_guard lock(mutex);
            --running;
            cv.notify_all();
        });
    {
        std::unique_lock lock(mutex);
        while (running > 0) {
            cv.wait_for(lock, std::chrono::milliseconds(200));
            s.progress.draw();
        }
    }
    for (auto& t : threads) t.join();
}

} // namespace

int run_batch(BatchJob& job) {
    const BatchPlan& plan = job.plan;
    if (std::string error = check_templates(plan, job.outputs); !error.empty()) {
        std::cerr << "plant: " << error << "\n";
        return kUsage;
    }
    if (!job.batch.manifest.empty() && !manifest_format(job.batch.manifest)) {
        std::cerr << fmt::format("plant: --manifest '{}': name a .jsonl (JSON lines) or .csv file\n",
                                 escape_controls(job.batch.manifest));
        return kUsage;
    }
    // the manifest is written over whatever has its name: not over the grammar (no output can
    // have its name, .csv and .jsonl being no output's format)
    if (std::error_code ec; !job.batch.manifest.empty() && !reads_standard_input(job.grammar) &&
                            std::filesystem::equivalent(job.batch.manifest, job.grammar.file, ec)) {
        std::cerr << fmt::format("plant: --manifest '{}' is the grammar being run: writing it would replace "
                                 "the grammar; give the manifest a name of its own\n",
                                 escape_controls(job.batch.manifest));
        return kUsage;
    }
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    const int jobs =
        static_cast<int>(std::clamp<std::uint64_t>(job.batch.jobs > 0 ? std::uint64_t(job.batch.jobs) : cores,
                                                   1, std::max<std::uint64_t>(plan.shard_size(), 1)));
    // --max-memory bounds the process (docs/batch.md): each of the variants running at once has a
    // 1/jobs share, for its string's estimate and its mesh's (the charges add up to the process's)
    const std::uint64_t share = memory::limit() / static_cast<std::uint64_t>(jobs);
    job.grammar.max_memory = share;
    job.output.max_memory = share;
    Programs programs(job, 4 * static_cast<std::size_t>(jobs));
    // the grammar with the first variant's values, before any work: its errors stop the batch
    if (auto first = programs.get(0); !first->program) {
        std::cerr << first->messages;
        return first->exit_code;
    }
    // Each variant allocates and frees about the same memory as the one before it on its thread.
    // By default glibc gives the freed tops of its per-thread heaps, and blocks from 128 KiB up,
    // back to the system, and the next variant faults in fresh, zeroed pages for them: on two
    // jobs several times the page faults of one, the kernel's clearing of pages taking a tenth
    // of the time. Keeping up to 256 MiB a thread for the next variant avoids that.
    mallopt(M_MMAP_THRESHOLD, 256 << 20);
    mallopt(M_TRIM_THRESHOLD, 256 << 20);
    g_stop.store(false);
    g_signal = 0;
    int exit_code = kOk;
    {
        StopOnSignal signals;
        try {
            ManifestWriter manifest(job.batch.manifest, plan);
            Progress progress(plan.shard_size(), isatty(2) != 0);
            Shared shared{job, programs, manifest, progress, jobs};
            run_pool(shared, jobs);
            progress.finish(g_stop.load());
            manifest.finish();
            if (progress.failed() > 0) exit_code = kFailed;
        } catch (const ExportError& e) {
            std::cerr << "plant: " << escape_controls(e.what(), true) << "\n";
            exit_code = kCantCreate;
        }
    }
    if (g_signal != 0) raise(g_signal); // the handlers are back: end as the signal would have
    return exit_code;
}

} // namespace plant::cli
