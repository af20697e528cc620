// The derivation's kept threads: a step that splits its string over T threads hands the stretches
// to threads started once and kept for the process, instead of starting T - 1 threads for every
// pass (a step runs one or two passes: the count and the write of the direct path). Private to
// the language library.
#pragma once

#include <cstddef>
#include <type_traits>

namespace plant {

// Runs job(context, k) for k in [0, parts): part 0 on the calling thread, the others on the kept
// threads. When those are busy (derivations on several threads at once: the view server's
// requests, --jobs variants, or a call from inside a part) the other parts run on threads
// started for this call. Returns when every part has finished; if parts threw, rethrows what
// the first to throw threw.
void run_on_crew(std::size_t parts, void (*job)(void* context, std::size_t k), void* context);

// run_on_crew for a callable f(k).
template <class F> void run_on_crew(std::size_t parts, F&& f) {
    using Fn = std::remove_reference_t<F>;
    run_on_crew(
        parts, [](void* c, std::size_t k) { (*static_cast<Fn*>(c))(k); },
        const_cast<void*>(static_cast<const void*>(&f)));
}

} // namespace plant
