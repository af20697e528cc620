// The kept threads (common/include/plant/crew.hpp, shared by the derivation and the physics):
// every part of a call runs exactly once on its own thread, call after call on the same kept
// threads, from inside a part (which falls back to threads of its own) and from two callers at
// once; what a part throws reaches the caller.
#include <plant/crew.hpp>

#include <catch2/catch.hpp>

#include <atomic>
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

} // namespace

TEST_CASE("crew: every part runs once, on as many threads, call after call") {
    for (int call = 0; call < 200; ++call) CHECK(each_once(1 + static_cast<std::size_t>(call) % 4));
    std::mutex m;
    std::set<std::thread::id> threads;
    run_on_crew(3, [&](std::size_t) {
        std::lock_guard hold(m);
        threads.insert(std::this_thread::get_id());
    });
    CHECK(threads.size() == 3);
    CHECK(threads.count(std::this_thread::get_id()) == 1); // part 0 on the caller
    // the same threads, kept: what a part leaves on its thread is there at the next call (a
    // thread started for the call would start from nothing)
    static thread_local int calls_here = 0;
    std::atomic<int> fresh{0};
    for (int call = 0; call < 2; ++call)
        run_on_crew(3, [&](std::size_t) {
            if (call == 1 && calls_here == 0) fresh.fetch_add(1);
            ++calls_here;
        });
    CHECK(fresh.load() == 0);
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
