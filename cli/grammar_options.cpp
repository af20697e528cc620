#include "commands.hpp"
#include "outputs.hpp"

#include "plant/environments.hpp"
#include "plant/memory_budget.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>
#include <unistd.h>

namespace plant::cli {

void add_grammar_options(CLI::App& cmd, GrammarOptions& o, bool derivation) {
    cmd.add_option("FILE", o.file, "The .plant grammar; '-' reads it from standard input")->required();
    cmd.add_option("-D,--define", o.defines, "Override a param: -D name=value (value is an expression)")
        ->type_name("NAME=VALUE");
    cmd.add_option("-I,--include", o.include_dirs, "Add a directory to the library search path")
        ->type_name("DIR");
    add_allow_read(cmd, o.allow_read);
    cmd.add_option("--edits", o.edits,
                   "Apply the decomposition graph's edits from FILE (default: the grammar's 'edits \"F\";')")
        ->type_name("FILE");
    // plant check takes them too, so that a run's command line checks as it is; it derives
    // nothing, and -n only tells it that the steps are given
    const std::string unused = "Taken as plant run takes it, so that a run's command line checks as it is; "
                               "check derives nothing";
    add_count(
        cmd, "-n,--steps", 0, 1000000, [&o](std::uint64_t v) { o.steps = static_cast<int>(v); },
        derivation ? "Number of derivation steps, 0 to 1000000 (default: the grammar's 'derive N;')"
                   : "The steps a run would derive: given, no note that the grammar has no 'derive N;'");
    add_count(
        cmd, "--seed", 0, kAnyCount, [&o](std::uint64_t v) { o.seed = v; },
        derivation
            ? "Random seed, a whole number from 0 to 2^64 - 1 (default: the grammar's 'seed S;', else 0)"
            : unused)
        ->type_name("UINT");
    add_count(
        cmd, "--threads", 0, 256, [&o](std::uint64_t v) { o.threads = static_cast<int>(v); },
        derivation ? "Rewriting threads, 0 to 256; 0 means one per core. The result never depends on it"
                   : unused);
    add_count(
        cmd, "--max-modules", 1, kAnyCount, [&o](std::uint64_t v) { o.max_modules = v; },
        derivation
            ? fmt::format("Stop with an error when the string grows past this many modules (default {})",
                          o.max_modules)
            : unused);
    add_count(
        cmd, "--max-steps", 1, kAnyCount, [&o](std::uint64_t v) { o.max_steps = v; },
        fmt::format("Stop with an error when one evaluation (a hook call; a production's condition, "
                    "weight or body for one module; a constant) runs more than this many "
                    "instructions, the functions it calls included (default {})",
                    kDefaultMaxSteps));
    add_max_work(cmd, o.max_work, "the derivation");
    add_max_memory(cmd, o.max_memory);
    // the same param set twice on one command line is a usage error, not "the last one wins"
    cmd.parse_complete_callback([&o] {
        for (std::size_t k = 0; k < o.defines.size(); ++k)
            for (std::size_t j = 0; j < k; ++j) {
                const std::string name = o.defines[k].substr(0, o.defines[k].find('='));
                if (!name.empty() && o.defines[j].substr(0, o.defines[j].find('=')) == name)
                    throw CLI::ValidationError(fmt::format(
                        "-D sets {} twice, to '{}' and to '{}': keep one of them", escape_controls(name),
                        escape_controls(o.defines[j]), escape_controls(o.defines[k])));
            }
    });
    o.color = isatty(2) != 0 && std::getenv("NO_COLOR") == nullptr;
}

void add_max_work(CLI::App& cmd, std::uint64_t& max_work, const char* what) {
    add_count(
        cmd, "--max-work", 1, kAnyCount, [&max_work](std::uint64_t v) { max_work = v; },
        fmt::format("Stop with an error (exit 70) when {} does more than this much work: every VM "
                    "instruction plus every module its steps write (default {}, minutes of "
                    "running, not days)",
                    what, kDefaultMaxWork));
}

void add_max_memory(CLI::App& cmd, std::uint64_t& bytes) {
    cmd.add_option_function<std::string>(
           "--max-memory",
           [&bytes](const std::string& v) {
               // an empty value is an error too, not the default
               if ((bytes = parse_memory(v)) == 0) throw CLI::ValidationError(memory_usage_error(v));
           },
           "Memory the command may take, as 512M or 4G (default: half the physical memory): "
           "the derivation's strings and tables, the skeleton, the mesh, the physics and the "
           "export buffers are charged against it before they are allocated, and a stage that "
           "would pass it stops with an error (exit 70)")
        ->type_name("SIZE");
}

void set_memory_budget(std::uint64_t bytes) {
    memory::set_limit(bytes ? bytes : default_max_memory());
}

void add_allow_read(CLI::App& cmd, std::vector<std::string>& dirs) {
    cmd.add_option("--allow-read", dirs,
                   "Let the grammar read files under DIR too (imports, load(...), meshes); by default "
                   "only its own folder, -I and PLANT_PATH folders and the standard library")
        ->type_name("DIR")
        ->allow_extra_args(false);
}

namespace {

// An option's value as a message shows it: at most 40 bytes, not cut inside a UTF-8 character.
std::string cut_for_message(const std::string& text) {
    if (text.size() <= 40) return text;
    std::size_t end = 40;
    while (end > 0 && (static_cast<unsigned char>(text[end]) & 0xC0) == 0x80) --end;
    return text.substr(0, end) + "...";
}

} // namespace

CLI::Option* add_count(CLI::App& cmd, const std::string& flags, std::uint64_t lowest, std::uint64_t highest,
                       std::function<void(std::uint64_t)> set, const std::string& help) {
    const std::string name = flags.substr(flags.rfind(',') + 1); // the long name, as messages say it
    return cmd
        .add_option_function<std::string>(
            flags,
            [name, lowest, highest, set = std::move(set)](const std::string& v) {
                set(parse_count(name, v, lowest, highest));
            },
            help)
        ->type_name("N");
}

std::uint64_t parse_count(const std::string& option, const std::string& text, std::uint64_t lowest,
                          std::uint64_t highest) {
    std::uint64_t v = 0;
    const char* end = text.data() + text.size();
    auto r = std::from_chars(text.data(), end, v);
    if (text.empty() || r.ec != std::errc() || r.ptr != end || v < lowest || v > highest)
        throw CLI::ValidationError(fmt::format("{} must be a whole number from {} to {}, found '{}'", option,
                                               lowest, highest, cut_for_message(text)));
    return v;
}

CLI::Validator number_in(double lowest, double highest, Bound bound) {
    auto shown = [](double v) { // 1000000, not 1e6
        return v == std::floor(v) && std::fabs(v) < 1e15 ? fmt::format("{}", static_cast<long long>(v))
                                                         : format_double(v);
    };
    const std::string want =
        bound == Bound::Whole ? fmt::format("a whole number from {} to {}", shown(lowest), shown(highest))
        : bound == Bound::From
            ? fmt::format("a number from {} to {}", shown(lowest), shown(highest))
            : fmt::format("a number above {} and at most {}", shown(lowest), shown(highest));
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            double v = 0;
            const char* end = text.data() + text.size();
            auto r = std::from_chars(text.data(), end, v);
            const bool read = !text.empty() && r.ec == std::errc() && r.ptr == end;
            const bool fits = read && v <= highest && (bound == Bound::Above ? v > lowest : v >= lowest) &&
                              (bound != Bound::Whole || v == std::floor(v));
            if (fits) {
                // in decimal for CLI11, which would read '010' as octal 8 and not take '5.0' or '1e1'
                if (bound == Bound::Whole) text = fmt::format("{}", static_cast<long long>(v));
                return {};
            }
            return fmt::format("must be {}, found '{}'", want, cut_for_message(text));
        },
        bound == Bound::Above ? fmt::format("(above {}, at most {})", shown(lowest), shown(highest))
                              : fmt::format("({} to {})", shown(lowest), shown(highest)),
        "number_in");
}

