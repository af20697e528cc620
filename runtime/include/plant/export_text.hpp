// Text outputs: the derived string (.txt), the skeleton (.skel.json, see docs/skeleton.md) and
// an orthographic line drawing of the XY plane (.svg, for 2D grammars).
#pragma once

#include "plant/export.hpp"
#include "plant/skeleton.hpp"

namespace plant {

std::string skeleton_json(const Skeleton& skeleton);
std::string skeleton_svg(const Skeleton& skeleton);
void write_skeleton_json(const Skeleton& skeleton, const std::string& path);
void write_svg(const Skeleton& skeleton, const std::string& path);

} // namespace plant
