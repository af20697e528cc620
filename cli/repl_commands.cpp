// The REPL's commands: one table that :help, Tab completion and dispatch read, and the bodies of
// the commands that are more than a call into the session (repl.cpp holds the session itself).
#include "repl.hpp"
#include "repl_text.hpp"

#include "plant/compiler.hpp"
#include "plant/parser.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <sstream>
#include <tuple>

namespace plant::cli {

std::span<const ReplCommand> Session::commands() {
    using C = ReplCompletion;
    using S = Session;
    using A = const std::string&;
    // Adding a command: one row here, and what it does (a call into the session).
    static const ReplCommand table[] = {
        {"load", "",
         [](S& s, A, A rest) {
             if (rest.empty())
                 s.error() << "':load' expects a file name\n";
             else
                 s.load(rest);
         },
         ":load FILE", "read a grammar file; the session starts again at step 0", C::Files},
        {"reload", "", [](S& s, A, A) { s.reload(); }, ":reload",
         "read the file again, keep :set values and typed rules, replay the same number of steps",
         C::Nothing},
        {"step", "s",
         [](S& s, A typed, A rest) {
             if (auto n = s.count_arg(typed, rest, 1)) s.step(*n);
         },
         ":step [N]", "derive N more steps (default 1)", C::Nothing},
        {"back", "b", [](S& s, A typed, A rest) { s.back_command(typed, rest); }, ":back [N]",
         "undo the last N steps (default 1), with the edits (:do) made in them and the :use choices made "
         "after "
         "the step it goes back to",
         C::Nothing},
        {"reset", "", [](S& s, A, A) { s.reset_command(); }, ":reset", "go back to the axiom (step 0)",
         C::Nothing},
        {"show", "", [](S& s, A, A rest) { s.show(rest); }, ":show [A..B] [--ids]",
         "print the string, or modules A to B; long strings are shortened", C::Nothing},
        {"find", "", [](S& s, A, A rest) { s.find(rest); }, ":find PATTERN",
         "list the modules a name or predecessor pattern matches (A, A(x) : x > 2, B < A(x)), with positions "
         "and "
         "identities",
         C::Modules},
        {"set", "", [](S& s, A, A rest) { s.set_param(rest); }, ":set NAME VALUE",
         "change a param or a const of the loaded file (VALUE is an expression) and replay", C::Params},
        {"params", "", [](S& s, A, A) { s.params(); }, ":params",
         "list the params and vars with their current values", C::Nothing},
        {"seed", "", [](S& s, A, A rest) { s.set_seed(rest); }, ":seed S",
         "change the random seed and replay", C::Nothing},
        {"rules", "", [](S& s, A, A) { s.rules(); }, ":rules", "list the productions, typed ones included",
         C::Nothing},
        {"use", "", [](S& s, A, A rest) { s.use(rest); }, ":use GROUP",
         "select a rule group for the next steps (:use none to clear)", C::Groups},
        {"do", "", [](S& s, A, A rest) { s.edit(rest); }, ":do STATEMENTS",
         "run statements as an on before_step hook would before the next step: a climber's edits "
         "(ivy.cut(ID), ivy.pull(ID, vec3(X, Y, Z)), ivy.wind(vec3(X, Y, Z)), ivy.seed(ID), "
         "ivy.move(K, vec3(X, Y, Z))), or assigning vars; such a call typed alone needs no :do. "
         "Kept with the step for replays; :back undoes it",
         C::Names},
        {"edits", "", [](S& s, A, A) { s.list_edits(); }, ":edits",
         "list the edits (:do) and the steps they run before, then the graph's edits and the node each "
         "applies to (or dormant)",
         C::Nothing},
        {"graph", "", [](S& s, A, A rest) { s.graph_command(rest, false); }, ":graph [PATH]",
         "print the decomposition graph from PATH (default /) down: each node's parameters, their "
         "status and origin",
         C::Nothing},
        {"node", "", [](S& s, A, A rest) { s.graph_command(rest, true); }, ":node PATH",
         "print one node of the decomposition graph", C::Nothing},
        {"edit", "", [](S& s, A, A rest) { s.graph_edit("edit", rest); }, ":edit PATH NAME = EXPR",
         "give a graph node's parameter a value (NAME += EXPR, NAME *= EXPR: relative to the inherited one) "
         "and derive again; the edit is bound to the node's range of positions; :back undoes it",
         C::Nothing},
        {"inherit", "", [](S& s, A, A rest) { s.graph_edit("inherit", rest); }, ":inherit PATH NAME",
         "make a graph node's parameter inherited again", C::Nothing},
        {"private", "", [](S& s, A, A rest) { s.graph_edit("private", rest); }, ":private PATH NAME",
         "make a graph node's parameter private: its children inherit from further up", C::Nothing},
        {"public", "", [](S& s, A, A rest) { s.graph_edit("public", rest); }, ":public PATH NAME",
         "make a graph node's parameter public again", C::Nothing},
        {"share", "", [](S& s, A, A rest) { s.graph_edit("share", rest); }, ":share LEVEL NAME = EXPR",
         "give every graph node at depth LEVEL one explicit value", C::Nothing},
        {"save", "", [](S& s, A, A rest) { s.save_edits(rest); }, ":save [FILE]",
         "write the graph's edits as an edits file (default: the grammar's edits \"file\";)", C::Files},
        {"stats", "", [](S& s, A, A) { s.stats(); }, ":stats",
         "modules per symbol, branch depth, steps and the time of the last step", C::Nothing},
        {"time", "", [](S& s, A, A) { s.out_ << fmt::format("last step: {:.3f} ms\n", s.last_step_ms_); },
         ":time", "the time of the last step", C::Nothing},
        {"export", "", [](S& s, A, A rest) { s.export_command(rest); }, ":export [OPTION]... FILE...",
         "write files as plant run does (.glb .png .obj .svg .txt .skel.json ...); options "
         "--flatten, --no-gpu-instancing, --camera X,Y,Z, --look-at X,Y,Z, --size WxH (PNG and SVG)",
         C::Files},
        {"render", "",
         [](S& s, A, A rest) { s.export_files({rest.empty() ? std::string("out/repl.png") : rest}); },
         ":render [FILE.png]", "write a PNG preview (default out/repl.png)", C::Files},
        {"help", "h ?", [](S& s, A, A rest) { s.help(rest); }, ":help [COMMAND]",
         "list the commands, or explain one", C::Commands},
        {"quit", "q exit", [](S& s, A, A) { s.quit_ = true; }, ":quit", "end the session", C::Nothing},
    };
    return table;
}

std::string Session::command_list() {
    std::string out;
    for (const auto& c : commands()) out += fmt::format("  {:<22} {}\n", c.usage, c.help);
    return out;
}

const ReplCommand* Session::find_command(const std::string& name) const {
    for (const auto& c : commands()) {
        if (name == c.name) return &c;
        std::istringstream aliases(c.aliases);
        for (std::string alias; aliases >> alias;)
            if (name == alias) return &c;
    }
    return nullptr;
}

bool Session::command(const std::string& name, const std::string& rest) {
    const ReplCommand* c = find_command(name);
    if (!c) {
        std::vector<std::string> names;
        for (const auto& known : commands()) names.emplace_back(known.name);
        const std::string near = nearest_name(name, names);
        error() << fmt::format("unknown command ':{}'; {}\n", escape_controls(name),
                               near.empty() ? ":help lists the commands"
                                            : fmt::format("did you mean ':{}'?", near));
        return true;
    }
    c->run(*this, name, rest);
    return !quit_;
}

void Session::help(const std::string& topic) {
    std::string name = topic.empty() || topic[0] != ':' ? topic : topic.substr(1);
    if (name.empty()) {
        out_ << command_list();
        out_ << "Anything else is a production (A(x) -> B(x + 1);), an axiom (axiom: A(1);), a setting "
                "(angle 30;), a declaration (module A(x);, const k = 2;, fn f(x) = 2 * x;, ignore: F;), a "
                "block (rules grow { B -> C; }, on start { ... }) or an expression to evaluate (2 * pi). A "
                "line that leaves a '{' open (or, in a declaration, a '(') goes on over the lines after it "
                "until it is closed.\n";
        return;
    }
    for (const auto& c : commands()) {
        if (name == c.name) {
            out_ << c.usage << "\n  " << c.help << "\n";
            return;
        }
    }
    error() << fmt::format("no command ':{}'; :help lists them\n", name);
}

std::optional<int> Session::count_arg(const std::string& typed, const std::string& rest, int fallback) {
    if (rest.empty()) return fallback;
    if (auto v = whole_number(rest); v && *v <= 1000000) return static_cast<int>(*v);
    error() << fmt::format("':{}' expects a whole number from 0 to 1000000, found '{}'\n", typed, rest);
    return std::nullopt;
}

void Session::reload() {
    if (file_.empty()) {
        error() << "nothing to reload: :load a file first\n";
    } else {
        int steps = history_.empty() ? 0 : current().steps_done();
        std::string saved = file_text_;
        if (!read_file(file_, file_text_)) {
            error() << fmt::format("plant: cannot read '{}'\n", escape_controls(file_));
        } else if (rebuild(steps)) {
            out_ << fmt::format("reloaded; step {}: {}\n", current().steps_done(),
                                modules(current().string().size()));
        } else {
            file_text_ = saved;
        }
    }
}

void Session::set_param(const std::string& rest) {
    std::istringstream in(rest);
    std::string pname;
    in >> pname;
    std::string value;
    std::getline(in, value);
    value = trim(value);
    const auto is_param = [&] {
        return std::any_of(program_->globals.begin(), program_->globals.end(),
                           [&](const Global& g) { return g.kind == GlobalKind::Param && g.name == pname; });
    };
    // a const of the loaded file is set by replacing its value in the session's copy of the file
    const bool is_const = program_ && !is_param() && file_consts().count(pname) > 0;
    if (pname.empty() || value.empty()) {
        error() << "':set' expects NAME VALUE, as in :set r1 0.8\n";
    } else if (program_ && !is_const && !is_param()) {
        error() << fmt::format("no param '{}'; :params lists them\n", pname);
    } else if (is_const && !parses_as_expression(":set " + pname, value)) {
        return; // said why, on the value as typed
    } else {
        auto saved = std::pair{params_, consts_};
        (is_const ? consts_ : params_)[pname] = value;
        int steps = history_.empty() ? 0 : current().steps_done();
        if (rebuild(steps))
            out_ << fmt::format("{} = {}; step {}: {}\n", pname, value, current().steps_done(),
                                modules(current().string().size()));
        else
            std::tie(params_, consts_) = saved;
    }
}

bool Session::parses_as_expression(const std::string& name, const std::string& text) {
    SourceManager sources;
    Diagnostics diags;
    if (parse_expression(sources, sources.add(name, text), diags) && !diags.has_errors()) return true;
    error() << render_all(diags, sources, color_);
    return false;
}

std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> Session::file_consts() const {
    std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> out;
    if (file_.empty()) return out;
    SourceManager sources;
    Diagnostics diags;
    auto ast = parse_file(sources, sources.add(file_, file_text_), diags);
    if (!ast) return out;
    for (const auto& v : ast->values)
        if (v.kind == ast::DeclKind::Const && v.value) out[v.name] = {v.value->span.begin, v.value->span.end};
    return out;
}

std::string Session::file_text_with_consts() const {
    if (consts_.empty()) return file_text_;
    std::vector<std::pair<std::pair<std::uint32_t, std::uint32_t>, std::string>> edits;
    const auto found = file_consts();
    for (const auto& [name, value] : consts_)
        if (auto it = found.find(name); it != found.end()) edits.emplace_back(it->second, "(" + value + ")");
    std::sort(edits.begin(), edits.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    std::string text = file_text_; // from the end, so that earlier ranges stay where they were
    for (const auto& [range, value] : edits) text.replace(range.first, range.second - range.first, value);
    return text;
}

Session::Item Session::item_kind(std::string_view line) {
    // a keyword, then a blank (or, for ignore and consider, a ':'; for a block, its '{')
    auto starts = [&](std::string_view word, std::string_view then) {
        if (line.rfind(word, 0) != 0) return false;
        std::size_t at = word.size();
        const bool blank = at < line.size() && (line[at] == ' ' || line[at] == '\t');
        while (at < line.size() && (line[at] == ' ' || line[at] == '\t')) ++at;
        return (blank && then.empty()) || (at < line.size() && then.find(line[at]) != std::string_view::npos);
    };
    static constexpr std::string_view kDeclarations[] = {"param", "const",   "var",     "module", "fn",
                                                         "curve", "surface", "texture", "env",    "import"};
    for (std::string_view w : kDeclarations)
        if (starts(w, "")) return Item::Declaration;
    if (starts("ignore", ":") || starts("consider", ":")) return Item::Declaration;
    // a block as a grammar has it: `rules grow { A -> B; }`, `on start { ... }`, `graph { ... }`
    static constexpr std::string_view kBlocks[] = {"rules", "decompose", "interpret",
                                                   "on",    "graph",     "instance"};
    for (std::string_view w : kBlocks)
        if (starts(w, "") || starts(w, "{")) return Item::Block;
    return Item::Other;
}

bool Session::brings_axiom() const {
    auto sources = std::make_unique<SourceManager>();
    Diagnostics quiet; // what is wrong is told by the compile that follows
    auto program =
        compile_source(*sources, add_session(*sources, session_source()), compile_options(), quiet);
    return program != nullptr;
}

bool Session::compiles_alone() {
    auto sources = std::make_unique<SourceManager>();
    Diagnostics diags;
    SessionText session = session_source();
    session.add("axiom: ;", 0);
    auto program = compile_source(*sources, add_session(*sources, session), compile_options(), diags);
    err_ << render_all(news(diags, *sources), *sources, color_);
    if (!program) failed_ = true;
    return program != nullptr;
}

bool Session::typed_declaration(const std::string& line) {
    const Item kind = item_kind(line);
    // a block is whole once it ends with its '}' (a line that starts like one and does not,
    // `on_x + 1` or `rules -> B`, is something else)
    if (kind == Item::Other || (kind == Item::Block && line.back() != '}')) return false;
    std::string text = line;
    if (text.back() != ';' && text.back() != '}') text += ';';
    // blocks go with the typed productions, so that the one typed first applies first
    auto& list = kind == Item::Block ? extra_rules_ : declarations_;
    list.push_back({text, item_line_, kind == Item::Block});
    const char* done = kind == Item::Block ? "added" : "declared";
    bool ok = false;
    if (history_.empty() && brings_axiom()) {
        // an import of a grammar with an axiom: the session starts as after :load
        if ((ok = rebuild(0)))
            out_ << fmt::format("{}; step 0: {}\n", done, modules(current().string().size()));
    } else if (history_.empty()) {
        // no grammar yet: checked with an empty axiom, kept for the axiom typed next
        if ((ok = compiles_alone()))
            out_ << fmt::format("{}; type an axiom such as 'axiom: F;' to start\n", done);
    } else if ((ok = rebuild(current().steps_done()))) {
        out_ << fmt::format("{}; step {}: {}\n", done, current().steps_done(),
                            modules(current().string().size()));
    }
    if (!ok) {
        failed_ = true;
        list.pop_back();
    }
    return true;
}

bool Session::typed_setting(const std::string& line) {
    std::size_t sp = line.find_first_of(" \t");
    if (sp == std::string::npos) return false;
    const std::string key = line.substr(0, sp);
    if (std::none_of(ast::kSettings.begin(), ast::kSettings.end(),
                     [&](const auto& s) { return key == s.spelling; }))
        return false;
    // a grammar may name a param `width`: then `width * 2` is an expression
    if (program_ && (std::any_of(program_->globals.begin(), program_->globals.end(),
                                 [&](const Global& g) { return g.name == key; }) ||
                     file_consts().count(key) > 0))
        return false;
    std::string value = trim(line.substr(sp));
    if (!value.empty() && value.back() == ';') value = trim(value.substr(0, value.size() - 1));
    if (value.empty()) return false;
    if (history_.empty() && key != "seed") {
        // no grammar yet: kept for the axiom typed next, as a declaration is
        auto saved = settings_;
        settings_[key] = Typed{value, item_line_};
        if (compiles_alone())
            out_ << fmt::format("{} = {}; type an axiom such as 'axiom: F;' to start\n", key, value);
        else
            settings_ = saved;
        return true;
    }
    if (!need_derivation()) return true;
    if (key == "seed") { // the session's seed, as :seed sets it
        auto seed = whole_number(value);
        if (!seed) {
            error() << fmt::format("'seed' expects a whole number, found '{}'\n", value);
            return true;
        }
        auto saved = seed_;
        seed_ = *seed;
        if (rebuild(current().steps_done()))
            out_ << fmt::format("seed = {}; step {}: {}\n", *seed_, current().steps_done(),
                                modules(current().string().size()));
        else
            seed_ = saved;
        return true;
    }
    auto saved = settings_;
    settings_[key] = Typed{value, item_line_};
    int steps = current().steps_done();
    if (key == "derive") { // the session derives that many steps from the axiom
        auto n = whole_number(value);
        if (!n || *n > 1000000) {
            error() << fmt::format("'derive' expects a whole number from 0 to 1000000, found '{}'\n", value);
            settings_ = saved;
            return true;
        }
        steps = static_cast<int>(*n);
    }
    if (rebuild(steps))
        out_ << fmt::format("{} = {}; step {}: {}\n", key, value, current().steps_done(),
                            modules(current().string().size()));
    else
        settings_ = saved;
    return true;
}

void Session::set_seed(const std::string& rest) {
    if (auto v = whole_number(rest)) {
        auto saved = seed_;
        seed_ = *v;
        int steps = history_.empty() ? 0 : current().steps_done();
        if (history_.empty())
            out_ << fmt::format("seed {}\n", *seed_);
        else if (rebuild(steps)) // reported as :set reports a param
            out_ << fmt::format("seed = {}; step {}: {}\n", *seed_, current().steps_done(),
                                modules(current().string().size()));
        else
            seed_ = saved;
    } else {
        error() << fmt::format("':seed' expects a whole number, found '{}'\n", rest);
    }
}

void Session::use(const std::string& rest) {
    if (need_derivation()) {
        int g = rest == "none" ? -1 : program_->group_index(rest);
        if (g < 0 && rest != "none")
            error() << fmt::format("no rule group '{}'\n", rest);
        else {
            current().use_group(g);
            // remembered with its step, for replays; later choices at the same step win
            std::erase_if(uses_, [&](const auto& u) { return u.first >= current().steps_done(); });
            uses_.emplace_back(current().steps_done(), rest == "none" ? std::string() : rest);
            out_ << fmt::format("using {}\n", rest);
        }
    }
}

void Session::export_command(const std::string& rest) {
    std::istringstream in(rest);
    std::vector<std::string> paths;
    OutputOptions options;
    std::vector<std::string> words;
    for (std::string w; in >> w;) words.push_back(w);
    for (std::size_t k = 0; k < words.size(); ++k) {
        const std::string& w = words[k];
        if (w == "--flatten" || w == "--no-gpu-instancing") {
            options.gltf_layout = w == "--flatten" ? GltfLayout::Baked : GltfLayout::Nodes;
        } else if (w == "--camera" || w == "--look-at") {
            const auto point = k + 1 < words.size() ? parse_point(words[k + 1]) : std::nullopt;
            if (!point) {
                error() << fmt::format("':export {}' expects a point X,Y,Z after it, such as {} 0,5,20\n", w,
                                       w);
                return;
            }
            (w == "--camera" ? options.camera : options.look_at) = *point;
            ++k;
        } else if (w == "--size") {
            int width = 0, height = 0;
            char end = 0; // nothing may follow the height
            const std::string size = k + 1 < words.size() ? words[k + 1] : std::string();
            if (std::sscanf(size.c_str(), "%dx%d%c", &width, &height, &end) != 2 || width < 16 ||
                height < 16 || width > 16384 || height > 16384 ||
                static_cast<long long>(width) * height > 64LL * 1000 * 1000) {
                error() << fmt::format(
                    "':export --size' expects WIDTHxHEIGHT after it, each from 16 to 16384 "
                    "and at most 64 million pixels, such as --size 200x200; found '{}'\n",
                    escape_controls(size));
                return;
            }
            options.width = width;
            options.height = height;
            options.size_given = true;
            ++k;
        } else if (w.size() > 1 && w[0] == '-' && w[1] == '-') {
            error() << fmt::format("':export' has no option '{}': it takes --flatten, --no-gpu-instancing, "
                                   "--camera X,Y,Z and --look-at X,Y,Z before the file names\n",
                                   escape_controls(w));
            return;
        } else {
            paths.push_back(w);
        }
    }
    if (options.look_at && !options.camera) {
        error() << "':export --look-at' needs --camera: the point is where the camera looks\n";
        return;
    }
    if (options.camera && options.look_at && *options.camera == *options.look_at) {
        error() << "':export --camera' must not be the point it looks at\n";
        return;
    }
    if (paths.empty())
        error() << "':export' expects one or more file names\n";
    else
        export_files(paths, options);
}

ReplCompletion Session::completion_kind(const std::string& before) const {
    // the line's first word (a command's name, say), or a word in a production or expression
    std::string line = trim(before);
    if (line.empty() || line[0] != ':') return ReplCompletion::Names;
    std::size_t sp = line.find_first_of(" \t");
    const ReplCommand* c = find_command(line.substr(1, sp == std::string::npos ? std::string::npos : sp - 1));
    return c ? c->completes : ReplCompletion::Nothing;
}

std::vector<std::string> Session::completions(const std::string& before) const {
    const ReplCompletion kind = completion_kind(before);
    std::vector<std::string> out;
    if (kind == ReplCompletion::Names)
        for (const auto& c : commands()) out.push_back(std::string(":") + c.name);
    if (kind == ReplCompletion::Commands)
        for (const auto& c : commands()) out.push_back(c.name);
    if (kind == ReplCompletion::Groups) out.push_back("none");
    if (program_) {
        const bool all = kind == ReplCompletion::Names;
        for (const auto& g : program_->globals)
            if (all || (kind == ReplCompletion::Params && g.kind == GlobalKind::Param)) out.push_back(g.name);
        if (all || kind == ReplCompletion::Params) // consts, which :set may change too
            for (const auto& [name, range] : file_consts()) out.push_back(name);
        if (all || kind == ReplCompletion::Modules)
            for (const auto& s : program_->symbols.all())
                if (s.arity >= 0 && !s.name.empty()) out.push_back(s.name);
        if (all || kind == ReplCompletion::Groups)
            for (const auto& g : program_->groups) out.push_back(g.name);
        if (all) {
            for (const auto& e : program_->environments) out.push_back(e.name);
            for (const auto& c : program_->curves) out.push_back(c.name);
            for (const auto& f : program_->functions) out.push_back(f.name);
        }
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

} // namespace plant::cli