namespace {

// The grammar piped in for FILE '-', read once: a batch compiles the grammar again for each grid
// tuple, and standard input can be read only once. Its messages name it '<stdin>'; it may read
// files of the current folder, as a grammar of that folder may.
ReadFailure read_standard_input(std::string& out) {
    static std::mutex mutex;
    static std::optional<std::pair<ReadFailure, std::string>> read;
    std::lock_guard lock(mutex);
    if (!read) {
        std::string text;
        const ReadFailure f = read_descriptor(STDIN_FILENO, text);
        read.emplace(f, std::move(text));
    }
    out = read->second;
    return read->first;
}

} // namespace

bool reads_standard_input(const GrammarOptions& o) {
    return o.file == "-";
}

std::unique_ptr<Program> load_program(const GrammarOptions& o, SourceManager& sources, int& exit_code,
                                      std::string* messages) {
    std::string printed;
    std::string& out = messages ? *messages : printed;
    struct Flush { // prints what was gathered, on every way out, unless the caller takes it
        std::string& text;
        bool print;
        ~Flush() {
            if (print) std::cerr << text;
        }
    } flush{out, messages == nullptr};
    std::string text;
    if (reads_standard_input(o)) {
        // a terminal would wait for typing that nobody knows is wanted
        if (::isatty(STDIN_FILENO)) {
            out += "plant: '-' reads the grammar from standard input, which is a terminal here: pipe a "
                   "grammar in ('cat tree.plant | plant derive -') or type one in 'plant repl'\n";
            exit_code = kUsage;
            return nullptr;
        }
        if (ReadFailure f = read_standard_input(text); f != ReadFailure::None) {
            out += fmt::format("plant: cannot read the grammar from standard input: {}\n", describe(f));
            exit_code = kNoInput;
            return nullptr;
        }
        if (text.empty()) { // (an empty file is a grammar without an axiom; empty input is more likely a
                            // slip)
            out += "plant: standard input was empty: '-' reads the grammar from it, so pipe one in\n";
            exit_code = kNoInput;
            return nullptr;
        }
    } else if (ReadFailure f = read_input_file(o.file, text, kMaxSourceBytes, false);
               f != ReadFailure::None) {
        std::error_code ec;
        out += fmt::format("plant: cannot read '{}': {}\n", escape_controls(o.file),
                           std::filesystem::is_directory(o.file, ec) ? "it is a directory" : describe(f));
        exit_code = kNoInput;
        return nullptr;
    }
    CompileOptions co;
    co.include_dirs = o.include_dirs;
    co.confine_reads = true;
    co.allow_read = o.allow_read;
    co.environments = runtime_environments();
    co.max_steps = o.max_steps;
    co.steps_given = o.steps.has_value();
    for (const auto& d : o.defines) {
        auto eq = d.find('=');
        if (eq == std::string::npos || eq == 0) {
            out += fmt::format("plant: -D expects name=value, found '{}'\n", escape_controls(d));
            exit_code = kUsage;
            return nullptr;
        }
        co.defines.emplace_back(d.substr(0, eq), d.substr(eq + 1));
    }
    if (!o.appended.empty()) text += "\n" + o.appended;
    Diagnostics diags;
    std::uint32_t id = sources.add(reads_standard_input(o) ? "<stdin>" : o.file, std::move(text));
    std::unique_ptr<Program> program;
    try {
        program = compile_source(sources, id, co, diags);
    } catch (const RuntimeError& e) { // an environment made while compiling is past --max-memory
        out += render_all(diags, sources, o.color);
        out += render(Diagnostic{Severity::Error, e.span, e.message, {}}, sources, o.color);
        exit_code = kRuntime;
        return nullptr;
    }
    out += render_all(diags, sources, o.color);
    if (diags.error_count() > diags.all().size())
        out += fmt::format("plant: {} more errors not shown\n", diags.error_count() - diags.all().size());
    if (!program) exit_code = diags.has_input_errors() ? kNoInput : kGrammar;
    if (program && !load_edits(o, *program, sources, out, exit_code)) return nullptr;
    return program;
}

