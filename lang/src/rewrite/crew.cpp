// The derivation's kept threads (crew.hpp). One round per call: the caller publishes the job and
// bumps the round number; each kept thread whose number is below the part count runs its part and
// reports. A kept thread waits for the next round by looking for a short while, then sleeping on a
// condition variable: the passes of one step follow each other within microseconds, but between
// steps the caller may run single-threaded work (decomposition, hooks) for a long time, and a
// thread spinning then would take a core from it on a small machine.
#include "crew.hpp"

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace plant {

namespace {

void pause_briefly() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
}

class Crew {
  public:
    // False, having run nothing, when another call holds the crew.
    bool run(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
        bool idle = false;
        if (!busy_.compare_exchange_strong(idle, true, std::memory_order_acquire)) return false;
        {
            std::lock_guard hold(mutex_);
            try {
                while (threads_.size() + 1 < parts) {
                    const std::size_t number = threads_.size() + 1;
                    threads_.emplace_back([this, number] { serve(number); });
                }
            } catch (...) {
                busy_.store(false, std::memory_order_release);
                throw;
            }
            job_ = job;
            context_ = context;
            parts_ = parts;
            failure_ = nullptr;
            finished_.store(0, std::memory_order_relaxed);
            round_.fetch_add(1, std::memory_order_release);
        }
        wake_.notify_all();
        attempt(job, context, 0);
        const std::size_t others = parts - 1;
        for (int k = 0; k < 2048 && finished_.load(std::memory_order_acquire) < others; ++k) pause_briefly();
        if (finished_.load(std::memory_order_acquire) < others) {
            std::unique_lock hold(mutex_);
            all_done_.wait(hold, [&] { return finished_.load(std::memory_order_acquire) >= others; });
        }
        std::exception_ptr failure = failure_;
        failure_ = nullptr;
        busy_.store(false, std::memory_order_release);
        if (failure) std::rethrow_exception(failure);
        return true;
    }

  private:
    void attempt(void (*job)(void*, std::size_t), void* context, std::size_t k) {
        try {
            job(context, k);
        } catch (...) {
            std::lock_guard hold(failure_mutex_);
            if (!failure_) failure_ = std::current_exception();
        }
    }

    void serve(std::size_t number) {
        std::uint64_t seen = 0;
        for (;;) {
            for (int k = 0; k < 2048 && round_.load(std::memory_order_acquire) == seen; ++k) pause_briefly();
            void (*job)(void*, std::size_t) = nullptr;
            void* context = nullptr;
            std::size_t parts = 0;
            {
                std::unique_lock hold(mutex_);
                wake_.wait(hold, [&] { return round_.load(std::memory_order_relaxed) != seen; });
                seen = round_.load(std::memory_order_relaxed);
                job = job_;
                context = context_;
                parts = parts_;
            }
            if (number >= parts) continue; // this round needs fewer threads
            attempt(job, context, number);
            if (finished_.fetch_add(1, std::memory_order_acq_rel) + 1 == parts - 1) {
                std::lock_guard hold(mutex_); // (the caller may be between its test and its wait)
                all_done_.notify_one();
            }
        }
    }

    std::atomic<bool> busy_{false};
    std::mutex mutex_; // guards the job and the thread list; the counters are atomics
    std::condition_variable wake_, all_done_;
    std::vector<std::thread> threads_;
    void (*job_)(void*, std::size_t) = nullptr;
    void* context_ = nullptr;
    std::size_t parts_ = 0;
    std::atomic<std::uint64_t> round_{0};
    std::atomic<std::size_t> finished_{0};
    std::mutex failure_mutex_;
    std::exception_ptr failure_;
};

// Made on first use and never destroyed: its threads sleep through the process's exit, and no
// static destructor runs while one of them might still hold it.
Crew& crew() {
    static Crew* c = new Crew;
    return *c;
}

} // namespace

void run_on_crew(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
    if (parts <= 1) {
        if (parts == 1) job(context, 0);
        return;
    }
    if (crew().run(parts, job, context)) return;
    std::exception_ptr failure;
    std::mutex failure_mutex;
    auto attempt = [&](std::size_t k) {
        try {
            job(context, k);
        } catch (...) {
            std::lock_guard hold(failure_mutex);
            if (!failure) failure = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> started;
        started.reserve(parts - 1);
        for (std::size_t k = 1; k < parts; ++k) started.emplace_back([&attempt, k] { attempt(k); });
        attempt(0);
    }
    if (failure) std::rethrow_exception(failure);
}

} // namespace plant
