// Rules: rule blocks into rule sets, productions (patterns that bind names, conditions, weights,
// bodies), successors and letter runs split into modules, and the successor templates that let
// the engine apply an arrow-form production without running its code module by module.
#include "compiler_internal.hpp"
#include "habits.hpp"
#include "plant/derive.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>

namespace plant {

namespace {

// ?P, ?H, ?U and ?L are filled with three numbers (cpfg's two-slot 2-D form is not read)
std::string query_arity_message(const std::string& name, std::size_t given) {
    return fmt::format("'{}' has three slots, filled with x, y, z: write {}(x, y, z), or {}(p) for one vec3; "
                       "given {}",
                       name, name, name, given);
}

// "leaf" as "l e a f"
std::string spaced(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (!out.empty()) out += ' ';
        out += c;
    }
    return out;
}

} // namespace

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
        for (const auto& p : rb.productions) compile_production(p, *set);
    }
}

void Compiler::compile_production(const ast::Production& p, RuleSet& set) {
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
        if (auto v = fold_number(*p.condition)) {
            // `a : 0.2 -> X`: a probability written where the condition goes
            if (t == ValueType::Number && *v != 0 && *v != 1)
                diags_->error(
                    p.condition->span,
                    fmt::format("a condition of {} is always true: a condition is a bool (x > 1); a "
                                "probability is the production's weight, after its successor: {} -> "
                                "... : {};",
                                format_double(*v), p.strict.empty() ? "A" : p.strict[0].name,
                                format_double(*v)));
            // always true: the production is unconditional, and shadows those after it as one
            if (*v != 0) cp.condition = Code{};
        }
    }
    if (p.weight) {
        c.code = &cp.weight;
        ValueType t = compile_expr(c, *p.weight);
        if (t != ValueType::Number && t != ValueType::Bool)
            diags_->error(p.weight->span,
                          fmt::format("a weight must be a number, found a {}", value_type_name(t)));
        emit(c, Op::Halt, 0, 1, p.weight->span);
        // a constant weight is checked now, as a derivation would at its first choice
        if (auto v = fold_number(*p.weight); v && t == ValueType::Number && (!std::isfinite(*v) || *v < 0))
            diags_->error(p.weight->span,
                          fmt::format("a production weight must be a finite number >= 0, found {}: weights "
                                      "are relative chances (1 and 3 give a quarter and three quarters)",
                                      format_double(*v)));
        else if (v && *v == 0)
            diags_->warning(p.weight->span, "this production is never chosen: its weight is always 0 (a "
                                            "module whose applicable productions all weigh 0 is copied "
                                            "unchanged)");
    }
    c.code = &cp.body;
    cp.body_form = p.body_form;
    if (p.body_form) {
        compile_block(c, p.body);
        emit(c, Op::Halt, 0, 0, p.span);
    } else {
        compile_successor(c, p.successor);
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
    check_shadowed(p, cp, set);
    set.productions.push_back(std::move(cp));
}

void Compiler::finish_rule_set(RuleSet& set) {
    set.index(P_.symbols.size());
}

// The kinds of the successor templates' modules (docs/rewriting.md, memory): a module with
// constant numbers gets a kind of its own, shared by every module with the same symbol, the
// same constants and its holes in the same places, and the string stores only its holes. Plain
// (every number stored, the kind's id the symbol's): a module without constants, and every
// query or communication module, whose numbers the environment phase writes in place.
void Compiler::assign_kinds() {
    P_.kinds.reset(static_cast<std::uint32_t>(P_.symbols.size()));
    for (const auto& [s, n] : emitted_) P_.kinds.add_plain(s, n);
    std::map<std::vector<std::uint64_t>, KindId> known;
    auto each = [&](RuleSet& rs) {
        for (Production& pr : rs.productions)
            if (pr.tmpl.valid) assign_kinds(pr.tmpl, known);
    };
    each(P_.rules);
    for (RuleSet& g : P_.groups) each(g);
    each(P_.decompose);
    each(P_.interpret);
}

