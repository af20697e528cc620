#include "test_matching.hpp"

#include "commands.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace plant::cli {

namespace fs = std::filesystem;

std::vector<std::string> lines_of(const std::string& s) {
    std::vector<std::string> out;
    std::string line;
    std::istringstream in(s);
    while (std::getline(in, line)) out.push_back(line);
    return out;
}

namespace {

// "12:5: message" -> "message"; anything else as it is.
std::string without_position(const std::string& s) {
    static const std::regex placed(R"(^\d+:\d+: )");
    std::smatch m;
    return std::regex_search(s, m, placed) ? m.suffix().str() : s;
}

bool has_position(const std::string& s) {
    static const std::regex placed(R"(^\d+:\d+: )");
    return std::regex_search(s, placed);
}

// `text` equals `want`, or starts with it followed by "; " or ": " (a tail left out).
bool same_or_head(const std::string& want, const std::string& text) {
    if (text == want) return true;
    if (want.empty() || text.size() < want.size() + 2 || text.compare(0, want.size(), want) != 0)
        return false;
    const std::string sep = text.substr(want.size(), 2);
    return sep == "; " || sep == ": ";
}

} // namespace

bool diagnostic_matches(const ExpectedDiagnostic& want, const std::string& got) {
    if (want.contains) return got.find(want.text) != std::string::npos;
    if (same_or_head(want.text, got)) return true;
    return !has_position(want.text) && same_or_head(want.text, without_position(got));
}

std::string compare_diagnostics(const char* what, const std::vector<ExpectedDiagnostic>& want,
                                const std::vector<std::string>& got) {
    std::string msg;
    for (std::size_t i = 0; i < std::max(want.size(), got.size()); ++i) {
        if (i < want.size() && i < got.size() && diagnostic_matches(want[i], got[i])) continue;
        std::string expected = "(nothing)";
        if (i < want.size()) expected = (want[i].contains ? "containing: " : "") + want[i].text;
        msg += fmt::format("  {} {}:\n    expected: {}\n    got:      {}\n", what, i + 1,
                           escape_controls(expected), i < got.size() ? escape_controls(got[i]) : "(nothing)");
    }
    return msg;
}

std::string short_diff(const std::string& before, const std::string& after, std::size_t max_lines) {
    const std::vector<std::string> a = lines_of(before), b = lines_of(after);
    std::size_t head = 0;
    while (head < a.size() && head < b.size() && a[head] == b[head]) ++head;
    std::size_t ta = a.size(), tb = b.size(); // the common tail is left out too
    while (ta > head && tb > head && a[ta - 1] == b[tb - 1]) {
        --ta;
        --tb;
    }
    auto clip = [](const std::string& s) { return s.size() > 100 ? s.substr(0, 100) + "..." : s; };
    std::string out;
    for (std::size_t k = head; k < ta && k < head + max_lines; ++k)
        out += fmt::format("    {:>5} - {}\n", k + 1, escape_controls(clip(a[k])));
    if (ta - head > max_lines) out += fmt::format("          - ... {} more\n", ta - head - max_lines);
    for (std::size_t k = head; k < tb && k < head + max_lines; ++k)
        out += fmt::format("    {:>5} + {}\n", k + 1, escape_controls(clip(b[k])));
    if (tb - head > max_lines) out += fmt::format("          + ... {} more\n", tb - head - max_lines);
    return out;
}

std::vector<fs::path> library_files(const std::vector<fs::path>& files) {
    static const std::regex import_line(R"re(^\s*import\s+"([^"]+)")re");
    // a directive as read_expectations reads one: the line's first '#', then " expect" or " command:"
    auto directive = [](const std::string& line) {
        const std::size_t hash = line.find('#');
        return hash != std::string::npos &&
               (line.compare(hash + 1, 7, " expect") == 0 || line.compare(hash + 1, 9, " command:") == 0);
    };
    std::set<fs::path> imported;
    std::map<fs::path, bool> is_test; // has expectations or a sidecar
    for (const fs::path& f : files) {
        std::string text;
        if (!read_file(f.string(), text)) continue;
        fs::path sidecar = f;
        sidecar.replace_extension(".txt");
        std::error_code ec;
        bool test = fs::exists(sidecar, ec);
        for (const std::string& line : lines_of(text)) {
            test = test || directive(line);
            std::smatch m;
            if (std::regex_search(line, m, import_line))
                imported.insert(fs::weakly_canonical(f.parent_path() / m[1].str(), ec));
        }
        is_test[fs::weakly_canonical(f, ec)] = test;
    }
    std::vector<fs::path> out;
    for (const fs::path& f : files) {
        std::error_code ec;
        const fs::path c = fs::weakly_canonical(f, ec);
        if (imported.count(c) && !is_test[c]) out.push_back(f);
    }
    return out;
}

} // namespace plant::cli
