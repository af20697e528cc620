// Splitting a loop over threads without changing its result (internal to plant_physics).
#pragma once

#include <plant/crew.hpp>

#include <cstddef>
#include <type_traits>

namespace plant::physics {

// Runs f(begin, end) over [0, n) split into at most `threads` contiguous ranges of at least
// `grain` indices (one range when n is below twice the grain). Each index is handled by exactly
// one call and writes only its own slots, so the result does not depend on the thread count.
template <class F> void parallel_ranges(std::size_t n, int threads, std::size_t grain, F&& f) {
    const std::size_t want = threads > 1 ? static_cast<std::size_t>(threads) : 1;
    const std::size_t most = grain > 0 ? n / grain : n;
    const std::size_t t = want < most ? want : most;
    if (t <= 1) {
        f(std::size_t{0}, n);
        return;
    }
    struct Context {
        std::remove_reference_t<F>* f;
        std::size_t n, t;
    } context{&f, n, t};
    plant::run_on_crew(
        t,
        [](void* c, std::size_t k) {
            const auto& x = *static_cast<Context*>(c);
            (*x.f)(x.n * k / x.t, x.n * (k + 1) / x.t);
        },
        &context);
}

} // namespace plant::physics
