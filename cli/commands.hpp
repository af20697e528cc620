// The `plant` commands. Only this front end prints to the terminal or picks exit codes.
#pragma once

#include "plant/compiler.hpp"
#include "plant/derive.hpp"

#include <CLI/CLI.hpp>

#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace plant::cli {

// Exit codes (sysexits.h): usage 64, unreadable input 66, grammar error 65, runtime error 70.
// 73: an output file cannot be created.
enum Exit {
    kOk = 0,
    kFailed = 1,
    kUsage = 64,
    kGrammar = 65,
    kNoInput = 66,
    kRuntime = 70,
    kCantCreate = 73
};

// Options shared by the commands that compile and derive a grammar.
struct GrammarOptions {
    std::string file;
    std::vector<std::string> defines; // name=value
    std::vector<std::string> include_dirs;
    std::vector<std::string> allow_read; // --allow-read DIR
    std::optional<int> steps;
    std::optional<std::uint64_t> seed;
    int threads = 0; // 0: one per core
    std::size_t max_modules = 50'000'000;
    std::uint64_t max_steps = kDefaultMaxSteps; // instructions one evaluation may run
    std::uint64_t max_work = kDefaultMaxWork;   // work the whole derivation may do (--max-work)
    std::uint64_t max_memory = 0;               // --max-memory in bytes; 0: default_max_memory()
    bool color = false;
    // --edits FILE: the decomposition graph's edits (docs/language.md, decomposition graphs);
    // empty: the grammar's `edits "file";`, if any.
    std::string edits;
    // Source text compiled after the file's own, as part of it (plant view's edits, made from
    // checked parts: an `on before_step` hook); empty: none.
    std::string appended;
};

// Reads a whole number from `lowest` to `highest` written in decimal digits; throws
// CLI::ValidationError naming `option` and the range otherwise (a usage error, exit 64).
std::uint64_t parse_count(const std::string& option, const std::string& text, std::uint64_t lowest,
                          std::uint64_t highest = std::numeric_limits<std::uint64_t>::max());

// The largest count an option takes when it names no bound of its own.
inline constexpr std::uint64_t kAnyCount = std::numeric_limits<std::uint64_t>::max();

// Adds an option (`flags`: "-n,--steps") taking a whole number from `lowest` to `highest`, read by
// parse_count and handed to `set`; its value is shown as N in --help.
CLI::Option* add_count(CLI::App& cmd, const std::string& flags, std::uint64_t lowest, std::uint64_t highest,
                       std::function<void(std::uint64_t)> set, const std::string& help);

// The check of a number option, whose message says what to give in the words parse_count uses:
// "--sides: must be a whole number from 3 to 64, found '2'". Whole: an integer from lowest to
// highest; From: any number from lowest to highest; Above: above lowest, at most highest.
enum class Bound { Whole, From, Above };
CLI::Validator number_in(double lowest, double highest, Bound bound);

void add_grammar_options(CLI::App& cmd, GrammarOptions& o, bool derivation);

// --max-work N: the whole derivation's work budget (DeriveOptions::max_work); `what` says what
// one budget covers for this command.
void add_max_work(CLI::App& cmd, std::uint64_t& max_work, const char* what);

// --max-memory SIZE, on every command that compiles a grammar: the memory budget
// (plant/memory_budget.hpp), read once, here, into `bytes` (a SIZE that does not read is a usage
// error, exit 64).
void add_max_memory(CLI::App& cmd, std::uint64_t& bytes);
// Sets the process's memory budget: `bytes` from --max-memory, 0 for default_max_memory().
void set_memory_budget(std::uint64_t bytes);

// --allow-read DIR (repeatable), on every command that compiles a grammar.
void add_allow_read(CLI::App& cmd, std::vector<std::string>& dirs);

// FILE '-': the grammar comes from standard input (read once, named '<stdin>' in messages).
bool reads_standard_input(const GrammarOptions& o);

// Compiles the grammar, printing diagnostics to stderr (or appending them to `*messages`, when
// given, in the same words). On failure sets `exit_code`.
std::unique_ptr<Program> load_program(const GrammarOptions& o, SourceManager& sources, int& exit_code,
                                      std::string* messages = nullptr);

// Reads the edits of a program with a graph into program.graph.edits: the --edits file, else the
// grammar's default (a default that does not exist yet is no edits). Errors are printed like the
// grammar's (exit 65; 66 when the file cannot be read). False on error.
bool load_edits(const GrammarOptions& o, Program& program, SourceManager& sources, std::string& out,
                int& exit_code);

// Runs a derivation, printing a runtime error as a diagnostic. Returns false on error.
bool run_derivation(Derivation& d, const SourceManager& sources, bool color);

DeriveOptions derive_options(const GrammarOptions& o);

void setup_derive(CLI::App& app, int& exit_code);
void setup_check(CLI::App& app, int& exit_code);
void setup_test(CLI::App& app, int& exit_code);
void setup_run(CLI::App& app, int& exit_code);
void setup_repl(CLI::App& app, int& exit_code);
void setup_view(CLI::App& app, int& exit_code);
void setup_help(CLI::App& app, int& exit_code);
void setup_graph(CLI::App& app, int& exit_code);

// plant check: derives a program with a graph and edits, and prints each dormant edit as a warning
// at its line of the edits file (cmd_graph.cpp). Returns the exit code.
int report_dormant_edits(const GrammarOptions& o, const Program& program, const SourceManager& sources);
// The graph from `node` down as plant graph prints it (only that node without `children`), and the
// node with a path as printed ("/0.25/0.5"), -1 if none (cmd_graph.cpp; the REPL's :graph, :node).
std::string graph_tree(const DecompositionGraph& g, int node, bool children);
int graph_node_at(const DecompositionGraph& g, const std::string& path);

} // namespace plant::cli
