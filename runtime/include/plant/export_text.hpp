// Text outputs: the derived string (.txt), the skeleton (.skel.json, see docs/skeleton.md) and
// an orthographic line drawing of the XY plane (.svg, for 2D grammars).
#pragma once

#include "plant/export.hpp"
#include "plant/scene.hpp"
#include "plant/skeleton.hpp"

namespace plant {

// With a scene that places instances (Scene::scene_prototypes), the JSON also lists every
// prototype (instance, arguments, view depth, its own placements) and the top-level placements.
std::string skeleton_json(const Skeleton& skeleton, const Scene* scene = nullptr);
// The .mesh.txt lines about instances: distinct scene prototypes, top-level placements and
// placements drawn at every level. Empty when the scene places none.
std::string scene_prototype_summary(const Scene& scene);
// The SVG's size in pixels: `width` wide and, with `height` 0, as tall as the figure's aspect
// asks (the default, 800 wide); with both given (plant run --size), the figure is fitted inside
// width x height, centred.
struct SvgOptions {
    int width = 800, height = 0;
};
std::string skeleton_svg(const Skeleton& skeleton, const SvgOptions& options = {});
void write_skeleton_json(const Skeleton& skeleton, const std::string& path);
void write_svg(const Skeleton& skeleton, const std::string& path);

} // namespace plant
