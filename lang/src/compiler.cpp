// The compiler: imports, declarations, name resolution, static types, and the checks of
// LANGUAGE.md (unknown names, arity, duplicates, assignments outside hooks, undeclared letter
// runs, productions that can never apply). Expressions become stack-machine code (vm.hpp).
#include "plant/compiler.hpp"

#include "compiler_internal.hpp"
#include "plant/builtins.hpp"
#include "plant/parser.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>

namespace plant {

namespace fs = std::filesystem;

bool read_file(const std::string& path, std::string& out) {
    std::error_code ec;
    if (fs::is_directory(path, ec)) return false;
    std::ifstream f(path, std::ios::binary);
    if (!f) return false;
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) return false;
    out = ss.str();
    return true;
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
    LineCol lc = f.line_col(s.begin);
    if (s.file == current_file_) return fmt::format("{}:{}", lc.line, lc.col);
    return fmt::format("{}:{}:{}", f.name(), lc.line, lc.col);
}

void Compiler::duplicate(const std::string& what, const std::string& name, Span here, Span first) {
    Diagnostic d{Severity::Error, here, fmt::format("duplicate definition of {} '{}'", what, name), {}};
    d.notes.emplace_back(first, fmt::format("'{}' was first defined here", name));
    diags_->add(std::move(d));
}

// ---- emission helpers ----------------------------------------------------------------------

// The operand stack is a fixed 1024 slots (vm.cpp): code that could need more is refused here.
constexpr int kMaxStack = 1000;

void Compiler::emit(Ctx& c, Op op, std::int32_t a, int n, Span span, std::uint16_t b) {
    c.code->instrs.push_back(Instr{op, static_cast<std::uint8_t>(n), b, a});
    c.code->spans.push_back(span);
    // stack effect, conservative along both branches of a jump
    switch (op) {
    case Op::Const:
    case Op::LoadMulConst:
    case Op::LoadAddConst:
        c.depth += 1;
        break;
    case Op::Const3:
        c.depth += 3;
        break;
    case Op::LoadLocal:
    case Op::LoadGlobal:
        c.depth += n;
        break;
    case Op::StoreLocal:
    case Op::StoreGlobal:
    case Op::Pop:
    case Op::Emit:
    case Op::Print:
        c.depth -= n;
        break;
    case Op::Add:
    case Op::Sub:
    case Op::Mul:
    case Op::Div:
    case Op::Mod:
    case Op::Lt:
    case Op::Le:
    case Op::Gt:
    case Op::Ge:
    case Op::Eq:
    case Op::Ne:
    case Op::JumpIfZero:
    case Op::JumpIfZeroKeep:
    case Op::JumpIfNonZeroKeep:
    case Op::VMulS:
    case Op::VSMul:
    case Op::VDivS:
        c.depth -= 1;
        break;
    case Op::VAdd:
    case Op::VSub:
        c.depth -= 3;
        break;
    case Op::VEq:
    case Op::VNe:
        c.depth -= 5;
        break;
    case Op::Member:
        c.depth -= 2;
        break;
    case Op::Builtin:
        c.depth += b - n;
        break; // b: width of the result
    case Op::EnvCall:
        c.depth += 3 - n;
        break; // at most a vec3
    case Op::Call: {
        const Function& fn = P_.functions[static_cast<std::size_t>(a)];
        c.depth += std::max(1, value_width(fn.result)) - fn.param_width;
        break;
    }
    default:
        break;
    }
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

// ---- constant folding ----------------------------------------------------------------------

// Evaluates an expression that may use only constants, params and literals, now.
std::optional<ConstVal> Compiler::eval_const(const ast::Expr& e, const char* what) {
    Code code;
    Ctx c;
    c.code = &code;
    c.kind = CtxKind::Global;
    std::size_t errors = diags_->error_count();
    ValueType t = compile_expr(c, e);
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
        return e.text == "-" ? -*v : (*v == 0 ? 1.0 : 0.0);
    }
    case ast::ExprKind::Binary: {
        auto a = fold_number(*e.args[0]);
        auto b = fold_number(*e.args[1]);
        if (!a || !b) return std::nullopt;
        const std::string& op = e.text;
        if (op == "+") return *a + *b;
        if (op == "-") return *a - *b;
        if (op == "*") return *a * *b;
        if (op == "/") return *b == 0 ? std::optional<double>{} : *a / *b;
        if (op == "<") return double(*a < *b);
        if (op == "<=") return double(*a <= *b);
        if (op == ">") return double(*a > *b);
        if (op == ">=") return double(*a >= *b);
        if (op == "==") return double(*a == *b);
        if (op == "!=") return double(*a != *b);
        if (op == "&&") return double(*a != 0 && *b != 0);
        if (op == "||") return double(*a != 0 || *b != 0);
        return std::nullopt;
    }
    default:
        return std::nullopt;
    }
}

