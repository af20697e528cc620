// From syntax trees to a runnable Program: imports, name resolution, types, checks.
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/environment.hpp"
#include "plant/program.hpp"
#include "plant/vm.hpp"

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace plant {

struct CompileOptions {
    std::vector<std::pair<std::string, std::string>> defines; // -D name=value
    std::vector<std::string> include_dirs;                    // -I dir, then PLANT_PATH, then stdlib
    std::map<std::string, std::string> file_texts;            // imported files' text, instead of reading them
    // Confine the files a grammar reads (imports, load(...), mesh files) to its own folder, the
    // library folders, the standard library and `allow_read` (file_access.hpp). The plant command
    // always does; a program embedding the compiler decides for its own grammars.
    bool confine_reads = false;
    std::vector<std::string> allow_read;        // --allow-read DIR
    EnvironmentFactory environments;            // the runtime's kinds; none: `env` cannot be used
    std::uint64_t max_steps = kDefaultMaxSteps; // the VM's budget for constants evaluated now
    bool steps_given = false; // the command line says how many steps (-n): no note that derive N is missing
};

// Reads, parses and compiles `path` and everything it imports. Returns null when there were
// errors (which are in `diags`). Warnings do not stop compilation.
std::unique_ptr<Program> compile_file(SourceManager& sources, const std::string& path,
                                      const CompileOptions& options, Diagnostics& diags);

// The same for a file already loaded into `sources`.
std::unique_ptr<Program> compile_source(SourceManager& sources, std::uint32_t file_id,
                                        const CompileOptions& options, Diagnostics& diags);

// Reads a whole file. Returns false when it cannot be read.
bool read_file(const std::string& path, std::string& out);

} // namespace plant
