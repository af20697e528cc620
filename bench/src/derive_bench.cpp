// Derivation time in one process, for profiling the rewriting engine without process start-up:
//   plant_derive_bench GRAMMAR STEPS [REPEATS] [THREADS]
// prints the first, best and median derive time of REPEATS runs (compiled once; identities
// dropped as `plant derive` without --ids drops them). The first run pays for cold caches as
// `plant derive --stats` does; the others show the engine warm. bench/run judges the
// `plant derive --stats` figures instead, which is what a user sees; this is the tool to look
// inside them (perf record build/plant_derive_bench ...).
#include "plant/compiler.hpp"
#include "plant/derive.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

using namespace plant;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: plant_derive_bench GRAMMAR STEPS [REPEATS] [THREADS]\n");
        return 64;
    }
    const int steps = std::atoi(argv[2]);
    const int repeats = argc > 3 ? std::max(1, std::atoi(argv[3])) : 100;
    const int threads = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1;
    SourceManager sm;
    Diagnostics diags;
    auto program = compile_file(sm, argv[1], {}, diags);
    if (!program) {
        std::fputs(render_all(diags, sm).c_str(), stderr);
        return 65;
    }
    std::vector<double> ms;
    std::size_t modules = 0;
    for (int r = 0; r < repeats; ++r) {
        DeriveOptions o;
        o.steps = steps;
        o.threads = threads;
        o.identities = false;
        Derivation d(*program, o);
        auto t0 = std::chrono::steady_clock::now();
        d.run();
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        modules = d.string().size();
    }
    const double first = ms.front();
    std::sort(ms.begin(), ms.end());
    std::printf("derive modules=%zu first_ms=%.4f best_ms=%.4f median_ms=%.4f repeats=%d threads=%d\n",
                modules, first, ms.front(), ms[ms.size() / 2], repeats, threads);
    return 0;
}
