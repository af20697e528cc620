// The REPL's front end: libedit line editing, history in ~/.plant_history and tab completion
// when standard input is a terminal; plain line reading otherwise (scripts and tests).
// libedit is loaded (dlopen) only then: linked, it and the libraries it needs (libtinfo, libbsd,
// libmd) would be loaded and relocated by every plant process, about 0.35 ms each
// (docs/architecture.md, the command line).
#include "commands.hpp"
#include "repl.hpp"

#include "plant/diagnostics.hpp"

#include <editline/readline.h> // its types only: the functions are looked up in the library
#include <fmt/format.h>

#include <algorithm>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <iostream>
#include <type_traits>
#include <unistd.h>

namespace plant::cli {

namespace {

std::atomic<bool> g_interrupt{false};
Session* g_session = nullptr;

extern "C" void on_sigint(int) {
    g_interrupt.store(true);
}

// The part of libedit's readline interface the REPL uses, looked up in libedit.so.2.
struct Editline {
    char* (*readline)(const char*) = nullptr;
    int (*add_history)(const char*) = nullptr;
    int (*read_history)(const char*) = nullptr;
    int (*write_history)(const char*) = nullptr;
    char** (*completion_matches)(const char*, rl_compentry_func_t*) = nullptr;
    char** line_buffer = nullptr;                         // rl_line_buffer
    int* completion_over = nullptr;                       // rl_attempted_completion_over
    rl_completion_func_t** completion_function = nullptr; // rl_attempted_completion_function
};
Editline g_edit;

// Loads libedit into g_edit; false (with the loader's reason in `why`) when it cannot.
bool load_editline(std::string& why) {
    void* lib = dlopen("libedit.so.2", RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        const char* e = dlerror();
        why = e ? e : "cannot load libedit.so.2";
        return false;
    }
    bool found = true;
    auto get = [&](auto& out, const char* name) {
        void* sym = dlsym(lib, name);
        found = found && sym;
        out = reinterpret_cast<std::remove_reference_t<decltype(out)>>(sym);
    };
    get(g_edit.readline, "readline");
    get(g_edit.add_history, "add_history");
    get(g_edit.read_history, "read_history");
    get(g_edit.write_history, "write_history");
    get(g_edit.completion_matches, "rl_completion_matches");
    get(g_edit.line_buffer, "rl_line_buffer");
    get(g_edit.completion_over, "rl_attempted_completion_over");
    get(g_edit.completion_function, "rl_attempted_completion_function");
    if (!found) why = "libedit.so.2 lacks part of the readline interface";
    return found;
}

std::vector<std::string> g_matches;

std::string g_before; // the line before the word being completed

char* completion_generator(const char* text, int state) {
    static std::size_t next = 0;
    if (state == 0) {
        next = 0;
        g_matches.clear();
        std::string prefix = text;
        for (const auto& c : g_session->completions(g_before))
            if (c.rfind(prefix, 0) == 0) g_matches.push_back(c);
    }
    if (next >= g_matches.size()) return nullptr;
    return strdup(g_matches[next++].c_str());
}

char** complete(const char* text, int start, int) {
    g_before.assign(*g_edit.line_buffer, static_cast<std::size_t>(std::max(start, 0)));
    // file names only where a command takes them (:load, :export)
    const bool files = g_session->completion_kind(g_before) == ReplCompletion::Files;
    *g_edit.completion_over = files ? 0 : 1;
    if (files) return nullptr;
    return g_edit.completion_matches(text, completion_generator);
}

std::string history_path() {
    const char* home = std::getenv("HOME");
    return home ? std::string(home) + "/.plant_history" : std::string(".plant_history");
}

// Reads and runs lines from standard input until it ends or :quit: scripts, and a terminal when
// libedit cannot be loaded (then with a prompt). Exit 1 when some line failed.
int read_script(Session& session, bool prompt) {
    std::string line;
    bool failed = false;
    for (;;) {
        if (prompt) std::cout << (session.continuing() ? "   ...> " : "plant> ") << std::flush;
        if (!std::getline(std::cin, line)) break;
        bool go_on = session.execute(line);
        failed = session.take_failed() || failed;
        std::cout.flush();
        std::cerr.flush();
        if (!go_on) break;
    }
    session.finish();
    failed = session.take_failed() || failed;
    return failed ? kFailed : kOk;
}

} // namespace

int repl_main(const std::string& file, bool color, const std::vector<std::string>& allow_read,
              std::uint64_t max_steps, std::size_t max_modules, std::uint64_t max_work) {
    const bool interactive = isatty(0) != 0;
    Session session(std::cout, std::cerr, color && interactive);
    session.allow_read(allow_read);
    session.set_max_steps(max_steps);
    session.set_max_work(max_work);
    session.set_max_modules(max_modules);
    // (before the grammar is loaded: the derivation made then keeps the flag for its steps)
    if (interactive) session.set_interrupt(&g_interrupt);
    g_session = &session;
    if (!file.empty()) {
        int code = session.load(file);
        if (code != 0 && !interactive) return code;
    }
    // scripts: one line at a time, no prompt; exit 1 when some line failed (Ctrl-C ends the
    // script as usual: no handler is installed)
    if (!interactive) return read_script(session, false);
    // interactive: Ctrl-C interrupts a long step and returns to the prompt
    std::string why;
    if (!load_editline(why)) {
        std::cerr << "plant: no line editing (" << escape_controls(why) << "); reading lines plainly\n";
        read_script(session, true);
        return kOk; // as the editing REPL: a failed line is not the session's failure
    }
    struct sigaction sa {};
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, nullptr);
    std::cout << "plant repl: :help lists the commands, :quit ends; Tab completes names\n";
    *g_edit.completion_function = complete;
    const std::string hist = history_path();
    g_edit.read_history(hist.c_str());
    for (;;) {
        g_interrupt.store(false);
        char* raw = g_edit.readline(session.continuing() ? "   ...> " : "plant> ");
        if (!raw && g_interrupt.load()) { // Ctrl-C at the prompt: a fresh line, not the end
            std::cout << "\n";
            session.drop_pending(); // and a block being typed is dropped
            continue;
        }
        if (!raw) { // Ctrl-D
            std::cout << "\n";
            session.finish();
            break;
        }
        std::string line = raw;
        std::free(raw);
        if (line.find_first_not_of(" \t") != std::string::npos) g_edit.add_history(line.c_str());
        bool go_on = session.execute(line);
        session.take_failed();
        std::cout.flush();
        if (!go_on) break;
    }
    g_edit.write_history(hist.c_str());
    return kOk;
}

