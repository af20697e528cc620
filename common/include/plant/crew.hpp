// Threads kept for the process, shared by the derivation's parallel passes and the physics'
// parallel loops (both call a split many times a step; starting threads for each call cost more
// than the work they shared). Header-only, like the rest of plant_common, so that the physics
// library stays usable without the language; not part of the public API.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace plant {

namespace crew_detail {

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

// Runs one part, keeping what it throws in `error` (the first part to throw wins).
inline void run_part(void (*job)(void*, std::size_t), void* context, std::size_t k, std::exception_ptr& error,
                     std::mutex& error_mutex) {
    try {
        job(context, k);
    } catch (...) {
        std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
    }
}

// Threads that wait for parts to run. A call raises `round_` and wakes them; the caller and
// the threads then take parts in turn from one counter until none is left, so a part goes to
// whoever is free first. A thread that wakes late (on a virtual machine a sleeping core can take
// milliseconds to be scheduled again) finds the parts taken and the caller has not waited for
// it: a call takes at worst about what it takes on one thread, never that plus the late thread's
// delay. Which thread runs a part does not change what the part does. The crew is made once and
// never destroyed: its threads sleep through the process's exit, and no static destructor can
// find it gone.
class Crew {
  public:
    // false when the crew is busy with another call (from another thread, or from inside a part)
    bool run(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
        bool expected = false;
        if (!busy_.compare_exchange_strong(expected, true, std::memory_order_acquire)) return false;
        std::uint32_t tag = 0;
        {
            std::lock_guard lock(mutex_);
            try {
                while (threads_.size() + 1 < parts) {
                    threads_.emplace_back([this] { serve(); });
                }
            } catch (...) { // no thread to be had: the crew stays usable for fewer parts
                busy_.store(false, std::memory_order_release);
                throw;
            }
            job_ = job;
            context_ = context;
            parts_ = parts;
            error_ = nullptr;
            done_.store(0, std::memory_order_relaxed);
            tag = static_cast<std::uint32_t>(round_.load(std::memory_order_relaxed) + 1);
            next_.store(std::uint64_t{tag} << 32, std::memory_order_relaxed);
            round_.fetch_add(1, std::memory_order_release);
        }
        wake_.notify_all();
        for (std::size_t k; (k = take(tag, parts)) < parts;) {
            run_part(job, context, k, error_, error_mutex_);
            done_.fetch_add(1, std::memory_order_acq_rel);
        }
        // every part finishes before this returns, also when one threw: the others use the
        // caller's data. They are usually about as far along, so look briefly before sleeping.
        for (int spin = 0; spin < 4096 && done_.load(std::memory_order_acquire) < parts; ++spin) cpu_relax();
        if (done_.load(std::memory_order_acquire) < parts) {
            std::unique_lock lock(mutex_);
            finished_.wait(lock, [&] { return done_.load(std::memory_order_acquire) >= parts; });
        }
        std::exception_ptr error = error_;
        error_ = nullptr;
        busy_.store(false, std::memory_order_release);
        if (error) std::rethrow_exception(error);
        return true;
    }

  private:
    // The next part of the round tagged `tag`, or `parts` when the round has none left or is
    // over (a newer round's tag is in the counter).
    std::size_t take(std::uint32_t tag, std::size_t parts) {
        std::uint64_t c = next_.load(std::memory_order_acquire);
        for (;;) {
            const std::size_t k = static_cast<std::uint32_t>(c);
            if ((c >> 32) != tag || k >= parts) return parts;
            if (next_.compare_exchange_weak(c, c + 1, std::memory_order_acq_rel)) return k;
        }
    }

    void serve() {
        std::uint64_t seen = 0;
        for (;;) {
            // a step hands out parts a dozen times in quick succession: look for the next round
            // for a little while before sleeping, since waking a sleeping thread takes longer
            for (int spin = 0; spin < (1 << 14) && round_.load(std::memory_order_acquire) == seen; ++spin)
                cpu_relax();
            void (*job)(void*, std::size_t) = nullptr;
            void* context = nullptr;
            std::size_t parts = 0;
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return round_.load(std::memory_order_relaxed) != seen; });
                seen = round_.load(std::memory_order_relaxed);
                job = job_;
                context = context_;
                parts = parts_;
            }
            // (job and context are those of round `seen`; they are used only for a part taken
            // in that round, while its caller waits for it)
            const auto tag = static_cast<std::uint32_t>(seen);
            for (std::size_t k; (k = take(tag, parts)) < parts;) {
                run_part(job, context, k, error_, error_mutex_);
                if (done_.fetch_add(1, std::memory_order_acq_rel) + 1 == parts) {
                    std::lock_guard lock(mutex_); // the caller may be between its check and its wait
                    finished_.notify_one();
                }
            }
        }
    }

    std::atomic<bool> busy_{false}; // one call at a time
    std::mutex mutex_;              // guards what follows, except the atomics
    std::condition_variable wake_, finished_;
    std::vector<std::thread> threads_;
    void (*job_)(void*, std::size_t) = nullptr;
    void* context_ = nullptr;
    std::size_t parts_ = 0;
    std::atomic<std::uint64_t> round_{0}; // written under mutex_, also read without it
    std::atomic<std::uint64_t> next_{0};  // the round's tag (its low 32 bits) above its next part
    std::atomic<std::size_t> done_{0};    // the round's parts finished
    std::mutex error_mutex_;
    std::exception_ptr error_; // what the first part to throw threw, this call
};

inline Crew& crew() {
    static Crew* c = new Crew; // never destroyed (see Crew)
    return *c;
}

} // namespace crew_detail

// Runs job(context, k) for k in [0, parts) on the calling thread and the kept threads, each
// part once, taken by whichever is free first. When those are busy (a call from inside a part,
// or from two threads at once: the view server's requests, --jobs variants) the parts run on
// threads started for this call instead. Returns when every part has finished; if parts threw,
// rethrows what the first to throw threw.
inline void run_on_crew(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
    if (parts <= 1) {
        if (parts == 1) job(context, 0);
        return;
    }
    if (crew_detail::crew().run(parts, job, context)) return;
    std::exception_ptr error;
    std::mutex error_mutex;
    {
        std::vector<std::jthread> pool;
        pool.reserve(parts - 1);
        for (std::size_t k = 1; k < parts; ++k)
            pool.emplace_back([&, k] { crew_detail::run_part(job, context, k, error, error_mutex); });
        crew_detail::run_part(job, context, 0, error, error_mutex);
    } // joined here
    if (error) std::rethrow_exception(error);
}

// run_on_crew for a callable f(k).
template <class F> void run_on_crew(std::size_t parts, F&& f) {
    using Fn = std::remove_reference_t<F>;
    run_on_crew(
        parts, [](void* c, std::size_t k) { (*static_cast<Fn*>(c))(k); },
        const_cast<void*>(static_cast<const void*>(&f)));
}

} // namespace plant
