// Expressions to stack-machine code (vm.hpp): emission with the operand stack's depth tracked
// from the opcode table, constant folding and compile-time evaluation, names, operators, calls
// of functions, curves and built-ins.
#include "compiler_internal.hpp"
#include "plant/builtins.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace plant {

// The operand stack is a fixed 1024 slots (vm.cpp): code that could need more is refused here.
constexpr int kMaxStack = 1000;

void Compiler::emit(Ctx& c, Op op, std::int32_t a, int n, Span span, std::uint16_t b) {
    c.code->instrs.push_back(Instr{op, static_cast<std::uint8_t>(n), b, a});
    c.code->spans.push_back(span);
    // the depth of the operand stack from the opcode table, conservative along both branches
    // of a jump (a call's n and b are the widths of its result and of its arguments)
    const StackEffect effect = stack_effect(c.code->instrs.back());
    c.depth += effect.pushes - effect.pops;
    if (c.depth > kMaxStack && !c.stack_error) {
        c.stack_error = true;
        diags_->error(span, "this expression is too large: it needs more than 1000 values at once");
    }
    if (c.depth < 0) c.depth = 0;
}

void Compiler::emit_const(Ctx& c, double v, Span span) {
    c.code->consts.push_back(v);
    emit(c, Op::Const, static_cast<std::int32_t>(c.code->consts.size() - 1), 1, span);
}

std::size_t Compiler::here(Ctx& c) const {
    return c.code->instrs.size();
}

void Compiler::patch(Ctx& c, std::size_t at) {
    c.code->instrs[at].a = static_cast<std::int32_t>(here(c));
}

// Evaluates an expression that may use only constants, params and literals, now.
std::optional<ConstVal> Compiler::eval_const(const ast::Expr& e, const char* what) {
    Code code;
    Ctx c;
    c.code = &code;
    c.kind = CtxKind::Global;
    std::size_t errors = diags_->error_count();
    const char* was = compile_time_;
    compile_time_ = what; // instance params have no value yet (placement_param_used)
    ValueType t = compile_expr(c, e);
    compile_time_ = was;
    if (diags_->error_count() != errors) return std::nullopt;
    if (t == ValueType::String) {
        diags_->error(e.span, fmt::format("{} must be a number or vector, not a string", what));
        return std::nullopt;
    }
    emit(c, Op::Halt, 0, value_width(t), e.span);
    EvalEnv env;
    env.prog = &P_;
    env.globals = P_.global_values.data();
    env.seed = 0;
    env.max_steps = opts_.max_steps;
    ConstVal v;
    v.type = t;
    v.span = e.span;
    try {
        run(code, nullptr, env, v.v);
    } catch (const RuntimeError& err) {
        diags_->error(err.span.valid() ? err.span : e.span, err.message);
        return std::nullopt;
    }
    for (int k = 0; k < value_width(t); ++k) {
        if (!std::isfinite(v.v[k])) {
            diags_->error(e.span, fmt::format("{} is not a finite number", what));
            return std::nullopt;
        }
    }
    return v;
}

// If the expression is a literal or made only of constants, its value.
std::optional<double> Compiler::fold_number(const ast::Expr& e) {
    switch (e.kind) {
    case ast::ExprKind::Number:
    case ast::ExprKind::Bool:
        return e.number;
    case ast::ExprKind::Name: {
        auto it = consts_.find(e.text);
        if (it != consts_.end() && it->second.type != ValueType::Vec3) return it->second.v[0];
        return std::nullopt;
    }
    case ast::ExprKind::Unary: {
        auto v = fold_number(*e.args[0]);
        if (!v) return std::nullopt;
        return e.unary == ast::UnaryOp::Neg ? -*v : (*v == 0 ? 1.0 : 0.0);
    }
    case ast::ExprKind::Binary: {
        auto a = fold_number(*e.args[0]);
        auto b = fold_number(*e.args[1]);
        if (!a || !b) return std::nullopt;
        using B = ast::BinaryOp;
        switch (e.binary) {
        case B::Add:
            return *a + *b;
        case B::Sub:
            return *a - *b;
        case B::Mul:
            return *a * *b;
        case B::Div:
            return *b == 0 ? std::optional<double>{} : *a / *b;
        case B::Mod: // not folded
            return std::nullopt;
        case B::Lt:
            return double(*a < *b);
        case B::Le:
            return double(*a <= *b);
        case B::Gt:
            return double(*a > *b);
        case B::Ge:
            return double(*a >= *b);
        case B::Eq:
            return double(*a == *b);
        case B::Ne:
            return double(*a != *b);
        case B::And:
            return double(*a != 0 && *b != 0);
        case B::Or:
            return double(*a != 0 || *b != 0);
        }
        return std::nullopt;
    }
    default:
        return std::nullopt;
    }
}