void Compiler::assign_kinds(SuccessorTemplate& t, std::map<std::vector<std::uint64_t>, KindId>& known) {
    KindTable& T = P_.kinds;
    std::vector<std::uint8_t> hole(t.params.size(), 0);
    for (std::uint32_t h : t.holes) hole[h] = 1;
    std::vector<std::uint32_t> where(t.params.size(), 0);
    t.kinds.clear();
    t.stored.clear();
    t.stored_nargs.clear();
    std::uint32_t from = 0;
    for (std::size_t j = 0; j < t.syms.size(); from = t.param_end[j], ++j) {
        const SymbolId s = t.syms[j];
        const std::uint32_t end = t.param_end[j], n = end - from;
        const SymbolInfo& info = P_.symbols[s];
        bool constants = false;
        for (std::uint32_t k = from; k < end; ++k) constants |= hole[k] == 0;
        const std::size_t first = t.stored.size();
        if (!constants || info.query || info.turtle_op == TurtleOp::Communicate ||
            T.kinds() + 1 >= kNoSymbol) { // plain
            for (std::uint32_t k = from; k < end; ++k) {
                where[k] = static_cast<std::uint32_t>(t.stored.size());
                t.stored.push_back(t.params[k]);
            }
            const std::uint32_t kind = T.add_plain(s, n);
            if (kind == KindTable::kNoKind) { // the table is full: the body writes the successor
                t.valid = false;
                return;
            }
            t.kinds.push_back(static_cast<KindId>(kind));
            t.stored_nargs.push_back(static_cast<std::uint8_t>(n));
            continue;
        }
        std::vector<std::uint64_t> key{s, n};
        for (std::uint32_t k = from; k < end; ++k) {
            key.push_back(hole[k]);
            key.push_back(hole[k] ? 0 : std::bit_cast<std::uint64_t>(t.params[k]));
            if (hole[k]) {
                where[k] = static_cast<std::uint32_t>(t.stored.size());
                t.stored.push_back(0.0);
            }
        }
        auto [it, fresh] = known.try_emplace(std::move(key), static_cast<KindId>(T.kinds()));
        if (fresh) {
            T.append(s, n, static_cast<std::uint32_t>(t.stored.size() - first),
                     static_cast<std::uint32_t>(T.slot.size()));
            std::int16_t at = 0;
            for (std::uint32_t k = from; k < end; ++k) {
                T.slot.push_back(hole[k] ? at++ : std::int16_t{-1});
                T.value.push_back(hole[k] ? 0.0 : t.params[k]);
            }
        }
        t.kinds.push_back(it->second);
        t.stored_nargs.push_back(static_cast<std::uint8_t>(t.stored.size() - first));
    }
    t.stored_holes.clear();
    for (std::uint32_t h : t.holes) t.stored_holes.push_back(where[h]);
}

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

SymbolId Compiler::module_symbol(const std::string& name) {
    return P_.symbols.intern(name);
}

// `~name` places the surface `name`: one not declared (here, in a library imported, or in the
// program an instance body belongs to) is an error at the module, with the nearest name.
void Compiler::check_surface_named(const std::string& module, Span at) {
    if (module.size() < 2 || module[0] != '~') return;
    const std::string_view name = std::string_view(module).substr(1);
    std::vector<std::string> names; // compiled (an instance body's inherited among them) or declared
    for (const auto& s : P_.surfaces) names.push_back(s.name);
    for (const ast::ShapeDecl* s : surface_decls_) names.push_back(s->name); // one that failed: told already
    if (std::find(names.begin(), names.end(), name) != names.end()) return;
    const std::string near = nearest_name(name, names);
    diags_->error(at, near.empty()
                          ? fmt::format("'{}' places a surface that is not declared: add 'surface {} = "
                                        "polygon(...);' or load(\"file.obj\")",
                                        module, name)
                          : fmt::format("'{}' places a surface that is not declared; did you mean '~{}'?",
                                        module, near));
}

// A size known now to be below 0 (the turtle stops at the others): the width of '!' and of F's
// second number, the radius of '@O' and of a bound segment's second number (`Seg(len, r) bound
// ivy`), a surface's scale ('~leaf(s)').
void Compiler::check_size_argument(const SymbolInfo& info, const ast::ModuleRef& m) {
    std::size_t at = 0;
    const char* what = nullptr;
    if (!info.bound_to.empty())
        at = 1, what = "radius";
    else if (info.turtle_op == TurtleOp::Forward)
        at = 1, what = "width";
    else if (info.turtle_op == TurtleOp::Width)
        what = "width";
    else if (info.turtle_op == TurtleOp::Sphere)
        what = "radius";
    else if (info.turtle_op == TurtleOp::Surface)
        what = "scale";
    if (!what || m.args.size() <= at) return;
    if (auto v = fold_number(*m.args[at]); v && *v < 0)
        diags_->error(m.args[at]->span, fmt::format("'{}' gives a {} of {}: a {} is at least 0", info.name,
                                                    what, format_double(*v), what));
}

