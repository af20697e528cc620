// What the exporters that cannot draw an image learn from a texture: its average colour.
#pragma once

#include "plant/scene.hpp"

#include <optional>

namespace plant::detail {

// The average colour of the texture's image in linear RGB (each pixel decoded from sRGB first),
// or none when the image cannot be decoded or has more than 64 million pixels.
std::optional<glm::vec3> average_color(const Texture& texture);

// Per material of `scene`, the colour a renderer without textures draws it in: a textured
// material's image's average colour, otherwise (or when the image cannot be decoded) its colour.
std::vector<glm::vec3> flat_colors(const Scene& scene);

} // namespace plant::detail
