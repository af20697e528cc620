// The kept threads (common/include/plant/crew.hpp, shared by the derivation and the physics):
// every part of a call runs exactly once, taken by whichever thread is free, call after call on
// the same kept threads, from inside a part (which falls back to threads of its own) and from two
// callers at once; what a part throws reaches the caller.
#include <plant/crew.hpp>

#include <catch2/catch.hpp>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

using plant::run_on_crew;

namespace {

// Runs `parts` parts that each count themselves; true when each ran once.
bool each_once(std::size_t parts) {
    std::vector<std::atomic<int>> ran(parts);
    run_on_crew(parts, [&](std::size_t k) { ran[k].fetch_add(1); });
    for (auto& r : ran)
        if (r.load() != 1) return false;
    return true;
}

// Runs `parts` parts that each wait (up to ten seconds) until all of them have started, so that
// each must be on a thread of its own; true when they all met. Adds the threads they ran on to
// `threads`.
bool all_at_once(std::size_t parts, std::set<std::thread::id>& threads) {
    std::mutex m;
    std::condition_variable cv;
    std::size_t started = 0;
    bool met = true;
    run_on_crew(parts, [&](std::size_t) {
        std::unique_lock lock(m);
        threads.insert(std::this_thread::get_id());
        ++started;
        cv.notify_all();
        if (!cv.wait_for(lock, std::chrono::seconds(10), [&] { return started == parts; })) met = false;
    });
    return met;
}

} // namespace

TEST_CASE("crew: every part runs once, on the kept threads, call after call") {
    for (int call = 0; call < 200; ++call) CHECK(each_once(1 + static_cast<std::size_t>(call) % 4));
    // parts that wait for each other run side by side: the caller and two kept threads
    std::set<std::thread::id> threads;
    CHECK(all_at_once(3, threads));
    CHECK(threads.size() == 3);
    CHECK(threads.count(std::this_thread::get_id()) == 1);
    // the same threads, kept: what a part leaves on its thread is there at the next call. Over
    // fifty calls the parts meet a thread new to them only on the caller and the kept threads
    // (one for each part of the widest call the process has made: four here, more when other
    // tests ran first in the same process, as with --order rand), where threads started for each
    // call would each start from nothing, about a hundred times.
    static thread_local int calls_here = 0;
    std::atomic<int> fresh{0};
    for (int call = 0; call < 50; ++call)
        run_on_crew(3, [&](std::size_t) {
            if (calls_here++ == 0) fresh.fetch_add(1);
        });
    CHECK(fresh.load() < 16);
}

TEST_CASE("crew: a call from inside a part, and two callers at once") {
    std::atomic<int> inner{0};
    run_on_crew(2, [&](std::size_t) {
        std::vector<std::atomic<int>> ran(3);
        run_on_crew(3, [&](std::size_t k) { ran[k].fetch_add(1); });
        for (auto& r : ran) inner.fetch_add(r.load());
    });
    CHECK(inner.load() == 6);
    std::atomic<bool> ok_a{true}, ok_b{true};
    std::thread a([&] {
        for (int k = 0; k < 100; ++k) ok_a = ok_a && each_once(2);
    });
    std::thread b([&] {
        for (int k = 0; k < 100; ++k) ok_b = ok_b && each_once(3);
    });
    a.join();
    b.join();
    CHECK(ok_a.load());
    CHECK(ok_b.load());
}

TEST_CASE("crew: what a part throws reaches the caller, after every part finished") {
    std::atomic<int> finished{0};
    CHECK_THROWS_AS(run_on_crew(3,
                                [&](std::size_t k) {
                                    if (k == 1) throw std::runtime_error("part 1");
                                    finished.fetch_add(1);
                                }),
                    std::runtime_error);
    CHECK(finished.load() == 2);
    CHECK(each_once(3)); // and the crew is free again
}
