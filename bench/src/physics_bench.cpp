// Step time of the climber's particle runtime at the size the climbing-plants issue names:
// 25,000 plant particles on one core, physics + growth + collision at most 10 ms a step
// (Hädrich et al. 2017 report 45 ms for the same work on a GTX 970).
//
// The plant is a trunk of T particles, each carrying a horizontal lateral of L particles
// (T * (1 + L) = 25,000 by default), grown up against a box-shaped wall and above a ground
// plane, so the collision stage has contacts to resolve; laterals that meet the wall run along
// it. Every step runs growth (the T + 1 apices lengthen and branch) and then the physics step,
// which includes the obstacle pass; the two are timed separately.
// With AIR > 0, that many SPH air particles blow past the plant, coupled both ways (section 5.3),
// ten 2.5 ms air steps per 25 ms plant step.
//   plant_physics_bench [PARTICLES] [STEPS] [THREADS] [AIR] [--per-step]
// Prints, per step with --per-step, the paper's stages (physics, growth, collision, SPH), then
// one line: particles=N threads=T steps=S physics_ms=... growth_ms=... collision_ms=... sph_ms=...
// total_ms=... (physics includes collision; total is physics + growth)
#include "plant/physics/fluid.hpp"
#include "plant/physics/world.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>

using namespace plant::physics;

int main(int argc, char** argv) {
    const long want = argc > 1 ? std::atol(argv[1]) : 25000;
    const int steps = argc > 2 ? std::atoi(argv[2]) : 40;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
    const long air = argc > 4 ? std::atol(argv[4]) : 0;
    const bool per_step = argc > 5 && std::string(argv[5]) == "--per-step";
    if (want < 100 || steps < 1 || threads < 1 || air < 0) {
        std::fprintf(stderr,
                     "usage: plant_physics_bench [PARTICLES >= 100] [STEPS >= 1] [THREADS >= 1] [AIR >= 0] "
                     "[--per-step]\n");
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
        // A lateral that reaches the wall turns to run along its face, as growth would have it
        // (a particle is never placed inside an obstacle): laterals laid straight through the
        // wall left their middle particles inside it, stacked on its faces by every step's
        // obstacle pass, which made the collision stage 1.7 times as dear (7.3 ms against 4.3) as
        // a plant that grew there makes it.
        constexpr double face = 0.3 - 0.02; // the wall's near face, a lateral's radius and a gap off
        glm::dvec3 d = dir, at = base;
        Handle lp = trunk_h;
        for (long k = 1; k <= lateral && static_cast<long>(w.size()) < want; ++k) {
            if ((at + d * 0.05).z > face) d = glm::normalize(glm::dvec3(d.x, d.y, 0));
            at += d * 0.05;
            lp = w.add_particle(lp, at, glm::dquat(glm::dvec3(0, 1, 0), d), r * 0.8); // +y turned to d
        }
        prev = trunk_h;
    }

    // air around the lower trunk and its laterals, blowing along x
    FluidSettings fs;
    fs.threads = threads;
    fs.wind = glm::dvec3(3, 0, 0);
    const double side = std::cbrt(static_cast<double>(std::max(air, 1L))) * fs.spacing;
    fs.domain_lo = glm::dvec3(-side / 2, 0.0, -side / 2);
    fs.domain_hi = glm::dvec3(side / 2, side, side / 2);
    Fluid fluid(fs);
    if (air > 0) fluid.fill(fs.domain_lo, fs.domain_hi);

    using clock = std::chrono::steady_clock;
    double physics = 0, growth = 0, collision = 0, sph = 0;
    const std::size_t start = w.size();
    for (int i = 0; i < steps; ++i) {
        auto t0 = clock::now();
        w.grow();
        auto t1 = clock::now();
        if (air > 0)
            for (int k = 0; k < 10; ++k) fluid.step(&w);
        auto t2 = clock::now();
        w.step();
        auto t3 = clock::now();
        const double g = std::chrono::duration<double, std::milli>(t1 - t0).count();
        const double a = std::chrono::duration<double, std::milli>(t2 - t1).count();
        const double p = std::chrono::duration<double, std::milli>(t3 - t2).count();
        growth += g, sph += a, physics += p, collision += w.last_step_times().collision;
        if (per_step)
            std::printf("step %d: physics %.3f ms (collision %.3f), growth %.3f ms, sph %.3f ms\n", i + 1, p,
                        w.last_step_times().collision, g, a);
    }
    std::printf("particles=%zu air=%zu threads=%d grown=%zu steps=%d physics_ms=%.3f growth_ms=%.3f "
                "collision_ms=%.3f "
                "sph_ms=%.3f total_ms=%.3f hash=%016llx\n",
                start, fluid.size(), threads, w.size() - start, steps, physics / steps, growth / steps,
                collision / steps, sph / steps, (physics + growth) / steps,
                static_cast<unsigned long long>(w.state_hash()));
    return 0;
}
