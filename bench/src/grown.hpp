// Compiling and growing a grammar for a benchmark: what plant_mesh_bench and plant_env_bench
// share before they time anything.
#pragma once

#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <cstdio>
#include <memory>

namespace plant::bench {

struct Grown {
    std::unique_ptr<Program> program;
    std::size_t modules = 0; // in the derived string
    Skeleton skeleton;
};

// Compiles `path`, derives `steps` steps on `threads` threads and draws the skeleton. On a
// grammar error prints the diagnostics and returns false.
inline bool grow(const char* path, int steps, int threads, Grown& out) {
    SourceManager sm;
    Diagnostics diags;
    out.program = compile_file(sm, path, {}, diags);
    if (!out.program) {
        std::fputs(render_all(diags, sm).c_str(), stderr);
        return false;
    }
    DeriveOptions o;
    o.steps = steps;
    o.threads = threads;
    Derivation d(*out.program, o);
    d.run();
    out.modules = d.string().size();
    out.skeleton = build_skeleton(*out.program, d.interpreted(d.string()), turtle_options(d));
    return true;
}

} // namespace plant::bench
