// plant test's matching of expected diagnostics and its report of blessed files (docs/testing.md).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace plant::cli {

// The lines of `s`, without their line ends (a last line without one counts).
std::vector<std::string> lines_of(const std::string& s);

// An expected diagnostic: `text` as written after `# expect error:` (or `warning:`), or after
// `# expect error contains:` with `contains` set.
struct ExpectedDiagnostic {
    std::string text;
    bool contains = false;
};

// Whether `got` ("L:C: message", or a bare message) is what `want` expects:
//   - the same text;
//   - or, when `want` has no "L:C: " position, the same message at any position;
//   - and either way `want` may leave out the message's tail after "; " or ": " (the suggestion,
//     what to write instead): "unknown name 'R'" matches "unknown name 'R'; did you mean 'l'?";
//   - with `contains`, `want.text` anywhere in `got`.
bool diagnostic_matches(const ExpectedDiagnostic& want, const std::string& got);

// The report of one diagnostics list: each expectation matched in order with the diagnostics
// (one each); empty when all match and there are no diagnostics left over.
std::string compare_diagnostics(const char* what, const std::vector<ExpectedDiagnostic>& want,
                                const std::vector<std::string>& got);

// A short diff of `before` and `after` by lines: the first differing lines (at most `max_lines`
// of each), marked "-" and "+", with the line number, indented for plant test's report.
std::string short_diff(const std::string& before, const std::string& after, std::size_t max_lines = 4);

// The files of `files` that are libraries: imported (`import "PATH"`) by another of `files`,
// with no `# expect` or `# command` comment and no golden sidecar (NAME.txt) of their own.
// plant test does not run them as tests when it found them by walking a folder.
std::vector<std::filesystem::path> library_files(const std::vector<std::filesystem::path>& files);

} // namespace plant::cli
