// Counter-based random numbers: every draw is a pure function of (seed, keys, draw index), so a
// derivation or a physics run depends on the seed only, never on thread count or order of work.
// Header-only and free of dependencies (the plant_common target): the language library and the
// physics library, which must stay usable without the language, both use it.
#pragma once

#include <cmath>
#include <cstdint>

namespace plant {

// SplitMix64's finalizer (Steele, Lea & Flood 2014): a bijective mix with full avalanche.
inline std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

namespace random_detail {
// The steps of a draw: the seed, then each key mixed in with its own odd multiplier, the draw
// index last.
inline std::uint64_t start(std::uint64_t seed, std::uint64_t phase) {
    return mix64(mix64(seed + 0x9e3779b97f4a7c15ULL) ^ (phase * 0xd1b54a32d192ed03ULL));
}
inline std::uint64_t finish(std::uint64_t h, std::uint64_t draw) {
    return mix64(h ^ (draw * 0x8cb92ba72f3d8dd7ULL + 0x2545f4914f6cdd1dULL));
}
} // namespace random_detail

// The part of the language's draws that depends on (seed, phase) alone: a loop drawing for many
// positions of one phase computes it once (random_bits_at).
inline std::uint64_t random_phase(std::uint64_t seed, std::uint64_t phase) {
    return random_detail::start(seed, phase);
}
// random_bits(seed, phase, position, draw) for h = random_phase(seed, phase).
inline std::uint64_t random_bits_at(std::uint64_t h, std::uint64_t position, std::uint64_t draw) {
    return random_detail::finish(mix64(h ^ (position * 0xabc98388fb8fac03ULL)), draw);
}

// The language's draws: a pure function of (seed, phase, position in the string, draw index).
inline std::uint64_t random_bits(std::uint64_t seed, std::uint64_t phase, std::uint64_t position,
                                 std::uint64_t draw) {
    return random_bits_at(random_phase(seed, phase), position, draw);
}

// Draws keyed by one number besides the seed (the physics world's: a particle).
inline std::uint64_t random_bits(std::uint64_t seed, std::uint64_t key, std::uint64_t draw) {
    return random_detail::finish(random_detail::start(seed, key), draw);
}

// Uniform in [0, 1) with 53 random bits.
inline double random_unit(std::uint64_t bits) {
    return static_cast<double>(bits >> 11) * 0x1.0p-53;
}

} // namespace plant
