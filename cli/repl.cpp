// The REPL session: every change (a typed production, axiom or :set) recompiles the session's
// grammar and replays the same number of steps, so what is shown is always what a fresh
// `plant derive` of the same grammar would give.
#include "repl.hpp"

#include "outputs.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
#include "plant/export.hpp"
#include "plant/vm.hpp"
#include "repl_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <sstream>
#include <thread>
#include <tuple>
#include <utility>

namespace plant::cli {

namespace fs = std::filesystem;

Session::Session(std::ostream& out, std::ostream& err, bool color) : out_(out), err_(err), color_(color) {}

DeriveOptions Session::options() const {
    DeriveOptions o;
    o.steps = 1000000; // the REPL decides when to stop, not the grammar's `derive N;`
    o.seed = seed_;
    o.threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    o.interrupt = interrupt_;
    o.max_steps = max_steps_;
    o.max_work = max_work_;
    if (max_modules_ > 0) o.max_modules = max_modules_;
    static TurtleEnvironmentPhase phase;
    o.environment_phase = &phase;
    std::ostream* out = &out_;
    o.on_print = [out](const std::string& text) { *out << escape_controls(text, true); };
    o.edits = graph_edits_;
    return o;
}

void Session::SessionText::add(std::string_view more, std::uint32_t typed_at) {
    text.append(more);
    text += '\n';
    std::uint32_t line = typed_at;
    lines.push_back(line);
    for (std::size_t i = 0; i < more.size(); ++i) // a lone '\r' ends a line too, as SourceFile has it
        if (more[i] == '\n' || (more[i] == '\r' && (i + 1 == more.size() || more[i + 1] != '\n')))
            lines.push_back(typed_at == 0 ? 0 : ++line);
}

Session::SessionText Session::session_source(const Extra* extra) const {
    SessionText s;
    if (!file_.empty()) s.add(fmt::format("import \"{}\";", file_), 0);
    for (const auto& d : declarations_) s.add(d.text, d.line);
    if (axiom_) s.add("axiom: " + axiom_->text + ";", axiom_->line);
    // typed settings: the session's file comes after the import, so its settings win
    for (const auto& [key, value] : settings_) s.add(fmt::format("{} {};", key, value.text), value.line);
    // productions in a rules block of the session's, blocks as typed, in the order typed
    bool open = false;
    for (const auto& r : extra_rules_) {
        if (open == r.block) s.add(std::exchange(open, !r.block) ? "}" : "rules {", 0);
        s.add(r.text, r.line);
    }
    if (open) s.add("}", 0);
    if (!edits_.empty()) {
        // each edit on lines of its own, so that an error points into what the user typed
        s.add(fmt::format("on {} {{", ast::spelling(ast::HookKind::BeforeStep)), 0);
        for (const auto& [at, statements] : edits_) {
            s.add(fmt::format("if step() == {} {{", at), 0);
            s.add(statements.text, statements.line);
            s.add("}", 0);
        }
        s.add("}", 0);
    }
    if (extra) {
        if (!extra->before.empty()) s.add(extra->before, 0);
        s.add(extra->typed, item_line_);
        if (!extra->after.empty()) s.add(extra->after, 0);
    }
    return s;
}

std::uint32_t Session::add_session(SourceManager& sources, const SessionText& session) const {
    const std::uint32_t id = sources.add("<session>", session.text);
    // Lines the session adds around what was typed (0) show the number of the typed line after
    // them (an expression's `fn ... =`, a `rules {`), or, after the last, the one before them
    // (a closing `}`, the empty line after the text's last newline, where an unterminated
    // comment is reported), so every message names a line of the input.
    std::vector<std::uint32_t> lines = session.lines;
    lines.push_back(0);
    std::uint32_t near = 0;
    for (auto it = lines.rbegin(); it != lines.rend(); ++it) near = *it = *it != 0 ? *it : near;
    for (auto& l : lines) near = l = l != 0 ? l : near;
    sources.show_lines(id, std::move(lines));
    return id;
}

CompileOptions Session::compile_options() const {
    CompileOptions co;
    co.max_steps = max_steps_;
    for (const auto& [name, value] : params_) co.defines.emplace_back(name, value);
    if (!file_.empty()) co.file_texts[file_] = file_text_with_consts(); // as read, with :set consts
    // the session's source is "<session>": the loaded grammar's folder is its own
    co.confine_reads = true;
    co.allow_read = allow_read_;
    if (!file_.empty()) co.allow_read.push_back(fs::path(file_).parent_path().string());
    co.environments = runtime_environments();
    return co;
}

// Diagnostics not shown before in this session: a rebuild repeats the grammar's warnings, which
// the user has seen already.
Diagnostics Session::news(const Diagnostics& diags, const SourceManager& sources) {
    Diagnostics out;
    for (const auto& d : diags.all()) {
        // by message and source line, not position: the session's own lines move as it grows
        std::string key = d.message;
        if (d.span.valid())
            key += "|" + std::string(sources.file(d.span.file)
                                         .line_text(sources.file(d.span.file).line_col(d.span.begin).line));
        if (d.severity == Severity::Error || shown_.insert(key).second) out.add(d);
    }
    return out;
}

bool Session::rebuild(int steps) {
    auto sources = std::make_unique<SourceManager>();
    CompileOptions co = compile_options();
    Diagnostics diags;
    std::uint32_t id = add_session(*sources, session_source());
    auto program = compile_source(*sources, id, co, diags);
    err_ << render_all(news(diags, *sources), *sources, color_);
    last_error_input_ = diags.has_input_errors();
    if (!program) {
        failed_ = true;
        last_error_runtime_ = false;
        return false;
    }
    if (!parse_graph_lines(*program, *sources)) return false;
    std::vector<std::unique_ptr<Derivation>> history;
    try {
        history.push_back(std::make_unique<Derivation>(*program, options()));
        history.back()->start();
        // :use choices are replayed at the steps where they were made
        auto apply_uses = [&](Derivation& d) {
            for (const auto& [at, group] : uses_)
                if (at == d.steps_done()) d.use_group(group.empty() ? -1 : program->group_index(group));
        };
        apply_uses(*history.back());
        for (int k = 0; k < steps; ++k) {
            auto next = std::make_unique<Derivation>(*history.back());
            int before = next->steps_done();
            auto t0 = std::chrono::steady_clock::now();
            next->step();
            last_step_ms_ =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            if (next->steps_done() == before) break; // a hook said stop
            apply_uses(*next);
            history.push_back(std::move(next));
        }
    } catch (const RuntimeError& e) {
        error() << render(Diagnostic{Severity::Error, e.span, e.message, {}}, *sources, color_);
        if ((e.kind == RuntimeErrorKind::ModuleLimit || e.kind == RuntimeErrorKind::WorkLimit) &&
            !history_.empty())
            error() << fmt::format("not changed; still at step {}: {}\n", current().steps_done(),
                                   modules(current().string().size()));
        last_error_runtime_ = true;
        return false;
    }
    last_error_runtime_ = false;
    sources_ = std::move(sources);
    program_ = std::move(program);
    history_ = std::move(history);
    return drop_orphaned_edits(steps);
}

int Session::load(const std::string& path) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
        error() << fmt::format("plant: cannot read '{}': {}\n", escape_controls(path),
                               fs::is_directory(path, ec) ? "it is a directory"
                               : path == "-" ? "no such file (the REPL reads its commands from standard "
                                               "input; pipe a grammar in as typed lines, or name its file)"
                                             : "no such file");
        return 66;
    }
    // a new grammar starts a new session; a grammar that does not build leaves the old one as it was
    auto saved = std::tuple{file_,   file_text_, declarations_, axiom_, extra_rules_, params_,
                            consts_, settings_,  seed_,         uses_,  edits_,       graph_lines_};
    file_ = fs::path(path).lexically_normal().string(); // as given: messages stay short and portable
    read_file(file_, file_text_);
    declarations_.clear();
    axiom_.reset();
    extra_rules_.clear();
    params_.clear();
    consts_.clear();
    settings_.clear();
    seed_.reset();
    uses_.clear();
    edits_.clear();
    graph_lines_.clear();
    graph_undo_.clear();
    default_edits_unreadable_ = false;
    if (!rebuild(0) || (read_default_edits() && !rebuild(0))) {
        std::tie(file_, file_text_, declarations_, axiom_, extra_rules_, params_, consts_, settings_, seed_,
                 uses_, edits_, graph_lines_) = saved;
        graph_undo_.clear();
        return last_error_runtime_ ? 70 : last_error_input_ ? 66 : 65;
    }
    out_ << fmt::format("loaded {}: {} at step 0\n", escape_controls(path),
                        modules(current().string().size()));
    return 0;
}

