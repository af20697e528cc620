// Stage 2: declarations. Modules (symbols with parameter types), params, consts and vars (with
// -D values and import overrides), functions (declared first, compiled on first use so that
// their result types are known), settings, ignore/consider and the axiom.
#include "compiler_internal.hpp"
#include "plant/builtins.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace plant {

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
        if (builtin_param_redeclared(v)) continue;
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
        if (cv && value != v.value.get()) check_override_type(v, *value, *cv);
        const bool evaluated = cv.has_value();
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
        if (v.range_low && evaluated) check_param_range(v, *value, *cv, g);
        for (int k = 0; k < value_width(cv->type); ++k) P_.global_values.push_back(cv->v[k]);
        P_.global_index[g.name] = static_cast<std::uint32_t>(P_.globals.size());
        P_.globals.push_back(std::move(g));
    }
    for (const auto& [name, ov] : lf.overrides) {
        if (!value_spans_.count(name) || value_spans_[name].file != f.source) {
            std::vector<std::string> names; // the file's own values, for "did you mean"
            for (const auto& v : f.values)
                if (v.kind == ast::DeclKind::Param) names.push_back(v.name);
            std::string near = nearest_name(name, names);
            diags_->error(
                ov.second,
                near.empty()
                    ? fmt::format("the imported file has no param '{}'", name)
                    : fmt::format("the imported file has no param '{}'; did you mean '{}'?", name, near));
        }
    }
}

// A param's value from -D or an import's `with { }` is of the type of its default: a vec3 for a
// number (or the other way round) would change every use of the param, where the error would
// point at the grammar, or at nothing when a module parameter silently took three numbers.
void Compiler::check_override_type(const ast::ValueDecl& v, const ast::Expr& value, const ConstVal& cv) {
    Diagnostics quiet; // the default's own errors are not this value's
    Diagnostics* saved = diags_;
    diags_ = &quiet;
    const auto dv = eval_const(*v.value, "the initial value");
    diags_ = saved;
    if (!dv) return;
    auto kind = [](ValueType t) { return t == ValueType::Bool ? ValueType::Number : t; };
    if (kind(dv->type) != kind(cv.type))
        diags_->add(
            {Severity::Error,
             value.span,
             fmt::format("'{}' is a {} by its default, found a {}: give a {}", v.name,
                         value_type_name(dv->type), value_type_name(cv.type), value_type_name(dv->type)),
             {{v.value->span, "the default"}}});
}

// `param r = 0.9 in 0.5 .. 1.0;`: constant numeric bounds, low below high, and the param's value
// (its default, a -D value or an import's override, whichever applies) inside them.
void Compiler::check_param_range(const ast::ValueDecl& v, const ast::Expr& value, const ConstVal& cv,
                                 Global& g) {
    auto low = eval_const(*v.range_low, "a param's range");
    auto high = eval_const(*v.range_high, "a param's range");
    if (!low || !high) return;
    for (const ConstVal* b : {&*low, &*high})
        if (b->type != ValueType::Number) {
            diags_->error(b == &*low ? v.range_low->span : v.range_high->span,
                          "a param's range takes two numbers: write `in LOW .. HIGH`");
            return;
        }
    if (!(low->v[0] < high->v[0])) {
        diags_->error(v.range_span,
                      fmt::format("the range of '{}' is empty: its low bound {} is not below its "
                                  "high bound {}; write `in LOW .. HIGH` with LOW < HIGH",
                                  v.name, low->v[0], high->v[0]));
        return;
    }
    if (cv.type != ValueType::Number) {
        diags_->error(value.span, fmt::format("'{}' has a range, so its value must be a number", v.name));
        return;
    }
    g.has_range = true;
    g.low = low->v[0];
    g.high = high->v[0];
    // whole numbers as written: digits only, perhaps negated ("5", "-1"; not "5.0" or "1e3")
    auto whole = [](const ast::Expr* e) {
        while (e && e->kind == ast::ExprKind::Unary && e->unary == ast::UnaryOp::Neg && !e->args.empty())
            e = e->args[0].get();
        return e && e->kind == ast::ExprKind::Number && !e->text.empty() &&
               e->text.find_first_not_of("0123456789") == std::string::npos;
    };
    g.whole = whole(v.value.get()) && whole(v.range_low.get()) && whole(v.range_high.get());
    if (cv.v[0] < g.low || cv.v[0] > g.high) {
        Diagnostic d{Severity::Error,
                     value.span,
                     fmt::format("'{}' = {} is outside its range {} .. {}; give a value in the range or "
                                 "widen the range",
                                 v.name, cv.v[0], g.low, g.high),
                     {}};
        if (&value != v.value.get()) // a -D value or an import's override: show the declaration too
            d.notes.emplace_back(v.range_span, "the range is declared here");
        diags_->add(std::move(d));
    }
}