void Compiler::compile_successor(Ctx& c, const ast::ModuleList& list) {
    for (const auto& m : list) {
        if (m.name == "*") {
            diags_->error(m.span, "'*' (any context) is allowed only in a context pattern");
            continue;
        }
        auto parts = split_run(m);
        for (std::size_t k = 0; k < parts.size(); ++k) {
            SymbolId sym = module_symbol(parts[k].first);
            produced_.insert(sym);
            const bool last = k + 1 == parts.size();
            check_surface_named(parts[k].first, last ? m.span : Span{parts[k].second});
            const SymbolInfo& info = P_.symbols[sym];
            int width = 0;
            std::size_t nargs = last ? m.args.size() : 0;
            if (info.arity >= 0 && (last ? m.has_args || info.arity > 0 : info.arity > 0) &&
                static_cast<int>(nargs) != info.arity && !instance_arity_ok(info, nargs)) {
                diags_->error(last ? m.span : Span{parts[k].second},
                              fmt::format("module '{}' takes {} parameter{}{}, given {} (declared at {})",
                                          info.name, info.arity, info.arity == 1 ? "" : "s",
                                          info.instance >= 0 ? " and an optional scale" : "", nargs,
                                          where(info.decl_span)));
            }
            if (info.instance >= 0 && last && m.args.size() == static_cast<std::size_t>(info.arity) + 1) {
                // a placement scale known now must be positive (the turtle checks the others)
                const ast::Expr& scale = *m.args.back();
                if (auto v = fold_number(scale); v && !(*v > 0))
                    diags_->error(scale.span, fmt::format("'{}' places the instance at scale {}: the scale, "
                                                          "its last number, must be positive (leave it "
                                                          "out for scale 1)",
                                                          info.name, *v));
            }
            if (info.instance >= 0 && self_index_ >= 0) // what this body places (check_instance_graph)
                graph_->places[static_cast<std::size_t>(self_index_)].emplace_back(
                    info.instance, last ? m.span : Span{parts[k].second});
            // ABOP's and cpfg's bare '!' narrows the width a step; here it sets it, and alone
            // changes nothing (said once a program)
            if (info.turtle_op == TurtleOp::Width && last && !m.has_args && !bare_width_told_) {
                bare_width_told_ = true;
                diags_->warning(m.span,
                                "'!' without a width changes nothing here; ABOP's and cpfg's '!' (a "
                                "step narrower) is written with the width it should take, as !(w * 0.7)");
            }
            if (last && info.instance < 0) check_size_argument(info, m);
            if (info.turtle_op == TurtleOp::Push || info.turtle_op == TurtleOp::Pop) {
                // the turtle table's only count it enforces: brackets take none
                if (nargs > turtle_symbol(info.turtle_op)->max_params)
                    diags_->error(m.span, "brackets take no parameters");
                emit(c, Op::Emit, static_cast<std::int32_t>(sym), 0, m.span);
                emitted_.emplace(sym, 0);
                continue;
            }
            std::vector<Span> arg_spans;
            const bool communication = info.turtle_op == TurtleOp::Communicate;
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
                if (info.instance >= 0 && i == info.param_types.size() && !numeric(t))
                    diags_->error(
                        m.args[i]->span,
                        fmt::format("the scale of instance '{}' (its last argument) must be a number, "
                                    "found a {}",
                                    info.name, value_type_name(t)));
                if (info.arity >= 0 && i < info.param_types.size() &&
                    (value_width(t) != value_width(info.param_types[i]) ||
                     (t == ValueType::Node) != (info.param_types[i] == ValueType::Node))) {
                    diags_->error(m.args[i]->span,
                                  fmt::format("parameter '{}' of '{}' is a {}, found a {}",
                                              info.param_names[i], info.name,
                                              value_type_name(info.param_types[i]), value_type_name(t)));
                }
                width += value_width(t);
            }
            if (info.query && info.turtle_op != TurtleOp::Communicate && nargs > 0 && width != 3)
                diags_->error(m.span, query_arity_message(info.name, static_cast<std::size_t>(width)));
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
            emitted_.emplace(sym, static_cast<std::uint32_t>(width));
        }
    }
}

// Compiles one pattern list (strict predecessor or context) and binds its names in `c`.
std::vector<PatternModule> Compiler::compile_pattern(Ctx& c, const ast::ModuleList& list, PatternRole role) {
    std::vector<PatternModule> out;
    for (const auto& m : list) {
        auto parts = split_run(m);
        if (role == PatternRole::Strict && parts.size() == m.name.size() && parts.size() > 1 &&
            habits::looks_like_a_name(m.name))
            // ABOP's `plant -> internode ...` typed with the words undeclared
            diags_->warning(
                m.name_span,
                fmt::format("'{}' is not a declared module, so this predecessor is the {} modules "
                            "{} in a row; declare it with 'module {};'",
                            m.name, parts.size(), spaced(m.name), m.name));
        for (std::size_t k = 0; k < parts.size(); ++k) {
            PatternModule pm;
            pm.sym = module_symbol(parts[k].first);
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
            if (info.arity >= 0 && static_cast<int>(nargs) != info.arity && !instance_arity_ok(info, nargs)) {
                diags_->error(
                    last ? m.span : pm.span,
                    fmt::format("module '{}' takes {} parameter{}{}, the pattern gives {} (declared at {})",
                                info.name, info.arity, info.arity == 1 ? "" : "s",
                                info.instance >= 0 ? " and an optional scale" : "", nargs,
                                where(info.decl_span)));
            }
            if (info.query && info.turtle_op != TurtleOp::Communicate && nargs != 0 && nargs != 1 &&
                nargs != 3)
                diags_->error(m.span, query_arity_message(info.name, nargs));
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
                if (is_jump(J.op)) J.a = static_cast<std::int32_t>(J.a + shift);
                if (J.op == Op::Emit || op_info(J.op).flow == OpFlow::End) return;
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

} // namespace plant