bool Session::need_derivation() {
    if (!history_.empty()) return true;
    error() << "no grammar yet: :load FILE, or type an axiom such as 'axiom: F;'\n";
    return false;
}

bool Session::step(int n) {
    if (!need_derivation()) return true;
    for (int k = 0; k < n; ++k) {
        std::unique_ptr<Derivation> next;
        int before = current().steps_done();
        auto t0 = std::chrono::steady_clock::now();
        try {
            // the copy charges the memory budget too: past it, the session stays at this step
            next = std::make_unique<Derivation>(current());
            if (k == 0) next->reset_work(); // each command starts a fresh --max-work budget
            next->step();
        } catch (const RuntimeError& e) {
            error() << render(Diagnostic{Severity::Error, e.span, e.message, {}}, *sources_, color_);
            if (e.kind == RuntimeErrorKind::Interrupted)
                error() << fmt::format("interrupted; still at step {}\n", current().steps_done());
            else if (e.kind == RuntimeErrorKind::ModuleLimit || e.kind == RuntimeErrorKind::Memory ||
                     e.kind == RuntimeErrorKind::WorkLimit)
                error() << fmt::format("still at step {}: {}\n", current().steps_done(),
                                       modules(current().string().size()));
            return false;
        }
        last_step_ms_ =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (next->steps_done() == before) {
            out_ << fmt::format("the derivation has stopped (a hook said stop) at step {}\n", before);
            return true;
        }
        history_.push_back(std::move(next));
    }
    out_ << fmt::format("step {}: {} ({:.3f} ms)\n", current().steps_done(),
                        modules(current().string().size()), last_step_ms_);
    return true;
}

