// Decomposition graphs in the compiler (docs/language.md, decomposition graphs): the `graph { }`
// block's parameters with their root defaults, the `edits "file";` default, the graph built-ins
// (root, child, depth, position, index) and parameter reads through a node (`n.length`,
// `n.bend(t)`), compiled to Op::GraphCall and Op::GraphRead.
#include "compiler_internal.hpp"
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
        diags_->error(v.span, fmt::format("silhouette parameters are not supported yet: declare '{}' as a "
                                          "number or a curve (linear(...), bezier(...))",
                                          p.name));
        return;
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
