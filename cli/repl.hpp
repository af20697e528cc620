// plant repl: a session to grow a grammar step by step, inspect it, change it and look at it.
// The session is independent of the terminal: the front end (repl_main.cpp) feeds it lines.
#pragma once

#include "plant/compiler.hpp"
#include "plant/derive.hpp"

#include "outputs.hpp"

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <span>
#include <string>
#include <vector>

namespace plant::cli {

class Session;

// What Tab offers after a command's name.
enum class ReplCompletion {
    Nothing,  // a number, a range, or no argument at all
    Files,    // file names (left to the line editor)
    Commands, // command names (:help)
    Params,   // the grammar's params (:set)
    Groups,   // rule groups and `none` (:use)
    Modules,  // module names (:find)
    Names,    // every name the grammar defines (:do, expressions)
};

// One REPL command: the one table :help, Tab completion and dispatch read (Session::commands()).
// Adding a command is one row plus what it does.
struct ReplCommand {
    const char* name;
    const char* aliases; // other names it answers to, separated by spaces
    void (*run)(Session& session, const std::string& typed, const std::string& rest); // typed: as written
    const char* usage;
    const char* help;
    ReplCompletion completes;
};

class Session {
  public:
    Session(std::ostream& out, std::ostream& err, bool color);
    // Runs one input line: a :command, `axiom: ...`, a production, or an expression.
    // Returns false when the session should end (:quit).
    bool execute(const std::string& line);
    // Whether the last line left a block open (the prompt shows that more is awaited), and
    // dropping it (Ctrl-C at that prompt).
    bool continuing() const { return !pending_.empty(); }
    void drop_pending() { pending_.clear(); }
    // At the end of the input: a block still open is an error naming where it began.
    void finish();
    // Names for tab completion of a word preceded on its line by `before`: after a command's
    // name, what that command takes; otherwise commands, params, modules, rule groups, ...
    std::vector<std::string> completions(const std::string& before) const;
    // What the word after `before` is: Files means the line editor completes file names.
    ReplCompletion completion_kind(const std::string& before) const;
    // The commands, in the order :help lists them.
    static std::span<const ReplCommand> commands();
    // The lines :help (and `plant help repl`) prints.
    static std::string command_list();
    void set_interrupt(const std::atomic<bool>* flag) { interrupt_ = flag; }
    // --allow-read: folders the grammar may read besides its own (file_access.hpp)
    void allow_read(std::vector<std::string> dirs) { allow_read_ = std::move(dirs); }
    void set_max_steps(std::uint64_t n) { max_steps_ = n; }   // --max-steps
    void set_max_work(std::uint64_t n) { max_work_ = n; }     // --max-work: each command's budget
    void set_max_modules(std::size_t n) { max_modules_ = n; } // --max-modules; 0: the default
    int load(const std::string& path); // :load; 0, or the exit code of the failure (65, 66, 70)
    // Whether some line since the last call reported an error (scripts exit 1 when one did).
    bool take_failed() {
        bool f = failed_;
        failed_ = false;
        return f;
    }

  private:
    bool command(const std::string& name, const std::string& rest);
    void help(const std::string& topic);
    // The bodies of the commands that are more than a call (repl_commands.cpp, and for :back and
    // :reset, repl.cpp beside back_to).
    std::optional<int> count_arg(const std::string& typed, const std::string& rest, int fallback);
    void reload();
    void back_command(const std::string& name, const std::string& rest);
    void reset_command();
    void set_param(const std::string& rest);
    void set_seed(const std::string& rest);
    // `angle 30;`, `derive 5;`, ... typed at the prompt: the session's own setting (repl_commands.cpp)
    // `module A(x);`, `const k = 2;`, `fn f(x) = ...;`, `ignore: F;` ...: kept and compiled with
    // the session's grammar.
    bool typed_declaration(const std::string& line);
    // What a line of grammar text starts: a declaration (`module`, `const`, `import`, ...), a
    // block (`rules`, `on`, `graph`, ... when it ends with '}'), or neither.
    enum class Item { Other, Declaration, Block };
    static Item item_kind(std::string_view line);
    // With no grammar yet, whether the typed declarations and settings compile (with an empty axiom).
    bool compiles_alone();
    // With no grammar yet, whether the typed declarations compile as they are: an import has
    // brought an axiom.
    bool brings_axiom() const;
    bool typed_setting(const std::string& line);
    // The loaded file's consts (name: the value's byte range), which :set may replace.
    std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> file_consts() const;
    std::string file_text_with_consts() const;
    bool parses_as_expression(const std::string& name, const std::string& text); // else says why
    void use(const std::string& rest);
    void export_command(const std::string& rest);
    const ReplCommand* find_command(const std::string& name) const;
    // Recompiles the session's grammar and replays `steps` steps. Keeps the previous state and
    // reports the error when the new grammar does not compile or derive.
    bool rebuild(int steps);
    CompileOptions compile_options() const;
    Diagnostics news(const Diagnostics& diags, const SourceManager& sources);
    // The session's grammar: the loaded file's import and what was typed, each typed line shown
    // in messages by its number in the input (`lines`, as SourceFile::show_lines takes them).
    struct SessionText {
        std::string text;
        std::vector<std::uint32_t> lines;
        // Appends `text` and a newline; its lines are numbered from `typed_at` on (0: the session's own)
        void add(std::string_view text, std::uint32_t typed_at);
    };
    // Text typed on the item being run (an expression, a pattern), with the session's own
    // wrapping around it: `before` + typed + `after` (an expression's function, a pattern's group).
    struct Extra {
        std::string before, typed, after;
    };
    SessionText session_source(const Extra* extra = nullptr) const;
    std::uint32_t add_session(SourceManager& sources, const SessionText& session) const;
    bool step(int n);
    void show(const std::string& rest);
    void find(const std::string& pattern);
    void error_if(const Diagnostics& errors, const SourceManager& sources);
    void stats();
    void rules();
    void params();
    void evaluate(const std::string& expr);
    void export_files(const std::vector<std::string>& paths, const OutputOptions& options = {});
    bool need_derivation();
    // :do STATEMENTS: adds them as an edit at the current step and replays.
    void edit(std::string statements);
    void list_edits();
    // A line calling a hook-only environment method (ivy.cut(12)): an edit, not an expression.
    bool is_edit(const std::string& line) const;
    // Going back to step k: uses and edits made after it are forgotten. Whether it derived again
    // (it does when edits were undone: the steps kept have their own environments).
    bool back_to(int k);
    // the decomposition graph's edits (repl_graph.cpp): :graph, :node, :edit, :inherit, :private,
    // :public, :share, :save, and the graph part of :edits and :back
    const DecompositionGraph* graph();
    void graph_command(const std::string& rest, bool one_node);
    void graph_edit(const std::string& command, const std::string& rest);
    void save_edits(const std::string& rest);
    void list_graph_edits();
    bool undo_graph_edit();
    // Reads graph_lines_ against a freshly compiled program into graph_edits_ (errors rendered).
    bool parse_graph_lines(const Program& program, SourceManager& sources);
    bool read_default_edits(); // true when it read some lines
    bool drop_orphaned_edits(int steps);
    Derivation& current() { return *history_.back(); }
    DeriveOptions options() const;

