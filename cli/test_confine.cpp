// plant test runs command lines a test file's comments give; the file may come from a stranger,
// so the command, the options and the paths they name are checked here before anything runs.
#include "test_confine.hpp"

#include "plant/diagnostics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <optional>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

enum class Kind { Flag, Value, Reads, Writes };

struct AllowedOption {
    const char* name;
    const char* short_name; // or nullptr
    Kind kind;
};

// Every option a test's `# args:` may pass (the options of derive, check and run that read or
// write nothing but the test's own files). `--allow-read` is left out on purpose: a test cannot
// widen what its grammar may read; the user passes it to `plant test` itself.
constexpr AllowedOption kAllowed[] = {
    {"--define", "-D", Kind::Value},
    {"--steps", "-n", Kind::Value},
    {"--seed", nullptr, Kind::Value},
    {"--threads", nullptr, Kind::Value},
    {"--max-modules", nullptr, Kind::Value},
    {"--max-steps", nullptr, Kind::Value},
    {"--max-work", nullptr, Kind::Value},
    {"--max-memory", nullptr, Kind::Value},
    {"--ids", nullptr, Kind::Flag},
    {"--stats", nullptr, Kind::Flag},
    {"--sides", nullptr, Kind::Value},
    {"--size", nullptr, Kind::Value},
    {"--width-scale", nullptr, Kind::Value},
    {"--view", nullptr, Kind::Value},
    {"--lines", nullptr, Kind::Flag},
    {"--tubes", nullptr, Kind::Flag},
    {"--min-line-width", nullptr, Kind::Value},
    {"--max-triangles", nullptr, Kind::Value},
    {"--no-gpu-instancing", nullptr, Kind::Flag},
    {"--flatten", nullptr, Kind::Flag},
    {"--camera", nullptr, Kind::Value},
    {"--look-at", nullptr, Kind::Value},
    {"--no-obstacles", nullptr, Kind::Flag},
    {"--seeds", nullptr, Kind::Value},
    {"--grid", nullptr, Kind::Value},
    {"--jobs", nullptr, Kind::Value},
    {"--shard", nullptr, Kind::Value},
    {"--include", "-I", Kind::Reads},
    {"--edits", nullptr, Kind::Reads},
    {"--output", "-o", Kind::Writes},
    {"--manifest", nullptr, Kind::Writes},
};

const AllowedOption* find_option(const std::string& name) {
    for (const auto& o : kAllowed)
        if (name == o.name || (o.short_name && name == o.short_name)) return &o;
    return nullptr;
}

// Whether `value`, taken relative to `dir`, leads to `dir` or under it once `..` and symbolic
// links are resolved.
bool stays_under(const fs::path& dir, const std::string& value) {
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(fs::absolute(dir.empty() ? fs::path(".") : dir, ec), ec);
    if (ec || root.empty()) return false;
    const fs::path target = fs::weakly_canonical(root / value, ec);
    if (ec) return false;
    auto r = root.begin(), t = target.begin();
    for (; r != root.end(); ++r, ++t)
        if (t == target.end() || *r != *t) return false;
    return true;
}

struct Word {
    std::string name, value; // the option, and its value when written in the same word
    bool inline_value = false;
    std::string prefix; // what comes before the value in the same word
};

std::optional<Word> split_option(const std::string& a) {
    Word w;
    if (a.rfind("--", 0) == 0 && a.size() > 2) {
        const auto eq = a.find('=');
        w.name = a.substr(0, eq);
        if (eq != std::string::npos) {
            w.value = a.substr(eq + 1);
            w.inline_value = true;
            w.prefix = a.substr(0, eq + 1);
        }
        return w;
    }
    if (a.size() >= 2 && a[0] == '-' && a[1] != '-') {
        w.name = a.substr(0, 2);
        if (a.size() > 2) {
            w.value = a.substr(2);
            w.inline_value = true;
            w.prefix = w.name;
        }
        return w;
    }
    return std::nullopt;
}

} // namespace

std::string confine_test_command(const fs::path& file, TestCommandLine& c, const fs::path& outdir) {
    auto at = [&](int line, int col, const std::string& msg) {
        return fmt::format("  {}:{}:{}: error: {}\n", escape_controls(file.string()), line, col,
                           escape_controls(msg));
    };
    static const std::string kCommands[] = {"derive", "check", "run"};
    if (std::find(std::begin(kCommands), std::end(kCommands), c.command) == std::end(kCommands))
        return at(c.command_line, c.command_col,
                  fmt::format("plant test runs only 'derive', 'check' and 'run' from a test's comments, "
                              "not '{}'",
                              c.command));
    bool outputs = false;
    for (std::size_t k = 0; k < c.args.size(); ++k) {
        const int line = c.args_line, col = c.arg_cols[k];
        const auto word = split_option(c.args[k]);
        if (!word)
            return at(line, col,
                      fmt::format("'{}' is not an option: a test's '# args:' holds options only (the "
                                  "grammar is the test file itself)",
                                  c.args[k]));
        if (word->name == "--allow-read")
            return at(line, col,
                      "a test cannot pass --allow-read: pass it to plant test itself "
                      "(plant test --allow-read DIR ...)");
        const AllowedOption* opt = find_option(word->name);
        if (!opt)
            return at(line, col,
                      fmt::format("'{}' is not an option a test may pass (docs/testing.md lists them)",
                                  word->name));
        if (opt->kind == Kind::Flag) continue;
        std::size_t value_k = k;
        std::string value = word->value;
        if (!word->inline_value) {
            if (k + 1 >= c.args.size()) break; // plant itself reports the missing value
            value_k = ++k;
            value = c.args[value_k];
        }
        const int value_col =
            c.arg_cols[value_k] + (word->inline_value ? static_cast<int>(word->prefix.size()) : 0);
        if (opt->kind == Kind::Reads && (value.empty() || !stays_under(file.parent_path(), value)))
            return at(line, value_col,
                      fmt::format("{} in a test must name a file or folder under the test's own folder, "
                                  "found '{}'",
                                  word->name, value));
        if (opt->kind != Kind::Writes) continue;
        if (opt->short_name && std::string(opt->short_name) == "-o") outputs = true;
        if (outdir.empty()) return at(line, value_col, "cannot create a folder for the outputs");
        if (value.empty() || value.find('/') != std::string::npos || value == "." || value == "..")
            return at(line, value_col,
                      fmt::format("an output of a test must be a plain file name (no folder, no '..'), "
                                  "found '{}': plant test writes outputs into a folder of its own",
                                  value));
        c.args[value_k] = (word->inline_value ? word->prefix : std::string()) + (outdir / value).string();
    }
    if (c.command == "run" && !outputs) {
        const std::string stem = file.stem().string();
        for (const char* ext : {".glb", ".png"})
            c.args.insert(c.args.end(), {"-o", (outdir / (stem + ext)).string()});
    }
    return {};
}

} // namespace plant::cli
