// The environment kinds of the runtime (docs/language.md, environments), made by
// `runtime_environments()` for the compiler; each derivation's clones see the plant in the
// environment phase of every step (environment_phase.hpp).
//
//   env crown = ellipsoid(center: vec3(0, 4, 0), radii: vec3(3, 2, 3));
//     crown.contains(p)          p inside the ellipsoid
//     crown.contains_scaled(p, g) p inside the ellipsoid shrunk (g < 1) or grown about its center
//     crown.level(p)             |(p - center) / radii|: 1 on the surface, below 1 inside
//   env space = proximity(radius: 0.5);
//     space.distance(p, id)      distance from p to the nearest segment of another axis than the
//                                one the module `id` belongs to (its branching point excluded);
//                                `radius` when none is that close
//     space.clearance(id)        smallest distance from a node of module id's stem (its first
//                                point excluded) to an older stem, one whose first segment has
//                                a smaller identity; `radius` when none is that close.
//                                ?E(space, d, c) receives both for the stem it stands on
//   env crown = envelope(top: ..., bottom: ..., px: ..., pz: ..., nx: ..., nz: ..., top_shape: 2);
//     crown.contains(p), crown.level(p)   Cescatti's asymmetric crown
//   env sun = light(direction: vec3(-1, 1, 0), resolution: 32, opacity: 0.3);
//     sun.exposure(p), sun.occlusion(p)   self-shading by the plant's segments and organs
//   env scene = obstacles(sphere: vec3(0, 2, 0), sphere_radius: 1, box_min: ..., box_max: ...,
//                          plane_point: ..., plane_normal: ...);
//     scene.distance(p)          signed distance to the nearest shape (negative inside)
//     scene.inside(p)            p inside some shape
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
