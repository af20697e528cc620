// The box around many points in one pass the compiler vectorizes (internal to plant_runtime):
// the tube buffers of a tree hold hundreds of thousands of vertices, and both the scene's bounds
// and the glTF accessor's min and max are taken over all of them.
#pragma once

#include <glm/glm.hpp>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>

namespace plant {

// Coordinate c of the first of the n points at p that is zero (0 or -0), or `start` when it is.
inline float first_zero(const glm::vec3* p, std::size_t n, int c, float start) {
    if (start == 0.0f) return start;
    for (std::size_t k = 0; k < n; ++k)
        if (p[k][c] == 0.0f) return p[k][c];
    return start;
}

// Grows [lo, hi] by the n points at p, comparing as `x < lo ? x : lo` and `hi < x ? x : hi` one
// point after another would (a NaN coordinate leaves the bound as it was); returns whether every
// coordinate is finite. Four points (twelve floats, three vectors of four) go through twelve
// lanes at a time; the lanes are then folded. Only a tie between 0 and -0 can depend on the
// order, so a bound that ends at zero is looked up again.
inline bool grow_point_bounds(const glm::vec3* p, std::size_t n, glm::vec3& lo, glm::vec3& hi) {
    static_assert(sizeof(glm::vec3) == 3 * sizeof(float));
    // GCC's and Clang's vector extension: four floats, and four ints for masks
    using F4 = float __attribute__((vector_size(16)));
    using I4 = int __attribute__((vector_size(16)));
    constexpr float kLargest = std::numeric_limits<float>::max();
    const glm::vec3 lo0 = lo, hi0 = hi;
    float l[12], h[12]; // float j of a block of four points is coordinate j % 3
    for (int j = 0; j < 12; ++j) l[j] = lo0[j % 3], h[j] = hi0[j % 3];
    F4 lv[3], hv[3];
    std::memcpy(lv, l, sizeof l);
    std::memcpy(hv, h, sizeof h);
    const F4 largest = {kLargest, kLargest, kLargest, kLargest};
    const I4 magnitude = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};
    I4 finite = {-1, -1, -1, -1};
    const auto* f = reinterpret_cast<const unsigned char*>(p);
    const std::size_t blocks = n / 4;
    for (std::size_t b = 0; b < blocks; ++b, f += sizeof l)
        for (int j = 0; j < 3; ++j) {
            F4 v;
            std::memcpy(&v, f + j * sizeof v, sizeof v);
            lv[j] = v < lv[j] ? v : lv[j];
            hv[j] = hv[j] < v ? v : hv[j];
            finite &= reinterpret_cast<F4>(reinterpret_cast<I4>(v) & magnitude) <= largest;
        }
    std::memcpy(l, lv, sizeof l);
    std::memcpy(h, hv, sizeof h);
    bool all = true;
    for (int j = 0; j < 4; ++j) all = all && finite[j] != 0;
    for (std::size_t k = blocks * 4; k < n; ++k)
        for (int c = 0; c < 3; ++c) {
            const float v = p[k][c];
            l[c] = v < l[c] ? v : l[c];
            h[c] = h[c] < v ? v : h[c];
            all = all && std::fabs(v) <= kLargest;
        }
    for (int c = 0; c < 3; ++c) {
        float a = l[c], b = h[c];
        for (int j = c + 3; j < 12; j += 3) a = l[j] < a ? l[j] : a, b = b < h[j] ? h[j] : b;
        // a bound of zero is the first zero met, the starting bound's when that is one: nothing
        // smaller (larger) came after it, and the other zero does not replace it
        if (a == 0.0f) a = first_zero(p, n, c, lo0[c]);
        if (b == 0.0f) b = first_zero(p, n, c, hi0[c]);
        lo[c] = a, hi[c] = b;
    }
    return all;
}

} // namespace plant