void Session::show(const std::string& rest) {
    if (!need_derivation()) return;
    std::istringstream in(rest);
    std::string word, range;
    bool ids = false;
    while (in >> word) {
        if (word == "--ids")
            ids = true;
        else
            range = word;
    }
    const ModuleString& s = current().string();
    std::size_t b = 0, e = s.size();
    if (!range.empty()) {
        auto dots = range.find("..");
        auto b_ok = whole_number(range.substr(0, dots));
        auto e_ok = dots == std::string::npos ? std::optional<std::uint64_t>(b_ok ? *b_ok + 1 : 0)
                                              : whole_number(range.substr(dots + 2));
        if (!b_ok || !e_ok) {
            error() << fmt::format("':show' expects a range such as 0..20, found '{}'\n", range);
            return;
        }
        b = static_cast<std::size_t>(*b_ok);
        e = static_cast<std::size_t>(*e_ok);
        e = std::min(e, s.size());
        if (b >= e) {
            error() << fmt::format("the range {} is empty: the string has {}\n", range, modules(s.size()));
            return;
        }
    }
    ModuleString part;
    part.append_range(s, b, e);
    const std::size_t limit = 2000;
    std::string text = format_string(*program_, part, ids, limit); // stops soon after the limit
    if (text.size() > limit)
        out_ << text.substr(0, limit) << fmt::format("... ({} modules; :show A..B shows a part)\n", e - b);
    else
        out_ << text << "\n";
}

void Session::find(const std::string& pattern) {
    if (!need_derivation()) return;
    if (pattern.empty()) {
        error() << "':find' expects a predecessor pattern, as in :find A(x) : x > 2 or :find B < A\n";
        return;
    }
    const ModuleString& s = current().string();
    auto list = [&](const std::vector<std::size_t>& found, const char* what) {
        for (std::size_t k = 0; k < found.size() && k < 50; ++k) {
            ModuleString one;
            one.append_range(s, found[k], found[k] + 1);
            out_ << fmt::format("  {:>8}  #{:<8} {}\n", found[k], s.id(found[k]),
                                format_string(*program_, one));
        }
        if (found.size() > 50) out_ << fmt::format("  ... and {} more\n", found.size() - 50);
        out_ << fmt::format("{} {}{}\n", found.size(), what, found.size() == 1 ? "" : "es");
    };
    // a bare name finds every module of that name, whatever its parameters
    if (pattern.find_first_of("()<>:[] \t") == std::string::npos) {
        std::vector<std::size_t> found;
        if (auto sym = program_->symbols.find(pattern))
            for (std::size_t i = 0; i < s.size(); ++i)
                if (s.symbol(i) == *sym) found.push_back(i);
        list(found, "match");
        return;
    }
    // a pattern becomes the only production of a rule group of its own, compiled with the
    // session's grammar, then matched (context and condition included) against the string
    const Extra group{"rules __find__ {", pattern + " -> ;", "}"};
    auto sources = std::make_unique<SourceManager>();
    Diagnostics diags;
    auto program =
        compile_source(*sources, add_session(*sources, session_source(&group)), compile_options(), diags);
    Diagnostics errors;
    for (const auto& d : diags.all())
        if (d.severity == Severity::Error) errors.add(d);
    error_if(errors, *sources);
    if (!program) return;
    int g = program->group_index("__find__");
    if (g < 0) return;
    const Derivation& d = current();
    std::vector<std::size_t> found;
    try {
        found = find_matches(d, *program, program->groups[static_cast<std::size_t>(g)]);
    } catch (const RuntimeError& e) {
        error() << render(Diagnostic{Severity::Error, e.span, e.message, {}}, *sources, color_);
        return;
    }
    list(found, "match");
}

