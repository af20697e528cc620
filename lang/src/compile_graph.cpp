// Decomposition graphs in the compiler (docs/language.md, decomposition graphs): the `graph { }`
// block's parameters with their root defaults, the `edits "file";` default, the graph built-ins
// (root, child, depth, position, index) and parameter reads through a node (`n.length`,
// `n.bend(t)`), compiled to Op::GraphCall and Op::GraphRead.
#include "compiler_internal.hpp"
#include "graph_ops.hpp"
#include "graph_silhouette.hpp"
#include "plant/builtins.hpp"

#include <fmt/format.h>

#include <filesystem>

namespace plant {

namespace fs = std::filesystem;

namespace {
constexpr std::size_t kMaxGraphParams = 1000;
} // namespace

// At most one graph block a file; an importing file's block replaces a library's (files are
// compiled imports first), as its axiom does.
void Compiler::compile_graph() {
    const ast::GraphBlock* chosen = nullptr;
    const ast::EditsDecl* edits = nullptr;
    for (const auto& lf : order_) {
        const ast::File& f = *lf.file;
        if (self_index_ >= 0) {
            for (const auto& g : f.graphs)
                diags_->error(g.span,
                              "a graph block belongs at the top level of a grammar, not in an instance");
            continue;
        }
        for (std::size_t k = 0; k < f.graphs.size(); ++k) {
            if (k > 0) {
                duplicate("graph", "graph", f.graphs[k].span, f.graphs[0].span);
                continue;
            }
            chosen = &f.graphs[k];
        }
        for (std::size_t k = 0; k < f.edits_files.size(); ++k) {
            if (k > 0) {
                duplicate("edits file", "edits", f.edits_files[k].span, f.edits_files[0].span);
                continue;
            }
            edits = &f.edits_files[k];
        }
    }
    if (chosen) compile_graph_block(*chosen);
    if (!edits) return;
    if (!chosen) {
        diags_->error(edits->span, "an edits file needs a graph block: declare graph { ... } first");
        return;
    }
    fs::path p(edits->path);
    if (p.is_relative()) p = fs::path(sm_.file(edits->span.file).name()).parent_path() / p;
    P_.graph.edits_path = p.lexically_normal().string();
    P_.graph.edits_span = edits->path_span;
    if (readable(edits->path, P_.graph.edits_path, edits->path_span).empty()) P_.graph.edits_path.clear();
}

void Compiler::compile_graph_block(const ast::GraphBlock& g) {
    P_.graph.declared = true;
    P_.graph.span = g.span;
    if (g.match == "single") {
        P_.graph.match = GraphMatch::Single;
    } else if (!g.match.empty() && g.match != "range") {
        diags_->error(
            g.match_span,
            fmt::format("unknown matching '{}': expected 'match range' (the default) or 'match single'",
                        g.match));
    }
    if (g.params.size() > kMaxGraphParams)
        diags_->error(g.span, fmt::format("a graph may declare at most {} parameters", kMaxGraphParams));
    for (const auto& p : g.params) {
        if (P_.graph.params.size() >= kMaxGraphParams) break;
        compile_graph_param(p);
    }
    for (const auto& [name, v] : consts_) {
        Program::NamedConst nc;
        nc.name = name;
        nc.type = v.type;
        for (int k = 0; k < 3; ++k) nc.v[k] = v.v[k];
        P_.constants.push_back(nc);
    }
    std::sort(P_.constants.begin(), P_.constants.end(),
              [](const auto& a, const auto& b) { return a.name < b.name; });
}

// One parameter: a number (any expression of params and consts), a curve (linear(...) or
// bezier(...), as a `curve` declaration takes), or a silhouette (not supported yet).
void Compiler::compile_graph_param(const ast::GraphParam& p) {
    if (int k = P_.graph.find(p.name); k >= 0) {
        duplicate("graph parameter", p.name, p.name_span, P_.graph.params[static_cast<std::size_t>(k)].span);
        return;
    }
    GraphParamDecl d;
    d.name = p.name;
    d.span = p.name_span;
    const ast::Expr& v = *p.value;
    if (v.kind == ast::ExprKind::Call && (v.text == "linear" || v.text == "bezier")) {
        auto curve = make_curve(p.name, v.text, v.span, v.args, v.span);
        if (!curve) return;
        d.kind = GraphParamKind::Curve;
        d.curve = std::make_shared<const CurveDef>(std::move(*curve));
    } else if (v.kind == ast::ExprKind::Call && v.text == "silhouette") {
        SilhouetteEval ev;
        ev.vec = [&](const ast::Expr& x) -> std::optional<glm::dvec3> {
            auto r = eval_const(x, "a silhouette's point");
            if (!r) return std::nullopt;
            if (r->type != ValueType::Vec3) {
                diags_->error(x.span, "a silhouette's point is a vec3");
                return std::nullopt;
            }
            return glm::dvec3(r->v[0], r->v[1], r->v[2]);
        };
        ev.number = [&](const ast::Expr& x) -> std::optional<double> {
            auto r = eval_const(x, "a silhouette's shape coefficient");
            if (!r) return std::nullopt;
            if (r->type == ValueType::Vec3) {
                diags_->error(x.span, "a shape coefficient is a number");
                return std::nullopt;
            }
            return r->v[0];
        };
        ev.error = [&](Span s, std::string m) { diags_->error(s, std::move(m)); };
        d.silhouette = build_silhouette(v, ev);
        if (!d.silhouette) return;
        d.kind = GraphParamKind::Silhouette;
    } else {
        auto value = eval_const(v, "a graph parameter's default");
        if (!value) return;
        if (value->type == ValueType::Vec3) {
            diags_->error(v.span, "a graph parameter is a number, a curve (linear(...), bezier(...)) or a "
                                  "silhouette, not a vec3");
            return;
        }
        d.number = value->v[0];
    }
    P_.graph.params.push_back(std::move(d));
}

// `n.name` (a number parameter) or `n.name(t)` (a curve at t); the node is on the stack.
ValueType Compiler::compile_node_read(Ctx& c, const ast::Expr& e, const ast::Expr* object) {
    const bool call = object != nullptr;
    const int k = P_.graph.find(e.text);
    if (!P_.graph.declared || k < 0) {
        std::vector<std::string> names;
        for (const auto& p : P_.graph.params) names.push_back(p.name);
        const std::string near = nearest_name(e.text, names);
        diags_->error(e.span,
                      !P_.graph.declared
                          ? fmt::format("'.{}' reads a graph parameter, but the grammar declares no "
                                        "graph: add graph {{ {} = ...; }}",
                                        e.text, e.text)
                      : near.empty()
                          ? fmt::format("the graph has no parameter '{}'", e.text)
                          : fmt::format("the graph has no parameter '{}'; did you mean '{}'?", e.text, near));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    const GraphParamDecl& p = P_.graph.params[static_cast<std::size_t>(k)];
    if (p.kind == GraphParamKind::Silhouette) {
        diags_->error(e.span,
                      fmt::format("'{}' is a silhouette: call one of its methods, as in n.{}.level(p) "
                                  "({})",
                                  p.name, p.name, silhouette_method_list()));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    if (p.kind == GraphParamKind::Curve) {
        if (!call || e.args.size() != 2) {
            diags_->error(e.span, fmt::format("'{}' is a curve: read it at a t from 0 to 1, as in n.{}(t)",
                                              p.name, p.name));
            emit_const(c, 0, e.span);
            return ValueType::Number;
        }
        ValueType t = compile_expr(c, *e.args[1]);
        if (!numeric(t)) diags_->error(e.args[1]->span, fmt::format("curve '{}' takes a number", p.name));
        emit(c, Op::GraphRead, k, 2, e.span);
        return ValueType::Number;
    }
    if (call) {
        diags_->error(e.span,
                      fmt::format("'{}' is a number: read it as n.{}, without arguments", p.name, p.name));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    emit(c, Op::GraphRead, k, 1, e.span);
    return ValueType::Number;
}

std::string Compiler::silhouette_method_list() const {
    std::string out;
    for (const auto& m : silhouette_methods()) out += (out.empty() ? "" : ", ") + std::string(m.name);
    return out;
}

// `n.crown.METHOD(args)` on a silhouette parameter; false when obj.text names none.
bool Compiler::compile_silhouette_method(Ctx& c, const ast::Expr& e, ValueType& result) {
    const ast::Expr& obj = *e.args[0];
    const int k = P_.graph.find(obj.text);
    if (obj.kind != ast::ExprKind::Member || k < 0 ||
        P_.graph.params[static_cast<std::size_t>(k)].kind != GraphParamKind::Silhouette)
        return false;
    result = ValueType::Number;
    if (compile_expr(c, *obj.args[0]) != ValueType::Node) {
        diags_->error(obj.args[0]->span, fmt::format("'.{}' reads a graph parameter of a node", obj.text));
        emit_const(c, 0, e.span);
        return true;
    }
    const auto methods = silhouette_methods();
    std::size_t m = 0;
    while (m < methods.size() && e.text != methods[m].name) ++m;
    if (m == methods.size()) {
        std::vector<std::string> names;
        for (const auto& x : methods) names.push_back(x.name);
        const std::string near = nearest_name(e.text, names);
        diags_->error(
            e.span,
            near.empty()
                ? fmt::format("a silhouette has no method '{}' (it has {})", e.text, silhouette_method_list())
                : fmt::format("a silhouette has no method '{}'; did you mean '{}'?", e.text, near));
        emit_const(c, 0, e.span);
        return true;
    }
    const SilhouetteMethodInfo& info = methods[m];
    const std::size_t given = e.args.size() - 1;
    if (given != info.nargs) {
        diags_->error(e.span, fmt::format("'{}.{}' takes {} argument{}, given {}", obj.text, e.text,
                                          info.nargs, info.nargs == 1 ? "" : "s", given));
        emit_const(c, 0, e.span);
        return true;
    }
    int width = 1;
    for (std::size_t i = 0; i < given; ++i) {
        const ValueType t = compile_expr(c, *e.args[i + 1]);
        const bool fits = info.args[i] == ValueType::Vec3 ? t == ValueType::Vec3 : numeric(t);
        if (!fits)
            diags_->error(e.args[i + 1]->span,
                          fmt::format("argument {} of '{}.{}' must be a {}, found a {}", i + 1, obj.text,
                                      e.text, value_type_name(info.args[i]), value_type_name(t)));
        width += value_width(t);
    }
    emit(c, Op::GraphShape, k, width, e.span, env_call_operand(m, value_width(info.result)));
    result = info.result;
    return true;
}

// child(n, position, index, base, dir): the child's silhouettes placed as Fig. 8 says.
ValueType Compiler::compile_child_placed(Ctx& c, const ast::Expr& e) {
    static constexpr ValueType kWant[5] = {ValueType::Node, ValueType::Number, ValueType::Number,
                                           ValueType::Vec3, ValueType::Vec3};
    static constexpr const char* kWhat[5] = {"the parent node", "the position", "the branch index",
                                             "the branching point (a vec3)", "the branch direction (a vec3)"};
    if (!P_.graph.declared)
        diags_->error(e.span,
                      "'child' needs a decomposition graph: declare graph { ... } with its parameters");
    if (c.kind == CtxKind::Global)
        diags_->error(e.span,
                      "'child' depends on the module being rewritten and cannot be used where the value "
                      "must be known before the derivation starts");
    if (c.function >= 0) fn_random_[static_cast<std::size_t>(c.function)] = true;
    bool ok = true;
    for (std::size_t i = 0; i < 5; ++i) {
        const ValueType t = compile_expr(c, *e.args[i]);
        const bool fits = kWant[i] == ValueType::Number ? numeric(t) : t == kWant[i];
        if (!fits) {
            diags_->error(e.args[i]->span,
                          fmt::format("argument {} of child(n, position, index, base, dir) is {}, "
                                      "found a {}",
                                      i + 1, kWhat[i], value_type_name(t)));
            ok = false;
        }
    }
    if (ok) {
        emit(c, Op::GraphPlace, 0, 9, e.span);
    } else {
        emit_const(c, 0, e.span);
    }
    return ValueType::Node;
}

// root(), child(...), depth(n), position(n), index(n): arguments are on the stack.
ValueType Compiler::compile_graph_call(Ctx& c, const ast::Expr& e, const BuiltinInfo& b, int width) {
    if (!P_.graph.declared)
        diags_->error(e.span, fmt::format("'{}' needs a decomposition graph: declare graph {{ ... }} with "
                                          "its parameters",
                                          b.name));
    emit(c, Op::GraphCall, static_cast<std::int32_t>(b.id), width, e.span,
         static_cast<std::uint16_t>(value_width(b.result)));
    return b.result;
}

} // namespace plant
