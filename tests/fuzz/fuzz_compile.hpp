// What both libFuzzer targets do first: compile the bytes as a grammar file the way the plant
// command does (the runtime's environment kinds, reads confined to the grammar's folder) with a
// small evaluation budget, so that a fuzzed loop in a constant ends quickly.
#pragma once

#include "plant/compiler.hpp"
#include "plant/environments.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace plant::fuzz {

inline constexpr std::uint64_t kMaxSteps = 1'000'000;

inline std::unique_ptr<Program> compile_bytes(const std::uint8_t* data, std::size_t size,
                                              SourceManager& sources, Diagnostics& diags) {
    CompileOptions options;
    options.environments = runtime_environments();
    options.confine_reads = true;
    options.max_steps = kMaxSteps;
    std::uint32_t id = sources.add("fuzz.plant", std::string(reinterpret_cast<const char*>(data), size));
    return compile_source(sources, id, options, diags);
}

} // namespace plant::fuzz
