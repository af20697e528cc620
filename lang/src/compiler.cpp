// The compiler's driver: reads the main file and its imports, then runs the stages in the order
// data flows (declarations, shapes, functions, settings and rules, hooks, the whole-program
// checks) and hands back a Program that holds no syntax tree. The stages are in compile_*.cpp
// and check.cpp; their shared state is Compiler (compiler_internal.hpp).
#include "plant/compiler.hpp"

#include "compiler_internal.hpp"
#include "plant/parser.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>

namespace plant {

namespace fs = std::filesystem;

bool read_file(const std::string& path, std::string& out) {
    return read_input_file(path, out, kMaxSourceBytes, false) == ReadFailure::None;
}

// Optimal string alignment distance: insertions, deletions, substitutions and swaps of two
// neighbouring letters each cost one, so the usual typos ('lenght', 'widht') are one edit away.
std::size_t edit_distance(std::string_view a, std::string_view b) {
    const std::size_t w = b.size() + 1;
    std::vector<std::size_t> d((a.size() + 1) * w);
    for (std::size_t i = 0; i <= a.size(); ++i) d[i * w] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        for (std::size_t j = 1; j <= b.size(); ++j) {
            std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            std::size_t v =
                std::min({d[(i - 1) * w + j] + 1, d[i * w + j - 1] + 1, d[(i - 1) * w + j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                v = std::min(v, d[(i - 2) * w + j - 2] + 1);
            d[i * w + j] = v;
        }
    }
    return d[a.size() * w + b.size()];
}

std::string nearest_name(std::string_view name, const std::vector<std::string>& candidates) {
    // short names get only close suggestions: 'g' should not suggest 'log'
    std::string best;
    std::size_t best_d = std::max<std::size_t>(1, name.size() / 3) + 1;
    for (const auto& c : candidates) {
        std::size_t d = edit_distance(name, c);
        if (d < best_d) {
            best_d = d;
            best = c;
        }
    }
    return best;
}

std::string Compiler::where(Span s) const {
    if (!s.valid()) return "?";
    const SourceFile& f = sm_.file(s.file);
    LineCol lc = f.shown_line_col(s.begin);
    if (s.file == current_file_) return fmt::format("{}:{}", lc.line, lc.col);
    return fmt::format("{}:{}:{}", f.name(), lc.line, lc.col);
}

void Compiler::duplicate(const std::string& what, const std::string& name, Span here, Span first) {
    Diagnostic d{Severity::Error, here, fmt::format("duplicate definition of {} '{}'", what, name), {}};
    d.notes.emplace_back(first, fmt::format("'{}' was first defined here", name));
    diags_->add(std::move(d));
}

std::unique_ptr<Program> Compiler::compile(std::uint32_t main_file) {
    // -D values are expressions, parsed from their own small sources
    for (const auto& [name, text] : opts_.defines) {
        std::uint32_t id = sm_.add(fmt::format("-D {}", name), text);
        auto e = parse_expression(sm_, id, *diags_);
        if (e) defines_[name] = {std::move(e), id};
    }
    std::vector<std::string> stack;
    main_file_ = main_file;
    load(main_file, {}, stack);
    if (diags_->has_errors()) return nullptr; // do not pile checks on a broken parse

    declare();
    declare_builtin_params();
    check_defines_used();
    compile_stages();
    current_file_ = main_file;
    if (!has_axiom_) {
        diags_->error(Span{main_file, 0, 0}, "the grammar has no axiom: add a line such as 'axiom: F;'");
    }
    if (!diags_->has_errors()) check_instance_graph();
    if (!diags_->has_errors()) {
        check_raw_runs();
        check_never_applying();
    }
    if (diags_->has_errors()) return nullptr;
    if (!table_->empty()) {
        P_.instance_table = table_;
        P_.instances = table_.get();
    }
    return std::move(program_);
}

// Shapes, functions, instance bodies, settings, rules and hooks, in the order data flows.
void Compiler::compile_stages() {
    find_assigned_params();
    fold_params_ = true; // every param now has its final value (after -D and import overrides)
    for (const ast::ShapeDecl* s : curve_decls_) compile_curve(*s); // before the code that calls them
    compile_graph();                                                // before the code that reads it
    for (const ast::ShapeDecl* s : env_decls_) compile_environment(*s);
    check_bound_modules();
    // an outer program's functions, inherited by an instance body, are compiled when called
    for (auto i = static_cast<std::uint32_t>(inherited_functions_); i < P_.functions.size(); ++i)
        ensure_function_compiled(i);
    for (const ast::ShapeDecl* s : surface_decls_) compile_surface(*s);
    compile_instances(); // they see the shapes and functions above
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        compile_settings(*lf.file);
        compile_rules(*lf.file);
        compile_hooks(*lf.file);
    }
    compile_hook_bodies();
    finish();
}

// Every file's names, in the order files were loaded (imports first): modules, then functions,
// shapes and rule groups, then params, consts and vars.
void Compiler::declare() {
    for (const auto& info : P_.symbols.all())
        if (info.declared) max_declared_len_ = std::max(max_declared_len_, info.name.size());
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        declare_modules(*lf.file);
    }
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        declare_instances(*lf.file);
    }
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        for (const auto& fd : lf.file->functions) declare_function(fd);
        for (const auto& e : lf.file->envs) {
            env_names_[e.name] = e.kind;
            env_decls_.push_back(&e);
        }
        for (const auto& cv : lf.file->curves) {
            curve_names_.insert(cv.name);
            curve_decls_.push_back(&cv);
        }
        for (const auto& t : lf.file->textures) declare_texture(t); // before the values: names are consts
        for (const auto& s : lf.file->surfaces) {
            surface_decls_.push_back(&s);
            P_.symbols.intern("~" + s.name);
        }
        for (const auto& rb : lf.file->rule_blocks) {
            if (rb.kind != ast::RuleKind::Rules || rb.group.empty()) continue;
            if (P_.group_index(rb.group) < 0) {
                RuleSet rs;
                rs.name = rb.group;
                rs.span = rb.group_span;
                P_.groups.push_back(std::move(rs));
                group_decls_.emplace_back(rb.group, rb.group_span);
            }
        }
    }
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        declare_values(lf);
    }
}

