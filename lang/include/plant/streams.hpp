// The named random streams of a derivation (the generator itself is plant/random.hpp, shared
// with the physics library).
#pragma once

#include "plant/random.hpp"

#include <cstddef>
#include <cstdint>

namespace plant {

// The streams a derivation draws from. A draw is random_bits(seed, phase, position, draw): the
// phase names the stream (which step, which pass over the string), the position is the module's
// index in the string the pass reads, and the draw counts the draws made there. Every pass that
// draws has a phase of its own, so no two passes ever see the same numbers. Changing a value here
// changes every stochastic derivation's output.
namespace stream {

// The rewrite of step s (counted from 1): s << 16, the low 16 bits zero.
constexpr std::uint64_t step(int s) {
    return static_cast<std::uint64_t>(s) << 16;
}
// Decomposition pass p (from 0) after step s (0: after the axiom): passes 1, 2, ... in the low bits.
constexpr std::uint64_t decompose(int s, int pass) {
    return (static_cast<std::uint64_t>(s) << 16) | static_cast<std::uint64_t>(pass + 1);
}
// Interpretation pass p (from 0) of the string after step s: 0x8000 + p in the low bits.
constexpr std::uint64_t interpret(int s, int pass) {
    return (static_cast<std::uint64_t>(s) << 16) | 0x8000u | static_cast<std::uint64_t>(pass);
}
// The hook of kind k (HookKind's index) run at step s: 0xF000 + k in the low bits.
constexpr std::uint64_t hook(int s, std::size_t kind) {
    return (static_cast<std::uint64_t>(s) << 16) | (0xF000u + kind);
}
// The axiom, built once before step 1.
constexpr std::uint64_t kAxiom = 0xFFFF0000ULL;
// The position of draws made in hooks, which belong to no module.
constexpr std::uint64_t kNoPosition = ~std::uint64_t{0};
// The draw index of the stochastic choice between weighted productions at a module: far above the
// draws its condition or weights make (numbered from 0), so the choice never repeats one of them.
constexpr std::uint64_t kChoiceDraw = 0xffffffffULL;

} // namespace stream

} // namespace plant
