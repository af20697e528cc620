// plant test: golden files and script tests.
//
// A .plant file with `# expect...` comments is a script test: it is derived (or checked) by a
// child `plant` process and its standard output, diagnostics and exit code are compared with
// the comments:
//   # args: -n 3 --seed 7           extra command-line arguments
//   # command: check                run `plant check` instead of `plant derive`
//   # expect: LINE                  one line of standard output, in order
//   # expect error: 3:14: message   an error at line 3, column 14; without the position, at any
//                                   place; the message's tail after "; " or ": " may be left out
//   # expect error contains: TEXT   an error whose line contains TEXT
//   # expect warning: 3:14: message a warning (and `# expect warning contains: TEXT`)
//   # expect exit: 70               the exit code (default 65 with errors, else 0)
// A file without such comments is a golden test: its derived string is compared with the
// sidecar NAME.txt beside it, which `--bless` rewrites. docs/testing.md describes them all.
#include "commands.hpp"
#include "test_child.hpp"
#include "test_confine.hpp"
#include "test_matching.hpp"

#include "plant/export.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <sstream>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

constexpr double kDefaultTestTimeout = 300;

struct Expectations : TestCommandLine {
    bool script = false;
    std::vector<std::string> out;
    std::vector<ExpectedDiagnostic> errors, warnings;
    std::optional<int> exit_code;
    std::vector<std::string> misspelt; // "line N: ..." for a comment that looks like a directive mistyped
};

// The words of `rest` with the 1-based column each begins at, `rest` starting at column `col`.
std::vector<std::string> split_words_at(const std::string& rest, int col, std::vector<int>& cols) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < rest.size();) {
        if (std::isspace(static_cast<unsigned char>(rest[i]))) {
            ++i;
            continue;
        }
        std::size_t e = i;
        while (e < rest.size() && !std::isspace(static_cast<unsigned char>(rest[e]))) ++e;
        out.push_back(rest.substr(i, e - i));
        cols.push_back(col + static_cast<int>(i));
        i = e;
    }
    return out;
}

Expectations read_expectations(const std::string& text) {
    Expectations e;
    int line_no = 0;
    for (auto raw : lines_of(text)) {
        ++line_no;
        if (!raw.empty() && raw.back() == '\r') raw.pop_back(); // files with CRLF line ends
        auto hash = raw.find('#');
        if (hash == std::string::npos) continue;
        std::string c = raw.substr(hash + 1);
        int rest_col = 0; // the 1-based column `rest` begins at
        auto take = [&](const char* key, std::string& rest) {
            std::string k = std::string(" ") + key;
            if (c.rfind(k, 0) != 0) return false;
            rest = c.substr(k.size());
            rest_col = static_cast<int>(hash + 1 + k.size()) + 1;
            if (!rest.empty() && rest[0] == ' ') {
                rest.erase(0, 1);
                ++rest_col;
            }
            return true;
        };
        std::string rest;
        if (take("args:", rest)) {
            e.arg_cols.clear();
            e.args = split_words_at(rest, rest_col, e.arg_cols);
            e.args_line = line_no;
        } else if (take("command:", rest)) {
            std::vector<int> cols;
            const std::vector<std::string> words = split_words_at(rest, rest_col, cols);
            e.command = words.empty() ? "derive" : words[0];
            e.command_line = line_no;
            e.command_col = words.empty() ? rest_col : cols[0];
            e.script = true;
        } else if (take("expect error contains:", rest)) {
            e.errors.push_back({rest, true});
            e.script = true;
        } else if (take("expect warning contains:", rest)) {
            e.warnings.push_back({rest, true});
            e.script = true;
        } else if (take("expect error:", rest)) {
            e.errors.push_back({rest, false});
            e.script = true;
        } else if (take("expect warning:", rest)) {
            e.warnings.push_back({rest, false});
            e.script = true;
        } else if (take("expect exit:", rest)) {
            e.exit_code = std::atoi(rest.c_str());
            e.script = true;
        } else if (take("expect:", rest)) {
            e.out.push_back(rest);
            e.script = true;
        } else {
            // `# expcet: F`, `# Expect:`: a directive mistyped would otherwise be a comment, and the
            // test would run without what it meant to check
            std::size_t a = 0;
            while (a < c.size() && c[a] == ' ') ++a;
            std::size_t b = a;
            while (b < c.size() && std::isalpha(static_cast<unsigned char>(c[b]))) ++b;
            const std::string word = c.substr(a, b - a);
            const std::size_t colon = c.find(':', b);
            const bool directive_like =
                b > a && colon != std::string::npos &&
                std::all_of(c.begin() + static_cast<std::ptrdiff_t>(b),
                            c.begin() + static_cast<std::ptrdiff_t>(colon), [](char ch) {
                                return std::isalpha(static_cast<unsigned char>(ch)) || ch == ' ';
                            });
            if (directive_like)
                if (const std::string near = nearest_name(word, {"expect", "args", "command"});
                    !near.empty() && near != word)
                    e.misspelt.push_back(
                        fmt::format("line {}: '#{}' is not a directive; did you mean '# {}:'?", line_no,
                                    escape_controls(c.substr(0, colon + 1)), near));
        }
    }
    return e;
}