void Session::error_if(const Diagnostics& errors, const SourceManager& sources) {
    if (errors.all().empty()) return;
    error() << render_all(errors, sources, color_);
}

void Session::stats() {
    if (!need_derivation()) return;
    const ModuleString& s = current().string();
    std::map<SymbolId, std::size_t> counts;
    int depth = 0, max_depth = 0;
    std::size_t numbers = 0; // the modules' parameters (a constant one is stored with its kind)
    for (std::size_t i = 0; i < s.size(); ++i) {
        const SymbolId x = s.symbol(i);
        ++counts[x];
        numbers += s.arity(i);
        if (x == program_->symbols.open_bracket) max_depth = std::max(max_depth, ++depth);
        if (x == program_->symbols.close_bracket) --depth;
    }
    std::vector<std::pair<std::size_t, SymbolId>> sorted;
    for (auto [sym, n] : counts) sorted.emplace_back(n, sym);
    std::sort(sorted.begin(), sorted.end(),
              [](auto a, auto b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
    out_ << fmt::format("step {}, {} modules, {} parameters, branch depth {}, last step {:.3f} ms\n",
                        current().steps_done(), s.size(), numbers, max_depth, last_step_ms_);
    for (std::size_t k = 0; k < sorted.size() && k < 20; ++k)
        out_ << fmt::format("  {:<10} {}\n", program_->symbols[sorted[k].second].name, sorted[k].first);
}

void Session::rules() {
    if (!program_) {
        need_derivation();
        return;
    }
    auto text_of = [&](Span sp) {
        const std::string& t = sources_->file(sp.file).text();
        std::string s = t.substr(sp.begin, sp.end - sp.begin);
        std::replace(s.begin(), s.end(), '\n', ' ');
        return trim(s);
    };
    // the grammar's files first (imports come before the session's own text), typed rules last
    for (auto it = program_->files.rbegin(); it != program_->files.rend(); ++it) {
        const ProgramFile& f = *it;
        const bool typed = sources_->file(f.source).name() == "<session>";
        for (const auto& rb : f.rule_blocks) {
            const char* kind = rb.kind == ast::RuleKind::Rules       ? "rules"
                               : rb.kind == ast::RuleKind::Decompose ? "decompose"
                                                                     : "interpret";
            out_ << kind << (rb.group.empty() ? "" : " " + rb.group) << (typed ? " (typed)" : "") << ":\n";
            for (Span p : rb.productions) out_ << "  " << text_of(p) << "\n";
        }
    }
}

void Session::params() {
    if (!need_derivation()) return;
    for (const auto& gl : program_->globals) {
        const double* v = current().globals().data() + gl.slot;
        std::string value = gl.type == ValueType::Vec3 ? fmt::format("vec3({}, {}, {})", format_double(v[0]),
                                                                     format_double(v[1]), format_double(v[2]))
                                                       : format_double(v[0]);
        out_ << fmt::format("  {} {} = {}\n", gl.kind == GlobalKind::Param ? "param" : "var", gl.name, value);
    }
}

void Session::evaluate(const std::string& expr) {
    static const std::string kFn = "__repl_value__";
    // the expression on a line of its own, so that errors point into what the user typed
    const Extra fn{fmt::format("fn {}() =", kFn), expr, ";"};
    // compile the session with the expression as a function, then run it on the current globals
    auto sources = std::make_unique<SourceManager>();
    CompileOptions co = compile_options();
    Diagnostics diags;
    SessionText session = session_source(&fn);
    if (history_.empty()) session.add("axiom: ;", 0); // no grammar yet: typed declarations only
    const std::string& text = session.text;
    const std::uint32_t id = add_session(*sources, session);
    auto program = compile_source(*sources, id, co, diags);
    // An error past the typed expression (at the `;` the session added on the next line) is
    // shown at the end of what was typed, on the line the user typed.
    const std::size_t typed_end = text.rfind(fn.before) + fn.before.size() + 1 + fn.typed.size();
    Diagnostics placed;
    for (Diagnostic d : diags.all()) {
        if (d.span.valid() && d.span.file == id && d.span.begin > typed_end) {
            d.span = Span{id, static_cast<std::uint32_t>(typed_end), static_cast<std::uint32_t>(typed_end)};
            if (auto at = d.message.rfind("found ';'"); at != std::string::npos)
                d.message.replace(at, 9, "found the end of the line");
        }
        placed.add(std::move(d));
    }
    err_ << render_all(news(placed, *sources), *sources, color_);
    if (!program) {
        failed_ = true;
        return;
    }
    const Function* f = nullptr;
    for (const auto& candidate : program->functions)
        if (candidate.name == kFn) f = &candidate;
    if (!f) return;
    std::vector<double> globals = program->global_values;
    if (!history_.empty() && current().globals().size() == globals.size()) globals = current().globals();
    EvalEnv env;
    env.prog = program.get();
    env.globals = globals.data();
    env.seed = seed_.value_or(0);
    env.interrupt = interrupt_; // Ctrl-C stops a long evaluation too
    env.max_steps = max_steps_;
    if (!history_.empty()) env.step = current().steps_done();
    std::vector<double> frame(std::max<std::size_t>(f->frame_size, 1));
    double r[3] = {0, 0, 0};
    try {
        run(f->code, frame.data(), env, r);
    } catch (const RuntimeError& e) {
        error() << render(Diagnostic{Severity::Error, e.span, e.message, {}}, *sources, color_);
        return;
    }
    if (f->result == ValueType::Vec3)
        out_ << fmt::format("vec3({}, {}, {})\n", format_double(r[0]), format_double(r[1]),
                            format_double(r[2]));
    else if (f->result == ValueType::Bool)
        out_ << (r[0] != 0 ? "true" : "false") << "\n";
    else
        out_ << format_double(r[0]) << "\n";
}

bool Session::back_to(int k) {
    history_.resize(std::min(history_.size(), static_cast<std::size_t>(k) + 1));
    // a graph edit made after step k can no longer be the last thing done (the edit itself stays)
    std::erase_if(graph_undo_, [&](const auto& u) { return u.first > history_.size(); });
    // what was chosen or done after step k belongs to the steps undone
    std::erase_if(uses_, [&](const auto& u) { return u.first > k; });
    std::size_t before = edits_.size();
    // an edit at step k ran in step k + 1 (undone), or is still waiting for it
    std::erase_if(edits_, [&](const auto& e) { return e.first >= k; });
    if (edits_.size() < before)
        out_ << fmt::format("undid {} edit{} made at step {} or later\n", before - edits_.size(),
                            before - edits_.size() == 1 ? "" : "s", k);
    // each kept step has its own copy of the environments (a climber's particles): only undone
    // edits need the steps derived again, without them
    return edits_.size() < before && rebuild(k);
}

void Session::edit(std::string statements) {
    if (!need_derivation()) return;
    statements = trim(statements);
    if (statements.empty()) {
        error() << "':do' expects statements, as in :do ivy.cut(12);\n";
        return;
    }
    if (statements.back() != ';' && statements.back() != '}') statements += ';';
    int at = current().steps_done();
    edits_.emplace_back(at, Typed{statements, item_line_});
    if (rebuild(at))
        out_ << fmt::format("before step {}: {}\n", at + 1, statements);
    else
        edits_.pop_back();
}

void Session::list_edits() {
    const DecompositionGraph* g = history_.empty() ? nullptr : current().run_state().graph();
    if (edits_.empty() && (!g || !g->edits() || g->edits()->edits.empty())) out_ << "no edits\n";
    for (const auto& [at, statements] : edits_)
        out_ << fmt::format("  before step {}: {}\n", at + 1, statements.text);
    list_graph_edits();
}

bool Session::is_edit(const std::string& line) const {
    if (!program_) return false;
    std::size_t dot = line.find('.'), paren = line.find('(');
    if (dot == std::string::npos || paren == std::string::npos || paren < dot) return false;
    std::string env = trim(line.substr(0, dot)), method = trim(line.substr(dot + 1, paren - dot - 1));
    for (const EnvironmentDecl& d : program_->environments) {
        if (d.name != env || !d.kind) continue;
        if (const EnvMethod* m = d.kind->method(method)) return m->access == EnvAccess::Edit;
    }
    return false;
}

void Session::export_files(const std::vector<std::string>& paths, const OutputOptions& options) {
    if (!need_derivation()) return;
    OutputOptions o = options;
    if (const std::atomic<bool>* flag = interrupt_) // Ctrl-C: checked at each stage (interpreting,
        o.progress = [flag](const std::string&) {   // meshing, writing each file)
            if (flag->load()) throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
        };
    try {
        OutputSummary s = write_outputs(*program_, current(), paths, o);
        for (const auto& p : paths) out_ << "wrote " << escape_controls(p) << "\n";
        out_ << fmt::format("{} triangles, {} organs\n", s.triangles, s.organs);
    } catch (const RuntimeError& e) {
        if (e.kind == RuntimeErrorKind::Interrupted) { // the files are written whole or not at all
            error() << fmt::format("interrupted; nothing written, still at step {}\n",
                                   current().steps_done());
            return;
        }
        error() << render(Diagnostic{Severity::Error, e.span, e.message, {}}, *sources_, color_);
    } catch (const ExportError& e) {
        error() << "plant: " << escape_controls(e.what(), true) << "\n";
    }
}

// :back [N] and :reset; back_to (above) does their work
void Session::back_command(const std::string& name, const std::string& rest) {
    auto count = [&](int fallback) { return count_arg(name, rest, fallback); };
    if (auto n = count(1); n && need_derivation()) {
        if (undo_graph_edit()) return; // the last thing done was a graph edit
        int k = std::min<int>(*n, static_cast<int>(history_.size()) - 1);
        if (k == 0)
            out_ << "nothing to undo\n";
        else if (k < *n)
            out_ << fmt::format("only {} step{} to undo\n", k, k == 1 ? "" : "s");
        back_to(static_cast<int>(history_.size()) - 1 - k);
        out_ << fmt::format("step {}: {}\n", current().steps_done(), modules(current().string().size()));
    }
}

void Session::reset_command() {
    // back_to derives again only when it has to; :reset always starts afresh
    if (need_derivation() && (back_to(0) || rebuild(0)))
        out_ << fmt::format("step 0: {}\n", modules(current().string().size()));
}

std::ostream& Session::error() {
    failed_ = true;
    return err_;
}

namespace {

// What lex() reports of a character: code, the opening quote of a string, the '#' of a comment
// that runs to the end of its line.
enum class Lexed { Code, String, LineComment };

// Walks `text` as the grammar's lexer does (docs/language.md, lexical rules), calling
// `on(i, what)` for every character outside comments and strings and for the start of each
// string and # comment; `comment` says whether a /* comment */ is open, before and after.
template <typename On> void lex(std::string_view text, bool& comment, On&& on) {
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        const char next = i + 1 < text.size() ? text[i + 1] : '\0';
        if (comment) {
            if (c == '*' && next == '/') comment = false, ++i;
        } else if (c == '#') {
            on(i, Lexed::LineComment);
            while (i + 1 < text.size() && text[i + 1] != '\n') ++i;
        } else if (c == '/' && next == '*') {
            comment = true;
            ++i;
        } else if (c == '"') { // a string ends at its closing quote or with its line
            on(i, Lexed::String);
            while (++i < text.size() && text[i] != '"' && text[i] != '\n')
                if (text[i] == '\\') ++i;
        } else {
            on(i, Lexed::Code);
        }
    }
}

// `text` without a # comment at its end (outside strings and /* */), and without what it would
// then end with of blanks: a `;` the session adds must not fall into the comment.
std::string without_trailing_comment(const std::string& text) {
    std::size_t cut = text.size();
    bool comment = false;
    lex(text, comment, [&](std::size_t i, Lexed what) {
        if (what == Lexed::LineComment && text.find('\n', i) == std::string::npos) cut = i;
    });
    return trim(text.substr(0, cut));
}

// Whether `text` holds nothing but comments and blanks.
bool only_comments(std::string_view text) {
    bool comment = false, code = false;
    lex(text, comment, [&](std::size_t i, Lexed what) {
        const char c = text[i];
        code = code || what == Lexed::String ||
               (what == Lexed::Code && c != ' ' && c != '\t' && c != '\n' && c != '\r');
    });
    return !code;
}

// A REPL command: ':' and a letter (a line of a block may start with a condition's ':').
bool is_command(std::string_view line) {
    return line.size() >= 2 && line[0] == ':' && std::isalpha(static_cast<unsigned char>(line[1]));
}

} // namespace

void Session::OpenScan::line(std::string_view text) {
    lex(text, comment, [&](std::size_t i, Lexed what) {
        if (what != Lexed::Code) return;
        braces += text[i] == '{' ? 1 : text[i] == '}' ? -1 : 0;
        parens += text[i] == '(' ? 1 : text[i] == ')' ? -1 : 0;
    });
}

std::string Session::open_thing() const {
    if (pending_scan_.comment) return "a /* comment */";
    return pending_scan_.braces > 0 ? "a '{'" : "a '('";
}

void Session::finish() {
    if (pending_.empty()) return;
    error() << fmt::format("<session>:{}:1: error: {} opened on this line is not closed at the end of the "
                           "input; what was typed from "
                           "here was not run\n",
                           pending_line_, open_thing());
    pending_.clear();
}

bool Session::execute(const std::string& raw) {
    ++input_line_;
    if (!pending_.empty()) {
        if (is_command(trim(raw))) { // a command: the block is given up
            error() << fmt::format(
                "<session>:{}:1: error: {} opened on this line is not closed; dropped what was typed "
                "from here to run {}\n",
                pending_line_, open_thing(), trim(raw));
            pending_.clear();
        } else {
            pending_ += "\n" + raw;
            pending_scan_.line(raw);
            if (goes_on(pending_scan_, pending_declaration_)) return true;
            std::string item = std::move(pending_);
            pending_.clear();
            item_line_ = pending_line_;
            return run_item(trim(item));
        }
    }
    std::string line = trim(raw);
    if (line.empty() || line[0] == '#') return true;
    // (of the commands, only :do takes grammar text, statements that may hold a block)
    const bool statements =
        line.rfind(":do", 0) == 0 && (line.size() == 3 || line[3] == ' ' || line[3] == '\t');
    if (!is_command(line) || statements) {
        OpenScan scan;
        scan.line(line);
        const bool declaration = item_kind(line) == Item::Declaration;
        if (goes_on(scan, declaration)) {
            pending_ = line;
            pending_line_ = input_line_;
            pending_scan_ = scan;
            pending_declaration_ = declaration;
            return true;
        }
    }
    item_line_ = input_line_;
    return run_item(line);
}

bool Session::run_item(std::string line) {
    if (line[0] != ':') {
        if (only_comments(line)) return true; // a /* comment */ over lines
        line = without_trailing_comment(line);
    }
    if (line[0] == ':') {
        std::size_t sp = line.find_first_of(" \t");
        std::string name = line.substr(1, sp == std::string::npos ? std::string::npos : sp - 1);
        std::string rest = sp == std::string::npos ? std::string() : trim(line.substr(sp));
        return command(name, rest);
    }
    int steps = history_.empty() ? 0 : current().steps_done();
    if (line.rfind("axiom:", 0) == 0) {
        auto saved = axiom_;
        std::string a = trim(line.substr(6));
        if (!a.empty() && a.back() == ';') a.pop_back();
        axiom_ = Typed{a, item_line_};
        if (rebuild(steps))
            out_ << fmt::format("axiom set; step {}: {}\n", current().steps_done(),
                                modules(current().string().size()));
        else
            axiom_ = saved;
        return true;
    }
    if (typed_setting(line)) return true;
    if (typed_declaration(line)) return true;
    bool production =
        line.find("->") != std::string::npos || (line.back() == '}' && line.find('{') != std::string::npos);
    if (production) {
        if (line.back() != ';' && line.back() != '}') line += ';';
        extra_rules_.push_back({line, item_line_});
        if (rebuild(steps))
            out_ << fmt::format("rule added; step {}: {}\n", current().steps_done(),
                                modules(current().string().size()));
        else
            extra_rules_.pop_back();
        return true;
    }
    if (is_edit(line)) {
        edit(line);
        return true;
    }
    if (line.back() == ';') line.pop_back(); // `2 * r1;` is an expression too
    evaluate(line);
    return true;
}

} // namespace plant::cli
