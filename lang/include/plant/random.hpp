// Counter-based random numbers: every draw is a pure function of (seed, phase, position, draw
// index), so a derivation depends on the seed only, never on thread count or order of work.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

namespace plant {

// SplitMix64's finalizer (Steele, Lea & Flood 2014): a bijective mix with full avalanche.
inline std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

inline std::uint64_t random_bits(std::uint64_t seed, std::uint64_t phase, std::uint64_t position,
                                 std::uint64_t draw) {
    std::uint64_t h = mix64(seed + 0x9e3779b97f4a7c15ULL);
    h = mix64(h ^ (phase * 0xd1b54a32d192ed03ULL));
    h = mix64(h ^ (position * 0xabc98388fb8fac03ULL));
    return mix64(h ^ (draw * 0x8cb92ba72f3d8dd7ULL + 0x2545f4914f6cdd1dULL));
}

// Uniform in [0, 1) with 53 random bits.
inline double random_unit(std::uint64_t bits) {
    return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

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
