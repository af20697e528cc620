// plant help [TOPIC [NAME]]: the commands, and the tables the language and the tools are made
// of (built-ins, environment kinds and their methods, output formats, REPL commands), printed
// from those tables themselves so that the help cannot drift from what the program does.
#include "commands.hpp"
#include "man_page.hpp"
#include "outputs.hpp"
#include "repl.hpp"

#include "plant/ast.hpp"
#include "plant/builtins.hpp"
#include "plant/environments.hpp"
#include "plant/turtle_symbols.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <iostream>

namespace plant::cli {

namespace {

struct HelpArgs {
    std::vector<std::string> words; // the topic and what follows it
    bool names = false;             // only the names, one per line (for scripts and the docs test)
    bool man = false;               // the man page plant.1 (troff), made at build time
};

std::string signature(const char* name, std::span<const ValueType> args, ValueType result) {
    std::string s = std::string(name) + "(";
    for (std::size_t k = 0; k < args.size(); ++k)
        s += (k ? ", " : "") + std::string(value_type_name(args[k]));
    return s + ") -> " + value_type_name(result);
}

// Rows of `left  right`, the right column aligned.
void print_columns(const std::vector<std::pair<std::string, std::string>>& rows) {
    std::size_t width = 0;
    for (const auto& r : rows) width = std::max(width, r.first.size());
    for (const auto& [left, right] : rows) std::cout << fmt::format("  {:<{}}  {}\n", left, width, right);
}

int help_builtins(const HelpArgs& a) {
    std::vector<std::pair<std::string, std::string>> rows;
    std::vector<std::string> names;
    for (const auto& b : builtin_table()) {
        if (std::find(names.begin(), names.end(), b.name) == names.end()) names.emplace_back(b.name);
        std::string doc = b.doc;
        if (b.draws_random()) doc += " (draws random numbers)";
        if (b.reads == BuiltinReads::Identity) doc += " (reads the module's identity)";
        rows.emplace_back(signature(b.name, std::span(b.args, b.nargs), b.result), doc);
    }
    if (a.names) {
        for (const auto& n : names) std::cout << n << "\n";
        return kOk;
    }
    std::cout << "Built-in functions (a bool is accepted where a number is expected):\n";
    print_columns(rows);
    return kOk;
}

int help_env_kind(const EnvironmentKind& k, const HelpArgs& a) {
    std::vector<std::pair<std::string, std::string>> rows;
    for (const EnvMethod& m : k.methods) {
        if (a.names) {
            std::cout << m.name << "\n";
            continue;
        }
        std::vector<ValueType> args(m.args.types.begin(), m.args.types.begin() + m.args.size());
        rows.emplace_back(signature(m.name, args, m.result),
                          std::string(m.doc) + (m.access == EnvAccess::Edit ? " (in hooks only)" : ""));
    }
    if (a.names) return kOk;
    std::cout << fmt::format("{}: {}. Methods (called as NAME.method(...)):\n", k.name, k.doc);
    print_columns(rows);
    return kOk;
}

int help_env(const HelpArgs& a) {
    const auto kinds = environment_kinds();
    if (a.words.size() > 1) {
        for (const EnvironmentKind* k : kinds)
            if (a.words[1] == k->name) return help_env_kind(*k, a);
        std::string names;
        for (const EnvironmentKind* k : kinds) names += (names.empty() ? "" : ", ") + std::string(k->name);
        std::cerr << fmt::format("plant: no environment kind '{}'; the kinds are {}\n", a.words[1], names);
        return kUsage;
    }
    std::vector<std::pair<std::string, std::string>> rows;
    for (const EnvironmentKind* k : kinds) {
        if (a.names) std::cout << k->name << "\n";
        rows.emplace_back(k->name, k->doc);
    }
    if (a.names) return kOk;
    std::cout << "Environment kinds (env NAME = KIND(key: value, ...); 'plant help env KIND' lists its "
                 "methods):\n";
    print_columns(rows);
    return kOk;
}

int help_turtle(const HelpArgs& a) {
    std::vector<std::pair<std::string, std::string>> turtle, queries;
    for (const TurtleSymbol& t : kTurtleSymbols) {
        std::string name = std::string(t.name) + (t.prefix ? "name" : ""); // "~name": any name after '~'
        if (a.names) {
            std::cout << name << "\n";
            continue;
        }
        if (!t.params.empty()) name += "(" + std::string(t.params) + ")";
        (t.kind == TurtleKind::Query ? queries : turtle).emplace_back(name, std::string(t.doc));
    }
    if (a.names) return kOk;
    std::cout << "Turtle symbols (H heading, L left, U up; angles in degrees; every parameter optional "
                 "unless the line says otherwise):\n";
    print_columns(turtle);
    std::cout << "Query modules (the turtle pass writes their parameters before a step that reads them):\n";
    print_columns(queries);
    return kOk;
}

// A small table of the language's {enum, spelling, doc} (ast.hpp), under a title.
template <typename Table> int help_spelled(const HelpArgs& a, const char* title, const Table& table) {
    std::vector<std::pair<std::string, std::string>> rows;
    for (const auto& entry : table) {
        if (a.names) std::cout << entry.spelling << "\n";
        rows.emplace_back(entry.spelling, entry.doc);
    }
    if (a.names) return kOk;
    std::cout << title << "\n";
    print_columns(rows);
    return kOk;
}

int help_hooks(const HelpArgs& a) {
    return help_spelled(a, "Hooks (on NAME { statements }), in the order they run:", ast::kHooks);
}

int help_settings(const HelpArgs& a) {
    return help_spelled(a, "Settings (NAME expression; at the top level):", ast::kSettings);
}

int help_operators(const HelpArgs& a) {
    if (a.names) {
        for (const auto& op : ast::kBinaryOps) std::cout << op.spelling << "\n";
        for (const auto& op : ast::kUnaryOps) std::cout << op.spelling << "\n";
        for (const auto& op : ast::kAssignOps) std::cout << op.spelling << "\n";
        return kOk;
    }
    help_spelled(a, "Binary operators, tightest first:", ast::kBinaryOps);
    help_spelled(a, "Unary operators:", ast::kUnaryOps);
    return help_spelled(a, "Assignments (in hooks and function bodies):", ast::kAssignOps);
}

int help_formats(const HelpArgs& a) {
    std::vector<std::pair<std::string, std::string>> rows;
    for (const auto& f : output_formats()) {
        if (a.names) std::cout << f.extension << "\n";
        rows.emplace_back(f.extension, f.doc);
    }
    if (a.names) return kOk;
    std::cout << "Output formats of 'plant run -o FILE' and the REPL's :export, chosen by extension:\n";
    print_columns(rows);
    return kOk;
}

int help_repl(const HelpArgs& a) {
    if (a.names) {
        for (const auto& c : Session::commands()) std::cout << ":" << c.name << "\n";
        return kOk;
    }
    std::cout << "Commands of 'plant repl':\n" << Session::command_list();
    return kOk;
}

// Adding a topic: one row here and its printer above.
struct HelpTopic {
    const char* name;
    const char* summary;
    int (*print)(const HelpArgs& args);
};

const HelpTopic kTopics[] = {
    {"builtins", "the built-in functions, their argument types and what they do", help_builtins},
    {"turtle", "the turtle symbols and query modules, their parameters and defaults", help_turtle},
    {"hooks", "the hooks a grammar can define, in the order they run", help_hooks},
    {"settings", "the top-level settings (derive, angle, ...)", help_settings},
    {"operators", "the operators of expressions and assignments", help_operators},
    {"env", "environment kinds; 'plant help env KIND' lists a kind's methods", help_env},
    {"formats", "the output formats 'plant run' writes, by extension", help_formats},
    {"repl", "the commands of 'plant repl'", help_repl},
};

int help_main(CLI::App& app, const HelpArgs& a) {
    if (a.man) {
        if (!a.words.empty() || a.names) {
            std::cerr << "plant: help --man prints the whole man page: give it no topic and no --names\n";
            return kUsage;
        }
        std::vector<std::pair<std::string, std::string>> topics;
        for (const auto& t : kTopics) topics.emplace_back(t.name, t.summary);
        std::cout << man_page(app, topics);
        return kOk;
    }
    if (a.words.empty()) {
        std::vector<std::pair<std::string, std::string>> commands, topics;
        for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
            commands.emplace_back(sub->get_name(), sub->get_description());
        for (const auto& t : kTopics) topics.emplace_back(t.name, t.summary);
        if (a.names) {
            for (const auto& c : commands) std::cout << c.first << "\n";
            for (const auto& t : topics) std::cout << t.first << "\n";
            return kOk;
        }
        std::cout << "Commands ('plant COMMAND --help' or 'plant help COMMAND' shows a command's options):\n";
        print_columns(commands);
        std::cout << "Topics ('plant help TOPIC'; --names lists only the names):\n";
        print_columns(topics);
        return kOk;
    }
    for (const auto& t : kTopics)
        if (a.words[0] == t.name) return t.print(a);
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
        if (sub->get_name() != a.words[0]) continue;
        std::cout << sub->help("plant");
        return kOk;
    }
    std::string names;
    for (const auto& t : kTopics) names += (names.empty() ? "" : ", ") + std::string(t.name);
    std::cerr << fmt::format("plant: no help topic or command '{}'; the topics are {}\n", a.words[0], names);
    return kUsage;
}

} // namespace

void setup_help(CLI::App& app, int& exit_code) {
    auto a = std::make_shared<HelpArgs>();
    CLI::App* cmd = app.add_subcommand("help", "List the commands and topics, or explain one");
    cmd->add_option("TOPIC", a->words, "A command or a topic, and for env a kind: plant help env climber")
        ->type_name("");
    cmd->add_flag("--names", a->names, "Print only the names the topic lists, one per line");
    cmd->add_flag("--man", a->man, "Print the man page plant.1 (troff), made from the commands' help");
    std::string topics = "Topics:\n";
    for (const auto& t : kTopics) topics += fmt::format("  {:<10} {}\n", t.name, t.summary);
    cmd->footer(topics);
    cmd->callback([&app, a, &exit_code] {
        exit_code = help_main(app, *a);
        if (exit_code == kOk && !(std::cout << std::flush)) { // a full disk, a closed pipe
            std::cerr << "plant: cannot write to the standard output\n";
            exit_code = kCantCreate;
        }
    });
}

} // namespace plant::cli
