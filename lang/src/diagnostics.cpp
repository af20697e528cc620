#include "plant/diagnostics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <vector>

namespace plant {

void Diagnostics::add(Diagnostic d) {
    for (const auto& o : items_)
        if (o.span.file == d.span.file && o.span.begin == d.span.begin && o.message == d.message) return;
    if (d.severity == Severity::Error) ++errors_;
    if (items_.size() >= cap_) return;
    items_.push_back(std::move(d));
}

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

// The length of the UTF-8 sequence at s[i], or 0 when it is not one (RFC 3629: no overlong
// forms, no surrogates, nothing past U+10FFFF).
std::size_t utf8_length(std::string_view s, std::size_t i) {
    const auto at = [&](std::size_t k) { return static_cast<unsigned char>(s[k]); };
    const unsigned char c = at(i);
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xbf; // the second byte's range
    if (c >= 0xc2 && c <= 0xdf)
        n = 2;
    else if (c >= 0xe0 && c <= 0xef) {
        n = 3;
        if (c == 0xe0) lo = 0xa0;
        if (c == 0xed) hi = 0x9f;
    } else if (c >= 0xf0 && c <= 0xf4) {
        n = 4;
        if (c == 0xf0) lo = 0x90;
        if (c == 0xf4) hi = 0x8f;
    } else
        return 0;
    if (i + n > s.size() || at(i + 1) < lo || at(i + 1) > hi) return 0;
    for (std::size_t k = 2; k < n; ++k)
        if (at(i + k) < 0x80 || at(i + k) > 0xbf) return 0;
    return n;
}

namespace {

// The code point of the well-formed UTF-8 sequence of `n` bytes at s[i].
char32_t code_point(std::string_view s, std::size_t i, std::size_t n) {
    const auto at = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
    char32_t cp = n == 2 ? at(0) & 0x1fu : n == 3 ? at(0) & 0x0fu : at(0) & 0x07u;
    for (std::size_t k = 1; k < n; ++k) cp = (cp << 6) | (at(k) & 0x3fu);
    return cp;
}

// Characters that are not shown but change what is: the C1 controls (U+0080 to U+009F, the
// terminal's 8-bit escapes) and Unicode's format characters that reorder or hide text (zero
// width spaces and joiners, the marks U+200E and U+200F, the bidirectional embeddings,
// overrides and isolates U+202A to U+202E and U+2066 to U+2069, the invisible operators
// U+2060 to U+2064, the byte-order mark U+FEFF): a right-to-left override in a file name
// would make a message read backwards (the "Trojan Source" attack, Boucher and Anderson 2021).
bool hidden_format(char32_t c) {
    return (c >= 0x80 && c <= 0x9f) || (c >= 0x200b && c <= 0x200f) || (c >= 0x202a && c <= 0x202e) ||
           (c >= 0x2060 && c <= 0x2064) || (c >= 0x2066 && c <= 0x2069) || c == 0xfeff;
}

// Replaces control bytes and bytes that are not UTF-8 so that binary garbage in a source line
// cannot mangle the terminal; tabs become a space so the caret lines up. A well-formed UTF-8
// character (a '→' or 'ω' typed from a book) is kept. `cols` receives, for each byte, the
// column it is shown at.
std::string printable(std::string_view s, std::vector<std::size_t>& cols) {
    std::string out;
    out.reserve(s.size());
    cols.clear();
    std::size_t col = 0;
    for (std::size_t i = 0; i < s.size();) {
        const auto c = static_cast<unsigned char>(s[i]);
        std::size_t n = c >= 0x80 ? utf8_length(s, i) : 0;
        if (n > 0 && hidden_format(code_point(s, i, n))) { // shown as one '?'
            out += '?';
            cols.insert(cols.end(), n, col);
            i += n;
        } else if (n > 0) {
            out.append(s.substr(i, n));
            cols.insert(cols.end(), n, col);
            i += n;
        } else {
            out += (c == '\t') ? ' ' : (c < 0x20 || c >= 0x7f) ? '?' : static_cast<char>(c);
            cols.push_back(col);
            ++i;
        }
        ++col;
    }
    cols.push_back(col);
    return out;
}

void render_one(std::string& out, Severity sev, Span span, const std::string& message,
                const SourceManager& sources, bool color) {
    const char* on = "";
    const char* off = color ? "\x1b[0m" : "";
    if (color)
        on = sev == Severity::Error ? "\x1b[1;31m" : sev == Severity::Warning ? "\x1b[1;35m" : "\x1b[1;36m";
    if (!span.valid()) {
        out +=
            fmt::format("plant: {}{}:{} {}\n", on, severity_name(sev), off, escape_controls(message, true));
        return;
    }
    const SourceFile& f = sources.file(span.file);
    LineCol lc = f.line_col(span.begin);
    const std::uint32_t shown_line = f.shown(lc).line;
    out += fmt::format("{}:{}:{}: {}{}:{} {}\n", escape_controls(f.name()), shown_line, lc.col, on,
                       severity_name(sev), off, escape_controls(message, true));
    std::vector<std::size_t> cols;
    std::string_view raw = f.line_text(lc.line);
    if (raw.size() > 200) raw = raw.substr(0, 200);
    const std::string line = printable(raw, cols);
    const std::size_t width = cols.back(); // the line's length in shown columns
    out += fmt::format("{:5} | {}\n", shown_line, line);
    auto shown = [&](std::size_t byte_col) { return cols[std::min(byte_col, cols.size() - 1)]; };
    std::size_t col = shown(lc.col - 1);
    std::size_t len = 1;
    LineCol ec = f.line_col(span.end > span.begin ? span.end - 1 : span.begin);
    if (ec.line == lc.line && span.end > span.begin) len = shown(ec.col - 1) - col + 1;
    if (col > width) col = width;
    if (col + len > width + 1) len = width + 1 - col;
    if (len == 0) len = 1;
    out += fmt::format("      | {}{}^{}{}\n", std::string(col, ' '), on, std::string(len - 1, '~'), off);
}

} // namespace

std::string escape_controls(std::string_view text, bool keep_lines) {
    bool plain = true;
    for (unsigned char c : text)
        if ((c < 0x20 && !(keep_lines && (c == '\n' || c == '\t'))) || c >= 0x7f) {
            plain = false;
            break;
        }
    if (plain) return std::string(text);
    std::string out;
    out.reserve(text.size() + 16);
    for (std::size_t i = 0; i < text.size();) {
        const auto c = static_cast<unsigned char>(text[i]);
        if (c < 0x80) {
            if ((c < 0x20 && !(keep_lines && (c == '\n' || c == '\t'))) || c == 0x7f)
                out += fmt::format("\\x{:02x}", c);
            else
                out += static_cast<char>(c);
            ++i;
            continue;
        }
        const std::size_t n = utf8_length(text, i);
        if (n == 0) {
            out += fmt::format("\\x{:02x}", c);
            ++i;
        } else if (const char32_t cp = code_point(text, i, n); hidden_format(cp)) {
            out += fmt::format("\\u{:04x}", static_cast<std::uint32_t>(cp)); // a C1 control, a bidi override
            i += n;
        } else {
            out.append(text.substr(i, n));
            i += n;
        }
    }
    return out;
}

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