// Diagnostics from stderr as "LINE:COL: message" (or the bare message when it has no place).
void parse_diagnostics(const std::string& err, std::vector<std::string>& errors,
                       std::vector<std::string>& warnings) {
    static const std::regex placed(R"(^.*?:(\d+):(\d+): (error|warning): (.*)$)");
    static const std::regex bare(R"(^plant: (error|warning): (.*)$)");
    for (const auto& line : lines_of(err)) {
        std::smatch m;
        if (std::regex_match(line, m, placed)) {
            (m[3] == "error" ? errors : warnings)
                .push_back(fmt::format("{}:{}: {}", m[1].str(), m[2].str(), m[4].str()));
        } else if (std::regex_match(line, m, bare)) {
            (m[1] == "error" ? errors : warnings).push_back(m[2].str());
        }
    }
}

std::string compare_lists(const char* what, const std::vector<std::string>& want,
                          const std::vector<std::string>& got) {
    std::string msg;
    for (std::size_t i = 0; i < std::max(want.size(), got.size()); ++i) {
        if (i < want.size() && i < got.size() && want[i] == got[i]) continue;
        msg += fmt::format("  {} {}:\n    expected: {}\n    got:      {}\n", what, i + 1,
                           i < want.size() ? escape_controls(want[i]) : "(nothing)",
                           i < got.size() ? escape_controls(got[i]) : "(nothing)");
    }
    return msg;
}

std::string first_difference(const std::string& want, const std::string& got) {
    std::size_t i = 0;
    while (i < want.size() && i < got.size() && want[i] == got[i]) ++i;
    auto excerpt = [&](const std::string& s) {
        std::size_t b = i > 30 ? i - 30 : 0;
        std::string e = s.substr(b, 70);
        std::replace(e.begin(), e.end(), '\n', ' ');
        return escape_controls(e);
    };
    return fmt::format(
        "  differs at byte {} (expected {} bytes, got {})\n    expected: ...{}\n    got:      ...{}\n", i,
        want.size(), got.size(), excerpt(want), excerpt(got));
}

bool write_atomically(const fs::path& path, const std::string& text) {
    try {
        write_file_atomically(path.string(), text);
        return true;
    } catch (const ExportError&) {
        return false;
    }
}

// A folder of plant test's own for one test's outputs, removed with everything in it.
struct OutputFolder {
    fs::path path;
    OutputFolder() {
        char name[] = "/tmp/plant-test-XXXXXX";
        if (mkdtemp(name)) path = name;
    }
    ~OutputFolder() {
        std::error_code ignored;
        if (!path.empty()) fs::remove_all(path, ignored);
    }
    OutputFolder(const OutputFolder&) = delete;
    OutputFolder& operator=(const OutputFolder&) = delete;
};

// Returns an empty string when the test passed, else what went wrong.
std::string timed_out(double seconds) {
    return fmt::format("  did not end within {} s: stopped (plant test --timeout SECONDS gives each "
                       "test more)\n",
                       seconds);
}

// Whether `path` (which may not exist yet) resolves inside `folder`: a test file, or a golden
// file beside it, that is a symbolic link out of its folder is not read (the folder may come from
// a stranger, and a failing test prints an excerpt of what it read).
bool resolves_inside(const fs::path& path, const fs::path& folder) {
    std::error_code ec;
    const fs::path root = fs::weakly_canonical(fs::absolute(folder.empty() ? fs::path(".") : folder, ec), ec);
    if (ec) return false;
    const fs::path target = fs::weakly_canonical(fs::absolute(path, ec), ec);
    if (ec) return false;
    auto r = root.begin(), t = target.begin();
    for (; r != root.end(); ++r, ++t)
        if (t == target.end() || *r != *t) return false;
    return true;
}

// The test file as its child process is given it, run in the file's folder: by its name, with
// './' before a name that would read as an option ('-x.plant') or as standard input ('-').
std::string child_name(const fs::path& file) {
    const std::string name = file.filename().string();
    return name.empty() || name[0] != '-' ? name : "./" + name;
}

std::string outside_folder(const fs::path& path) {
    return fmt::format("  {} is a symbolic link out of the test's folder: plant test does not read it "
                       "(make it a file of its own)\n",
                       escape_controls(path.string()));
}

