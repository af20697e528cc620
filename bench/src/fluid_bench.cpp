// Step time of the SPH air the climbing-plants issue asks for: 10,000 air particles on one core,
// at most 5 ms a step (Hädrich et al. 2017, section 5.3; the paper's Fig. 7 ran 1,000 fluid
// particles beside 5,000 plant particles). The air fills a box at rest density with a wind
// blowing through it along x (air leaving downwind re-enters upwind), around a coupled branch of
// 200 full-grown plant particles, so every stage of the step runs: neighbour grid, densities
// (with the walls' mirrors and the branch's anisotropic support), forces, the branch's reaction
// and the integration.
//   plant_fluid_bench [PARTICLES] [STEPS] [THREADS]
// Prints one line: particles=N threads=T steps=S sph_ms=... (per step, best of 3 runs)
#include "plant/physics/fluid.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

using namespace plant::physics;

int main(int argc, char** argv) {
    const long want = argc > 1 ? std::atol(argv[1]) : 10000;
    const int steps = argc > 2 ? std::atoi(argv[2]) : 50;
    const int threads = argc > 3 ? std::atoi(argv[3]) : 1;
    if (want < 100 || steps < 1 || threads < 1) {
        std::fprintf(stderr, "usage: plant_fluid_bench [PARTICLES >= 100] [STEPS >= 1] [THREADS >= 1]\n");
        return 64;
    }
    FluidSettings s;
    s.spacing = 0.05;
    s.support = 0.1;
    s.wind = glm::dvec3(2, 0, 0);
    s.threads = threads;
    // a box of k x k cells across the wind and enough along it for at least `want` particles
    // (10,000 = 25 x 20 x 20)
    const long k = static_cast<long>(std::floor(std::cbrt(static_cast<double>(want) / 1.25)));
    const long along = (want + k * k - 1) / (k * k);
    const double side = static_cast<double>(k) * s.spacing;
    s.domain_lo = glm::dvec3(0.0);
    s.domain_hi = glm::dvec3(static_cast<double>(along) * s.spacing, side, side);
    double best = 1e300;
    std::size_t n = 0;
    for (int run = 0; run < 3; ++run) {
        Fluid f(s);
        f.fill(s.domain_lo, s.domain_hi);
        n = f.size();
        World plant;
        plant.settings().fixed_stiffness = 1.0;
        glm::dquat up(1, 0, 0, 0);
        Handle h =
            plant.add_root(glm::dvec3(s.domain_hi.x / 2, 0, side / 2), up, glm::dvec3(0.01, 0.025, 0.01));
        for (int j = 1; j < 200; ++j)
            h = plant.add_particle(
                h, glm::dvec3(s.domain_hi.x / 2 + 0.3 * std::sin(j * 0.1), side * j / 200.0, side / 2), up,
                glm::dvec3(0.01, 0.025, 0.01));
        for (int w = 0; w < 5; ++w) f.step(&plant); // warm up
        auto t0 = std::chrono::steady_clock::now();
        for (int t = 0; t < steps; ++t) f.step(&plant);
        auto t1 = std::chrono::steady_clock::now();
        best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count() / steps);
    }
    std::printf("particles=%zu threads=%d steps=%d sph_ms=%.3f\n", n, threads, steps, best);
    return 0;
}
