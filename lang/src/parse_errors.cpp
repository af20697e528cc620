// How a syntax error is told: what was found, where the construct began, where a ';' was left
// off, and where parsing resumes after it.
#include "grammar_errors.hpp"

#include "habits.hpp"
#include "plant/ast.hpp"
#include "plant/diagnostics.hpp"
#include "plant/source.hpp"

#include <fmt/format.h>

#include <cctype>
#include <cstring>
#include <optional>

namespace plant::grammar {

std::string describe_found(const std::string& text, std::size_t byte) {
    if (byte >= text.size()) return "end of file";
    unsigned char c = static_cast<unsigned char>(text[byte]);
    if (std::isalnum(c) || c == '_') {
        std::size_t e = byte;
        while (e < text.size() && e - byte < 30 &&
               (std::isalnum(static_cast<unsigned char>(text[e])) || text[e] == '_' || text[e] == '.'))
            ++e;
        return fmt::format("'{}'", text.substr(byte, e - byte));
    }
    if (c == '\n' || c == '\r') return "end of line";
    if (std::size_t n = utf8_length(text, byte); n > 0) {
        // a character typed from a book, shown as itself with its code point
        std::uint32_t cp = c & (0xff >> (n + 1));
        for (std::size_t k = 1; k < n; ++k)
            cp = (cp << 6) | (static_cast<unsigned char>(text[byte + k]) & 0x3f);
        return fmt::format("'{}' (U+{:04X})", text.substr(byte, n), cp);
    }
    if (c < 0x20 || c >= 0x7f) return fmt::format("byte 0x{:02x}", c);
    return fmt::format("'{}'", static_cast<char>(c));
}

// Where a ';' was left off at the end of a line, for an "expected ';'" error at `byte` in a
// statement begun at `at`: when the error is on a later line than the statement's start and at
// most one word comes before it there (`rules {`: the next item's keyword, read as modules of
// the unfinished statement; `F -> FF;`: a production's predecessor, read as a successor's
// module), the ';' belongs after the last thing on the line before (before its # comment).
// Returns that place and where the next line's first word is.
namespace {

std::optional<std::pair<std::uint32_t, std::size_t>> missing_semicolon_at(const std::string& text,
                                                                          std::size_t at, std::size_t byte) {
    if (at == std::string::npos || byte > text.size()) return std::nullopt;
    std::size_t line = byte;
    while (line > 0 && text[line - 1] != '\n' && text[line - 1] != '\r') --line;
    if (at >= line) return std::nullopt; // the statement began on this line
    std::size_t first = line;
    while (first < byte && (text[first] == ' ' || text[first] == '\t')) ++first;
    std::size_t word = first;
    while (word < byte && (std::isalnum(static_cast<unsigned char>(text[word])) || text[word] == '_')) ++word;
    while (word < byte && (text[word] == ' ' || text[word] == '\t')) ++word;
    // more than one word before the error, unless the error is at the line's '->' (`A(x) : x > 1
    // -> B;`, its predecessor and condition read as more of the production before)
    if (word != byte && text.compare(byte, 2, "->") != 0) return std::nullopt;
    // the last line before this one with something on it other than a comment
    std::size_t end = line;
    while (end > at) {
        std::size_t begin = end - 1; // at the previous line's end of line
        while (begin > 0 && text[begin - 1] != '\n' && text[begin - 1] != '\r') --begin;
        std::size_t stop = begin;
        bool quoted = false;
        for (; stop < end - 1 && !(text[stop] == '#' && !quoted); ++stop)
            if (text[stop] == '"') quoted = !quoted;
        while (stop > begin && std::isspace(static_cast<unsigned char>(text[stop - 1]))) --stop;
        if (stop > begin && stop > at) return std::pair{static_cast<std::uint32_t>(stop), first};
        end = begin;
    }
    return std::nullopt;
}

} // namespace

// A grammar error as a diagnostic: {at} becomes the line:column where the construct began, and
// what was found at the error is named.
void report(const GrammarError& e, const SourceFile& src, std::uint32_t file_id, Diagnostics& diags) {
    std::string msg = e.message;
    if (auto p = msg.find("{hooks}"); p != std::string::npos) msg.replace(p, 7, ast::hook_list("", " or "));
    if (auto p = msg.find("{at}"); p != std::string::npos) {
        std::string at = "?";
        if (e.at != std::string::npos) {
            LineCol a = src.shown_line_col(static_cast<std::uint32_t>(e.at));
            at = fmt::format("{}:{}", a.line, a.col);
        }
        msg.replace(p, 4, at);
    }
    const std::string hint = habits::hint(src.text(), e.byte, msg);
    if (msg.rfind("expected ';'", 0) == 0) {
        if (auto end = missing_semicolon_at(src.text(), e.at, e.byte)) {
            // the ';' left off at the end of a line: shown there, naming what began the next line
            const std::string found = describe_found(src.text(), end->second);
            msg += ", found " + found + (found == "end of file" ? "" : " on the next line") + hint;
            diags.error({file_id, end->first, end->first + 1}, msg);
            return;
        }
    }
    msg += ", found " + describe_found(src.text(), e.byte) + hint;
    auto b = static_cast<std::uint32_t>(e.byte);
    diags.error({file_id, b, b + 1}, msg);
}

// After an error, restart at the first line that starts with a top-level keyword at or after the
// error (the error may be the keyword itself, as when a ';' is missing at the end of the line
// before), but always after `item_start` so that parsing makes progress.
std::size_t resync(const std::string& text, std::size_t from, std::size_t item_start) {
    static const char* keywords[] = {"param ",   "const ",    "var ",      "module ",   "fn ",     "curve ",
                                     "surface ", "texture ",  "env ",      "instance ", "derive ", "angle ",
                                     "step ",    "width ",    "seed ",     "axiom",     "ignore",  "consider",
                                     "rules",    "decompose", "interpret", "on ",       "import ", "graph",
                                     "edits ",   "/*"};
    std::size_t b = from;
    while (b > 0 && text[b - 1] != '\n') --b; // start of the error's line
    while (b < text.size()) {
        std::size_t s = b;
        while (s < text.size() && (text[s] == ' ' || text[s] == '\t')) ++s;
        if (s >= from && b > item_start)
            for (const char* kw : keywords)
                if (text.compare(s, std::strlen(kw), kw) == 0) return b;
        std::size_t nl = text.find('\n', b);
        if (nl == std::string::npos) break;
        b = nl + 1;
    }
    return text.size();
}

} // namespace plant::grammar
