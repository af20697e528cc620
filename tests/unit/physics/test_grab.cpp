// A hand grabbing a stem and pulling it (runtime/physics/src/grab.cpp; docs/physics.md,
// "Grabbing"; Hädrich et al. 2017, Fig. 7 (c)).
#include "plant/physics/world.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace plant::physics;

namespace {

// ten 5 cm links up the face z = 0 of a wall (behind it), each particle anchored to it
struct Stem {
    World w;
    std::vector<Handle> h;
    Stem()
        : w([] {
              Settings s;
              s.fixed_stiffness = 0.5;
              return s;
          }()) {
        Obstacle wall;
        wall.kind = Obstacle::Box;
        wall.a = glm::dvec3(-1, 0, -0.2);
        wall.b = glm::dvec3(1, 2, 0);
        w.add_obstacle(wall);
        const glm::dvec3 radii(0.006, 0.025, 0.006);
        const glm::dquat up(1, 0, 0, 0);
        h.push_back(w.add_root({0, 0, 0.006}, up, radii));
        for (int k = 1; k <= 10; ++k) {
            h.push_back(w.add_particle(h.back(), {0, 0.05 * k, 0.006}, up, radii));
            w.add_anchor(h.back(), {0, 0.05 * k, 0.006}, 0.3, 0.1);
        }
    }
    double worst_link() const {
        double worst = 0;
        for (std::size_t k = 1; k < h.size(); ++k)
            worst =
                std::max(worst, std::fabs(glm::distance(w.position(h[k]), w.position(h[k - 1])) / 0.05 - 1));
        return worst;
    }
};

} // namespace

TEST_CASE("grab: the stem follows the hand within its length and comes off its wall", "[physics]") {
    Stem s;
    const glm::dvec3 hand(0.2, 0.3, 0.5); // out from the wall, beyond the grabbed particle's reach
    double worst = 0;
    for (int step = 0; step < 40; ++step) {
        const glm::dvec3 before = s.w.position(s.h[6]);
        s.w.grab(s.h[6], hand, 0.025);
        s.w.step();
        // the hand moves at most its pace a step, and every link keeps its length
        CHECK(glm::distance(before, s.w.position(s.h[6])) < 0.025 + 1e-9);
        worst = std::max(worst, s.worst_link());
    }
    INFO("worst link " << worst << ", grabbed particle at z = " << s.w.position(s.h[6]).z);
    CHECK(worst < 0.01);
    // the grabbed particle is as far from the root toward the hand as its 30 cm of stem allow
    const double reach = glm::distance(s.w.position(s.h[6]), s.w.position(s.h[0]));
    CHECK(reach == Approx(0.3).epsilon(0.02));
    CHECK(s.w.position(s.h[6]).z > 0.2);
    // pulled more than the release distance (0.1 m) from their anchors, they let go; the lowest,
    // near the root, stay
    CHECK(!s.w.anchored(s.h[6]));
    CHECK(!s.w.anchored(s.h[5]));
    CHECK(s.w.anchored(s.h[1]));
    // nothing went into the wall
    for (const Handle& p : s.h) CHECK(s.w.obstacles()[0].distance(s.w.position(p)) > 0.005);
}

TEST_CASE("grab: a hand within reach moves only the stem's taut part", "[physics]") {
    Stem s;
    // a hand 2 cm out from the top particle: the links below it go slack after the first
    for (int step = 0; step < 4; ++step) {
        s.w.grab(s.h[10], {0, 0.5, 0.03}, 0.025);
        s.w.step();
    }
    CHECK(s.w.position(s.h[10]).z == Approx(0.03).margin(0.002));
    CHECK(s.w.position(s.h[2]).z < 0.01); // the lower stem stays on the wall
    CHECK(s.worst_link() < 0.05);
}
