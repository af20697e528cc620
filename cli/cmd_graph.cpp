// plant graph: the decomposition graph a grammar derives (docs/language.md, decomposition graphs),
// as an indented tree or JSON; and the dormant edits `plant check` reports.
#include "commands.hpp"

#include "plant/environment_phase.hpp"
#include "plant/graph.hpp"

#include <fmt/format.h>

#include <cmath>

#include <iostream>

namespace plant::cli {

namespace {

struct GraphCmd {
    GrammarOptions g;
    bool json = false;
};

// Curves are shown by their values at these t.
constexpr double kSamples[] = {0, 0.25, 0.5, 0.75, 1};

std::string json_string(const std::string& s) {
    std::string out = "\"";
    for (char ch : s) {
        const auto c = static_cast<unsigned char>(ch);
        if (ch == '"' || ch == '\\')
            out += std::string("\\") + ch;
        else if (c < 0x20)
            out += fmt::format("\\u{:04x}", c);
        else
            out += ch;
    }
    return out + "\"";
}

std::string where(const SourceManager& sources, Span s) {
    if (!s.valid()) return "";
    const SourceFile& f = sources.file(s.file);
    const LineCol lc = f.line_col(s.begin);
    return fmt::format("{}:{}:{}", f.name(), lc.line, lc.col);
}

std::string value_text(const DecompositionGraph& g, int node, int param, bool json) {
    const NodeValue& v = g.value(node, param);
    if (g.decl().params[static_cast<std::size_t>(param)].kind == GraphParamKind::Silhouette) {
        // the placed silhouette (Fig. 8): where its base and T are, and its scale
        const PlacedSilhouette s = v.placed();
        auto vec = [&](const glm::dvec3& p) {
            const std::string xyz =
                format_double(p.x) + ", " + format_double(p.y) + ", " + format_double(p.z);
            return json ? "[" + xyz + "]" : "(" + xyz + ")";
        };
        const std::string scale = format_double(s.placement.scale);
        if (json)
            return "{\"base\": " + vec(s.base()) + ", \"tip\": " + vec(s.tip()) + ", \"scale\": " + scale +
                   "}";
        return "silhouette base " + vec(s.base()) + " tip " + vec(s.tip()) + " scale " + scale;
    }
    if (g.decl().params[static_cast<std::size_t>(param)].kind != GraphParamKind::Curve)
        return format_double(v.number);
    std::string out;
    for (double t : kSamples) out += (out.empty() ? "" : json ? ", " : " ") + format_double(v.at(t));
    return json ? "[" + out + "]" : out;
}

// Calls visit(node) for node and, with children, every node below it in tree order: an explicit
// stack, so a graph as deep as the node limit allows cannot overflow the call stack.
template <typename Visit> void preorder(const DecompositionGraph& g, int node, bool children, Visit visit) {
    std::vector<int> stack{node};
    while (!stack.empty()) {
        const int k = stack.back();
        stack.pop_back();
        visit(k);
        if (!children) continue;
        const auto& below = g.node(k).children;
        stack.insert(stack.end(), below.rbegin(), below.rend());
    }
}

// With `sink`, what is written goes out whenever it passes 64 KB, so a large graph is not held
// whole in memory.
void tree(const DecompositionGraph& g, int root, std::string& out, bool children = true,
          std::ostream* sink = nullptr) {
    preorder(g, root, children, [&](int node) {
        if (sink && out.size() > (64 << 10)) {
            *sink << out;
            out.clear();
        }
        const GraphNode& n = g.node(node);
        const std::string pad(static_cast<std::size_t>(2 * n.depth), ' ');
        out += pad + g.path(node) + "\n";
        for (std::size_t p = 0; p < g.decl().params.size(); ++p) {
            const GraphParamDecl& decl = g.decl().params[p];
            const NodeValue& v = g.value(node, static_cast<int>(p));
            out += fmt::format("{}  {}{} = {}  ({}, {}, from {})\n", pad, decl.name,
                               decl.kind == GraphParamKind::Curve ? "(0..1)" : "",
                               value_text(g, node, static_cast<int>(p), false), value_status_name(v.status),
                               v.is_private ? "private" : "public", g.path(v.from));
        }
    });
}

void json_nodes(const DecompositionGraph& g, int root, std::string& out, std::ostream* sink = nullptr) {
    preorder(g, root, true, [&](int node) {
        if (sink && out.size() > (64 << 10) && out.back() == '}') {
            // all but the last '}', which the next node's separator looks at
            *sink << std::string_view(out).substr(0, out.size() - 1);
            out.erase(0, out.size() - 1);
        }
        const GraphNode& n = g.node(node);
        if (out.back() == '}') out += ",\n";
        out +=
            fmt::format("    {{\"path\": {}, \"depth\": {}, \"position\": {}, \"index\": {}, \"params\": {{",
                        json_string(g.path(node)), n.depth, format_double(n.position), n.index);
        for (std::size_t p = 0; p < g.decl().params.size(); ++p) {
            const NodeValue& v = g.value(node, static_cast<int>(p));
            out += fmt::format("{}{}: {{\"value\": {}, \"status\": \"{}\", \"private\": {}, \"from\": {}}}",
                               p ? ", " : "", json_string(g.decl().params[p].name),
                               value_text(g, node, static_cast<int>(p), true), value_status_name(v.status),
                               v.is_private ? "true" : "false", json_string(g.path(v.from)));
        }
        out += "}}";
    });
}

std::string edits_text(const DecompositionGraph& g, const SourceManager& sources, bool json) {
    std::string out;
    if (!g.edits()) return json ? "  \"edits\": []\n" : "";
    const auto& edits = g.edits()->edits;
    for (std::size_t k = 0; k < edits.size(); ++k) {
        const GraphEdit& e = edits[k];
        const int m = g.matches()[k];
        const std::string target = e.share ? fmt::format("level {}", e.level) : (m >= 0 ? g.path(m) : "");
        if (json) {
            out +=
                fmt::format("{}    {{\"at\": {}, \"path\": {}, \"param\": {}, \"node\": {}}}", k ? ",\n" : "",
                            json_string(where(sources, e.span)), json_string(edit_path_text(e)),
                            json_string(g.decl().params[static_cast<std::size_t>(e.param)].name),
                            m >= 0 ? json_string(target) : "null");
        } else {
            out += fmt::format("  {}: {} {}: {}\n", where(sources, e.span), edit_path_text(e),
                               g.decl().params[static_cast<std::size_t>(e.param)].name,
                               m >= 0 ? "applies to " + target : "dormant");
        }
    }
    if (json) return "  \"edits\": [\n" + out + (edits.empty() ? "" : "\n") + "  ]\n";
    return edits.empty() ? "" : "edits:\n" + out;
}

int graph_main(const GraphCmd& c) {
    int exit_code = kOk;
    SourceManager sources;
    auto program = load_program(c.g, sources, exit_code);
    if (!program) return exit_code;
    if (!program->graph.declared) {
        std::cerr << "plant: the grammar declares no decomposition graph (graph { ... })\n";
        return kUsage;
    }
    DeriveOptions opt = derive_options(c.g);
    TurtleEnvironmentPhase phase;
    opt.environment_phase = &phase;
    opt.on_print = [](const std::string& text) { std::cerr << escape_controls(text, true); };
    Derivation d(*program, opt);
    if (!run_derivation(d, sources, c.g.color)) return kRuntime;
    const DecompositionGraph& g = *d.run_state().graph();
    std::string out;
    if (c.json) {
        out = fmt::format("{{\n  \"match\": \"{}\",\n  \"nodes\": [\n",
                          program->graph.match == GraphMatch::Range ? "range" : "single");
        json_nodes(g, 0, out, &std::cout);
        out += "\n  ],\n" + edits_text(g, sources, true) + "}\n";
    } else {
        tree(g, 0, out, true, &std::cout);
        out += edits_text(g, sources, false);
    }
    std::cout << out << std::flush;
    if (std::cout) return kOk;
    std::cerr << "plant: cannot write the graph to standard output\n";
    return kCantCreate;
}

} // namespace

std::string graph_tree(const DecompositionGraph& g, int node, bool children) {
    std::string out;
    tree(g, node, out, children);
    return out;
}

// Walks down from the root, one component of `path` (read as an edits file reads it) at a time:
// the child at that position (within 1e-9) with that index; a component's range is ignored.
int graph_node_at(const DecompositionGraph& g, const std::string& path) {
    const auto steps = parse_node_path(path);
    if (!steps) return -1;
    int node = 0;
    for (const EditStep& step : *steps) {
        int next = -1;
        for (int c : g.node(node).children) {
            const GraphNode& n = g.node(c);
            if (n.index == step.index && std::fabs(n.position - step.position) <= 1e-9) {
                next = c;
                break;
            }
        }
        if (next < 0) return -1;
        node = next;
    }
    return node;
}

int report_dormant_edits(const GrammarOptions& o, const Program& program, const SourceManager& sources) {
    if (!program.graph.declared || !program.graph.edits || program.graph.edits->edits.empty()) return kOk;
    DeriveOptions opt = derive_options(o);
    TurtleEnvironmentPhase phase;
    opt.environment_phase = &phase;
    opt.on_print = [](const std::string&) {};
    Derivation d(program, opt);
    if (!run_derivation(d, sources, o.color)) return kRuntime;
    const DecompositionGraph& g = *d.run_state().graph();
    for (std::size_t k = 0; k < g.matches().size(); ++k) {
        if (g.matches()[k] >= 0) continue;
        const GraphEdit& e = g.edits()->edits[k];
        Diagnostic diag{
            Severity::Warning,
            e.span,
            e.share ? fmt::format("dormant edit: the derived graph has no node at level {}", e.level)
                    : fmt::format("dormant edit: no branch of the derived graph matches {}; it is kept "
                                  "and applies again when one does",
                                  edit_path_text(e)),
            {}};
        std::cerr << render(diag, sources, o.color);
    }
    return kOk;
}

void setup_graph(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<GraphCmd>();
    CLI::App* cmd = app.add_subcommand(
        "graph", "Derive a grammar and print its decomposition graph: every node's path and parameters");
    add_grammar_options(*cmd, c->g, true);
    cmd->add_flag("--json", c->json, "Print the graph as JSON instead of an indented tree");
    cmd->footer(
        "Each parameter shows its value (a curve by its values at t = 0, 0.25, 0.5, 0.75 and 1), its "
        "status (explicit, inherited, relative-offset, relative-fraction, shared), public or private, "
        "and the node the value comes from; then each edit and the node it applies to, or 'dormant'.");
    cmd->callback([c, &exit_code] {
        set_memory_budget(c->g.max_memory);
        exit_code = graph_main(*c);
    });
}

} // namespace plant::cli