// ---- expressions ---------------------------------------------------------------------------

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

void Compiler::unknown_name(Ctx& c, const std::string& name, Span span, const char* what) {
    std::vector<std::string> names = visible_names(c);
    if (std::string(what) == "function") {
        names.clear();
        for (const auto& f : P_.functions) names.push_back(f.name);
        for (const auto& b : builtin_table()) names.emplace_back(b.name);
    }
    std::string near = nearest_name(name, names);
    diags_->error(span, near.empty() ? fmt::format("unknown {} '{}'", what, name)
                                     : fmt::format("unknown {} '{}'; did you mean '{}'?", what, name, near));
}

static bool numeric(ValueType t) {
    return t == ValueType::Number || t == ValueType::Bool;
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
    case K::Name: {
        if (const LocalVar* l = find_local(c, e.text)) {
            emit(c, Op::LoadLocal, l->slot, value_width(l->type), e.span);
            return l->type;
        }
        if (auto it = consts_.find(e.text); it != consts_.end()) {
            const ConstVal& v = it->second;
            for (int k = 0; k < value_width(v.type); ++k) emit_const(c, v.v[k], e.span);
            return v.type;
        }
        if (auto it = P_.global_index.find(e.text); it != P_.global_index.end()) {
            const Global& g = P_.globals[it->second];
            emit(c, Op::LoadGlobal, static_cast<std::int32_t>(g.slot), value_width(g.type), e.span);
            return g.type;
        }
        if (e.text == "pi") {
            emit_const(c, std::numbers::pi, e.span);
            return ValueType::Number;
        }
        if (env_names_.count(e.text)) {
            diags_->error(
                e.span,
                fmt::format("environment '{}' can only be queried with a method, as in '{}.contains(p)'",
                            e.text, e.text));
        } else {
            unknown_name(c, e.text, e.span, "name");
        }
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    case K::Unary: {
        if (e.text == "-" && e.args[0]->kind == K::Number) { // a negative literal is a constant
            emit_const(c, -e.args[0]->number, e.span);
            return ValueType::Number;
        }
        ValueType t = compile_expr(c, *e.args[0]);
        if (e.text == "-") {
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
    case K::Method: {
        const ast::Expr& obj = *e.args[0];
        std::size_t env = P_.environments.size();
        if (obj.kind == K::Name)
            for (std::size_t k = 0; k < P_.environments.size(); ++k)
                if (P_.environments[k].name == obj.text && P_.environments[k].kind) env = k;
        if (env < P_.environments.size()) return compile_env_call(c, e, env);
        if (obj.kind == K::Name && env_names_.count(obj.text)) {
            diags_->error(
                e.span,
                opts_.environments
                    ? fmt::format("environment '{}' is not available: its declaration has an error", obj.text)
                    : fmt::format("environment '{}' (kind '{}') cannot be queried here: no runtime "
                                  "provides environments to this compilation",
                                  obj.text, env_names_[obj.text]));
        } else {
            diags_->error(
                e.span, fmt::format("'.{}(...)' is a method call, and only environment objects have methods",
                                    e.text));
        }
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    }
    return ValueType::Number;
}

void Compiler::type_error(Span span, const std::string& op, ValueType a, ValueType b) {
    diags_->error(span, fmt::format("operator '{}' cannot be applied to {} and {}", op, value_type_name(a),
                                    value_type_name(b)));
}

ValueType Compiler::compile_binary(Ctx& c, const ast::Expr& e) {
    const std::string& op = e.text;
    if (op == "&&" || op == "||") {
        ValueType a = compile_expr(c, *e.args[0]);
        std::size_t j = here(c);
        emit(c, op == "&&" ? Op::JumpIfZeroKeep : Op::JumpIfNonZeroKeep, 0, 0, e.span);
        ValueType b = compile_expr(c, *e.args[1]);
        patch(c, j);
        emit_const(c, 0, e.span);
        emit(c, Op::Ne, 0, 0, e.span);
        if (!numeric(a) || !numeric(b)) type_error(e.span, op, a, b);
        return ValueType::Bool;
    }
    ValueType a = compile_expr(c, *e.args[0]);
    ValueType b = compile_expr(c, *e.args[1]);
    // an operand of unknown type (a recursive call) takes the other operand's type
    if (a == ValueType::Void) a = b == ValueType::Vec3 && (op == "+" || op == "-") ? b : ValueType::Number;
    if (b == ValueType::Void) b = a == ValueType::Vec3 && (op == "+" || op == "-") ? a : ValueType::Number;
    bool na = numeric(a), nb = numeric(b);
    bool va = a == ValueType::Vec3, vb = b == ValueType::Vec3;
    if (na && nb) {
        static const std::pair<const char*, Op> ops[] = {
            {"+", Op::Add}, {"-", Op::Sub}, {"*", Op::Mul}, {"/", Op::Div}, {"%", Op::Mod}, {"<", Op::Lt},
            {"<=", Op::Le}, {">", Op::Gt},  {">=", Op::Ge}, {"==", Op::Eq}, {"!=", Op::Ne}};
        for (const auto& [name, o] : ops) {
            if (op == name) {
                emit(c, o, 0, 0, e.span);
                bool cmp = o >= Op::Lt && o <= Op::Ne;
                return cmp ? ValueType::Bool : ValueType::Number;
            }
        }
    }
    if (va && vb) {
        if (op == "+") {
            emit(c, Op::VAdd, 0, 0, e.span);
            return ValueType::Vec3;
        }
        if (op == "-") {
            emit(c, Op::VSub, 0, 0, e.span);
            return ValueType::Vec3;
        }
        if (op == "==") {
            emit(c, Op::VEq, 0, 0, e.span);
            return ValueType::Bool;
        }
        if (op == "!=") {
            emit(c, Op::VNe, 0, 0, e.span);
            return ValueType::Bool;
        }
    }
    if (va && nb && op == "*") {
        emit(c, Op::VMulS, 0, 0, e.span);
        return ValueType::Vec3;
    }
    if (va && nb && op == "/") {
        emit(c, Op::VDivS, 0, 0, e.span);
        return ValueType::Vec3;
    }
    if (na && vb && op == "*") {
        emit(c, Op::VSMul, 0, 0, e.span);
        return ValueType::Vec3;
    }
    type_error(e.span, op, a, b);
    return ValueType::Number;
}

ValueType Compiler::compile_env_call(Ctx& c, const ast::Expr& e, std::size_t env) {
    const EnvironmentDecl& decl = P_.environments[env];
    const std::string& env_name = decl.name;
    const auto& methods = decl.kind->methods;
    std::size_t m = 0;
    while (m < methods.size() && methods[m].name != e.text) ++m;
    if (m == methods.size()) {
        std::vector<std::string> names;
        for (const auto& mm : methods) names.push_back(mm.name);
        std::string near = nearest_name(e.text, names);
        diags_->error(e.span, near.empty()
                                  ? fmt::format("environment '{}' has no method '{}'", env_name, e.text)
                                  : fmt::format("environment '{}' has no method '{}'; did you mean '{}'?",
                                                env_name, e.text, near));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    const EnvMethod& method = methods[m];
    if (method.access == EnvAccess::Edit && c.kind != CtxKind::Hook)
        diags_->error(e.span, fmt::format("'{}.{}' changes the environment and can be called only in hooks "
                                          "(on start, on before_step, on after_step, on end)",
                                          env_name, e.text));
    const std::size_t given = e.args.size() - 1;
    if (given != method.args.size()) {
        diags_->error(e.span, fmt::format("'{}.{}' takes {} argument{}, given {}", env_name, e.text,
                                          method.args.size(), method.args.size() == 1 ? "" : "s", given));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    int width = 0;
    for (std::size_t i = 0; i < given; ++i) {
        ValueType t = compile_expr(c, *e.args[i + 1]);
        bool fits = method.args[i] == ValueType::Vec3 ? t == ValueType::Vec3 : numeric(t);
        if (!fits)
            diags_->error(e.args[i + 1]->span,
                          fmt::format("argument {} of '{}.{}' must be a {}, found a {}", i + 1, env_name,
                                      e.text, value_type_name(method.args[i]), value_type_name(t)));
        width += value_width(t);
    }
    emit(c, Op::EnvCall, static_cast<std::int32_t>(env), width, e.span, static_cast<std::uint16_t>(m));
    return method.result;
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
        // diagnostics would be lost with the inference's); their result is unknown for now
        if (!inferring_ || fn_state_[it->second] != 0) ensure_function_compiled(it->second);
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
            emit(c, Op::Call, static_cast<std::int32_t>(it->second), 0, e.span);
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
            ok = ok && (b.args[i] == ValueType::Vec3 ? types[i] == ValueType::Vec3 : numeric(types[i]));
            width += value_width(types[i]);
        }
        if (!ok) continue;
        if ((b.id == BuiltinId::Uniform || b.id == BuiltinId::Normal || b.id == BuiltinId::Chance ||
             b.id == BuiltinId::Id) &&
            c.kind == CtxKind::Global) {
            diags_->error(e.span,
                          fmt::format("'{}' depends on the module being rewritten and cannot be used where "
                                      "the value must be known before the derivation starts",
                                      name));
        }
        if ((b.id == BuiltinId::Uniform || b.id == BuiltinId::Normal || b.id == BuiltinId::Chance ||
             b.id == BuiltinId::Id) &&
            c.function >= 0)
            fn_random_[static_cast<std::size_t>(c.function)] = true;
        if (b.id == BuiltinId::Id) P_.uses_id = true;
        emit(c, Op::Builtin, static_cast<std::int32_t>(b.id), width, e.span,
             static_cast<std::uint16_t>(value_width(b.result)));
        return b.result;
    }
    if (!name_known) {
        unknown_name(c, name, e.span, "function");
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

// ---- functions -----------------------------------------------------------------------------

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
    diags_->error(p.span, fmt::format("unknown type '{}': expected number, bool or vec3", p.type));
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

void Compiler::ensure_function_compiled(std::uint32_t index) {
    if (fn_state_[index] != 0) return; // compiled, or being compiled (recursion)
    fn_state_[index] = 1;
    // First pass, quietly: learn the result type, which recursive calls need. Second pass: the
    // real code, with recursive calls typed.
    {
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

// ---- statements ----------------------------------------------------------------------------

void Compiler::compile_block(Ctx& c, const std::vector<ast::Stmt>& body) {
    std::size_t mark = c.locals.size();
    for (const auto& s : body) compile_stmt(c, s);
    c.locals.resize(mark);
}

void Compiler::compile_stmt(Ctx& c, const ast::Stmt& s) {
    using K = ast::StmtKind;
    switch (s.kind) {
    case K::Let: {
        ValueType t = compile_expr(c, *s.expr);
        if (t == ValueType::String || t == ValueType::Void) t = ValueType::Number;
        std::uint16_t slot = add_local(c, s.name, t);
        emit(c, Op::StoreLocal, slot, value_width(t), s.span);
        break;
    }
    case K::Assign:
        compile_assign(c, s);
        break;
    case K::If: {
        ValueType t = compile_expr(c, *s.expr);
        if (!numeric(t)) diags_->error(s.expr->span, "the condition of 'if' must be a number or bool");
        std::size_t j_else = here(c);
        emit(c, Op::JumpIfZero, 0, 0, s.span);
        compile_block(c, s.body);
        if (!s.else_body.empty()) {
            std::size_t j_end = here(c);
            emit(c, Op::Jump, 0, 0, s.span);
            patch(c, j_else);
            compile_block(c, s.else_body);
            patch(c, j_end);
        } else {
            patch(c, j_else);
        }
        break;
    }
    case K::For: {
        // for i in a..b { } runs i = a, a+1, ... while i < b
        std::size_t mark = c.locals.size();
        ValueType ta = compile_expr(c, *s.expr);
        std::uint16_t var = add_local(c, s.name, ValueType::Number);
        emit(c, Op::StoreLocal, var, 1, s.span);
        ValueType tb = compile_expr(c, *s.expr2);
        if (!numeric(ta) || !numeric(tb))
            diags_->error(s.span, "the bounds of a 'for' range must be numbers");
        std::uint16_t end = add_local(c, " end", ValueType::Number);
        emit(c, Op::StoreLocal, end, 1, s.span);
        std::uint16_t guard = add_local(c, " guard", ValueType::Number);
        emit_const(c, 0, s.span);
        emit(c, Op::StoreLocal, guard, 1, s.span);
        std::size_t top = here(c);
        emit(c, Op::LoadLocal, var, 1, s.span);
        emit(c, Op::LoadLocal, end, 1, s.span);
        emit(c, Op::Lt, 0, 0, s.span);
        std::size_t j_exit = here(c);
        emit(c, Op::JumpIfZero, 0, 0, s.span);
        emit(c, Op::ForCheck, guard, 0, s.span);
        compile_block(c, s.body);
        emit(c, Op::LoadLocal, var, 1, s.span);
        emit_const(c, 1, s.span);
        emit(c, Op::Add, 0, 0, s.span);
        emit(c, Op::StoreLocal, var, 1, s.span);
        emit(c, Op::Jump, static_cast<std::int32_t>(top), 0, s.span);
        patch(c, j_exit);
        c.locals.resize(mark);
        break;
    }
    case K::Produce:
    case K::NProduce:
        if (c.kind != CtxKind::Production) {
            diags_->error(s.span, fmt::format("'{}' is allowed only in the body of a production",
                                              s.kind == K::Produce ? "produce" : "nproduce"));
            break;
        }
        compile_successor(c, s.successor, s.span);
        emit(c, s.kind == K::Produce ? Op::ProduceEnd : Op::NProduceMark, 0, 0, s.span);
        break;
    case K::Use: {
        if (c.kind != CtxKind::Hook) {
            diags_->error(s.span, "'use' is allowed only in hooks (on start, on before_step, ...)");
            break;
        }
        int g = s.name == "none" ? -1 : P_.group_index(s.name);
        if (g == -1 && s.name != "none") {
            std::vector<std::string> names;
            for (const auto& rs : P_.groups) names.push_back(rs.name);
            std::string near = nearest_name(s.name, names);
            diags_->error(s.span, near.empty() ? fmt::format("unknown rule group '{}'", s.name)
                                               : fmt::format("unknown rule group '{}'; did you mean '{}'?",
                                                             s.name, near));
        }
        used_groups_.insert(s.name);
        emit(c, Op::Use, g, 0, s.span);
        break;
    }
    case K::Stop:
        if (c.kind != CtxKind::Hook) {
            diags_->error(s.span, "'stop' is allowed only in hooks");
            break;
        }
        emit(c, Op::Stop, 0, 0, s.span);
        break;
    case K::Return: {
        if (c.kind != CtxKind::Function) {
            diags_->error(s.span, "'return' is allowed only in functions");
            break;
        }
        ValueType t = s.expr ? compile_expr(c, *s.expr) : ValueType::Number;
        if (!s.expr) emit_const(c, 0, s.span);
        if (t == ValueType::Void) { // `return f(...)` inside f: the width is set when f is done
            c.void_returns.push_back(here(c));
            emit(c, Op::Return, 0, 0, s.span);
            break;
        }
        if (c.fn_result_known && value_width(t) != value_width(*c.fn_result))
            diags_->error(s.span, "all 'return' statements of a function must give the same type");
        *c.fn_result = t;
        c.fn_result_known = true;
        emit(c, Op::Return, 0, value_width(t), s.span);
        break;
    }
    case K::Expr: {
        const ast::Expr& e = *s.expr;
        if (e.kind == ast::ExprKind::Call && e.text == "print") {
            compile_print(c, e);
            break;
        }
        if (e.kind == ast::ExprKind::Method) {
            compile_expr(c, e); // reports that environments cannot be queried yet
            emit(c, Op::Pop, 0, 1, s.span);
            break;
        }
        ValueType t = compile_expr(c, e);
        if (t == ValueType::Void) t = ValueType::Number;
        emit(c, Op::Pop, 0, value_width(t), s.span);
        diags_->warning(s.span, "this expression's value is not used");
        break;
    }
    }
}

void Compiler::compile_print(Ctx& c, const ast::Expr& e) {
    if (c.kind != CtxKind::Hook) {
        diags_->error(e.span, "print(...) is allowed only in hooks");
        return;
    }
    std::string format;
    int width = 0;
    for (const auto& a : e.args) {
        if (a->kind == ast::ExprKind::String) {
            format += 's' + a->text + '\x1f';
            continue;
        }
        ValueType t = compile_expr(c, *a);
        format += t == ValueType::Vec3 ? 'v' : t == ValueType::Bool ? 'b' : 'n';
        width += value_width(t);
    }
    if (width > 255) {
        diags_->error(e.span, "print(...) can show at most 255 numbers at once");
        return;
    }
    P_.print_formats.push_back(format);
    emit(c, Op::Print, static_cast<std::int32_t>(P_.print_formats.size() - 1), width, e.span);
}

void Compiler::compile_assign(Ctx& c, const ast::Stmt& s) {
    auto compile_value = [&](ValueType target) {
        if (s.op == "=") {
            ValueType t = compile_expr(c, *s.expr);
            if (t == ValueType::Void) t = ValueType::Number;
            if (value_width(t) != value_width(target))
                diags_->error(s.expr->span, fmt::format("cannot assign a {} to '{}', which holds a {}",
                                                        value_type_name(t), s.name, value_type_name(target)));
            return;
        }
        // compound: load, value, op
        ast::Expr load;
        load.kind = ast::ExprKind::Name;
        load.text = s.name;
        load.span = s.span;
        compile_expr(c, load);
        ValueType t = compile_expr(c, *s.expr);
        if (t == ValueType::Void) t = ValueType::Number;
        char op = s.op[0];
        if (target == ValueType::Vec3 && t == ValueType::Vec3 && (op == '+' || op == '-'))
            emit(c, op == '+' ? Op::VAdd : Op::VSub, 0, 0, s.span);
        else if (target == ValueType::Vec3 && numeric(t) && (op == '*' || op == '/'))
            emit(c, op == '*' ? Op::VMulS : Op::VDivS, 0, 0, s.span);
        else if (numeric(target) && numeric(t))
            emit(c, op == '+' ? Op::Add : op == '-' ? Op::Sub : op == '*' ? Op::Mul : Op::Div, 0, 0, s.span);
        else
            type_error(s.span, s.op, target, t);
    };
    if (const LocalVar* l = find_local(c, s.name)) {
        if (l->bound) {
            diags_->error(
                s.span,
                fmt::format("'{}' is bound by the predecessor and cannot be assigned; use 'let'", s.name));
            return;
        }
        LocalVar copy = *l;
        compile_value(copy.type);
        emit(c, Op::StoreLocal, copy.slot, value_width(copy.type), s.span);
        return;
    }
    if (auto it = consts_.find(s.name); it != consts_.end()) {
        diags_->error(s.span, fmt::format("'{}' is a const and cannot be assigned (defined at {})", s.name,
                                          where(it->second.span)));
        return;
    }
    if (auto it = P_.global_index.find(s.name); it != P_.global_index.end()) {
        const Global g = P_.globals[it->second];
        if (c.kind != CtxKind::Hook) {
            diags_->error(s.span, fmt::format("'{}' is a {}: it can be assigned only in hooks (on start, on "
                                              "before_step, on after_step, on end)",
                                              s.name, g.kind == GlobalKind::Param ? "param" : "var"));
            return;
        }
        compile_value(g.type);
        emit(c, Op::StoreGlobal, static_cast<std::int32_t>(g.slot), value_width(g.type), s.span);
        return;
    }
    unknown_name(c, s.name, s.span, "variable");
}

// ---- modules, successors, patterns ---------------------------------------------------------

// Splits a letter run by longest match over declared module names, else one letter a module.
std::vector<std::pair<std::string, Span>> Compiler::split_run(const ast::ModuleRef& m) {
    std::vector<std::pair<std::string, Span>> out;
    const std::string& s = m.name;
    if (!m.raw) {
        out.emplace_back(s, m.name_span);
        return out;
    }
    if (auto id = P_.symbols.find(s); id && P_.symbols[*id].declared) {
        out.emplace_back(s, m.name_span);
        return out;
    }
    std::size_t i = 0;
    while (i < s.size()) {
        std::size_t best = 1;
        for (std::size_t len = std::min(s.size() - i, max_declared_len_); len > 1; --len) {
            if (auto id = P_.symbols.find(std::string_view(s).substr(i, len));
                id && P_.symbols[*id].declared) {
                best = len;
                break;
            }
        }
        Span sp{m.name_span.file, static_cast<std::uint32_t>(m.name_span.begin + i),
                static_cast<std::uint32_t>(m.name_span.begin + i + best)};
        out.emplace_back(s.substr(i, best), sp);
        i += best;
    }
    if (out.size() > 1) {
        RawRun run{s, m.name_span, {}};
        for (const auto& part : out) run.letters.push_back(part.first);
        raw_runs_.push_back(std::move(run));
    }
    return out;
}

SymbolId Compiler::module_symbol(const std::string& name, Span span) {
    (void)span;
    return P_.symbols.intern(name);
}

void Compiler::compile_successor(Ctx& c, const ast::ModuleList& list, Span span) {
    (void)span;
    for (const auto& m : list) {
        if (m.name == "*") {
            diags_->error(m.span, "'*' (any context) is allowed only in a context pattern");
            continue;
        }
        auto parts = split_run(m);
        for (std::size_t k = 0; k < parts.size(); ++k) {
            SymbolId sym = module_symbol(parts[k].first, parts[k].second);
            produced_.insert(sym);
            const bool last = k + 1 == parts.size();
            const SymbolInfo& info = P_.symbols[sym];
            int width = 0;
            std::size_t nargs = last ? m.args.size() : 0;
            if (info.arity >= 0 && (last ? m.has_args || info.arity > 0 : info.arity > 0) &&
                static_cast<int>(nargs) != info.arity) {
                diags_->error(last ? m.span : Span{parts[k].second},
                              fmt::format("module '{}' takes {} parameter{}, given {} (declared at {})",
                                          info.name, info.arity, info.arity == 1 ? "" : "s", nargs,
                                          where(info.decl_span)));
            }
            if (sym == P_.symbols.open_bracket || sym == P_.symbols.close_bracket) {
                if (nargs) diags_->error(m.span, "brackets take no parameters");
                emit(c, Op::Emit, static_cast<std::int32_t>(sym), 0, m.span);
                continue;
            }
            std::vector<Span> arg_spans;
            const bool communication = info.query && info.name == "?E";
            for (std::size_t i = 0; i < nargs; ++i) {
                // ?E(env, slots...): the first argument names an environment, which is kept as its index
                if (communication && i == 0) {
                    const ast::Expr& a = *m.args[0];
                    std::size_t env = P_.environments.size();
                    if (a.kind == ast::ExprKind::Name)
                        for (std::size_t e = 0; e < P_.environments.size(); ++e)
                            if (P_.environments[e].name == a.text) env = e;
                    if (env == P_.environments.size()) {
                        diags_->error(a.span,
                                      "the first argument of ?E names an environment, as in ?E(sun, 0)");
                        emit_const(c, -1, a.span);
                    } else {
                        emit_const(c, static_cast<double>(env), a.span);
                    }
                    arg_spans.push_back(a.span);
                    width += 1;
                    continue;
                }
                ValueType t = compile_expr(c, *m.args[i]);
                for (int w = 0; w < std::max(1, value_width(t)); ++w) arg_spans.push_back(m.args[i]->span);
                if (t == ValueType::String) t = ValueType::Number;
                if (info.arity >= 0 && i < info.param_types.size() &&
                    value_width(t) != value_width(info.param_types[i])) {
                    diags_->error(m.args[i]->span,
                                  fmt::format("parameter '{}' of '{}' is a {}, found a {}",
                                              info.param_names[i], info.name,
                                              value_type_name(info.param_types[i]), value_type_name(t)));
                }
                width += value_width(t);
            }
            if (width > 255) {
                diags_->error(m.span, "a module can carry at most 255 numbers");
                width = 0;
            }
            std::uint16_t spans_index = 0;
            if (!arg_spans.empty() && c.code->arg_spans.size() < 65535) {
                c.code->arg_spans.push_back(std::move(arg_spans));
                spans_index = static_cast<std::uint16_t>(c.code->arg_spans.size());
            }
            emit(c, Op::Emit, static_cast<std::int32_t>(sym), width, last ? m.span : parts[k].second,
                 spans_index);
        }
    }
}

// Compiles one pattern list (strict predecessor or context) and binds its names in `c`.
std::vector<PatternModule> Compiler::compile_pattern(Ctx& c, const ast::ModuleList& list, PatternRole role) {
    std::vector<PatternModule> out;
    for (const auto& m : list) {
        auto parts = split_run(m);
        for (std::size_t k = 0; k < parts.size(); ++k) {
            PatternModule pm;
            pm.sym = module_symbol(parts[k].first, parts[k].second);
            pm.span = parts[k].second;
            const SymbolInfo& info = P_.symbols[pm.sym];
            const bool last = k + 1 == parts.size();
            bool bracket = pm.sym == P_.symbols.open_bracket || pm.sym == P_.symbols.close_bracket;
            if (bracket && role != PatternRole::Right) {
                diags_->error(m.span, role == PatternRole::Strict
                                          ? "a predecessor cannot contain '[' or ']'"
                                          : "brackets are allowed only in a right context");
            }
            std::size_t nargs = last ? m.args.size() : 0;
            if (info.arity >= 0 && static_cast<int>(nargs) != info.arity) {
                diags_->error(
                    last ? m.span : pm.span,
                    fmt::format("module '{}' takes {} parameter{}, the pattern gives {} (declared at {})",
                                info.name, info.arity, info.arity == 1 ? "" : "s", nargs,
                                where(info.decl_span)));
            }
            for (std::size_t i = 0; i < nargs; ++i) {
                const ast::Expr& a = *m.args[i];
                PatternArg pa;
                ValueType t = ValueType::Number;
                if (info.arity >= 0 && i < info.param_types.size()) t = info.param_types[i];
                if (info.query && nargs == 1) t = ValueType::Vec3;
                pa.width = static_cast<std::uint8_t>(value_width(t));
                if (a.kind == ast::ExprKind::Name && !consts_.count(a.text)) {
                    if (a.text == "_") {
                        pa.bind = false;
                        pa.value = std::nan("");
                    } else {
                        for (const auto& l : c.locals) {
                            if (l.name == a.text) {
                                diags_->error(a.span,
                                              fmt::format("'{}' is bound twice in this production", a.text));
                                break;
                            }
                        }
                        pa.slot = add_local(c, a.text, t);
                        c.locals.back().bound = true;
                    }
                } else if (auto v = fold_number(a)) {
                    pa.bind = false;
                    pa.value = *v;
                    if (t == ValueType::Vec3)
                        diags_->error(a.span, "a vec3 parameter cannot be matched against a number");
                } else {
                    diags_->error(a.span, "a pattern argument must be a name to bind or a constant value");
                }
                pm.width += pa.width;
                pm.args.push_back(pa);
            }
            out.push_back(std::move(pm));
        }
    }
    return out;
}

} // namespace plant
