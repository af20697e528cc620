// Diagnostics as data: collected during parsing, checking and running, rendered separately
// by the front end. A second diagnostic at the same place with the same message is dropped and
// the number kept is capped, so one mistake never floods the terminal.
#pragma once

#include "plant/source.hpp"

#include <exception>
#include <string>
#include <string_view>
#include <vector>

namespace plant {

enum class Severity { Note, Warning, Error };

// "note", "warning" or "error", as diagnostics are printed.
const char* severity_name(Severity s);

// The length of the UTF-8 sequence at s[i], or 0 when it is not one (RFC 3629: no overlong
// forms, no surrogates, nothing past U+10FFFF).
// The candidate nearest to `name` by edit distance (a swap of two letters counts one), when it is
// near enough for a "did you mean" (short names only get close ones); "" otherwise.
std::string nearest_name(std::string_view name, const std::vector<std::string>& candidates);
std::size_t utf8_length(std::string_view s, std::size_t i);

struct Diagnostic {
    Severity severity = Severity::Error;
    Span span;
    std::string message;
    std::vector<std::pair<Span, std::string>> notes; // secondary places ("first defined here")
};

class Diagnostics {
  public:
    explicit Diagnostics(std::size_t cap = 50) : cap_(cap) {}
    void error(Span span, std::string message) { add({Severity::Error, span, std::move(message), {}}); }
    void warning(Span span, std::string message) { add({Severity::Warning, span, std::move(message), {}}); }
    // An error about a file the program names that cannot or may not be read (an import, a
    // mesh): the command line exits 66 (unreadable input) rather than 65.
    void input_error(Span span, std::string message) {
        ++input_errors_;
        error(span, std::move(message));
    }
    bool has_input_errors() const { return input_errors_ > 0; }
    void add(Diagnostic d);
    bool has_errors() const { return errors_ > 0; }
    std::size_t error_count() const { return errors_; }
    const std::vector<Diagnostic>& all() const { return items_; }
    void clear() {
        items_.clear();
        errors_ = 0;
        input_errors_ = 0;
    }

  private:
    std::size_t cap_;
    std::size_t errors_ = 0;
    std::size_t input_errors_ = 0;
    std::vector<Diagnostic> items_;
};

// Source text quoted in a message: at most `max` characters, then "..." (a megabyte-long number
// is named by its start).
inline std::string excerpt(std::string_view text, std::size_t max = 40) {
    return text.size() <= max ? std::string(text) : std::string(text.substr(0, max)) + "...";
}

// `file:line:col: error: message`, the source line, and a caret under the span.
// Text from a grammar, a file or a file name made safe to print to a terminal: the C0 control
// characters (but newline and tab when `keep_lines`), DEL, the C1 controls (U+0080 to U+009F),
// the invisible format characters that reorder or hide text (U+200B to U+200F, U+202A to U+202E,
// U+2060 to U+2064, U+2066 to U+2069, U+FEFF) and bytes that are not UTF-8 become visible
// escapes (`\x1b`, `\u009b`, `\u202e`, `\xff`), so no escape sequence reaches the terminal and
// no text is shown reordered; all other text is kept as it is.
std::string escape_controls(std::string_view text, bool keep_lines = false);

std::string render(const Diagnostic& d, const SourceManager& sources, bool color = false);
std::string render_all(const Diagnostics& ds, const SourceManager& sources, bool color = false);

// What kind of runtime error it is: callers decide by the kind, never by the message's text.
enum class RuntimeErrorKind {
    General,     // a mistake the program makes at run time (deep recursion, a long loop, a bad weight)
    Arithmetic,  // division by zero, or NaN or infinity reaching a module parameter
    ModuleLimit, // the string outgrew --max-modules or --max-bytes
    Interrupted, // the derivation was asked to stop (Ctrl-C in the REPL)
    StepLimit,   // one evaluation ran more instructions than --max-steps allows
    WorkLimit,   // the whole run did more work than --max-work allows
    Setting,     // a setting (derive, seed) out of its range
    Turtle,      // the turtle cannot interpret the string (unbalanced ']', leaving finite space)
    Geometry,    // the plant cannot be meshed (a surface that cannot be loaded, out-of-range points)
    Input,       // a file the program names cannot be read (a surface's mesh file): exit 66
    Physics,     // an environment's simulation broke down (a particle's position is no longer finite)
    Memory,      // a stage would need more memory than --max-memory allows
};

// Thrown by the runtime for errors that end a derivation (runtime errors exit 70).
struct RuntimeError : std::exception {
    RuntimeError(Span s, std::string m) : span(s), message(std::move(m)) {}
    RuntimeError(RuntimeErrorKind k, Span s, std::string m) : kind(k), span(s), message(std::move(m)) {}
    const char* what() const noexcept override { return message.c_str(); }

    // Names the step the error happened in, unless one is named already: sets `step` and puts
    // "step N: " before the message.
    void at_step(int n) {
        if (step >= 0) return;
        step = n;
        message = "step " + std::to_string(n) + ": " + message;
    }

    RuntimeErrorKind kind = RuntimeErrorKind::General;
    Span span;
    std::string message; // as shown to the user, with the step's prefix once `step` is set
    int step = -1;       // the derivation step it happened in; -1: none named
};

// Thrown while making an environment when a file it reads (a mesh) cannot be read or is
// malformed; the compiler reports it as an input error (exit 66).
struct InputError : std::exception {
    explicit InputError(std::string m) : message(std::move(m)) {}
    const char* what() const noexcept override { return message.c_str(); }
    std::string message;
};

} // namespace plant
