// Statements: production bodies, function bodies and hooks (let, assignment, if, for, produce,
// use, stop, return, print), and the four hooks, each compiled from its bodies in file order.
#include "compiler_internal.hpp"

#include <fmt/format.h>

#include <functional>

namespace plant {

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
    case K::For:
        compile_for(c, s);
        break;
    case K::Produce:
    case K::NProduce:
        if (c.kind != CtxKind::Production) {
            diags_->error(s.span, fmt::format("'{}' is allowed only in the body of a production",
                                              s.kind == K::Produce ? "produce" : "nproduce"));
            break;
        }
        compile_successor(c, s.successor);
        emit(c, s.kind == K::Produce ? Op::ProduceEnd : Op::NProduceMark, 0, 0, s.span);
        break;
    case K::Use:
        compile_use(c, s);
        break;
    case K::Stop:
        if (c.kind != CtxKind::Hook) {
            diags_->error(s.span, "'stop' is allowed only in hooks");
            break;
        }
        emit(c, Op::Stop, 0, 0, s.span);
        break;
    case K::Return:
        compile_return(c, s);
        break;
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

void Compiler::compile_for(Ctx& c, const ast::Stmt& s) {
    // for i in a..b { } runs i = a, a+1, ... while i < b
    std::size_t mark = c.locals.size();
    ValueType ta = compile_expr(c, *s.expr);
    std::uint16_t var = add_local(c, s.name, ValueType::Number);
    emit(c, Op::StoreLocal, var, 1, s.span);
    ValueType tb = compile_expr(c, *s.expr2);
    if (!numeric(ta) || !numeric(tb)) diags_->error(s.span, "the bounds of a 'for' range must be numbers");
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
}

void Compiler::compile_use(Ctx& c, const ast::Stmt& s) {
    if (c.kind != CtxKind::Hook) {
        diags_->error(s.span, fmt::format("'use' is allowed only in hooks (on {}, on {}, ...)",
                                          ast::spelling(ast::HookKind::Start),
                                          ast::spelling(ast::HookKind::BeforeStep)));
        return;
    }
    int g = s.name == "none" ? -1 : P_.group_index(s.name);
    if (g == -1 && s.name != "none") {
        std::vector<std::string> names;
        for (const auto& rs : P_.groups) names.push_back(rs.name);
        std::string near = nearest_name(s.name, names);
        diags_->error(s.span, near.empty()
                                  ? fmt::format("unknown rule group '{}'", s.name)
                                  : fmt::format("unknown rule group '{}'; did you mean '{}'?", s.name, near));
    }
    used_groups_.insert(s.name);
    emit(c, Op::Use, g, 0, s.span);
}

void Compiler::compile_return(Ctx& c, const ast::Stmt& s) {
    if (c.kind != CtxKind::Function) {
        diags_->error(s.span, "'return' is allowed only in functions");
        return;
    }
    ValueType t = s.expr ? compile_expr(c, *s.expr) : ValueType::Number;
    if (!s.expr) emit_const(c, 0, s.span);
    if (t == ValueType::Void) { // `return f(...)` inside f: the width is set when f is done
        c.void_returns.push_back(here(c));
        emit(c, Op::Return, 0, 0, s.span);
        return;
    }
    if (c.fn_result_known && value_width(t) != value_width(*c.fn_result))
        diags_->error(s.span, "all 'return' statements of a function must give the same type");
    *c.fn_result = t;
    c.fn_result_known = true;
    emit(c, Op::Return, 0, value_width(t), s.span);
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
        using A = ast::AssignOp;
        if (s.op == A::Set) {
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
        const A op = s.op;
        if (target == ValueType::Vec3 && t == ValueType::Vec3 && (op == A::Add || op == A::Sub))
            emit(c, op == A::Add ? Op::VAdd : Op::VSub, 0, 0, s.span);
        else if (target == ValueType::Vec3 && numeric(t) && (op == A::Mul || op == A::Div))
            emit(c, op == A::Mul ? Op::VMulS : Op::VDivS, 0, 0, s.span);
        else if (numeric(target) && numeric(t))
            emit(c,
                 op == A::Add   ? Op::Add
                 : op == A::Sub ? Op::Sub
                 : op == A::Mul ? Op::Mul
                                : Op::Div,
                 0, 0, s.span);
        else
            type_error(s.span, ast::spelling(op), target, t);
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
            diags_->error(s.span, fmt::format("'{}' is a {}: it can be assigned only in hooks ({})", s.name,
                                              g.kind == GlobalKind::Param ? "param" : "var",
                                              ast::hook_list("on ", ", ")));
            return;
        }
        compile_value(g.type);
        emit(c, Op::StoreGlobal, static_cast<std::int32_t>(g.slot), value_width(g.type), s.span);
        return;
    }
    unknown_name(c, s.name, s.span, Unknown::Variable);
}

void Compiler::compile_hooks(const ast::File& f) {
    for (const auto& h : f.hooks) {
        const auto k = static_cast<std::size_t>(h.when);
        hook_bodies_[k].push_back(&h);
    }
}

// The names assigned anywhere in this program's hooks (the only code that may assign a param or
// var), nested blocks included; a name assigned as a local counts too, which only keeps a param
// from being folded (folded_param).
void Compiler::find_assigned_params() {
    std::function<void(const std::vector<ast::Stmt>&)> scan = [&](const std::vector<ast::Stmt>& body) {
        for (const ast::Stmt& s : body) {
            if (s.kind == ast::StmtKind::Assign) assigned_params_.insert(s.name);
            scan(s.body);
            scan(s.else_body);
        }
    };
    for (const auto& lf : order_)
        for (const ast::Hook& h : lf.file->hooks) scan(h.body);
}

// Each hook's bodies, from every file in load order, become one piece of code.
void Compiler::compile_hook_bodies() {
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
}

} // namespace plant
