// The REPL's decomposition-graph commands (docs/language.md, decomposition graphs): :graph and
// :node print the graph, :edit :inherit :private :public and :share add a line to the session's
// edits and derive again (:back undoes it), :save writes the edits file, :edits lists them. The
// edits are kept as the lines of an edits file, so :save writes exactly what is applied.
#include "commands.hpp"
#include "repl.hpp"
#include "repl_text.hpp"

#include "plant/export.hpp"
#include "plant/graph.hpp"
#include "plant/source.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace plant::cli {

const DecompositionGraph* Session::graph() {
    if (!need_derivation()) return nullptr;
    const DecompositionGraph* g = current().run_state().graph();
    if (!g) error() << "the grammar declares no decomposition graph (graph { ... })\n";
    return g;
}

// :graph [PATH] (the tree from PATH down) and :node PATH (one node)
void Session::graph_command(const std::string& rest, bool one_node) {
    const DecompositionGraph* g = graph();
    if (!g) return;
    const std::string path = rest.empty() ? "/" : rest;
    if (one_node && rest.empty()) {
        error() << "':node' expects a node path, as in :node /0.25\n";
        return;
    }
    const int node = graph_node_at(*g, path);
    if (node < 0) {
        error() << fmt::format("no node {} in the graph at step {} (:graph lists them)\n",
                               escape_controls(path), current().steps_done());
        return;
    }
    out_ << graph_tree(*g, node, !one_node);
}

bool Session::parse_graph_lines(const Program& program, SourceManager& sources) {
    graph_edits_ = nullptr;
    if (graph_lines_.empty()) return true;
    std::string text;
    for (const auto& l : graph_lines_) text += l + "\n";
    Diagnostics diags;
    // (named as what :save writes: the grammar's edits file, then the lines typed in the session)
    graph_edits_ = parse_edits(program, sources, sources.add("<edits>", std::move(text)), diags);
    err_ << render_all(diags, sources, color_);
    if (graph_edits_) return true;
    failed_ = true;
    last_error_runtime_ = false;
    return false;
}

bool Session::read_default_edits() {
    if (!program_ || program_->graph.edits_path.empty()) return false;
    std::string text;
    const ReadFailure f = read_input_file(program_->graph.edits_path, text);
    if (f == ReadFailure::Missing) return false; // a default not written yet: no edits
    if (f != ReadFailure::None) {
        // as plant run refuses it; :save will not overwrite a file the session could not read
        error() << fmt::format("plant: cannot read the edits file '{}': {}; the session has none of "
                               "its edits, and :save needs a file name\n",
                               escape_controls(program_->graph.edits_path), describe(f));
        default_edits_unreadable_ = true;
        return false;
    }
    // the lines as the edits' parser numbers them (SourceFile: '\n', "\r\n" or a lone '\r' ends one),
    // which drop_orphaned_edits matches the edits' spans against
    const SourceFile lines(program_->graph.edits_path, std::move(text));
    const auto size = static_cast<std::uint32_t>(lines.text().size());
    std::uint32_t last = size == 0 ? 0 : lines.line_col(size).line;
    if (size > 0 && lines.text().back() == '\n') --last; // nothing after the final line end
    for (std::uint32_t line = 1; line <= last; ++line) graph_lines_.emplace_back(lines.line_text(line));
    return !graph_lines_.empty();
}

// Single-position matching (the paper's Fig. 10 c): an edit whose node the last derivation
// removed is dropped, with a message, and the steps derived again without it.
bool Session::drop_orphaned_edits(int steps) {
    const DecompositionGraph* g = history_.empty() ? nullptr : current().run_state().graph();
    if (!g || !g->edits() || g->decl().match != GraphMatch::Single) return true;
    std::vector<std::string> kept;
    std::size_t line = 0, dropped = 0, edit = 0;
    for (const auto& l : graph_lines_) {
        ++line;
        // the edits are the non-blank lines (comments aside) in order: find this line's edit
        const auto& edits = g->edits()->edits;
        const bool is_edit =
            edit < edits.size() &&
            sources_->file(edits[edit].span.file).line_col(edits[edit].span.begin).line == line;
        if (is_edit && g->orphaned(edit)) {
            out_ << fmt::format("dropped the edit '{}': its branch is gone (match single)\n",
                                escape_controls(l));
            ++dropped;
        } else {
            kept.push_back(l);
        }
        if (is_edit) ++edit;
    }
    if (dropped == 0) return true;
    // lost for good, as in the paper: :back cannot bring a dropped edit back either
    for (auto& [size, lines] : graph_undo_)
        std::erase_if(lines, [&](const std::string& l) {
            return std::find(kept.begin(), kept.end(), l) == kept.end() &&
                   std::find(graph_lines_.begin(), graph_lines_.end(), l) != graph_lines_.end();
        });
    graph_lines_ = std::move(kept);
    return rebuild(steps);
}

