// The environment kinds of the runtime (docs/language.md, environments), made by
// `runtime_environments()` for the compiler; each derivation's clones see the plant in the
// environment phase of every step (environment_phase.hpp).
//
//   env crown = ellipsoid(center: vec3(0, 4, 0), radii: vec3(3, 2, 3));
//   ... crown.level(p) < 1 ...
//
// Each kind's methods, with their argument types and what they answer, are its method table in
// environments.cpp or climber.cpp; `plant help env KIND` prints it.
#pragma once

#include "plant/environment.hpp"
#include "plant/skeleton.hpp"

#include <span>

namespace plant {

// Makes the runtime's kinds, by name.
EnvironmentFactory runtime_environments();

// Every kind the runtime has, in the order its messages list them, with its method table
// (for `plant help env KIND`); nothing is made.
std::span<const EnvironmentKind* const> environment_kinds();

} // namespace plant