bool load_edits(const GrammarOptions& o, Program& program, SourceManager& sources, std::string& out,
                int& exit_code) {
    std::string path = o.edits.empty() ? program.graph.edits_path : o.edits;
    if (path.empty()) return true;
    if (!program.graph.declared) {
        out += fmt::format("plant: --edits '{}': the grammar declares no graph, so it takes no edits\n",
                           escape_controls(path));
        exit_code = kUsage;
        return false;
    }
    std::string text;
    ReadFailure f = read_input_file(path, text, kMaxSourceBytes, o.edits.empty());
    if (f == ReadFailure::Missing && o.edits.empty()) return true; // a default not written yet
    if (f != ReadFailure::None) {
        const std::string why =
            fmt::format("cannot read the edits file '{}': {}", escape_controls(path), describe(f));
        if (o.edits.empty() && program.graph.edits_span.valid()) // the grammar's `edits "FILE";`
            out += render(Diagnostic{Severity::Error, program.graph.edits_span, why, {}}, sources, o.color);
        else
            out += "plant: " + why + "\n";
        exit_code = kNoInput;
        return false;
    }
    Diagnostics diags;
    const std::uint32_t id = sources.add(path, std::move(text));
    program.graph.edits = parse_edits(program, sources, id, diags);
    out += render_all(diags, sources, o.color);
    if (program.graph.edits) return true;
    exit_code = kGrammar;
    return false;
}

DeriveOptions derive_options(const GrammarOptions& o) {
    DeriveOptions d;
    d.steps = o.steps;
    d.seed = o.seed;
    d.threads =
        o.threads > 0 ? o.threads : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    d.max_modules = o.max_modules;
    d.max_steps = o.max_steps;
    d.max_work = o.max_work;
    // the strings' estimate (rewrite/engine.cpp) takes half of --max-memory: a step holds the
    // string it reads and the one it writes
    if (o.max_memory) d.max_bytes = std::min<std::uint64_t>(d.max_bytes, o.max_memory / 2);
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
