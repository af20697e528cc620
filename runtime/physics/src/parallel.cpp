#include "parallel.hpp"

#include <atomic>
#include <cstdint>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace plant::physics {

namespace {

// Threads that wait for parts to run. A call hands out parts 1..parts-1 by raising `round`;
// each thread takes the part of its own number, if there is one, and counts itself done.
class Crew {
public:
    ~Crew() {
        {
            std::lock_guard lock(mutex_);
            stop_ = true;
        }
        wake_.notify_all();
        for (auto& t : threads_) t.join();
    }

    // false when the crew is busy with another call
    bool run(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
        std::unique_lock busy(busy_, std::try_to_lock);
        if (!busy.owns_lock()) return false;
        {
            std::lock_guard lock(mutex_);
            while (threads_.size() + 1 < parts) {
                const std::size_t number = threads_.size() + 1;
                threads_.emplace_back([this, number] { serve(number); });
            }
            job_ = job;
            context_ = context;
            parts_ = parts;
            done_.store(0, std::memory_order_relaxed);
            round_.fetch_add(1, std::memory_order_release);
        }
        wake_.notify_all();
        job(context, 0);
        // the others are usually about as far along: wait for them briefly before sleeping
        const std::size_t others = parts - 1;
        for (int spin = 0; spin < 4096 && done_.load(std::memory_order_acquire) < others; ++spin) std::this_thread::yield();
        if (done_.load(std::memory_order_acquire) < others) {
            std::unique_lock lock(mutex_);
            finished_.wait(lock, [&] { return done_.load(std::memory_order_acquire) >= others; });
        }
        return true;
    }

private:
    void serve(std::size_t number) {
        std::uint64_t seen = 0;
        for (;;) {
            void (*job)(void*, std::size_t) = nullptr;
            void* context = nullptr;
            std::size_t parts = 0;
            // a step hands out parts a dozen times in quick succession: look for the next round
            // for a little while before sleeping, since waking a sleeping thread takes longer
            for (int spin = 0; spin < (1 << 14) && round_.load(std::memory_order_acquire) == seen; ++spin) {
            }
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return stop_ || round_.load(std::memory_order_relaxed) != seen; });
                if (stop_) return;
                seen = round_.load(std::memory_order_relaxed);
                job = job_;
                context = context_;
                parts = parts_;
            }
            if (number >= parts) continue; // not needed this round: do not count
            job(context, number);
            if (done_.fetch_add(1, std::memory_order_acq_rel) + 1 == parts - 1) {
                std::lock_guard lock(mutex_); // the caller may be between its check and its wait
                finished_.notify_one();
            }
        }
    }

    std::mutex busy_;  // one call at a time
    std::mutex mutex_; // guards what follows, except done_
    std::condition_variable wake_, finished_;
    std::vector<std::thread> threads_;
    void (*job_)(void*, std::size_t) = nullptr;
    void* context_ = nullptr;
    std::size_t parts_ = 0;
    std::atomic<std::uint64_t> round_{0}; // written under mutex_, also read without it
    bool stop_ = false;
    std::atomic<std::size_t> done_{0};
};

Crew& crew() {
    static Crew c;
    return c;
}

} // namespace

void run_parts(std::size_t parts, void (*job)(void*, std::size_t), void* context) {
    if (parts <= 1) {
        if (parts == 1) job(context, 0);
        return;
    }
    if (crew().run(parts, job, context)) return;
    std::vector<std::thread> pool;
    pool.reserve(parts - 1);
    for (std::size_t k = 1; k < parts; ++k) pool.emplace_back([job, context, k] { job(context, k); });
    job(context, 0);
    for (auto& t : pool) t.join();
}

} // namespace plant::physics