// `walk_root`: the folder `file` was found in by walking it (nullptr: named on the command line).
std::string run_one(const fs::path& file, const fs::path* walk_root, bool bless, std::string& blessed,
                    const std::vector<std::string>& allow_read, double timeout) {
    if (walk_root && !resolves_inside(file, *walk_root)) return outside_folder(file);
    std::string text;
    if (!read_file(file.string(), text)) return "  cannot read the file\n";
    Expectations e = read_expectations(text);
    if (!e.misspelt.empty()) {
        std::string msg;
        for (const std::string& m : e.misspelt) msg += "  " + m + "\n";
        return msg;
    }
    OutputFolder outdir;
    if (std::string refused = confine_test_command(file, e, outdir.path); !refused.empty()) return refused;
    std::vector<std::string> args{e.command, child_name(file)};
    args.insert(args.end(), e.args.begin(), e.args.end());
    for (const auto& d : allow_read) args.insert(args.end(), {"--allow-read", fs::absolute(d).string()});
    ChildOutcome o = run_child(args, file.parent_path(), timeout);
    if (o.timed_out) return timed_out(timeout);
    if (e.script) {
        std::vector<std::string> errors, warnings;
        parse_diagnostics(o.err, errors, warnings);
        std::string msg;
        int want_exit = e.exit_code ? *e.exit_code : (e.errors.empty() ? 0 : 65);
        if (o.exit_code != want_exit)
            msg += fmt::format("  exit code: expected {}, got {}\n", want_exit, o.exit_code);
        msg += compare_diagnostics("error", e.errors, errors);
        msg += compare_diagnostics("warning", e.warnings, warnings);
        if (!e.out.empty() || o.exit_code == 0) {
            if (!e.out.empty() || (!o.out.empty() && e.command != "check"))
                msg += compare_lists("output line", e.out, lines_of(o.out));
        }
        if (!msg.empty() && !o.err.empty() && errors.empty() && warnings.empty())
            msg += "  stderr:\n" + escape_controls(o.err, true);
        return msg;
    }
    fs::path sidecar = file;
    sidecar.replace_extension(".txt");
    fs::path mesh_sidecar = file;
    mesh_sidecar.replace_extension(".mesh.txt");
    for (const fs::path& golden : {sidecar, mesh_sidecar})
        if (!resolves_inside(golden, file.parent_path())) return outside_folder(golden);
    if (o.exit_code != 0)
        return fmt::format("  exit code {} (a golden grammar must derive cleanly)\n{}", o.exit_code,
                           escape_controls(o.err, true));
    // the mesh summary: counts and bounds of `plant run`'s scene
    std::string mesh;
    if (bless || fs::exists(mesh_sidecar)) {
        char tmp_name[] = "/tmp/plant-test-XXXXXX.mesh.txt";
        int fd = mkstemps(tmp_name, 9);
        if (fd < 0) return "  cannot create a temporary file\n";
        close(fd);
        std::vector<std::string> run_args{"run", child_name(file)};
        run_args.insert(run_args.end(), e.args.begin(), e.args.end());
        run_args.insert(run_args.end(), {"-o", tmp_name});
        for (const auto& d : allow_read)
            run_args.insert(run_args.end(), {"--allow-read", fs::absolute(d).string()});
        ChildOutcome m = run_child(run_args, file.parent_path(), timeout);
        if (m.timed_out) {
            unlink(tmp_name);
            return timed_out(timeout);
        }
        read_file(tmp_name, mesh);
        unlink(tmp_name);
        if (m.exit_code != 0)
            return fmt::format("  plant run: exit code {}\n{}", m.exit_code, escape_controls(m.err, true));
    }
    if (bless) {
        for (const auto& [path, content] : {std::pair{sidecar, o.out}, std::pair{mesh_sidecar, mesh}}) {
            std::string old;
            const bool existed = read_file(path.string(), old);
            if (!existed || old != content) {
                if (!write_atomically(path, content))
                    return "  cannot write " + escape_controls(path.string()) + "\n";
                blessed += fmt::format("wrote {}{}\n{}", escape_controls(path.string()),
                                       existed ? "" : " (new)", short_diff(old, content));
            }
        }
        return {};
    }
    std::string want;
    if (!read_file(sidecar.string(), want))
        return fmt::format("  no expectations: add '# expect' comments or create {} with --bless\n",
                           escape_controls(sidecar.string()));
    if (want != o.out) return first_difference(want, o.out);
    if (fs::exists(mesh_sidecar)) {
        std::string want_mesh;
        read_file(mesh_sidecar.string(), want_mesh);
        if (want_mesh != mesh)
            return "  mesh summary (" + escape_controls(mesh_sidecar.filename().string()) + ") differs\n" +
                   first_difference(want_mesh, mesh);
    }
    return {};
}

