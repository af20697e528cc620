// Decoding texture images for the PNG preview, through stb_image (libstb, which Debian ships
// compiled: no STB_IMAGE_IMPLEMENTATION here).
#include "texture_image.hpp"

#include <stb/stb_image.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>

namespace plant::detail {

namespace {

constexpr std::int64_t kMaxPixels = std::int64_t(64) << 20;

double srgb_to_linear(int c) {
    const double s = c / 255.0;
    return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

} // namespace

std::optional<glm::vec3> average_color(const Texture& texture) {
    if (!texture.bytes || texture.bytes->empty() ||
        texture.bytes->size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
        return std::nullopt;
    const auto* data = reinterpret_cast<const stbi_uc*>(texture.bytes->data());
    const int size = static_cast<int>(texture.bytes->size());
    int w = 0, h = 0, channels = 0;
    if (!stbi_info_from_memory(data, size, &w, &h, &channels) || w <= 0 || h <= 0 ||
        std::int64_t(w) * h > kMaxPixels)
        return std::nullopt;
    std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load_from_memory(data, size, &w, &h, &channels, 3),
                                                     stbi_image_free);
    if (!pixels) return std::nullopt;
    double table[256];
    for (int i = 0; i < 256; ++i) table[i] = srgb_to_linear(i);
    double sum[3] = {0, 0, 0};
    const std::size_t n = std::size_t(w) * std::size_t(h);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) sum[c] += table[pixels.get()[i * 3 + std::size_t(c)]];
    return glm::vec3(float(sum[0] / double(n)), float(sum[1] / double(n)), float(sum[2] / double(n)));
}

std::vector<glm::vec3> flat_colors(const Scene& scene) {
    std::vector<std::optional<glm::vec3>> averages(scene.textures.size());
    std::vector<bool> decoded(scene.textures.size(), false);
    std::vector<glm::vec3> colors;
    colors.reserve(scene.materials.size());
    for (const Material& m : scene.materials) {
        glm::vec3 c = m.color;
        if (m.texture >= 0 && static_cast<std::size_t>(m.texture) < scene.textures.size()) {
            const auto t = static_cast<std::size_t>(m.texture);
            if (!decoded[t]) {
                decoded[t] = true;
                averages[t] = average_color(scene.textures[t]);
            }
            if (averages[t]) c = *averages[t];
        }
        colors.push_back(c);
    }
    return colors;
}

} // namespace plant::detail
