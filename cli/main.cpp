// plant: grow plants from parametric L-system grammars.
#include "commands.hpp"
#include "version.hpp"

#include "plant/big_pages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <string_view>
#include <thread>
#include <vector>

int main(int argc, char** argv) {
    using namespace plant::cli;
    // `plant run` and `plant derive` derive once, in a process of their own: while the options
    // are read and the grammar is compiled, the other core clears the page the derivation's
    // first strings will take (docs/rewriting.md, "A page cleared ahead").
    if (argc > 1 && (std::strcmp(argv[1], "run") == 0 || std::strcmp(argv[1], "derive") == 0) &&
        std::thread::hardware_concurrency() > 1)
        plant::big_pages::clear_ahead();
    CLI::App app{
        "plant: an interpreter for the .plant L-system language.\n"
        "Grammars are parametric, context-sensitive and stochastic L-systems (see docs/language.md).",
        "plant"};
    app.require_subcommand(1);
    app.set_help_all_flag("--help-all", "Show help for every command");
    app.set_version_flag("--version", fmt::format("plant {} (commit {})", kVersion, kCommit),
                         "Print the version and the git commit plant was built from");
    int exit_code = kOk;
    setup_run(app, exit_code);
    setup_derive(app, exit_code);
    setup_check(app, exit_code);
    setup_graph(app, exit_code);
    setup_test(app, exit_code);
    setup_repl(app, exit_code);
    setup_view(app, exit_code);
    setup_help(app, exit_code);
    // a first word that is no command and no option: name it (CLI11 would say only that a command
    // is required)
    if (argc > 1 && argv[1][0] != '-') {
        bool known = false;
        std::string names;
        for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
            known = known || sub->get_name() == argv[1];
            names += (names.empty() ? "" : ", ") + sub->get_name();
        }
        if (!known) {
            std::vector<std::string> commands;
            for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
                commands.push_back(sub->get_name());
            const std::string near = plant::nearest_name(argv[1], commands);
            std::cerr << "plant: unknown command '" << plant::escape_controls(argv[1], true) << "'"
                      << (near.empty() ? "" : "; did you mean '" + near + "'?") << " (the commands: " << names
                      << ")\nRun 'plant --help' for usage.\n";
            return kUsage;
        }
    }
    // help and the version written where they cannot be (a full disk) fail as other outputs do
    auto printed = [](const std::string& text) {
        std::cout << text << std::flush;
        if (std::cout) return kOk;
        std::cerr << "plant: cannot write to the standard output\n";
        return kCantCreate;
    };
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        return printed(app.help());
    } catch (const CLI::CallForAllHelp&) {
        return printed(app.help("", CLI::AppFormatMode::All));
    } catch (const CLI::CallForVersion& e) {
        return printed(std::string(e.what()) + "\n");
    } catch (const CLI::ParseError& e) {
        // CLI11 reports --help of a subcommand as CallForHelp too, caught above; everything else
        // is a usage error.
        std::string which;
        const CLI::App* command = nullptr;
        for (const CLI::App* sub : app.get_subcommands()) which = sub->get_name(), command = sub;
        std::cerr << "plant: " << plant::escape_controls(e.what(), true) << "\n";
        // an option the command does not have: the nearest one it has
        if (command) {
            std::vector<std::string> options;
            for (const CLI::Option* o : command->get_options())
                for (const std::string& name : o->get_lnames()) options.push_back("--" + name);
            for (int k = 2; k < argc && std::string_view(argv[k]) != "--"; ++k) {
                const std::string word = std::string(argv[k]).substr(0, std::string_view(argv[k]).find('='));
                if (word.rfind("--", 0) != 0 ||
                    std::find(options.begin(), options.end(), word) != options.end())
                    continue;
                if (const std::string near = plant::nearest_name(word, options); !near.empty())
                    std::cerr << "plant: " << which << " has no option " << plant::escape_controls(word, true)
                              << "; did you mean " << near << "?\n";
            }
        }
        std::cerr << "Run 'plant " << (which.empty() ? "" : which + " ") << "--help' for usage.\n";
        return kUsage;
    } catch (const plant::RuntimeError& e) { // one no command caught (a memory budget refused)
        std::cerr << "plant: error: " << plant::escape_controls(e.message, true) << "\n";
        return kRuntime;
    } catch (const std::bad_alloc&) {
        std::cerr << "plant: out of memory (lower --max-modules or the derivation length)\n";
        return kRuntime;
    } catch (const std::exception& e) {
        std::cerr << "plant: internal error: " << plant::escape_controls(e.what(), true) << "\n";
        return kRuntime;
    }
    return exit_code;
}
