// libFuzzer target: derivation of small grammars. The bytes are a grammar file; when it compiles,
// a few steps are derived with small limits (as `plant derive -n 3 --max-modules 10000` would,
// environments and their phase included) and the string is formatted. A runtime error is an
// expected outcome; a crash, a sanitizer report, any other exception escaping (which the command
// line would report as an internal error), a leak or a run past libFuzzer's -timeout is a
// finding. docs/testing.md says how to run it.
#include "fuzz_compile.hpp"
#include "plant/derive.hpp"
#include "plant/environment_phase.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    plant::SourceManager sources;
    plant::Diagnostics diags;
    auto program = plant::fuzz::compile_bytes(data, size, sources, diags);
    if (!program) return 0;
    plant::DeriveOptions derive;
    derive.steps = 3;
    derive.max_modules = 10'000;
    derive.max_bytes = std::size_t{16} << 20;
    derive.threads = 1;
    derive.max_steps = plant::fuzz::kMaxSteps;
    derive.on_print = [](const std::string&) {};
    plant::TurtleEnvironmentPhase phase;
    derive.environment_phase = &phase;
    plant::Derivation d(*program, derive);
    try {
        d.run();
    } catch (const plant::RuntimeError&) {
        return 0;
    }
    std::string text = plant::format_string(*program, d.string(), true);
    (void)text;
    return 0;
}
