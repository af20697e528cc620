// The man page plant.1 (troff, man macros), made from the commands' own help so that it cannot
// drift from the program: `plant help --man`, run at build time (cmake/manpage.cmake).
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <utility>
#include <vector>

namespace plant::cli {

// `topics`: the help topics, name and summary (plant help).
std::string man_page(CLI::App& app, const std::vector<std::pair<std::string, std::string>>& topics);

} // namespace plant::cli