void setup_repl(CLI::App& app, int& exit_code) {
    auto file = std::make_shared<std::string>();
    auto max_steps = std::make_shared<std::uint64_t>(kDefaultMaxSteps);
    auto max_modules = std::make_shared<std::size_t>(0);
    auto max_work = std::make_shared<std::uint64_t>(kDefaultMaxWork);
    auto max_memory = std::make_shared<std::uint64_t>(0);
    CLI::App* cmd =
        app.add_subcommand("repl", "An interactive session: step a derivation, inspect the string, change "
                                   "rules and params, look at the plant");
    cmd->add_option("FILE", *file, "A grammar to load");
    auto allow = std::make_shared<std::vector<std::string>>();
    add_allow_read(*cmd, *allow);
    add_count(
        *cmd, "--max-steps", 1, kAnyCount, [max_steps](std::uint64_t v) { *max_steps = v; },
        fmt::format("Stop an evaluation (a hook call, a production for one module, an expression) "
                    "after this many instructions (default {})",
                    kDefaultMaxSteps));
    add_count(
        *cmd, "--max-modules", 1, kAnyCount, [max_modules](std::uint64_t v) { *max_modules = v; },
        "Stop a step with an error when the string grows past this many modules (the session "
        "stays at the step before)");
    add_max_work(*cmd, *max_work, "one command (a :step, a re-derivation after an edit)");
    add_max_memory(*cmd, *max_memory);
    cmd->footer("Reads commands from standard input without a prompt when it is not a terminal:\n"
                "  plant repl grammar.plant < script");
    cmd->callback([file, allow, max_steps, max_modules, max_work, max_memory, &exit_code] {
        set_memory_budget(*max_memory);
        exit_code = repl_main(*file, isatty(2) != 0 && !std::getenv("NO_COLOR"), *allow, *max_steps,
                              *max_modules, *max_work);
    });
}

} // namespace plant::cli