struct TestCmd {
    std::vector<std::string> paths;
    std::vector<std::string> allow_read; // passed on to each grammar's command
    bool bless = false;
    bool verbose = false;
    double timeout = kDefaultTestTimeout; // seconds each child process may take
};

int test_main(const TestCmd& c) {
    ChildSignalGuard guard;                  // a signal stops the running child too, and then plant test
    std::vector<fs::path> files, walked;     // walked: found in a folder, not named
    std::map<fs::path, fs::path> walk_roots; // each walked file's folder, as named
    std::vector<std::string> paths = c.paths.empty() ? std::vector<std::string>{"grammars"} : c.paths;
    for (const auto& p : paths) {
        std::error_code ec;
        if (fs::is_directory(p, ec)) {
            fs::recursive_directory_iterator it(p, fs::directory_options::skip_permission_denied, ec), end;
            for (; !ec && it != end; it.increment(ec)) {
                std::error_code fe;
                // (a test file that links out of the folder is listed, and fails in run_one)
                if (it->is_regular_file(fe) && it->path().extension() == ".plant") {
                    files.push_back(it->path());
                    walked.push_back(it->path());
                    walk_roots[it->path()] = p;
                }
            }
        } else if (fs::exists(p, ec)) {
            files.emplace_back(p);
        } else {
            std::cerr << fmt::format(
                "plant: cannot read '{}': no such file or directory{}\n", escape_controls(p),
                p == "-" ? " (plant test runs files with their golden files beside them, "
                           "so it does not read standard input)"
                         : "");
            return kNoInput;
        }
    }
    std::sort(files.begin(), files.end());
    // files imported by others, with no expectations of their own, are libraries, not tests
    std::vector<fs::path> libraries = library_files(walked);
    int passed = 0, failed = 0, written = 0;
    // on a terminal, a line on standard error says which test runs (the results go to standard
    // output): a folder of slow grammars otherwise runs a minute without a word
    const bool progress = isatty(2) != 0;
    auto clear_progress = [&] {
        if (progress) std::cerr << "\r\x1b[K" << std::flush;
    };
    std::size_t index = 0;
    for (const auto& f : files) {
        ++index;
        if (std::find(libraries.begin(), libraries.end(), f) != libraries.end()) {
            if (c.verbose)
                std::cout << "library " << escape_controls(f.string()) << " (imported, not a test)\n";
            continue;
        }
        if (progress)
            std::cerr << fmt::format("\r\x1b[Ktest {}/{}: {}", index, files.size(),
                                     escape_controls(f.string()))
                      << std::flush;
        std::string blessed;
        const auto root = walk_roots.find(f);
        std::string msg = run_one(f, root == walk_roots.end() ? nullptr : &root->second, c.bless, blessed,
                                  c.allow_read, c.timeout);
        clear_progress();
        if (ChildSignalGuard::pending()) break;
        if (msg.empty()) {
            ++passed;
            if (!blessed.empty()) {
                for (const std::string& line : lines_of(blessed)) written += line.rfind("wrote ", 0) == 0;
                std::cout << blessed;
            } else if (c.verbose) {
                std::cout << "ok " << escape_controls(f.string()) << "\n";
            }
        } else {
            ++failed;
            std::cout << "FAIL " << escape_controls(f.string()) << "\n" << msg;
        }
    }
    if (c.bless) std::cout << fmt::format("{} file{} written\n", written, written == 1 ? "" : "s");
    std::cout << fmt::format("{} passed, {} failed\n", passed, failed);
    return failed == 0 && !files.empty() ? kOk : kFailed;
}

} // namespace

void setup_test(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<TestCmd>();
    CLI::App* cmd = app.add_subcommand("test", "Run golden-file and script tests of grammars");
    cmd->add_option("PATH", c->paths, "Grammar files or directories (default: grammars)");
    cmd->add_flag("--bless", c->bless,
                  "Rewrite the golden files (NAME.txt, NAME.mesh.txt) from the current output; lists each "
                  "file written with a short diff (review it!)");
    cmd->add_flag("-v,--verbose", c->verbose, "List passing tests too");
    cmd->add_option("--timeout", c->timeout,
                    fmt::format("Seconds each process a test starts may run before it is stopped and "
                                "the test fails (default {})",
                                kDefaultTestTimeout))
        ->transform(number_in(0.1, 86400, Bound::From))
        ->type_name("SECONDS");
    add_allow_read(*cmd, c->allow_read);
    cmd->callback([c, &exit_code] { exit_code = test_main(*c); });
}

} // namespace plant::cli
