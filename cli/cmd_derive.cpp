// plant derive / plant check
#include "commands.hpp"

#include "plant/environment_phase.hpp"
#include "plant/mesh.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <sys/resource.h>
#include <unistd.h>
#include <vector>

namespace plant::cli {

namespace {

struct DeriveCmd {
    GrammarOptions g;
    bool ids = false;
    bool stats = false;
};

long peak_rss_kb() {
    rusage ru{};
    getrusage(RUSAGE_SELF, &ru);
    return ru.ru_maxrss;
}

// Writes `text` to standard output; exit 73 with a message when it cannot (a full disk, a closed pipe).
int write_stdout(const std::string& text) {
    errno = 0;
    bool ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size();
    ok = std::fflush(stdout) == 0 && ok;
    if (ok) return kOk;
    std::cerr << fmt::format("plant: cannot write the string to standard output: {}\n",
                             errno ? std::strerror(errno) : "write error");
    return kCantCreate;
}

int derive_main(const DeriveCmd& c) {
    int exit_code = kOk;
    SourceManager sources;
    auto program = load_program(c.g, sources, exit_code);
    if (!program) return exit_code;
    DeriveOptions opt = derive_options(c.g);
    opt.identities = c.ids; // the string printed without --ids needs none (kept if the program reads them)
    const bool progress = !c.stats && isatty(2);
    // the figures are kept and formatted at the end, so that the timing of one step is not
    // disturbed by formatting the last one
    std::vector<StepStats> steps;
    steps.reserve(256);
    opt.on_step = [&](const StepStats& s) {
        if (c.stats) steps.push_back(s);
        if (progress) std::cerr << fmt::format("\rstep {}: {} modules   ", s.step, s.modules) << std::flush;
    };
    opt.on_print = [](const std::string& text) { std::cerr << escape_controls(text, true); };
    TurtleEnvironmentPhase phase;
    opt.environment_phase = &phase;
    Derivation d(*program, opt);
    bool ok = run_derivation(d, sources, c.g.color);
    if (progress) std::cerr << "\r\x1b[K" << std::flush;
    if (c.stats) {
        std::string stats_out;
        double total_ms = 0;
        for (const StepStats& s : steps) {
            total_ms += s.ms;
            stats_out +=
                fmt::format("step {} modules={} bytes={} ms={:.4f}\n", s.step, s.modules, s.bytes, s.ms);
        }
        if (!ok) { // the steps that finished, and where it stopped (the error is on stderr)
            stats_out += fmt::format("failed step={} modules={} ms={:.4f}\n",
                                     steps.empty() ? 1 : steps.back().step + 1,
                                     steps.empty() ? 0 : steps.back().modules, total_ms);
            write_stdout(stats_out);
            return kRuntime;
        }
        stats_out += fmt::format("total steps={} modules={} bytes={} ms={:.4f} peak_rss_kb={} work={}\n",
                                 d.steps_done(), d.string().size(), d.string().bytes(), total_ms,
                                 peak_rss_kb(), d.work_done());
        return write_stdout(stats_out);
    }
    if (!ok) return kRuntime;
    std::string text = format_string(*program, d.string(), c.ids);
    text += '\n';
    return write_stdout(text);
}

} // namespace

void setup_derive(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<DeriveCmd>();
    CLI::App* cmd = app.add_subcommand("derive", "Derive a grammar and print the string in ABOP notation");
    add_grammar_options(*cmd, c->g, true);
    cmd->add_flag("--ids", c->ids, "Show each module's identity after it, as F(1)#7");
    cmd->add_flag("--stats", c->stats,
                  "Print counts and timings per step instead of the string (the steps finished, when a later "
                  "one fails)");
    cmd->callback([c, &exit_code] {
        set_memory_budget(c->g.max_memory);
        exit_code = derive_main(*c);
    });
}

namespace {

// The settings evaluated as `derive` evaluates them (`seed 1/0;`, `derive d;` with a param out of
// range): an error for check, not only for derive and run. Whether they passed.
bool check_settings(const GrammarOptions& o, const Program& program, const SourceManager& sources) {
    try {
        Derivation d(program, derive_options(o));
        d.evaluate_settings();
        return true;
    } catch (const RuntimeError& e) {
        std::cerr << render(Diagnostic{Severity::Error, e.span, e.message, {}}, sources, o.color);
        return false;
    }
}

} // namespace

void setup_check(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<GrammarOptions>();
    CLI::App* cmd = app.add_subcommand(
        "check", "Parse and check a grammar; print its diagnostics (and its graph's dormant edits) only");
    add_grammar_options(*cmd, *c, false);
    cmd->callback([c, &exit_code] {
        set_memory_budget(c->max_memory);
        SourceManager sources;
        int code = kOk;
        auto program = load_program(*c, sources, code);
        if (program && !check_settings(*c, *program, sources)) {
            exit_code = kGrammar;
            return;
        }
        if (program) {
            try { // the mesh files of `surface s = load(...)`, read as plant run would read them
                check_surface_files(*program);
            } catch (const RuntimeError& e) {
                std::cerr << render(Diagnostic{Severity::Error, e.span, e.message, {}}, sources, c->color);
                exit_code = e.kind == RuntimeErrorKind::Input ? kNoInput : kRuntime;
                return;
            }
        }
        exit_code = program ? report_dormant_edits(*c, *program, sources) : code;
    });
}

} // namespace plant::cli