void Compiler::declare_function(const ast::FnDecl& fd) {
    if (auto it = fn_index_.find(fd.name); it != fn_index_.end()) {
        duplicate("function", fd.name, fd.span, P_.functions[it->second].span);
        return;
    }
    for (const auto& b : builtin_table()) {
        if (fd.name == b.name) {
            diags_->error(fd.span,
                          fmt::format("'{}' is a built-in function and cannot be redefined", fd.name));
            return;
        }
    }
    Function fn;
    fn.name = fd.name;
    fn.span = fd.span;
    for (const auto& p : fd.params) {
        ValueType t = param_type(p);
        fn.param_types.push_back(t);
        fn.param_width = static_cast<std::uint16_t>(fn.param_width + value_width(t));
    }
    fn_index_[fd.name] = static_cast<std::uint32_t>(P_.functions.size());
    fn_decls_.push_back(&fd);
    fn_state_.push_back(0);
    fn_result_known_.push_back(false);
    fn_random_.push_back(false);
    P_.functions.push_back(std::move(fn));
}

ValueType Compiler::param_type(const ast::ParamName& p) {
    if (p.type.empty() || p.type == "number") return ValueType::Number;
    if (p.type == "vec3") return ValueType::Vec3;
    if (p.type == "bool") return ValueType::Bool;
    if (p.type == "node") return ValueType::Node;
    diags_->error(p.span, fmt::format("unknown type '{}': expected number, bool, vec3 or node", p.type));
    return ValueType::Number;
}

// Compiles a function body into `code`; returns its result type (Void if only recursive calls
// decide it).
ValueType Compiler::compile_function_body(std::uint32_t index, Code& code, std::uint16_t& frame_size) {
    const ast::FnDecl& fd = *fn_decls_[index];
    Ctx c;
    c.code = &code;
    c.kind = CtxKind::Function;
    c.function = static_cast<int>(index);
    for (std::size_t i = 0; i < fd.params.size(); ++i)
        add_local(c, fd.params[i].name, P_.functions[index].param_types[i]);
    ValueType result = ValueType::Number;
    if (fd.expr) {
        result = compile_expr(c, *fd.expr);
        emit(c, Op::Return, 0, value_width(result == ValueType::Void ? ValueType::Number : result),
             fd.expr->span);
    } else {
        c.fn_result = &result;
        c.fn_result_known = false;
        compile_block(c, fd.body);
        if (!c.fn_result_known) result = ValueType::Void;
        ValueType fall = result == ValueType::Void ? ValueType::Number : result;
        // falling off the end returns zero
        for (int k = 0; k < value_width(fall); ++k) emit_const(c, 0, fd.span);
        emit(c, Op::Return, 0, value_width(fall), fd.span);
        for (std::size_t at : c.void_returns)
            code.instrs[at].n = static_cast<std::uint8_t>(value_width(fall));
    }
    frame_size = c.next_slot;
    return result;
}

