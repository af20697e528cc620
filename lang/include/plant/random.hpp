// Counter-based random numbers: every draw is a pure function of (seed, phase, position, draw
// index), so a derivation depends on the seed only, never on thread count or order of work.
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

} // namespace plant