const LocalVar* Compiler::find_local(Ctx& c, const std::string& name) const {
    for (auto it = c.locals.rbegin(); it != c.locals.rend(); ++it)
        if (it->name == name) return &*it;
    return nullptr;
}

std::uint16_t Compiler::add_local(Ctx& c, const std::string& name, ValueType t) {
    if (c.next_slot > 60000) {
        if (c.next_slot < 60004)
            diags_->error(Span{}, fmt::format("too many local variables (at '{}')", name));
        c.next_slot = 60004;
        return 0;
    }
    std::uint16_t slot = c.next_slot;
    c.next_slot = static_cast<std::uint16_t>(c.next_slot + std::max(1, value_width(t)));
    c.locals.push_back({name, t, slot});
    return slot;
}

std::vector<std::string> Compiler::visible_names(Ctx& c) const {
    std::vector<std::string> out;
    for (const auto& l : c.locals) out.push_back(l.name);
    for (const auto& [n, v] : consts_) out.push_back(n);
    for (const auto& g : P_.globals) out.push_back(g.name);
    return out;
}

void Compiler::unknown_name(Ctx& c, const std::string& name, Span span, Unknown kind) {
    static constexpr const char* kWhat[] = {"name", "function", "variable"};
    const char* what = kWhat[static_cast<int>(kind)];
    std::vector<std::string> names = visible_names(c);
    if (kind == Unknown::Function) { // the suggestion comes from the callables
        names.clear();
        for (const auto& f : P_.functions) names.push_back(f.name);
        for (const auto& b : builtin_table()) names.emplace_back(b.name);
    }
    if (kind != Unknown::Function && outer_name_explained(name, span)) return;
    std::string near = nearest_name(name, names);
    diags_->error(span, near.empty() ? fmt::format("unknown {} '{}'", what, name)
                                     : fmt::format("unknown {} '{}'; did you mean '{}'?", what, name, near));
}

ValueType Compiler::compile_expr(Ctx& c, const ast::Expr& e) {
    using K = ast::ExprKind;
    switch (e.kind) {
    case K::Number:
        emit_const(c, e.number, e.span);
        return ValueType::Number;
    case K::Bool:
        emit_const(c, e.number, e.span);
        return ValueType::Bool;
    case K::String:
        diags_->error(e.span, "a string is allowed only as an argument of print(...) or load(...)");
        emit_const(c, 0, e.span);
        return ValueType::Number;
    case K::Name:
        return compile_name(c, e);
    case K::Unary: {
        if (e.unary == ast::UnaryOp::Neg &&
            e.args[0]->kind == K::Number) { // a negative literal is a constant
            emit_const(c, -e.args[0]->number, e.span);
            return ValueType::Number;
        }
        ValueType t = compile_expr(c, *e.args[0]);
        if (e.unary == ast::UnaryOp::Neg) {
            if (t == ValueType::Vec3) {
                emit(c, Op::VNeg, 0, 0, e.span);
                return t;
            }
            if (!numeric(t)) type_error(e.span, "-", t, t);
            emit(c, Op::Neg, 0, 0, e.span);
            return ValueType::Number;
        }
        if (!numeric(t)) type_error(e.span, "!", t, t);
        emit(c, Op::Not, 0, 0, e.span);
        return ValueType::Bool;
    }
    case K::Binary:
        return compile_binary(c, e);
    case K::Ternary: {
        ValueType ct = compile_expr(c, *e.args[0]);
        if (!numeric(ct)) diags_->error(e.args[0]->span, "the condition of '?:' must be a number or bool");
        std::size_t j_else = here(c);
        emit(c, Op::JumpIfZero, 0, 0, e.span);
        ValueType a = compile_expr(c, *e.args[1]);
        std::size_t j_end = here(c);
        emit(c, Op::Jump, 0, 0, e.span);
        patch(c, j_else);
        ValueType b = compile_expr(c, *e.args[2]);
        patch(c, j_end);
        if (a == ValueType::Void) a = b;
        if (b == ValueType::Void) b = a;
        if (a == ValueType::Void) a = b = ValueType::Number;
        if (value_width(a) != value_width(b)) {
            diags_->error(e.span, fmt::format("the two branches of '?:' have different types ({} and {})",
                                              value_type_name(a), value_type_name(b)));
        }
        return a == b ? a : (numeric(a) && numeric(b) ? ValueType::Number : a);
    }
    case K::Call:
        return compile_call(c, e);
    case K::Member: {
        ValueType t = compile_expr(c, *e.args[0]);
        if (t == ValueType::Node) return compile_node_read(c, e, nullptr);
        int comp = e.text == "x" ? 0 : e.text == "y" ? 1 : e.text == "z" ? 2 : -1;
        if (t != ValueType::Vec3 || comp < 0) {
            diags_->error(
                e.span, comp < 0 ? fmt::format("unknown member '.{}': vectors have .x, .y and .z", e.text)
                                 : fmt::format("'.{}' needs a vec3, found a {}", e.text, value_type_name(t)));
            if (t == ValueType::Vec3) emit(c, Op::Member, 0, 0, e.span);
            return ValueType::Number;
        }
        emit(c, Op::Member, comp, 0, e.span);
        return ValueType::Number;
    }
    case K::Method:
        return compile_method(c, e);
    }
    return ValueType::Number;
}

