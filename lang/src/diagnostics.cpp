#include "plant/diagnostics.hpp"

#include <fmt/format.h>

namespace plant {

void Diagnostics::add(Diagnostic d) {
    for (const auto& o : items_)
        if (o.span.file == d.span.file && o.span.begin == d.span.begin && o.message == d.message) return;
    if (d.severity == Severity::Error) ++errors_;
    if (items_.size() >= cap_) return;
    items_.push_back(std::move(d));
}

namespace {

const char* severity_name(Severity s) {
    switch (s) {
    case Severity::Note:
        return "note";
    case Severity::Warning:
        return "warning";
    case Severity::Error:
        return "error";
    }
    return "error";
}

// Replaces control and non-ASCII bytes so that binary garbage in a source line cannot mangle
// the terminal; tabs become a space so the caret lines up.
std::string printable(std::string_view s) {
    std::string out;
    out.reserve(s.size());
    for (unsigned char c : s) out += (c == '\t') ? ' ' : (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
    return out;
}

void render_one(std::string& out, Severity sev, Span span, const std::string& message,
                const SourceManager& sources, bool color) {
    const char* on = "";
    const char* off = color ? "\x1b[0m" : "";
    if (color)
        on = sev == Severity::Error ? "\x1b[1;31m" : sev == Severity::Warning ? "\x1b[1;35m" : "\x1b[1;36m";
    if (!span.valid()) {
        out += fmt::format("plant: {}{}:{} {}\n", on, severity_name(sev), off, message);
        return;
    }
    const SourceFile& f = sources.file(span.file);
    LineCol lc = f.line_col(span.begin);
    out += fmt::format("{}:{}:{}: {}{}:{} {}\n", f.name(), lc.line, lc.col, on, severity_name(sev), off,
                       message);
    std::string line = printable(f.line_text(lc.line));
    if (line.size() > 200) line = line.substr(0, 200);
    out += fmt::format("{:5} | {}\n", lc.line, line);
    std::size_t col = lc.col - 1;
    std::size_t len = 1;
    LineCol ec = f.line_col(span.end > span.begin ? span.end - 1 : span.begin);
    if (ec.line == lc.line && span.end > span.begin) len = ec.col - lc.col + 1;
    if (col > line.size()) col = line.size();
    if (col + len > line.size() + 1) len = line.size() + 1 - col;
    if (len == 0) len = 1;
    out += fmt::format("      | {}{}^{}{}\n", std::string(col, ' '), on, std::string(len - 1, '~'), off);
}

} // namespace

std::string render(const Diagnostic& d, const SourceManager& sources, bool color) {
    std::string out;
    render_one(out, d.severity, d.span, d.message, sources, color);
    for (const auto& [span, msg] : d.notes) render_one(out, Severity::Note, span, msg, sources, color);
    return out;
}

std::string render_all(const Diagnostics& ds, const SourceManager& sources, bool color) {
    std::string out;
    for (const auto& d : ds.all()) out += render(d, sources, color);
    return out;
}

} // namespace plant
