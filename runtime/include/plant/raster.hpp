// The software rasterizer behind write_png, exposed so tests can check pixels without decoding
// a PNG. Orthographic 3/4 view (from the front-right, somewhat above; y is up) framed on the
// scene's bounding box with a 5% margin, or a perspective view from a point (PngView: at the
// camera, looking at the target, its view angle the narrowest from 10 to 100 degrees that frames
// the bounding box's corners in front of it); z-buffer, two-sided Lambert shading plus ambient,
// 2x2 supersampling, white background. Output is sRGB.
#pragma once

#include "plant/export.hpp"
#include "plant/scene.hpp"

#include <cstdint>
#include <vector>

namespace plant {

struct Image {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb; // width * height * 3 bytes, rows top to bottom
};

// Renders the tubes and every instance, each primitive in its material's color. Degenerate
// input (no geometry, zero-size bounds, invalid indices) gives a blank or sparse image, never
// a crash. Throws ExportError (plant/export.hpp) if width or height is not positive or the
// image is too large (more than 64 million pixels).
Image render_scene(const Scene& scene, int width, int height,
                   const std::optional<PngView>& view = std::nullopt);
Image render_scene(const Scene& scene, int width, int height, const PngOptions& options);

// The view `options` resolve to (PngViewKind::Auto made definite; Iso under a camera).
PngViewKind resolved_view(const Scene& scene, const PngOptions& options);
// Where the point `p` lands in the image render_scene draws: pixel coordinates (x right, y down,
// the centre of the top-left pixel at 0.5, 0.5); none when it is behind a perspective camera.
std::optional<glm::dvec2> project_to_image(const Scene& scene, int width, int height,
                                           const PngOptions& options, const glm::dvec3& p);

} // namespace plant