// A name in an expression: a local, a const (its value), a param or var, or pi.
ValueType Compiler::compile_name(Ctx& c, const ast::Expr& e) {
    if (const LocalVar* l = find_local(c, e.text)) {
        emit(c, Op::LoadLocal, l->slot, value_width(l->type), e.span);
        return l->type;
    }
    if (outer_name_hidden(c, e.text, e.span)) {
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    if (auto it = consts_.find(e.text); it != consts_.end()) {
        const ConstVal& v = it->second;
        for (int k = 0; k < value_width(v.type); ++k) emit_const(c, v.v[k], e.span);
        return v.type;
    }
    auto it = P_.global_index.find(e.text);
    if (it == P_.global_index.end() && builtin_param(e.text)) it = P_.global_index.find(e.text);
    if (it != P_.global_index.end()) {
        const Global& g = P_.globals[it->second];
        if (compile_time_ && placement_params_.count(e.text)) placement_param_used(e.text, e.span);
        if (folded_param(g)) { // its value, as a const's (see find_assigned_params)
            for (int k = 0; k < value_width(g.type); ++k) emit_const(c, P_.global_values[g.slot + k], e.span);
            return g.type;
        }
        emit(c, Op::LoadGlobal, static_cast<std::int32_t>(g.slot), value_width(g.type), e.span);
        return g.type;
    }
    if (e.text == "pi") {
        emit_const(c, std::numbers::pi, e.span);
        return ValueType::Number;
    }
    if (env_names_.count(e.text)) {
        diags_->error(
            e.span, fmt::format("environment '{}' can only be queried with a method, as in '{}.contains(p)'",
                                e.text, e.text));
    } else {
        unknown_name(c, e.text, e.span, Unknown::Name);
    }
    emit_const(c, 0, e.span);
    return ValueType::Number;
}

// `object.method(args)`: only environments have methods.
ValueType Compiler::compile_method(Ctx& c, const ast::Expr& e) {
    using K = ast::ExprKind;
    const ast::Expr& obj = *e.args[0];
    std::size_t env = P_.environments.size();
    if (obj.kind == K::Name)
        for (std::size_t k = 0; k < P_.environments.size(); ++k)
            if (P_.environments[k].name == obj.text && P_.environments[k].kind) env = k;
    if (env < P_.environments.size()) return compile_env_call(c, e, env);
    const bool env_name = obj.kind == K::Name && env_names_.count(obj.text);
    if (ValueType r; !env_name && compile_silhouette_method(c, e, r)) return r;
    if (!env_name && compile_expr(c, obj) == ValueType::Node) return compile_node_read(c, e, &obj);
    if (env_name) {
        diags_->error(
            e.span,
            opts_.environments
                ? fmt::format("environment '{}' is not available: its declaration has an error", obj.text)
                : fmt::format("environment '{}' (kind '{}') cannot be queried here: no runtime "
                              "provides environments to this compilation",
                              obj.text, env_names_[obj.text]));
    } else {
        diags_->error(
            e.span,
            fmt::format(
                "'.{}(...)' is a method call, and only environment objects and graph nodes have methods",
                e.text));
    }
    emit_const(c, 0, e.span);
    return ValueType::Number;
}

void Compiler::type_error(Span span, const std::string& op, ValueType a, ValueType b) {
    diags_->error(span, fmt::format("operator '{}' cannot be applied to {} and {}", op, value_type_name(a),
                                    value_type_name(b)));
}

ValueType Compiler::compile_binary(Ctx& c, const ast::Expr& e) {
    using B = ast::BinaryOp;
    const B op = e.binary;
    if (op == B::And || op == B::Or) {
        ValueType a = compile_expr(c, *e.args[0]);
        std::size_t j = here(c);
        emit(c, op == B::And ? Op::JumpIfZeroKeep : Op::JumpIfNonZeroKeep, 0, 0, e.span);
        ValueType b = compile_expr(c, *e.args[1]);
        patch(c, j);
        emit_const(c, 0, e.span);
        emit(c, Op::Ne, 0, 0, e.span);
        if (!numeric(a) || !numeric(b)) type_error(e.span, ast::spelling(op), a, b);
        return ValueType::Bool;
    }
    ValueType a = compile_expr(c, *e.args[0]);
    ValueType b = compile_expr(c, *e.args[1]);
    // an operand of unknown type (a recursive call) takes the other operand's type
    const bool additive = op == B::Add || op == B::Sub;
    if (a == ValueType::Void) a = b == ValueType::Vec3 && additive ? b : ValueType::Number;
    if (b == ValueType::Void) b = a == ValueType::Vec3 && additive ? a : ValueType::Number;
    bool na = numeric(a), nb = numeric(b);
    bool va = a == ValueType::Vec3, vb = b == ValueType::Vec3;
    if (na && nb) {
        static const std::pair<B, Op> ops[] = {{B::Add, Op::Add}, {B::Sub, Op::Sub}, {B::Mul, Op::Mul},
                                               {B::Div, Op::Div}, {B::Mod, Op::Mod}, {B::Lt, Op::Lt},
                                               {B::Le, Op::Le},   {B::Gt, Op::Gt},   {B::Ge, Op::Ge},
                                               {B::Eq, Op::Eq},   {B::Ne, Op::Ne}};
        for (const auto& [name, o] : ops) {
            if (op == name) {
                emit(c, o, 0, 0, e.span);
                bool cmp = o >= Op::Lt && o <= Op::Ne;
                return cmp ? ValueType::Bool : ValueType::Number;
            }
        }
    }
    if (va && vb) {
        if (op == B::Add) {
            emit(c, Op::VAdd, 0, 0, e.span);
            return ValueType::Vec3;
        }
        if (op == B::Sub) {
            emit(c, Op::VSub, 0, 0, e.span);
            return ValueType::Vec3;
        }
        if (op == B::Eq) {
            emit(c, Op::VEq, 0, 0, e.span);
            return ValueType::Bool;
        }
        if (op == B::Ne) {
            emit(c, Op::VNe, 0, 0, e.span);
            return ValueType::Bool;
        }
    }
    if (va && nb && op == B::Mul) {
        emit(c, Op::VMulS, 0, 0, e.span);
        return ValueType::Vec3;
    }
    if (va && nb && op == B::Div) {
        emit(c, Op::VDivS, 0, 0, e.span);
        return ValueType::Vec3;
    }
    if (na && vb && op == B::Mul) {
        emit(c, Op::VSMul, 0, 0, e.span);
        return ValueType::Vec3;
    }
    type_error(e.span, ast::spelling(op), a, b);
    return ValueType::Number;
}

ValueType Compiler::compile_call(Ctx& c, const ast::Expr& e) {
    const std::string& name = e.text;
    if (name == "print") {
        diags_->error(e.span, "print(...) is a statement and gives no value; use it in a hook");
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    // user functions
    if (auto it = fn_index_.find(name); it != fn_index_.end()) {
        Function& fn = P_.functions[it->second];
        // while a result type is being inferred, other functions are not compiled yet (their
        // diagnostics would be lost with the inference's), only their result types inferred
        if (!inferring_ || fn_state_[it->second] != 0) {
            ensure_function_compiled(it->second);
        } else if (!fn_result_known_[it->second]) {
            fn_state_[it->second] = 1; // a call back into the caller's chain stays unknown
            infer_function_result(it->second);
            fn_state_[it->second] = 0;
        }
        if (fn_random_[it->second]) {
            if (c.kind == CtxKind::Global)
                diags_->error(e.span,
                              fmt::format("'{}' draws random numbers, so it cannot be used where the value "
                                          "must be known before the derivation starts",
                                          name));
            if (c.function >= 0) fn_random_[static_cast<std::size_t>(c.function)] = true;
        }
        if (e.args.size() != fn.param_types.size()) {
            diags_->error(e.span,
                          fmt::format("function '{}' takes {} argument{}, given {} (declared at {})", name,
                                      fn.param_types.size(), fn.param_types.size() == 1 ? "" : "s",
                                      e.args.size(), where(fn.span)));
        }
        for (std::size_t i = 0; i < e.args.size(); ++i) {
            ValueType t = compile_expr(c, *e.args[i]);
            if (i < fn.param_types.size() && value_width(t) != value_width(fn.param_types[i]))
                diags_->error(e.args[i]->span,
                              fmt::format("argument {} of '{}' must be a {}, found a {}", i + 1, name,
                                          value_type_name(fn.param_types[i]), value_type_name(t)));
        }
        if (e.args.size() == fn.param_types.size())
            emit(c, Op::Call, static_cast<std::int32_t>(it->second), std::max(1, value_width(fn.result)),
                 e.span, fn.param_width);
        // a recursive call inside the function's own body: its type is not known yet, and the
        // operators around it take it from their other operand
        if (!fn_result_known_[it->second]) return ValueType::Void;
        return fn.result;
    }
    for (std::size_t k = 0; k < P_.curves.size(); ++k) {
        if (P_.curves[k].name != name) continue;
        if (e.args.size() != 1) {
            diags_->error(e.span, fmt::format("curve '{}' takes one argument, t from 0 to 1", name));
            emit_const(c, 0, e.span);
            return ValueType::Number;
        }
        ValueType t = compile_expr(c, *e.args[0]);
        if (!numeric(t)) diags_->error(e.args[0]->span, fmt::format("curve '{}' takes a number", name));
        emit(c, Op::Curve, static_cast<std::int32_t>(k), 0, e.span);
        return ValueType::Number;
    }
    if (name == "child" && e.args.size() == 5) return compile_child_placed(c, e);
    // built-ins: first row whose name and argument types fit
    std::vector<ValueType> types;
    for (const auto& a : e.args) types.push_back(compile_expr(c, *a));
    bool name_known = false;
    const BuiltinInfo* arity_match = nullptr;
    for (const auto& b : builtin_table()) {
        if (name != b.name) continue;
        name_known = true;
        if (b.nargs != types.size()) continue;
        arity_match = &b;
        bool ok = true;
        int width = 0;
        for (std::size_t i = 0; i < types.size(); ++i) {
            const ValueType want = b.args[i];
            ok = ok &&
                 (want == ValueType::Vec3 || want == ValueType::Node ? types[i] == want : numeric(types[i]));
            width += value_width(types[i]);
        }
        if (!ok) continue;
        if (b.per_module() && c.kind == CtxKind::Global) {
            diags_->error(e.span,
                          fmt::format("'{}' depends on the module being rewritten and cannot be used where "
                                      "the value must be known before the derivation starts",
                                      name));
        }
        if (b.per_module() && c.function >= 0) fn_random_[static_cast<std::size_t>(c.function)] = true;
        if (b.reads == BuiltinReads::Graph) return compile_graph_call(c, e, b, width);
        if (b.id == BuiltinId::Id) P_.uses_id = true;
        if (b.id == BuiltinId::Lod && types.size() == 1) { // lod(count): the program's view depth
            for (const char* param : {"view_depth", "max_view_depth"}) {
                ast::Expr read;
                read.kind = ast::ExprKind::Name;
                read.span = e.span;
                read.text = param;
                compile_name(c, read);
            }
            width = 3;
        }
        emit(c, Op::Builtin, static_cast<std::int32_t>(b.id), width, e.span,
             static_cast<std::uint16_t>(value_width(b.result)));
        return b.result;
    }
    if (!name_known) {
        unknown_name(c, name, e.span, Unknown::Function);
    } else if (!arity_match) {
        std::string counts;
        for (const auto& b : builtin_table())
            if (name == b.name) counts += (counts.empty() ? "" : " or ") + std::to_string(b.nargs);
        diags_->error(e.span, fmt::format("'{}' takes {} argument{}, given {}", name, counts,
                                          counts == "1" ? "" : "s", e.args.size()));
    } else {
        std::string got;
        for (auto t : types) got += (got.empty() ? "" : ", ") + std::string(value_type_name(t));
        diags_->error(e.span, fmt::format("'{}' cannot take arguments of types ({})", name, got));
    }
    emit_const(c, 0, e.span);
    return ValueType::Number;
}

} // namespace plant
