// Compiling and deriving grammars given as strings, for the unit tests.
#pragma once

#include "plant/compiler.hpp"
#include "plant/derive.hpp"

#include <memory>
#include <string>

namespace plant::test {

struct Compiled {
    SourceManager sources;
    Diagnostics diags;
    std::unique_ptr<Program> program;
    std::string rendered() const { return render_all(diags, sources); }
};

inline std::unique_ptr<Compiled> compile(const std::string& text, CompileOptions opts = {}) {
    auto c = std::make_unique<Compiled>();
    std::uint32_t id = c->sources.add("test.plant", text);
    c->program = compile_source(c->sources, id, opts, c->diags);
    return c;
}

inline std::string derive(const std::string& text, DeriveOptions opts = {}, bool ids = false) {
    auto c = compile(text);
    if (!c->program) return "COMPILE ERROR: " + c->rendered();
    Derivation d(*c->program, opts);
    d.run();
    return format_string(*c->program, d.string(), ids);
}

} // namespace plant::test