// After every rule is compiled: the set of modules skipped when matching context, whether '%'
// is ever produced, and each rule set's index by first symbol.
void Compiler::finish() {
    P_.ignored.assign(P_.symbols.size(), 0);
    for (SymbolId s = 0; s < P_.symbols.size(); ++s) {
        if (s == P_.symbols.open_bracket || s == P_.symbols.close_bracket) continue;
        if (has_consider_)
            P_.ignored[s] = consider_syms_.count(s) ? 0 : 1;
        else
            P_.ignored[s] = ignore_syms_.count(s) ? 1 : 0;
    }
    P_.uses_cut = produced_.count(P_.symbols.cut) > 0;
    check_group_directions();
    finish_rule_set(P_.rules);
    for (auto& g : P_.groups) finish_rule_set(g);
    finish_rule_set(P_.decompose);
    finish_rule_set(P_.interpret);
    assign_kinds();
}

std::unique_ptr<Program> compile_source(SourceManager& sources, std::uint32_t file_id,
                                        const CompileOptions& options, Diagnostics& diags) {
    Compiler c(sources, options, diags);
    try {
        return c.compile(file_id);
    } catch (const SymbolTable::Full&) {
        diags.error(Span{file_id, 0, 0},
                    fmt::format("the program names more than {} different modules, the most "
                                "plant can tell apart",
                                kNoSymbol - 1));
        return nullptr;
    }
}

std::unique_ptr<Program> compile_file(SourceManager& sources, const std::string& path,
                                      const CompileOptions& options, Diagnostics& diags) {
    std::string text;
    if (!read_file(path, text)) {
        diags.error(Span{}, fmt::format("cannot read '{}'", path));
        return nullptr;
    }
    return compile_source(sources, sources.add(path, std::move(text)), options, diags);
}

} // namespace plant
