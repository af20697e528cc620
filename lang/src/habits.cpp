// Habits from ABOP, cpfg and L-Py: hints appended to parse errors, and cpfg's preprocessor lines
// reported instead of read as comments. Each decision is recorded in docs/language.md (coming
// from ABOP, cpfg or L-Py).
#include "habits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <utility>
#include <vector>

namespace plant::habits {

bool looks_like_a_name(std::string_view run) {
    if (run.size() < 3) return false;
    // a capital may begin a name (L-Py's Leaf, Apex) when three or more small letters follow
    const std::size_t first = std::isupper(static_cast<unsigned char>(run[0])) && run.size() >= 4 ? 1 : 0;
    bool vowel = false, consonant = false;
    for (std::size_t i = first; i < run.size(); ++i) {
        const auto c = static_cast<unsigned char>(run[i]);
        if (!std::islower(c)) return false; // Xab, FbFb: capitals are modules of their own
        (std::string_view("aeiouy").find(static_cast<char>(std::tolower(c))) != std::string_view::npos
             ? vowel
             : consonant) = true;
    }
    return vowel && consonant;
}

namespace {

// Words that open a section in cpfg's or L-Py's files, and what plant writes instead.
constexpr std::array<std::pair<std::string_view, std::string_view>, 14> kSectionWords{{
    {"production", "productions go in a block: rules { A -> F A; }"},
    {"productions", "productions go in a block: rules { A -> F A; }"},
    {"Production", "productions go in a block: rules { A -> F A; }"},
    {"Productions", "productions go in a block: rules { A -> F A; }"},
    {"Axiom", "the axiom is written axiom: F A; (lower case, ':' and ';')"},
    {"AXIOM", "the axiom is written axiom: F A; (lower case, ':' and ';')"},
    {"decomposition", "decomposition rules go in a block: decompose { A -> B C; }"},
    {"Decomposition", "decomposition rules go in a block: decompose { A -> B C; }"},
    {"homomorphism", "interpretation rules go in a block: interpret { A -> F; }"},
    {"interpretation", "interpretation rules go in a block: interpret { A -> F; }"},
    {"derivation", "the number of steps is written derive 5;"},
    {"Lsystem", "a plant file has no L-system header: write axiom:, rules { } and derive N; directly"},
    {"lsystem", "a plant file has no L-system header: write axiom:, rules { } and derive N; directly"},
    {"endlsystem", "a plant file has no L-system footer: leave it out"},
}};

std::string_view word_at(const std::string& text, std::size_t byte) {
    std::size_t e = byte;
    while (e < text.size() && (std::isalnum(static_cast<unsigned char>(text[e])) || text[e] == '_')) ++e;
    return std::string_view(text).substr(byte, e - byte);
}

} // namespace

std::string hint(const std::string& text, std::size_t byte, const std::string& message) {
    if (byte >= text.size()) return {};
    const char c = text[byte];
    const std::string_view word = word_at(text, byte);
    for (const auto& [w, fix] : kSectionWords)
        if (word == w) return fmt::format("; {}", fix);
    if (word == "maximum") return "; the depth bound is written decompose max_depth 8 { ... }";
    if (!word.empty() && message.rfind("expected a top-level item", 0) == 0) {
        static const std::vector<std::string> kItems = {
            "param",       "const", "var",      "module", "fn",       "curve", "surface",
            "texture",     "env",   "instance", "derive", "angle",    "step",  "width",
            "width_scale", "seed",  "axiom",    "ignore", "consider", "rules", "decompose",
            "interpret",   "on",    "import",   "graph",  "edits"};
        std::string lower(word);
        for (char& ch : lower) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
        if (lower != word && std::find(kItems.begin(), kItems.end(), lower) != kItems.end())
            return fmt::format("; keywords are lower case: write {}", lower);
        if (const std::string near = nearest_name(word, kItems); !near.empty())
            return fmt::format("; did you mean '{}'?", near);
    }
    if (c == '^' || (c == '*' && byte > 0 && text[byte - 1] == '*')) {
        // the operands as written, when they are a name or a number: x^2 is pow(x, 2)
        auto is_word = [](char ch) {
            return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '.';
        };
        std::size_t b = c == '^' ? byte : byte - 1;
        while (b > 0 && text[b - 1] == ' ') --b;
        std::size_t a = b;
        while (a > 0 && is_word(text[a - 1])) --a;
        std::size_t e = byte + 1;
        while (e < text.size() && text[e] == ' ') ++e;
        std::size_t f = e;
        while (f < text.size() && is_word(text[f])) ++f;
        if (a < b && e < f)
            return fmt::format("; there is no power operator: write pow({}, {})", text.substr(a, b - a),
                               text.substr(e, f - e));
        return "; there is no power operator: write pow(x, 0.5)";
    }
    if (c == '=' && ((byte + 1 < text.size() && text[byte + 1] == '>' &&
                      message.find("production") != std::string::npos) ||
                     message.find("after the predecessor") != std::string::npos))
        return "; a production's arrow is written ->";
    if (c == '+' && byte > 0 && text[byte - 1] == '+') return "; there is no ++: write n += 1";
    if (c == '-' && byte > 0 && text[byte - 1] == '-' &&
        message.find("after the operator") != std::string::npos)
        return "; there is no --: write n -= 1";
    if (c == '{') { // `elif (...) {`, read as a call of elif
        std::size_t line = text.rfind('\n', byte);
        line = line == std::string::npos ? 0 : line + 1;
        for (std::size_t at = text.find("elif", line); at != std::string::npos && at < byte;
             at = text.find("elif", at + 4))
            if ((at == 0 || !std::isalnum(static_cast<unsigned char>(text[at - 1]))) &&
                at + 4 < text.size() && !std::isalnum(static_cast<unsigned char>(text[at + 4])))
                return "; there is no elif: write else if (...) { ... }";
    }
    if (c == '\'') return "; cpfg's ' (next colour) is written ;(c) here, with the colour index, as in ;(2)";
    if ((c == '{' || c == '.') && message.find("after production") != std::string::npos)
        return "; cpfg's { . } polygons are written surface leaf = polygon(...); and drawn with ~leaf (a "
               "production has either '-> successor;' or a '{ }' body, not both)";
    if (c == '.' && message.find("range's end after '..'") != std::string::npos)
        return "; `0...2` would read as `0 .. .2`: write `0 .. 2` or `0 .. .2`";
    if (c == ',' && message.find("after production") != std::string::npos)
        return "; L-Py's ',' (previous colour) is written ;(c) here, with the colour index";
    return {};
}

void check_cpfg_lines(const SourceFile& src, std::uint32_t file_id, Diagnostics& diags) {
    const std::string& text = src.text();
    std::size_t b = 0;
    while (b < text.size()) {
        std::size_t nl = text.find('\n', b);
        std::size_t e = nl == std::string::npos ? text.size() : nl;
        std::string_view line = std::string_view(text).substr(b, e - b);
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
        auto after = [&](std::string_view directive) {
            std::string_view rest = line.substr(directive.size());
            while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
            return std::string(rest.substr(0, 80));
        };
        auto at = [&](std::size_t len) {
            return Span{file_id, static_cast<std::uint32_t>(b), static_cast<std::uint32_t>(b + len)};
        };
        if (line.rfind("#define ", 0) == 0) {
            std::string rest = after("#define");
            std::size_t sp = rest.find_first_of(" \t");
            std::string fix = sp == std::string::npos
                                  ? fmt::format("const {} = 1;", rest)
                                  : fmt::format("const {} = {};", rest.substr(0, sp),
                                                rest.substr(rest.find_first_not_of(" \t", sp)));
            diags.error(at(7), fmt::format("cpfg's #define is a comment in plant ('#' starts a comment); "
                                           "write {}",
                                           fix));
        } else if (line.rfind("#ignore:", 0) == 0 || line.rfind("#consider:", 0) == 0) {
            const bool ignore = line[1] == 'i';
            const std::string_view kw = ignore ? "ignore:" : "consider:";
            diags.error(at(kw.size() + 1),
                        fmt::format("cpfg's #{} is a comment in plant ('#' starts a comment); write {} {};",
                                    kw, kw, after(line.substr(0, kw.size() + 1))));
        } else if (line.rfind("#include ", 0) == 0) {
            diags.error(at(8), fmt::format("cpfg's #include is a comment in plant; write import \"{}\";",
                                           after("#include")));
        }
        // `// text` where a statement may begin (a line's start, after a ';', '{' or '}'): a C or
        // L-Py comment, which plant would read as two roll modules and the text as modules
        bool quoted = false;
        for (std::size_t i = 0; i + 2 < line.size() && line[i] != '#'; ++i) {
            if (line[i] == '"') quoted = !quoted;
            if (quoted || line.compare(i, 3, "// ") != 0) continue;
            std::size_t before = i;
            while (before > 0 && (line[before - 1] == ' ' || line[before - 1] == '\t')) --before;
            if (before == 0 || line[before - 1] == ';' || line[before - 1] == '{' ||
                line[before - 1] == '}') {
                diags.error(
                    {file_id, static_cast<std::uint32_t>(b + i), static_cast<std::uint32_t>(b + i + 2)},
                    "'//' is not a comment in plant: it is two '/' (roll) modules, and what follows "
                    "is read as more of the grammar; write # for a comment");
                break;
            }
        }
        if (nl == std::string::npos) break;
        b = nl + 1;
    }
}

} // namespace plant::habits