// Compiles a function's body quietly to learn its result type, which recursive calls need, and
// calls from functions compiled before it (a function declared later, or an outer function an
// instance body compiles when first called) while their own result types are inferred.
void Compiler::infer_function_result(std::uint32_t index) {
    Diagnostics scratch;
    Diagnostics* saved = diags_;
    const bool was_inferring = inferring_;
    diags_ = &scratch;
    inferring_ = true;
    Code code;
    std::uint16_t frame = 0;
    ValueType t = compile_function_body(index, code, frame);
    diags_ = saved;
    inferring_ = was_inferring;
    P_.functions[index].result = t == ValueType::Void ? ValueType::Number : t;
    fn_result_known_[index] = true;
}

void Compiler::ensure_function_compiled(std::uint32_t index) {
    if (fn_state_[index] != 0) return; // compiled, or being compiled (recursion)
    fn_state_[index] = 1;
    // First pass, quietly: learn the result type. Second pass: the real code, with recursive
    // calls typed.
    infer_function_result(index);
    Code code;
    std::uint16_t frame = 0;
    ValueType result = compile_function_body(index, code, frame);
    if (result == ValueType::Void) result = ValueType::Number;
    Function& fn = P_.functions[index];
    if (value_width(result) != value_width(fn.result))
        diags_->error(fn.span, fmt::format("function '{}' gives a {} on some paths and a {} on others",
                                           fn.name, value_type_name(fn.result), value_type_name(result)));
    fn.code = std::move(code);
    fn.result = result;
    fn.frame_size = frame;
    fn_state_[index] = 2;
}

void Compiler::compile_settings(const ast::File& f) {
    using Key = ast::SettingKey;
    std::map<Key, Span> seen;
    for (const auto& s : f.settings) {
        const char* key = ast::spelling(s.key);
        if (auto it = seen.find(s.key); it != seen.end()) {
            duplicate("setting", key, s.span, it->second);
            continue;
        }
        seen[s.key] = s.span;
        Code* target = &P_.settings[static_cast<std::size_t>(s.key)];
        *target = Code{};
        Ctx c;
        c.code = target;
        c.kind = CtxKind::Global;
        ValueType t = compile_expr(c, *s.value);
        if (t != ValueType::Number && t != ValueType::Bool)
            diags_->error(s.value->span,
                          fmt::format("'{}' needs a number, found a {}", key, value_type_name(t)));
        emit(c, Op::Halt, 0, 1, s.value->span);
        // settings made of constants are checked now, so `plant check` sees them
        if (auto v = fold_number(*s.value)) {
            bool whole = *v == std::floor(*v);
            if (s.key == Key::Derive && (!whole || *v < 0 || *v > 1e6))
                diags_->error(s.value->span,
                              fmt::format("the number of steps must be a whole number from 0 to "
                                          "1000000, found {}",
                                          *v));
            if (s.key == Key::Seed && (!whole || *v < 0 || *v > 9.0e18)) // the range start() accepts
                diags_->error(s.value->span,
                              fmt::format("the seed must be a whole number from 0 to 9e18, found {}", *v));
            if ((s.key == Key::Angle || s.key == Key::Step) && !std::isfinite(*v))
                diags_->error(s.value->span, fmt::format("the {} must be a finite number, found {}",
                                                         s.key == Key::Angle ? "angle" : "step", *v));
            if (s.key == Key::Width && !(*v >= 0 && std::isfinite(*v)))
                diags_->error(s.value->span,
                              fmt::format("the width must be a finite number, 0 or more, found {}", *v));
            if (s.key == Key::WidthScale && !(*v > 0 && *v <= 1e6))
                diags_->error(
                    s.value->span,
                    fmt::format("width_scale must be a number above 0 and at most 1000000, found {}", *v));
        }
    }
    // ignore / consider
    for (const auto& ss : f.symbol_sets) {
        for (const auto& m : ss.symbols) {
            for (const auto& part : split_run(m)) {
                SymbolId id = P_.symbols.intern(part.first);
                (ss.ignore ? ignore_syms_ : consider_syms_).insert(id);
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
        compile_successor(c, f.axioms[0].successor);
        emit(c, Op::Halt, 0, 0, f.axioms[0].span);
        has_axiom_ = true;
    }
}

} // namespace plant
