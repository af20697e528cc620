#include "commands.hpp"

#include "plant/environments.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <iostream>
#include <thread>
#include <unistd.h>

namespace plant::cli {

void add_grammar_options(CLI::App& cmd, GrammarOptions& o, bool derivation) {
    cmd.add_option("FILE", o.file, "The .plant grammar")->required();
    cmd.add_option("-D,--define", o.defines, "Override a param: -D name=value (value is an expression)")
        ->type_name("NAME=VALUE");
    cmd.add_option("-I,--include", o.include_dirs, "Add a directory to the library search path")
        ->type_name("DIR");
    if (derivation) {
        cmd.add_option("-n,--steps", o.steps,
                       "Number of derivation steps (default: the grammar's 'derive N;')")
            ->check(CLI::Range(0, 1000000));
        cmd.add_option("--seed", o.seed, "Random seed (default: the grammar's 'seed S;', else 0)");
        cmd.add_option("--threads", o.threads,
                       "Rewriting threads; 0 means one per core. The result never depends "
                       "on it")
            ->check(CLI::Range(0, 256));
        cmd.add_option("--max-modules", o.max_modules,
                       "Stop with an error when the string grows past this many "
                       "modules")
            ->check(CLI::PositiveNumber);
    }
    o.color = isatty(2) != 0 && std::getenv("NO_COLOR") == nullptr;
}

std::unique_ptr<Program> load_program(const GrammarOptions& o, SourceManager& sources, int& exit_code) {
    std::string text;
    if (!read_file(o.file, text)) {
        std::error_code ec;
        std::cerr << fmt::format("plant: cannot read '{}': {}\n", escape_controls(o.file),
                                 std::filesystem::is_directory(o.file, ec) ? "it is a directory"
                                 : std::filesystem::exists(o.file, ec)     ? "permission denied"
                                                                           : "no such file");
        exit_code = kNoInput;
        return nullptr;
    }
    CompileOptions co;
    co.include_dirs = o.include_dirs;
    co.environments = runtime_environments();
    for (const auto& d : o.defines) {
        auto eq = d.find('=');
        if (eq == std::string::npos || eq == 0) {
            std::cerr << fmt::format("plant: -D expects name=value, found '{}'\n", escape_controls(d));
            exit_code = kUsage;
            return nullptr;
        }
        co.defines.emplace_back(d.substr(0, eq), d.substr(eq + 1));
    }
    Diagnostics diags;
    std::uint32_t id = sources.add(o.file, std::move(text));
    auto program = compile_source(sources, id, co, diags);
    std::cerr << render_all(diags, sources, o.color);
    if (diags.error_count() > diags.all().size())
        std::cerr << fmt::format("plant: {} more errors not shown\n",
                                 diags.error_count() - diags.all().size());
    if (!program) exit_code = kGrammar;
    return program;
}

DeriveOptions derive_options(const GrammarOptions& o) {
    DeriveOptions d;
    d.steps = o.steps;
    d.seed = o.seed;
    d.threads =
        o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    d.max_modules = o.max_modules;
    return d;
}

bool run_derivation(Derivation& d, const SourceManager& sources, bool color) {
    try {
        d.run();
        return true;
    } catch (const RuntimeError& e) {
        Diagnostic diag{Severity::Error, e.span, e.message, {}};
        std::cerr << render(diag, sources, color);
        return false;
    }
}

} // namespace plant::cli
