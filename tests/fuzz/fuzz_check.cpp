// libFuzzer target: the front end on arbitrary bytes, as `plant check` runs it. The bytes are a
// grammar file; it is parsed and compiled with the runtime's environment kinds (so `env`
// declarations are made, as in the command), and its diagnostics are rendered and discarded.
// Only a crash, a sanitizer report, a leak or a run past libFuzzer's -timeout is a finding: a
// grammar error is the expected outcome for most inputs. docs/testing.md says how to run it.
#include "plant/compiler.hpp"
#include "plant/environments.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    plant::SourceManager sources;
    plant::Diagnostics diags;
    plant::CompileOptions options;
    options.environments = plant::runtime_environments();
    options.confine_reads = true;  // as the plant command does: a fuzzed import reads nothing outside
    options.max_steps = 1'000'000; // a fuzzed loop ends quickly
    std::uint32_t id = sources.add("fuzz.plant", std::string(reinterpret_cast<const char*>(data), size));
    auto program = plant::compile_source(sources, id, options, diags);
    std::string rendered = plant::render_all(diags, sources);
    (void)program;
    (void)rendered;
    return 0;
}
