// grow_point_bounds (runtime/src/bounds.hpp) against the same comparisons made one point after
// another: the bounds bit for bit (which zero, 0 or -0, included) and the finite flag.
#include "bounds.hpp"

#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <limits>
#include <vector>

using namespace plant;

namespace {

struct Box {
    glm::vec3 lo, hi;
    bool finite;
};

Box one_by_one(const std::vector<glm::vec3>& p, glm::vec3 lo, glm::vec3 hi) {
    bool finite = true;
    for (const glm::vec3& v : p)
        for (int c = 0; c < 3; ++c) {
            lo[c] = v[c] < lo[c] ? v[c] : lo[c];
            hi[c] = hi[c] < v[c] ? v[c] : hi[c];
            finite = finite && std::isfinite(v[c]);
        }
    return {lo, hi, finite};
}

void same(const std::vector<glm::vec3>& p, glm::vec3 lo, glm::vec3 hi) {
    const Box want = one_by_one(p, lo, hi);
    const bool finite = grow_point_bounds(p.data(), p.size(), lo, hi);
    CHECK(finite == want.finite);
    for (int c = 0; c < 3; ++c) {
        CHECK(std::bit_cast<std::uint32_t>(lo[c]) == std::bit_cast<std::uint32_t>(want.lo[c]));
        CHECK(std::bit_cast<std::uint32_t>(hi[c]) == std::bit_cast<std::uint32_t>(want.hi[c]));
    }
}

constexpr float kMax = std::numeric_limits<float>::max();

} // namespace

TEST_CASE("grow_point_bounds: the bounds one point after another would give", "[bounds]") {
    const glm::vec3 lo(kMax), hi(-kMax);
    for (std::size_t n : {0u, 1u, 3u, 4u, 5u, 11u, 12u, 13u, 1001u}) {
        std::vector<glm::vec3> p;
        for (std::size_t k = 0; k < n; ++k)
            p.emplace_back(std::sin(float(k)) * 3, std::cos(float(k) * 0.7f) + float(k % 5), -float(k) / 7);
        same(p, lo, hi);
        same(p, glm::vec3(-1.0f, 0.5f, 0.0f), glm::vec3(0.5f, 2.0f, -0.0f)); // a box grown further
    }
}

TEST_CASE("grow_point_bounds: a bound of zero is the first zero met, of either sign", "[bounds]") {
    const glm::vec3 lo(kMax), hi(-kMax);
    // x's minimum and y's maximum are zero, in several lanes: points 2 and 6 share one lane, 5
    // has another, so folding the lanes meets point 5's zero before point 2's
    std::vector<glm::vec3> p(9, glm::vec3(1.0f, -1.0f, 2.0f));
    for (std::size_t k : {2u, 5u, 6u}) p[k].x = p[k].y = 0.0f;
    p[5].x = p[5].y = -0.0f;
    same(p, lo, hi); // the first zero is point 2's, +0
    p[2].x = p[2].y = -0.0f;
    p[5].x = p[5].y = 0.0f;
    same(p, lo, hi);                            // now it is -0
    same(p, glm::vec3(0.0f), glm::vec3(-0.0f)); // a starting zero stays
}

TEST_CASE("grow_point_bounds: NaN leaves a bound alone, NaN and infinity are not finite", "[bounds]") {
    const glm::vec3 lo(kMax), hi(-kMax);
    std::vector<glm::vec3> p(10, glm::vec3(1.0f, -2.0f, 3.0f));
    p[7].y = std::numeric_limits<float>::quiet_NaN();
    same(p, lo, hi);
    p[7].y = -2.5f;
    same(p, lo, hi);
    p[9].z = std::numeric_limits<float>::infinity(); // in the tail, past the blocks of four
    same(p, lo, hi);
    p[9].z = 3.0f;
    p[0].x = -std::numeric_limits<float>::infinity();
    same(p, lo, hi);
}
