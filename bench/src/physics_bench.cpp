// Step time of the climber's particle runtime at the size the climbing-plants issue names:
// 25,000 plant particles on one core, physics + growth + collision at most 10 ms a step
// (Hädrich et al. 2017 report 45 ms for the same work on a GTX 970).
//
// The plant is a trunk of T particles, each carrying a horizontal lateral of L particles
// (T * (1 + L) = 25,000 by default), grown up against a box-shaped wall and above a ground
// plane, so the collision stage has contacts to resolve. Every step runs growth (the T + 1 apices
// lengthen and branch) and then the physics step, which includes the obstacle pass; the two are
// timed separately.
//   plant_physics_bench [PARTICLES] [STEPS] [THREADS]
// Prints one line: particles=N threads=T steps=S physics_ms=... growth_ms=... total_ms=...
#include "plant/physics/world.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>

using namespace plant::physics;

int main(int argc, char** argv) {
    const long want = argc > 1 ? std::atol(argv[1]) : 25000;
    const int steps = argc > 2 ? std::atoi(argv[2]) : 40;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
    if (want < 100 || steps < 1 || threads < 1) {
        std::fprintf(stderr, "usage: plant_physics_bench [PARTICLES >= 100] [STEPS >= 1] [THREADS >= 1]\n");
        return 64;
    }
    const long lateral = 99;
    const long trunk = want / (lateral + 1);

    Settings s;
    s.threads = threads;
    s.growth.speed = 0.05;
    s.growth.segment_length = 0.05;
    s.growth.max_particles = static_cast<std::size_t>(want) + 2000; // room to grow during the run
    s.growth.branch_probability = 0.05;
    s.growth.adaption = 0.5;
    s.growth.phototropism = 0.3;
    World w(s);
    w.add_obstacle({Obstacle::Plane, {0, 0, 0}, {0, 1, 0}});
    w.add_obstacle({Obstacle::Box, {-10, 0, 0.3}, {10, 40, 0.6}}); // a wall just behind the trunk

    const glm::dvec3 r(0.02, 0.025, 0.02);
    const glm::dquat up(1, 0, 0, 0);
    Handle prev = w.add_root({0, 0.05, 0}, up, r);
    for (long t = 0; t < trunk && static_cast<long>(w.size()) < want; ++t) {
        const glm::dvec3 base(0, 0.05 + 0.05 * static_cast<double>(t + 1), 0);
        Handle trunk_h = w.add_particle(prev, base, up, r);
        // a lateral leaving in the golden-angle direction, slightly rising
        const double a = static_cast<double>(t) * 2.39996322972865332;
        const glm::dvec3 dir = glm::normalize(glm::dvec3(std::cos(a), 0.2, std::sin(a)));
        const glm::dquat q(glm::dvec3(0, 1, 0), dir); // the rotation taking +y to dir
        Handle lp = trunk_h;
        for (long k = 1; k <= lateral && static_cast<long>(w.size()) < want; ++k)
            lp = w.add_particle(lp, base + dir * (0.05 * static_cast<double>(k)), q, r * 0.8);
        prev = trunk_h;
    }

    using clock = std::chrono::steady_clock;
    double physics = 0, growth = 0;
    const std::size_t start = w.size();
    for (int i = 0; i < steps; ++i) {
        auto t0 = clock::now();
        w.grow();
        auto t1 = clock::now();
        w.step();
        auto t2 = clock::now();
        growth += std::chrono::duration<double, std::milli>(t1 - t0).count();
        physics += std::chrono::duration<double, std::milli>(t2 - t1).count();
    }
    std::printf("particles=%zu threads=%d grown=%zu steps=%d physics_ms=%.3f growth_ms=%.3f total_ms=%.3f hash=%016llx\n",
                start, threads, w.size() - start, steps, physics / steps, growth / steps, (physics + growth) / steps,
                static_cast<unsigned long long>(w.state_hash()));
    return 0;
}
