// What plant test lets a test's comments ask for (docs/testing.md "What a test may run"): the
// command, the options of its `# args:` line, and where the paths those options name may lead.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace plant::cli {

// The command line a script test's comments ask for, with where each part was written.
struct TestCommandLine {
    std::string command = "derive";
    std::vector<std::string> args;
    int command_line = 0, command_col = 0; // where `# command:` names the command
    int args_line = 0;                     // the line of `# args:`, and where each word begins
    std::vector<int> arg_cols;
};

// Checks `c` against what a test may run, and rewrites its outputs into `outdir`:
//   - the command is `derive`, `check` or `run`;
//   - every word of `# args:` is an option of the allow-list (test_confine.cpp), or the value of
//     the option before it; `--allow-read` is never accepted from a comment;
//   - an option that reads a file or folder (`-I`, `--edits`) names one under the test file's
//     folder, symbolic links resolved;
//   - an option that writes (`-o`, `--manifest`) names a plain file name, which is moved into
//     `outdir`; a `run` without outputs gets the default pair there.
// Returns an error placed on the comment ("  FILE:LINE:COL: error: ...\n"), or an empty string.
std::string confine_test_command(const std::filesystem::path& file, TestCommandLine& c,
                                 const std::filesystem::path& outdir);

} // namespace plant::cli
