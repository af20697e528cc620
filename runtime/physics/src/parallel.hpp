// Splitting a loop over threads without changing its result (internal to plant_physics).
#pragma once

#include <algorithm>
#include <cstddef>
#include <thread>
#include <vector>

namespace plant::physics {

// Runs f(begin, end) over [0, n) split into at most `threads` contiguous ranges of at least
// `grain` indices. Each index is handled by exactly one call and writes only its own slots, so
// the result does not depend on the thread count.
template <class F> void parallel_ranges(std::size_t n, int threads, std::size_t grain, F&& f) {
    const std::size_t t = std::clamp<std::size_t>(static_cast<std::size_t>(std::max(threads, 1)), 1, n / grain + 1);
    if (t == 1) {
        f(std::size_t{0}, n);
        return;
    }
    std::vector<std::thread> pool;
    pool.reserve(t - 1);
    for (std::size_t k = 1; k < t; ++k) pool.emplace_back([&f, k, t, n] { f(n * k / t, n * (k + 1) / t); });
    f(std::size_t{0}, n / t);
    for (auto& th : pool) th.join();
}

} // namespace plant::physics
