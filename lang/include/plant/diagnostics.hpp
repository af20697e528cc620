// Diagnostics as data: collected during parsing, checking and running, rendered separately
// by the front end. A second diagnostic at the same place with the same message is dropped and
// the number kept is capped, so one mistake never floods the terminal.
#pragma once

#include "plant/source.hpp"

#include <exception>
#include <string>
#include <vector>

namespace plant {

enum class Severity { Note, Warning, Error };

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
    void add(Diagnostic d);
    bool has_errors() const { return errors_ > 0; }
    std::size_t error_count() const { return errors_; }
    const std::vector<Diagnostic>& all() const { return items_; }
    void clear() {
        items_.clear();
        errors_ = 0;
    }

  private:
    std::size_t cap_;
    std::size_t errors_ = 0;
    std::vector<Diagnostic> items_;
};

// `file:line:col: error: message`, the source line, and a caret under the span.
std::string render(const Diagnostic& d, const SourceManager& sources, bool color = false);
std::string render_all(const Diagnostics& ds, const SourceManager& sources, bool color = false);

// Thrown by the runtime for errors that end a derivation (runtime errors exit 70).
struct RuntimeError : std::exception {
    RuntimeError(Span s, std::string m) : span(s), message(std::move(m)) {}
    const char* what() const noexcept override { return message.c_str(); }
    Span span;
    std::string message;
};

} // namespace plant
