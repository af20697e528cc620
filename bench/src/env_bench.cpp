// Proximity queries per second on a skeleton of about 100,000 segments (the environment issue:
// at least 5 million a second). The skeleton is ABOP Fig. 1.24a grown to n = 7 (78,125 segments);
// the query radius (2 by default) is a few segment lengths, as density control uses it.
//   plant_env_bench GRAMMAR [STEPS] [QUERIES] [RADIUS]
#include "grown.hpp"
#include "plant/environments.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>

using namespace plant;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: plant_env_bench GRAMMAR [STEPS] [QUERIES]\n");
        return 64;
    }
    int steps = argc > 2 ? std::atoi(argv[2]) : 6;
    long queries = argc > 3 ? std::atol(argv[3]) : 5000000;
    bench::Grown g;
    if (!bench::grow(argv[1], steps, 1, g)) return 65;
    const Skeleton& sk = g.skeleton;
    std::size_t segments = 0;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (const auto& a : sk.axes) {
        segments += a.points.size() > 0 ? a.points.size() - 1 : 0;
        for (const auto& p : a.points) {
            lo = glm::min(lo, p.position);
            hi = glm::max(hi, p.position);
        }
    }
    double radius = argc > 4 ? std::atof(argv[4]) : 2.0; // a few segment lengths, as density control uses
    std::string error;
    EnvArg r;
    r.key = "radius";
    r.v[0] = radius;
    auto env = runtime_environments()("proximity", {r}, error);
    auto t0 = std::chrono::steady_clock::now();
    env->see(sk);
    double update_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    // query points spread over the plant's bounding box, asked for by modules of the plant
    std::uint64_t x = 88172645463325252ULL;
    double sum = 0;
    t0 = std::chrono::steady_clock::now();
    for (long q = 0; q < queries; ++q) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        double u = (x & 0xffff) / 65535.0, v = ((x >> 16) & 0xffff) / 65535.0;
        double args[4] = {lo.x + (hi.x - lo.x) * u, lo.y + (hi.y - lo.y) * v, 0, double((x >> 32) % 1000)};
        double res[3];
        env->query(0, args, res);
        sum += res[0];
    }
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf(
        "proximity segments=%zu radius=%.3f update_ms=%.2f queries=%ld mq_per_s=%.2f (checksum %.3f)\n",
        segments, radius, update_ms, queries, queries / s / 1e6, sum);
    return 0;
}
