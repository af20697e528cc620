// Deriving one instance (docs/language.md, instances): its body's program with the parameters of
// one placement, at one view depth. The runtime derives each distinct (instance, arguments, view
// depth) once and places the result by transform.
#pragma once

#include "plant/derive.hpp"
#include "plant/program.hpp"

#include <cstdint>
#include <span>

namespace plant {

// The seed of an instance's derivation: a mix of the outer derivation's seed, the instance's
// index and its argument tuple (their bits), so it is the same on every machine and thread count,
// differs between tuples and follows the outer seed. The view depth is left out: the levels of
// detail of one tuple draw the same numbers.
std::uint64_t instance_seed(std::uint64_t outer_seed, int index, std::span<const double> args);

// A derivation of `def` not yet started: the instance's parameters hold `args` (their widths
// summed: a vec3 parameter takes three numbers) and its view_depth `view_depth`. Unless the body
// sets `seed S;`, options.seed is instance_seed(outer_seed, ...). Throws std::invalid_argument
// when `def` has no program or `args` has the wrong length.
Derivation instance_derivation(const InstanceDef& def, int index, std::span<const double> args,
                               double view_depth, std::uint64_t outer_seed, DeriveOptions options);

// The number of values an instance's argument tuple carries.
std::size_t instance_arg_width(const InstanceDef& def);

} // namespace plant