    std::ostream& out_;
    std::ostream& err_;
    bool color_;
    const std::atomic<bool>* interrupt_ = nullptr;
    std::uint64_t max_steps_ = kDefaultMaxSteps;
    std::uint64_t max_work_ = kDefaultMaxWork;
    std::size_t max_modules_ = 0;

    std::vector<std::string> allow_read_; // --allow-read
    std::string file_;                    // the loaded grammar's path, as given
    std::string file_text_;               // its text as :load or :reload read it
    // Text typed at the prompt, with its line's number in the input (1 for the first line read)
    struct Typed {
        std::string text;
        std::uint32_t line = 0;
        bool block = false; // (extra_rules_) a top-level block, `rules grow { ... }`, not a production
    };
    std::uint32_t input_line_ = 0; // the last line read
    std::uint32_t item_line_ = 0;  // the first line of the item being run
    // An item whose '{' is not closed on its line goes on over the lines that follow, until its
    // braces balance: the lines so far, with '\n' between them, and the first one's number.
    std::string pending_;
    std::uint32_t pending_line_ = 0;
    // What is open at the end of the lines read so far: '{', '(', a /* comment */ (strings and
    // # comments end with their line). A declaration goes on while a '(' is open too.
    struct OpenScan {
        int braces = 0, parens = 0;
        bool comment = false;
        void line(std::string_view text);
    };
    OpenScan pending_scan_;
    std::string open_thing() const; // what is left open, for a message: "a '{'"
    bool pending_declaration_ = false;
    // Whether the lines typed for an item leave something open, so that it goes on.
    static bool goes_on(const OpenScan& scan, bool declaration) {
        return scan.braces > 0 || scan.comment || (declaration && scan.parens > 0);
    }
    bool run_item(std::string line);            // one whole item, its lines joined
    std::vector<Typed> declarations_;           // typed `module A(x);`, `const k = 2;` ...
    std::optional<Typed> axiom_;                // typed `axiom: ...`
    std::vector<Typed> extra_rules_;            // typed productions and blocks, in the order typed
    std::map<std::string, std::string> params_; // :set NAME VALUE
    std::optional<std::uint64_t> seed_;
    std::map<std::string, Typed> settings_;         // typed `angle 30;` and the like: key, value
    std::map<std::string, std::string> consts_;     // :set NAME VALUE on a const of the loaded file
    std::vector<std::pair<int, std::string>> uses_; // :use GROUP at step N, replayed by rebuilds
    // Edits (:do, or a hook-only call such as ivy.cut(12) typed at the prompt): statements run
    // by an `on before_step` hook at step N, that is before the step that follows N.
    std::vector<std::pair<int, Typed>> edits_;
    std::set<std::string> shown_; // warnings already shown
    bool failed_ = false;
    bool quit_ = false; // :quit was typed
    bool last_error_runtime_ = false;
    bool last_error_input_ = false; // the last compile failed on a file it could not read
    std::ostream& error();          // err_, marking the line as failed

    // The graph's edits as edits-file lines (the grammar's default file, then those typed), what
    // they read as, and for :back the lines before each typed edit with the history size then.
    std::vector<std::string> graph_lines_;
    std::shared_ptr<const GraphEdits> graph_edits_;
    std::vector<std::pair<std::size_t, std::vector<std::string>>> graph_undo_;
    bool default_edits_unreadable_ = false; // the grammar's edits file exists but could not be read

    std::unique_ptr<SourceManager> sources_;
    std::unique_ptr<Program> program_;
    std::vector<std::unique_ptr<Derivation>> history_; // one state per step; back() is current
    double last_step_ms_ = 0;
};

int repl_main(const std::string& file, bool color, const std::vector<std::string>& allow_read = {},
              std::uint64_t max_steps = kDefaultMaxSteps, std::size_t max_modules = 0,
              std::uint64_t max_work = kDefaultMaxWork);

} // namespace plant::cli
