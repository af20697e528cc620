// The scene's shade (runtime/physics/src/shadow.cpp; docs/climber-growth.md, "Growth rate and secondary
// growth"): a ray from a point toward the light, against each kind of obstacle.
#include "plant/physics/light.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <random>

using namespace plant::physics;

namespace {

Obstacle box(glm::dvec3 lo, glm::dvec3 hi) {
    Obstacle o;
    o.kind = Obstacle::Box;
    o.a = lo;
    o.b = hi;
    return o;
}

// a sphere of radius 0.5 about the origin sampled on a grid of 5 cm cells, as a mesh would be
Obstacle sampled_sphere() {
    auto g = std::make_shared<DistanceGrid>();
    g->cell = 0.05;
    g->lo = glm::dvec3(-1.0);
    g->n = glm::ivec3(41);
    for (int z = 0; z < 41; ++z)
        for (int y = 0; y < 41; ++y)
            for (int x = 0; x < 41; ++x)
                g->d.push_back(glm::length(g->lo + glm::dvec3(x, y, z) * g->cell) - 0.5);
    Obstacle o;
    o.kind = Obstacle::Grid;
    o.grid = g;
    return o;
}

} // namespace

TEST_CASE("shadow: a box between a point and the light shades it, beside it does not", "[physics]") {
    const Obstacle wall = box({0.0, 0.0, -0.5}, {0.1, 2.0, 0.5});
    const glm::dvec3 from_right = glm::normalize(glm::dvec3(1, 0.2, 0));
    CHECK(blocks_light(wall, {-0.3, 0.5, 0.0}, from_right));   // behind it
    CHECK(!blocks_light(wall, {0.4, 0.5, 0.0}, from_right));   // on its lit side
    CHECK(!blocks_light(wall, {-0.3, 0.5, 0.8}, from_right));  // beside it
    CHECK(!blocks_light(wall, {-0.3, 1.95, 0.0}, from_right)); // the ray passes over it
    CHECK(!blocks_light(wall, {0.05, 0.5, 0.0}, from_right));  // inside it: not shaded by it
    // a point on a face the light grazes (parallel to the face) is lit
    CHECK(!blocks_light(wall, {0.05, 2.006, 0.0}, glm::dvec3(1, 0, 0)));
    // several obstacles: any one of them shades
    const std::vector<Obstacle> scene = {box({5, 5, 5}, {6, 6, 6}), wall};
    CHECK(in_shadow(scene, {-0.3, 0.5, 0.0}, from_right));
    CHECK(!in_shadow(scene, {0.4, 0.5, 0.0}, from_right));
}

TEST_CASE("shadow: spheres, planes and sampled grids shade the points behind them", "[physics]") {
    Obstacle ball;
    ball.kind = Obstacle::Sphere;
    ball.a = glm::dvec3(0, 1, 0);
    ball.b = glm::dvec3(0.5, 0, 0);
    const glm::dvec3 up(0, 1, 0);
    CHECK(blocks_light(ball, {0.1, 0.2, 0}, up));  // under it
    CHECK(!blocks_light(ball, {0.6, 0.2, 0}, up)); // beside it
    CHECK(!blocks_light(ball, {0.1, 1.8, 0}, up)); // above it
    Obstacle ground;                               // the plane y = 0, facing up
    CHECK(!blocks_light(ground, {0, 0.1, 0}, up));
    CHECK(blocks_light(ground, {0, 0.1, 0},
                       glm::normalize(glm::dvec3(1, -0.1, 0)))); // a light below the horizon
    const Obstacle grid = sampled_sphere();
    CHECK(blocks_light(grid, {0.1, -0.8, 0}, up));                   // under it
    CHECK(!blocks_light(grid, {0.7, -0.8, 0}, up));                  // beside it
    CHECK(!blocks_light(grid, {0.1, 0.8, 0}, up));                   // above it
    CHECK(!blocks_light(grid, {0.1, -2.5, 0}, glm::dvec3(1, 0, 0))); // its ray misses the grid
    CHECK(blocks_light(grid, {-3, 0.1, 0}, glm::dvec3(1, 0, 0)));    // from outside the grid
    // moved with the obstacle (a grid's `a` is its offset)
    Obstacle moved = grid;
    moved.a = glm::dvec3(2, 0, 0);
    CHECK(!blocks_light(moved, {0.1, -0.8, 0}, up));
    CHECK(blocks_light(moved, {2.1, -0.8, 0}, up));
}