// :edit PATH NAME = EXPR (or += *=), :inherit PATH NAME, :private PATH NAME, :public PATH NAME,
// :share LEVEL NAME = EXPR: one line of an edits file, the path with the node's range
void Session::graph_edit(const std::string& command, const std::string& rest) {
    const DecompositionGraph* g = graph();
    if (!g) return;
    const std::size_t sp = rest.find_first_of(" \t");
    const std::string first = rest.substr(0, sp);
    const std::string tail = sp == std::string::npos ? "" : trim(rest.substr(sp));
    if (first.empty() || tail.empty()) {
        error() << fmt::format("':{}' expects {}\n", command,
                               command == "share" ? "a level and NAME = VALUE, as in :share 1 length = 7"
                               : command == "edit"
                                   ? "a node path and NAME = VALUE, as in :edit /0.25 length = 3"
                                   : "a node path and a parameter, as in :" + command + " /0.25 length");
        return;
    }
    std::string line;
    if (command == "share") {
        line = "share " + first + " " + tail;
    } else {
        const int node = graph_node_at(*g, first);
        if (node < 0) {
            error() << fmt::format("no node {} in the graph at step {} (:graph lists them)\n",
                                   escape_controls(first), current().steps_done());
            return;
        }
        line = g->path(node, true) + " " + tail + (command == "edit" ? "" : " " + command);
    }
    const int steps = current().steps_done();
    graph_undo_.emplace_back(history_.size(), graph_lines_);
    graph_lines_.push_back(line);
    if (!rebuild(steps)) {
        graph_lines_ = graph_undo_.back().second;
        graph_undo_.pop_back();
        return;
    }
    out_ << "edit: " << escape_controls(line) << "\n";
}

bool Session::undo_graph_edit() {
    // an edit that single matching has dropped since leaves nothing to undo: :back undoes a step
    while (!graph_undo_.empty() && graph_undo_.back().first == history_.size() &&
           graph_undo_.back().second == graph_lines_)
        graph_undo_.pop_back();
    if (graph_undo_.empty() || graph_undo_.back().first != history_.size()) return false;
    const std::vector<std::string> before = graph_lines_;
    graph_lines_ = graph_undo_.back().second;
    graph_undo_.pop_back();
    // the line undone: the last one the session has now and did not have then
    std::string undone;
    for (auto it = before.rbegin(); it != before.rend() && undone.empty(); ++it)
        if (std::find(graph_lines_.begin(), graph_lines_.end(), *it) == graph_lines_.end()) undone = *it;
    if (!rebuild(current().steps_done())) {
        graph_lines_ = before;
        return true;
    }
    out_ << fmt::format("undid the edit '{}'\n", escape_controls(undone));
    return true;
}

void Session::list_graph_edits() {
    const DecompositionGraph* g = history_.empty() ? nullptr : current().run_state().graph();
    if (!g || !g->edits()) return;
    for (std::size_t k = 0; k < g->edits()->edits.size(); ++k) {
        const GraphEdit& e = g->edits()->edits[k];
        const int m = g->matches()[k];
        const std::string line(
            sources_->file(e.span.file).text().substr(e.span.begin, e.span.end - e.span.begin));
        out_ << fmt::format("  {}    # {}\n", escape_controls(line),
                            m < 0     ? "dormant"
                            : e.share ? fmt::format("level {}", e.level)
                                      : g->path(m));
    }
}

// :save [FILE]: the edits as an edits file (default: the grammar's `edits "file";`)
void Session::save_edits(const std::string& rest) {
    if (!need_derivation()) return;
    const std::string path = rest.empty() && program_ ? program_->graph.edits_path : rest;
    if (rest.empty() && default_edits_unreadable_) {
        error() << fmt::format("':save' will not overwrite '{}', which the session could not read: "
                               "give a file name, as in :save new.edits\n",
                               escape_controls(path));
        return;
    }
    if (path.empty()) {
        error() << "':save' expects a file name (the grammar names no edits file)\n";
        return;
    }
    std::string text;
    for (const auto& l : graph_lines_) text += l + "\n";
    try {
        write_file_atomically(path, text);
    } catch (const ExportError& e) {
        error() << "plant: " << escape_controls(e.what(), true) << "\n";
        return;
    }
    out_ << fmt::format("wrote {} ({} line{})\n", escape_controls(path), graph_lines_.size(),
                        graph_lines_.size() == 1 ? "" : "s");
}

} // namespace plant::cli
