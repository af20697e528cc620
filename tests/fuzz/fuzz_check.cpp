// libFuzzer target: the front end on arbitrary bytes, as `plant check` runs it. The bytes are a
// grammar file; it is parsed and compiled with the runtime's environment kinds (so `env`
// declarations are made, as in the command), and its diagnostics are rendered and discarded.
// Only a crash, a sanitizer report, a leak or a run past libFuzzer's -timeout is a finding: a
// grammar error is the expected outcome for most inputs. docs/testing.md says how to run it.
#include "fuzz_compile.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    plant::SourceManager sources;
    plant::Diagnostics diags;
    auto program = plant::fuzz::compile_bytes(data, size, sources, diags);
    std::string rendered = plant::render_all(diags, sources);
    (void)program;
    (void)rendered;
    return 0;
}