TEST_CASE("diffuse light: the open sky lights a point in an obstacle's shadow", "[physics]") {
    // the share of the sky no obstacle hides: all of it in the open, about half beside a tall
    // wide wall, none under a roof
    const std::vector<Obstacle> none;
    CHECK(sky_visible(none, {0, 0.5, 0}) == 1.0);
    const std::vector<Obstacle> wall = {box({0.0, 0.0, -50}, {0.1, 100, 50})};
    const double beside = sky_visible(wall, {-0.05, 0.5, 0});
    INFO("sky beside a tall wall " << beside);
    CHECK(beside > 0.4);
    CHECK(beside < 0.6);
    const std::vector<Obstacle> roof = {box({-50, 1, -50}, {50, 1.1, 50})};
    CHECK(sky_visible(roof, {0, 0.5, 0}) == 0.0);
    // Eq. 7's O with a share d of the light from the sky: behind the wall from a level light, the
    // light is d times the sky it sees; in the open, all of it; with d = 0, as without the sky
    LightGrid empty;
    const glm::dvec3 from_right(1, 0, 0);
    const glm::dvec3 behind(-0.05, 0.5, 0), open(0.5, 0.5, 0);
    CHECK(scene_occlusion(empty, wall, true, behind, from_right, 0.15) == 1.0);
    CHECK(scene_occlusion(empty, wall, true, behind, from_right, 0.15, 0.3) == Approx(1 - 0.3 * beside));
    CHECK(scene_occlusion(empty, wall, true, open, from_right, 0.15, 0.3) ==
          Approx(1 - (0.7 + 0.3 * sky_visible(wall, open))));
    CHECK(scene_occlusion(empty, wall, false, behind, from_right, 0.15, 0.3) == 0.0);
    CHECK(scene_occlusion(empty, roof, true, {0, 0.5, 0}, glm::dvec3(0, 1, 0), 0.15, 0.3) == 1.0);
    // a share out of [0, 1] from a caller of the library (the climber clamps its argument): NaN or
    // below 0 is no sky, above 1 all sky; O stays within [0, 1]
    const double nan = std::numeric_limits<double>::quiet_NaN();
    CHECK(scene_occlusion(empty, wall, true, behind, from_right, 0.15, nan) == 1.0);
    CHECK(scene_occlusion(empty, wall, true, behind, from_right, 0.15, -2) == 1.0);
    CHECK(scene_occlusion(empty, wall, true, behind, from_right, 0.15, 7) == Approx(1 - beside));
}

TEST_CASE("diffuse light: sky_visible counts exactly the directions in_shadow finds open", "[physics]") {
    // sky_visible works out what its tests need of the point once and leaves out the boxes that
    // cannot hide any direction of the sky (the point inside, the box wholly below it); its count
    // is checked here against in_shadow itself over the same directions (light.hpp's spiral), for
    // points all around scenes of boxes (corners given either way round), a sphere and planes
    const std::vector<glm::dvec3>& sky = sky_directions();
    REQUIRE(sky.size() == static_cast<std::size_t>(kSkyDirections));
    Obstacle ball;
    ball.kind = Obstacle::Sphere;
    ball.a = glm::dvec3(1.0, 2.0, 0.5);
    ball.b = glm::dvec3(0.4, 0, 0);
    Obstacle ground;
    ground.kind = Obstacle::Plane;
    ground.a = glm::dvec3(0.0);
    ground.b = glm::dvec3(0, 1, 0);
    Obstacle slope; // a plane leaning over: it hides part of the sky of the points above it
    slope.kind = Obstacle::Plane;
    slope.a = glm::dvec3(0, 1, 0);
    slope.b = glm::dvec3(1, -0.4, 0.2);
    const std::vector<std::vector<Obstacle>> scenes = {
        {box({-2.5, 0, -1.5}, {2.5, 3.5, 0}), ground},
        {box({0.5, 1, 0.5}, {-0.5, 0, -0.5}), box({1, 0, 1}, {1.2, 2, 1.2}), ball},
        {ground, box({-1, 2, -1}, {1, 2.1, 1}), box({-0.1, 0, -0.1}, {0.1, 2, 0.1})},
        {slope, box({-1, 0, -1}, {-0.5, 1.5, 2}), ground},
        // corners not finite (a box moved by 1e308, say), or far enough that its distance is NaN
        {box({0, 2, -1}, {HUGE_VAL, 3, 1}), box({-0.5, 0, -0.5}, {0.5, 1, 0.5})},
        {box({-HUGE_VAL, 0, 1}, {HUGE_VAL, 10, 2})},
        {box({-1, 0, -1}, {1, std::numeric_limits<double>::quiet_NaN(), 1}), ground},
        {box({-1e308, 2, -1}, {1e308, 3, 1})},
    };
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> at(-3.0, 3.0);
    std::size_t points = 0, partly = 0;
    for (const auto& scene : scenes)
        for (int k = 0; k < 400; ++k) {
            const glm::dvec3 p(at(rng), at(rng) + 2.0, at(rng));
            int open = 0;
            for (const glm::dvec3& d : sky) open += in_shadow(scene, p, d) ? 0 : 1;
            INFO("point " << p.x << ", " << p.y << ", " << p.z);
            CHECK(sky_visible(scene, p) == static_cast<double>(open) / kSkyDirections);
            ++points;
            if (open > 0 && open < kSkyDirections) ++partly;
        }
    // (the points were not all in the open or all under cover)
    CHECK(points == 3200);
    CHECK(partly > 400);
}
