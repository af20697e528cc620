// Program structure: imports and their overrides, declarations, rule sets, hooks, and the
// whole-program checks (undeclared letter runs, productions that can never apply).
#include "compiler_internal.hpp"
#include "plant/parser.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#ifndef PLANT_STDLIB_DIR
#define PLANT_STDLIB_DIR ""
#endif

namespace plant {

namespace fs = std::filesystem;

// ---- symbols -------------------------------------------------------------------------------

SymbolTable::SymbolTable() {
    // the turtle's symbols and query modules, one row each in plant/turtle_symbols.hpp
    for (const TurtleSymbol& t : kTurtleSymbols) {
        SymbolId id = intern(t.name);
        SymbolInfo& info = infos_[id];
        if (!t.prefix) info.turtle_op = t.op;
        info.turtle = t.kind == TurtleKind::Turtle;
        info.query = t.kind == TurtleKind::Query;
        // multi-letter turtle names are declared so letter runs do not split them
        info.declared =
            info.query || (t.name.size() > 1 && std::isalpha(static_cast<unsigned char>(t.name[0])));
    }
    open_bracket = *find("[");
    close_bracket = *find("]");
    cut = *find("%");
}

SymbolId SymbolTable::intern(std::string_view name) {
    auto it = index_.find(std::string(name));
    if (it != index_.end()) return it->second;
    if (infos_.size() >= kNoSymbol) throw Full{};
    auto id = static_cast<SymbolId>(infos_.size());
    SymbolInfo info;
    info.name = std::string(name);
    info.turtle_op = prefixed_turtle_op(name);
    infos_.push_back(std::move(info));
    index_.emplace(std::string(name), id);
    return id;
}

std::optional<SymbolId> SymbolTable::find(std::string_view name) const {
    auto it = index_.find(std::string(name));
    if (it == index_.end()) return std::nullopt;
    return it->second;
}

void RuleSet::index(std::size_t symbols) {
    by_symbol.assign(symbols, {});
    for (std::uint32_t i = 0; i < productions.size(); ++i)
        by_symbol[productions[i].strict[0].sym].push_back(i);
}

int Program::group_index(std::string_view name) const {
    for (std::size_t i = 0; i < groups.size(); ++i)
        if (groups[i].name == name) return static_cast<int>(i);
    return -1;
}

// ---- imports -------------------------------------------------------------------------------

std::string Compiler::resolve_import(const ast::Import& im, std::uint32_t from_file,
                                     std::vector<std::string>& searched) {
    fs::path from_dir = fs::path(sm_.file(from_file).name()).parent_path();
    std::error_code ec;
    if (im.is_path) {
        fs::path p = fs::path(im.target).is_absolute() ? fs::path(im.target) : from_dir / im.target;
        if (opts_.file_texts.count(p.lexically_normal().string())) return p.lexically_normal().string();
        searched.push_back(p.string());
        return fs::exists(p, ec) ? p.lexically_normal().string() : std::string();
    }
    std::vector<std::string> dirs = opts_.include_dirs;
    if (const char* pp = std::getenv("PLANT_PATH")) {
        std::string s = pp;
        std::size_t b = 0;
        while (b <= s.size()) {
            std::size_t e = s.find(':', b);
            if (e == std::string::npos) e = s.size();
            if (e > b) dirs.push_back(s.substr(b, e - b));
            b = e + 1;
        }
    }
    if (std::string(PLANT_STDLIB_DIR).size()) dirs.emplace_back(PLANT_STDLIB_DIR);
    for (const auto& d : dirs) {
        fs::path p = fs::path(d) / (im.target + ".plant");
        searched.push_back(p.string());
        if (fs::exists(p, ec)) return p.lexically_normal().string();
    }
    return {};
}

void Compiler::load(std::uint32_t file_id, std::map<std::string, std::pair<const ast::Expr*, Span>> overrides,
                    std::vector<std::string>& stack) {
    auto file = parse_file(sm_, file_id, *diags_);
    ast::File* f = file.get();
    P_.files.push_back(std::move(file));
    std::string self = fs::path(sm_.file(file_id).name()).lexically_normal().string();
    stack.push_back(self);
    loaded_paths_.insert(self);
    for (const auto& im : f->imports) {
        std::vector<std::string> searched;
        std::string path = resolve_import(im, file_id, searched);
        if (path.empty()) {
            diags_->error(im.span, im.is_path ? fmt::format("cannot find imported file '{}' (looked for {})",
                                                            im.target, searched.empty() ? "?" : searched[0])
                                              : fmt::format("cannot find library '{}' (searched {})",
                                                            im.target, fmt::join(searched, ", ")));
            continue;
        }
        if (std::find(stack.begin(), stack.end(), path) != stack.end()) {
            diags_->error(im.span,
                          fmt::format("import cycle: '{}' imports '{}', which is already being imported "
                                      "(chain: {})",
                                      self, path, fmt::join(stack, " -> ")));
            continue;
        }
        if (loaded_paths_.count(path)) continue; // imported already through another path
        std::string text;
        if (auto it = opts_.file_texts.find(path); it != opts_.file_texts.end()) {
            text = it->second;
        } else if (!read_file(path, text)) {
            diags_->error(im.span, fmt::format("cannot read imported file '{}'", path));
            continue;
        }
        std::uint32_t id = sm_.add(path, std::move(text));
        std::map<std::string, std::pair<const ast::Expr*, Span>> ov;
        for (std::size_t k = 0; k < im.overrides.size(); ++k) {
            const std::string& name = im.overrides[k].first;
            if (auto it = ov.find(name); it != ov.end()) {
                duplicate("override", name, im.override_spans[k], it->second.second);
                continue;
            }
            ov[name] = {im.overrides[k].second.get(), im.override_spans[k]};
        }
        load(id, std::move(ov), stack);
    }
    stack.pop_back();
    order_.push_back({f, std::move(overrides)});
}

// ---- declarations --------------------------------------------------------------------------

void Compiler::declare_modules(const ast::File& f) {
    for (const auto& m : f.modules) {
        SymbolId id = P_.symbols.intern(m.name);
        SymbolInfo& info = P_.symbols[id];
        std::vector<ValueType> types;
        std::vector<std::string> names;
        for (const auto& p : m.params) {
            types.push_back(param_type(p));
            names.push_back(p.name);
        }
        if (info.turtle || info.query) {
            diags_->error(
                m.span,
                fmt::format("'{}' is a built-in turtle or query module and cannot be declared", m.name));
            continue;
        }
        if (info.arity >= 0) {
            bool same = info.param_types == types;
            if (!same || info.decl_span.file == f.source) {
                duplicate("module", m.name, m.span, info.decl_span);
                continue;
            }
            continue; // the same declaration in two libraries is fine
        }
        info.declared = true;
        info.arity = static_cast<int>(m.params.size());
        info.param_types = std::move(types);
        info.param_names = std::move(names);
        info.decl_span = m.span;
        info.bound_to = m.bound_to;
        max_declared_len_ = std::max(max_declared_len_, m.name.size());
    }
}

void Compiler::declare_values(const LoadedFile& lf) {
    const ast::File& f = *lf.file;
    for (const auto& v : f.values) {
        Span prev;
        if (auto it = value_spans_.find(v.name); it != value_spans_.end()) prev = it->second;
        if (prev.valid()) {
            duplicate(v.kind == ast::DeclKind::Const   ? "const"
                      : v.kind == ast::DeclKind::Param ? "param"
                                                       : "var",
                      v.name, v.name_span, prev);
            continue;
        }
        value_spans_[v.name] = v.name_span;
        const ast::Expr* value = v.value.get();
        if (auto it = lf.overrides.find(v.name); it != lf.overrides.end()) {
            if (v.kind != ast::DeclKind::Param)
                diags_->error(it->second.second,
                              fmt::format("'{}' is a {}, and only params can be overridden", v.name,
                                          v.kind == ast::DeclKind::Const ? "const" : "var"));
            else
                value = it->second.first;
        }
        if (v.kind == ast::DeclKind::Param) {
            if (auto it = defines_.find(v.name); it != defines_.end()) {
                value = it->second.first.get();
                defines_used_.insert(v.name);
            }
        }
        auto cv = eval_const(*value, v.kind == ast::DeclKind::Const ? "a const" : "the initial value");
        if (!cv) cv = ConstVal{}; // declared all the same, so later uses are not "unknown" too
        if (v.kind == ast::DeclKind::Const) {
            consts_[v.name] = *cv;
            consts_[v.name].span = v.name_span;
            continue;
        }
        Global g;
        g.name = v.name;
        g.kind = v.kind == ast::DeclKind::Param ? GlobalKind::Param : GlobalKind::Var;
        g.type = cv->type;
        g.slot = static_cast<std::uint32_t>(P_.global_values.size());
        g.span = v.name_span;
        for (int k = 0; k < value_width(cv->type); ++k) P_.global_values.push_back(cv->v[k]);
        P_.global_index[g.name] = static_cast<std::uint32_t>(P_.globals.size());
        P_.globals.push_back(std::move(g));
    }
    for (const auto& [name, ov] : lf.overrides) {
        if (!value_spans_.count(name) || value_spans_[name].file != f.source)
            diags_->error(ov.second, fmt::format("the imported file has no param '{}'", name));
    }
}

void Compiler::compile_settings(const ast::File& f) {
    std::map<std::string, Span> seen;
    for (const auto& s : f.settings) {
        if (auto it = seen.find(s.key); it != seen.end()) {
            duplicate("setting", s.key, s.span, it->second);
            continue;
        }
        seen[s.key] = s.span;
        Code* target = s.key == "derive"  ? &P_.setting_derive
                       : s.key == "angle" ? &P_.setting_angle
                       : s.key == "step"  ? &P_.setting_step
                       : s.key == "width" ? &P_.setting_width
                                          : &P_.setting_seed;
        *target = Code{};
        Ctx c;
        c.code = target;
        c.kind = CtxKind::Global;
        ValueType t = compile_expr(c, *s.value);
        if (t != ValueType::Number && t != ValueType::Bool)
            diags_->error(s.value->span,
                          fmt::format("'{}' needs a number, found a {}", s.key, value_type_name(t)));
        emit(c, Op::Halt, 0, 1, s.value->span);
        // settings made of constants are checked now, so `plant check` sees them
        if (auto v = fold_number(*s.value)) {
            bool whole = *v == std::floor(*v);
            if (s.key == "derive" && (!whole || *v < 0 || *v > 1e6))
                diags_->error(s.value->span,
                              fmt::format("the number of steps must be a whole number from 0 to "
                                          "1000000, found {}",
                                          *v));
            if (s.key == "seed" && (!whole || *v < 0))
                diags_->error(s.value->span,
                              fmt::format("the seed must be a whole number >= 0, found {}", *v));
        }
    }
    // ignore / consider
    for (const auto& ss : f.symbol_sets) {
        for (const auto& m : ss.symbols) {
            for (const auto& [name, sp] : split_run(m)) {
                SymbolId id = P_.symbols.intern(name);
                (ss.ignore ? ignore_syms_ : consider_syms_).insert(id);
                (void)sp;
            }
        }
        if (ss.ignore)
            has_ignore_ = true;
        else
            has_consider_ = true;
        if (has_ignore_ && has_consider_)
            diags_->error(ss.span, "a grammar can have 'ignore:' or 'consider:', not both");
    }
    if (!f.axioms.empty()) {
        if (f.axioms.size() > 1) duplicate("axiom", "axiom", f.axioms[1].span, f.axioms[0].span);
        P_.axiom = Code{};
        Ctx c;
        c.code = &P_.axiom;
        c.kind = CtxKind::Axiom;
        compile_successor(c, f.axioms[0].successor, f.axioms[0].span);
        emit(c, Op::Halt, 0, 0, f.axioms[0].span);
        has_axiom_ = true;
    }
}

// ---- rules ---------------------------------------------------------------------------------

void Compiler::compile_production(const ast::Production& p, RuleSet& set, bool is_decompose) {
    (void)is_decompose;
    Production cp;
    cp.span = p.span;
    Ctx c;
    c.kind = CtxKind::Production;
    cp.strict = compile_pattern(c, p.strict, PatternRole::Strict);
    cp.left = compile_pattern(c, p.left, PatternRole::Left);
    cp.left_new = compile_pattern(c, p.left_new, PatternRole::LeftNew);
    cp.right = compile_pattern(c, p.right, PatternRole::Right);
    cp.right_new = compile_pattern(c, p.right_new, PatternRole::RightNew);
    if (cp.strict.empty()) {
        diags_->error(p.span, "a production needs a predecessor");
        return;
    }
    if (cp.strict.size() > 32) diags_->error(p.span, "a predecessor can have at most 32 modules");
    if (p.condition) {
        c.code = &cp.condition;
        ValueType t = compile_expr(c, *p.condition);
        if (t != ValueType::Number && t != ValueType::Bool)
            diags_->error(p.condition->span, fmt::format("a condition must be a bool or number, found a {}",
                                                         value_type_name(t)));
        emit(c, Op::Halt, 0, 1, p.condition->span);
    }
    if (p.weight) {
        c.code = &cp.weight;
        ValueType t = compile_expr(c, *p.weight);
        if (t != ValueType::Number && t != ValueType::Bool)
            diags_->error(p.weight->span,
                          fmt::format("a weight must be a number, found a {}", value_type_name(t)));
        emit(c, Op::Halt, 0, 1, p.weight->span);
    }
    c.code = &cp.body;
    cp.body_form = p.body_form;
    if (p.body_form) {
        compile_block(c, p.body);
        emit(c, Op::Halt, 0, 0, p.span);
    } else {
        compile_successor(c, p.successor, p.span);
        emit(c, Op::ProduceEnd, 0, 0, p.arrow_span);
    }
    cp.frame_size = c.next_slot;
    if (!p.body_form) build_template(cp);
    if (!cp.left.empty() || !cp.right.empty()) set.needs_brackets = true;
    if (!cp.left_new.empty()) set.uses_left_new = true;
    if (!cp.right_new.empty()) set.uses_right_new = true;
    if (set.uses_left_new && set.uses_right_new)
        diags_->error(p.span,
                      "one rule set cannot read both the forward (<<) and the backward (>>) new context");
    // shadowing: an earlier production that always applies to the same predecessor
    for (const auto& q : set.productions) {
        bool same = q.strict.size() == cp.strict.size();
        for (std::size_t k = 0; same && k < q.strict.size(); ++k) {
            same = q.strict[k].sym == cp.strict[k].sym && q.strict[k].width == cp.strict[k].width;
            for (const auto& a : q.strict[k].args) same = same && a.bind;
        }
        bool always = same && q.condition.empty() && q.weight.empty() && !q.body_form && !q.has_context() &&
                      !q.has_new_context();
        if (always && cp.weight.empty()) {
            Diagnostic d{
                Severity::Warning,
                p.span,
                fmt::format("this production can never apply: the production at {} always applies first "
                            "to '{}'",
                            where(q.span), P_.symbols[cp.strict[0].sym].name),
                {}};
            diags_->add(std::move(d));
            break;
        }
    }
    if (p.condition) {
        if (auto v = fold_number(*p.condition); v && *v == 0)
            diags_->warning(p.condition->span,
                            "this production can never apply: its condition is always false");
    }
    set.productions.push_back(std::move(cp));
}

void Compiler::compile_rules(const ast::File& f) {
    for (const auto& rb : f.rule_blocks) {
        RuleSet* set = nullptr;
        if (rb.kind == ast::RuleKind::Rules) {
            set = rb.group.empty() ? &P_.rules : &P_.groups[P_.group_index(rb.group)];
        } else {
            set = rb.kind == ast::RuleKind::Decompose ? &P_.decompose : &P_.interpret;
            if (rb.max_depth) {
                if (auto v = eval_const(*rb.max_depth, "max_depth")) {
                    if (v->v[0] < 1 || v->v[0] > 1000 || v->v[0] != std::floor(v->v[0]))
                        diags_->error(rb.max_depth->span, "max_depth must be a whole number from 1 to 1000");
                    else
                        set->max_depth = static_cast<int>(v->v[0]);
                }
            }
        }
        for (const auto& p : rb.productions) compile_production(p, *set, rb.kind == ast::RuleKind::Decompose);
    }
}

void Compiler::compile_hooks(const ast::File& f) {
    for (const auto& h : f.hooks) {
        int k = h.when == "start" ? 0 : h.when == "before_step" ? 1 : h.when == "after_step" ? 2 : 3;
        hook_bodies_[k].push_back(&h);
    }
}

// ---- whole-program checks ------------------------------------------------------------------

void Compiler::check_raw_runs() {
    std::vector<bool> has_rule(P_.symbols.size(), false);
    auto mark = [&](const RuleSet& rs) {
        for (const auto& p : rs.productions)
            for (const auto& m : p.strict) has_rule[m.sym] = true;
    };
    mark(P_.rules);
    for (const auto& g : P_.groups) mark(g);
    mark(P_.decompose);
    mark(P_.interpret);
    std::vector<std::string> declared;
    for (const auto& s : P_.symbols.all())
        if (s.declared && s.arity >= 0) declared.push_back(s.name);
    std::set<std::pair<std::uint32_t, std::uint32_t>> reported;
    for (const auto& run : raw_runs_) {
        bool meaningful = false;
        for (const auto& l : run.letters) {
            auto id = P_.symbols.find(l);
            if (id && (has_rule[*id] || P_.symbols[*id].turtle || P_.symbols[*id].declared))
                meaningful = true;
        }
        if (meaningful || !reported.insert({run.span.file, run.span.begin}).second) continue;
        std::string near = nearest_name(run.text, declared);
        diags_->warning(
            run.span,
            near.empty()
                ? fmt::format("'{}' is not a declared module and is read as {} separate letters, none of "
                              "which has a rule or a turtle meaning; declare it with 'module {}(...);'",
                              run.text, run.letters.size(), run.text)
                : fmt::format("'{}' is not a declared module and is read as {} separate letters, none of "
                              "which has a rule or a turtle meaning; did you mean '{}'?",
                              run.text, run.letters.size(), near));
    }
}

void Compiler::check_never_applying() {
    auto check = [&](const RuleSet& rs) {
        for (const auto& p : rs.productions) {
            SymbolId s = p.strict[0].sym;
            if (!produced_.count(s)) {
                diags_->warning(p.span,
                                fmt::format("this production can never apply: neither the axiom nor any "
                                            "successor produces '{}'",
                                            P_.symbols[s].name));
            }
        }
    };
    check(P_.rules);
    for (const auto& g : P_.groups) check(g);
    check(P_.decompose);
    check(P_.interpret);
    for (const auto& [name, span, dummy] : group_decls_) {
        (void)dummy;
        if (!used_groups_.count(name))
            diags_->warning(
                span, fmt::format("rule group '{}' is never selected: no hook says 'use {};'", name, name));
    }
}

void Compiler::finish_rule_set(RuleSet& set) {
    set.index(P_.symbols.size());
}

void Compiler::compile_environment(const ast::ShapeDecl& s) {
    for (const ast::ShapeDecl* other : P_.deferred.envs) {
        if (other == &s) break;
        if (other->name == s.name) {
            duplicate("environment", s.name, s.span, other->span);
            return;
        }
    }
    P_.environment_names.push_back(s.name);
    P_.environments.emplace_back();  // null until made
    if (!opts_.environments) return; // no runtime: using it is reported where it is used
    std::vector<EnvArg> args;
    for (std::size_t i = 0; i < s.args.size(); ++i) {
        if (s.args[i]->kind == ast::ExprKind::String) { // a file, relative to the grammar
            EnvArg a;
            a.key = s.keys[i];
            a.type = ValueType::String;
            fs::path path(s.args[i]->text);
            if (path.is_relative()) path = fs::path(sm_.file(s.span.file).name()).parent_path() / path;
            a.text = path.lexically_normal().string();
            a.span = s.args[i]->span;
            args.push_back(a);
            continue;
        }
        auto v = eval_const(*s.args[i], "an environment's argument");
        if (!v) return;
        EnvArg a;
        a.key = s.keys[i];
        a.type = v->type;
        std::copy(v->v, v->v + 3, a.v);
        a.span = s.args[i]->span;
        args.push_back(a);
    }
    std::string error;
    auto env = opts_.environments(s.kind, args, error);
    if (!env) {
        diags_->error(s.kind_span,
                      error.empty() ? fmt::format("unknown environment kind '{}'", s.kind) : error);
        return;
    }
    P_.environments.back() = std::shared_ptr<Environment>(std::move(env));
}

void Compiler::compile_curve(const ast::ShapeDecl& s) {
    CurveDef def;
    def.name = s.name;
    def.span = s.span;
    for (const auto& other : P_.curves) {
        if (other.name == s.name) {
            duplicate("curve", s.name, s.span, other.span);
            return;
        }
    }
    if (s.kind != "linear" && s.kind != "bezier") {
        diags_->error(s.kind_span,
                      fmt::format("unknown curve kind '{}': expected linear(...) or bezier(...)", s.kind));
        return;
    }
    def.bezier = s.kind == "bezier";
    bool points = false;
    for (std::size_t i = 0; i < s.args.size(); ++i) {
        auto v = eval_const(*s.args[i], "a curve's control value");
        if (!v) return;
        bool vec = v->type == ValueType::Vec3;
        if (i == 0) points = vec;
        if (vec != points) {
            diags_->error(s.args[i]->span, "a curve's control values are all numbers or all vec3 points");
            return;
        }
        def.xs.push_back(vec ? v->v[0] : 0.0);
        def.ys.push_back(vec ? v->v[1] : v->v[0]);
    }
    if (def.ys.size() < 2) {
        diags_->error(s.span, fmt::format("curve '{}' needs at least two control values", s.name));
        return;
    }
    if (!points)
        for (std::size_t i = 0; i < def.xs.size(); ++i) def.xs[i] = double(i) / double(def.xs.size() - 1);
    for (std::size_t i = 1; i < def.xs.size(); ++i) {
        if (def.xs[i] < def.xs[i - 1]) {
            diags_->error(s.args[i]->span,
                          "the x of a curve's points must not decrease (x is t, from 0 to 1)");
            return;
        }
    }
    P_.curves.push_back(std::move(def));
}

void Compiler::compile_surface(const ast::ShapeDecl& s) {
    SurfaceDef def;
    def.name = s.name;
    def.kind = s.kind;
    def.span = s.span;
    // a surface in an importing file replaces the library's (libraries are compiled first), so a
    // user swaps a default leaf for load("my_leaf.obj"); twice in one file is an error
    std::size_t replace = P_.surfaces.size();
    for (std::size_t i = 0; i < P_.surfaces.size(); ++i) {
        if (P_.surfaces[i].name != s.name) continue;
        if (P_.surfaces[i].span.file == s.span.file) {
            duplicate("surface", s.name, s.span, P_.surfaces[i].span);
            return;
        }
        replace = i;
    }
    if (s.kind == "polygon") {
        for (const auto& a : s.args) {
            auto v = eval_const(*a, "a polygon corner");
            if (!v) return;
            if (v->type != ValueType::Vec3) {
                diags_->error(a->span, "a polygon corner must be a vec3, as in vec3(0, 1, 0)");
                return;
            }
            def.points.push_back({v->v[0], v->v[1], v->v[2]});
        }
        if (def.points.size() < 3) {
            diags_->error(s.span, fmt::format("polygon '{}' needs at least 3 corners, found {}", s.name,
                                              def.points.size()));
            return;
        }
    } else if (s.kind == "load") {
        if (s.args.size() != 1 || s.args[0]->kind != ast::ExprKind::String) {
            diags_->error(s.span, "load(...) takes one quoted file name, as in load(\"leaf.obj\")");
            return;
        }
        fs::path p(s.args[0]->text);
        if (p.is_relative()) p = fs::path(sm_.file(s.span.file).name()).parent_path() / p;
        def.path = p.lexically_normal().string();
    } else {
        diags_->error(
            s.kind_span,
            fmt::format("unknown surface kind '{}': expected polygon(...) or load(\"file\")", s.kind));
        return;
    }
    if (replace < P_.surfaces.size())
        P_.surfaces[replace] = std::move(def);
    else
        P_.surfaces.push_back(std::move(def));
}

// Splits an arrow-form body (argument code, Emit, argument code, Emit, ..., ProduceEnd) into a
// template: a module whose arguments are all constants is copied as it is; the argument code of
// the others is moved, in order, into `values`. Draws of random numbers happen in the same
// order as in the body, so both paths derive the same string.
void Compiler::build_template(Production& p) {
    SuccessorTemplate t;
    if (p.strict.size() != 1) return;
    const Code& body = p.body;
    t.values.consts = body.consts;
    std::size_t seg_begin = 0;
    for (std::size_t pc = 0; pc < body.instrs.size(); ++pc) {
        const Instr& I = body.instrs[pc];
        if (I.op == Op::ProduceEnd) break;
        if (I.op != Op::Emit) continue;
        const auto sym = static_cast<SymbolId>(I.a);
        if (t.keep < 0 && sym == p.strict[0].sym) t.keep = static_cast<int>(t.syms.size());
        t.syms.push_back(sym);
        const auto first = static_cast<std::uint32_t>(t.params.size());
        bool constant = true;
        for (std::size_t k = seg_begin; k < pc; ++k) constant = constant && body.instrs[k].op == Op::Const;
        if (constant) {
            for (std::size_t k = seg_begin; k < pc; ++k) t.params.push_back(body.consts[body.instrs[k].a]);
        } else {
            const auto shift =
                static_cast<std::int64_t>(t.values.instrs.size()) - static_cast<std::int64_t>(seg_begin);
            for (std::size_t k = seg_begin; k < pc; ++k) {
                Instr J = body.instrs[k];
                if (J.op == Op::Jump || J.op == Op::JumpIfZero || J.op == Op::JumpIfZeroKeep ||
                    J.op == Op::JumpIfNonZeroKeep)
                    J.a = static_cast<std::int32_t>(J.a + shift);
                if (J.op == Op::Emit || J.op == Op::ProduceEnd || J.op == Op::Return || J.op == Op::Halt)
                    return;
                t.values.instrs.push_back(J);
                t.values.spans.push_back(body.spans[k]);
            }
            for (int k = 0; k < I.n; ++k) {
                t.holes.push_back(first + static_cast<std::uint32_t>(k));
                t.hole_spans.push_back(I.b > 0 ? body.arg_spans[I.b - 1][static_cast<std::size_t>(k)]
                                               : body.spans[pc]);
                t.params.push_back(0);
            }
        }
        t.param_end.push_back(static_cast<std::uint32_t>(t.params.size()));
        seg_begin = pc + 1;
    }
    if (t.holes.size() > 255) return;
    if (!t.holes.empty()) {
        t.values.instrs.push_back(Instr{Op::Halt, static_cast<std::uint8_t>(t.holes.size()), 0, 0});
        t.values.spans.push_back(p.span);
        fuse(t.values);
        // the affine fast path: one instruction per computed number, each a slot with a factor
        std::vector<SuccessorTemplate::Affine> affine;
        for (std::size_t k = 0; k + 1 < t.values.instrs.size(); ++k) {
            const Instr& I = t.values.instrs[k];
            auto slot = static_cast<std::uint16_t>(I.a);
            using A = SuccessorTemplate::Affine;
            if (I.op == Op::LoadLocal && I.n == 1)
                affine.push_back({A::Copy, slot, 0.0});
            else if (I.op == Op::LoadMulConst)
                affine.push_back({A::Mul, slot, t.values.consts[I.b]});
            else if (I.op == Op::LoadAddConst)
                affine.push_back({A::Add, slot, t.values.consts[I.b]});
            else
                break;
        }
        if (affine.size() == t.holes.size() && affine.size() + 1 == t.values.instrs.size())
            t.affine = std::move(affine);
    }
    t.valid = true;
    p.tmpl = std::move(t);
}

// ---- the whole compilation -----------------------------------------------------------------

std::unique_ptr<Program> Compiler::compile(std::uint32_t main_file) {
    // -D values are expressions, parsed from their own small sources
    for (const auto& [name, text] : opts_.defines) {
        std::uint32_t id = sm_.add(fmt::format("-D {}", name), text);
        auto e = parse_expression(sm_, id, *diags_);
        if (e) defines_[name] = {std::move(e), id};
    }
    std::vector<std::string> stack;
    load(main_file, {}, stack);
    if (diags_->has_errors()) return nullptr; // do not pile checks on a broken parse

    for (const auto& info : P_.symbols.all())
        if (info.declared) max_declared_len_ = std::max(max_declared_len_, info.name.size());
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        declare_modules(*lf.file);
    }
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        for (const auto& fd : lf.file->functions) declare_function(fd);
        for (const auto& e : lf.file->envs) {
            env_names_[e.name] = e.kind;
            P_.deferred.envs.push_back(&e);
        }
        for (const auto& cv : lf.file->curves) {
            curve_names_.insert(cv.name);
            P_.deferred.curves.push_back(&cv);
        }
        for (const auto& s : lf.file->surfaces) {
            P_.deferred.surfaces.push_back(&s);
            P_.symbols.intern("~" + s.name);
        }
        for (const auto& in : lf.file->instances) P_.deferred.instances.push_back(&in);
        for (const auto& rb : lf.file->rule_blocks) {
            if (rb.kind != ast::RuleKind::Rules || rb.group.empty()) continue;
            if (P_.group_index(rb.group) < 0) {
                RuleSet rs;
                rs.name = rb.group;
                rs.span = rb.group_span;
                P_.groups.push_back(std::move(rs));
                group_decls_.emplace_back(rb.group, rb.group_span, true);
            }
        }
    }
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        declare_values(lf);
    }
    for (const auto& [name, d] : defines_) {
        if (!defines_used_.count(name)) {
            std::vector<std::string> params;
            for (const auto& g : P_.globals)
                if (g.kind == GlobalKind::Param) params.push_back(g.name);
            std::string near = nearest_name(name, params);
            diags_->error(
                Span{}, near.empty() ? fmt::format("-D {}: the grammar has no param '{}'", name, name)
                                     : fmt::format("-D {}: the grammar has no param '{}'; did you mean '{}'?",
                                                   name, name, near));
        }
    }
    for (const ast::ShapeDecl* s : P_.deferred.curves) compile_curve(*s); // before the code that calls them
    for (const ast::ShapeDecl* s : P_.deferred.envs) compile_environment(*s);
    // `module Seg(len, r) bound ivy;` needs ivy to be a climber
    for (const auto& info : P_.symbols.all()) {
        if (info.bound_to.empty()) continue;
        auto it = env_names_.find(info.bound_to);
        if (it == env_names_.end())
            diags_->error(info.decl_span,
                          fmt::format("module '{}' is bound to '{}', which is not an environment; "
                                      "declare it first, as in env {} = climber(...);",
                                      info.name, info.bound_to, info.bound_to));
        else if (it->second != "climber")
            diags_->error(info.decl_span,
                          fmt::format("module '{}' is bound to '{}', which is not a climber (it is "
                                      "'{}'); only a climber can hold segments",
                                      info.name, info.bound_to, it->second));
    }
    for (std::uint32_t i = 0; i < P_.functions.size(); ++i) ensure_function_compiled(i);
    for (const ast::ShapeDecl* s : P_.deferred.surfaces) compile_surface(*s);
    for (const auto& lf : order_) {
        current_file_ = lf.file->source;
        compile_settings(*lf.file);
        compile_rules(*lf.file);
        compile_hooks(*lf.file);
    }
    for (int k = 0; k < 4; ++k) {
        if (hook_bodies_[k].empty()) continue;
        Ctx c;
        c.code = &P_.hooks[k];
        c.kind = CtxKind::Hook;
        for (const ast::Hook* h : hook_bodies_[k]) compile_block(c, h->body);
        emit(c, Op::Halt, 0, 0, hook_bodies_[k].back()->span);
        P_.has_hook[k] = true;
        P_.hook_frame[k] = c.next_slot;
    }
    current_file_ = main_file;
    if (!has_axiom_) {
        diags_->error(Span{main_file, 0, 0}, "the grammar has no axiom: add a line such as 'axiom: F;'");
    }
    // the set of modules skipped when matching context
    P_.ignored.assign(P_.symbols.size(), 0);
    for (SymbolId s = 0; s < P_.symbols.size(); ++s) {
        if (s == P_.symbols.open_bracket || s == P_.symbols.close_bracket) continue;
        if (has_consider_)
            P_.ignored[s] = consider_syms_.count(s) ? 0 : 1;
        else
            P_.ignored[s] = ignore_syms_.count(s) ? 1 : 0;
    }
    P_.uses_cut = produced_.count(P_.symbols.cut) > 0;
    // a named group runs together with the unnamed one: together they may read only one
    // direction of new context
    for (const auto& g : P_.groups) {
        bool left = g.uses_left_new || P_.rules.uses_left_new,
             right = g.uses_right_new || P_.rules.uses_right_new;
        if (left && right)
            diags_->error(g.span,
                          fmt::format("rule group '{}' and the unnamed rules together read both the forward "
                                      "(<<) and the backward (>>) new context; use one direction",
                                      g.name));
    }
    finish_rule_set(P_.rules);
    for (auto& g : P_.groups) finish_rule_set(g);
    finish_rule_set(P_.decompose);
    finish_rule_set(P_.interpret);
    if (!diags_->has_errors()) {
        check_raw_runs();
        check_never_applying();
    }
    if (diags_->has_errors()) return nullptr;
    return std::move(program_);
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
