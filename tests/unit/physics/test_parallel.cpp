// The physics runtime's thread crew (runtime/physics/src/parallel.hpp): every index of a split
// loop runs exactly once, over many calls, from inside a part, and from two threads at once.
#include "parallel.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

using plant::physics::parallel_ranges;

namespace {

// Runs a split loop that counts each index it visits; true when every index of [0, n) was
// visited once.
bool covers_once(std::size_t n, int threads, std::size_t grain) {
    std::vector<std::atomic<int>> seen(n);
    parallel_ranges(n, threads, grain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) seen[i].fetch_add(1, std::memory_order_relaxed);
    });
    for (auto& s : seen)
        if (s.load() != 1) return false;
    return true;
}

} // namespace

TEST_CASE("parallel: a split loop visits every index once, call after call") {
    for (int threads : {1, 2, 3, 4, 7})
        for (std::size_t n : {0u, 1u, 5u, 100u, 4099u}) {
            INFO("threads " << threads << ", n " << n);
            for (int round = 0; round < 50; ++round) REQUIRE(covers_once(n, threads, 16));
        }
}

TEST_CASE("parallel: a split loop inside a part, and two callers at once") {
    // from inside a part the crew is busy: the inner loop runs on threads of its own
    std::atomic<int> inner_ok{0};
    parallel_ranges(64, 2, 16, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i)
            if (covers_once(200, 2, 16)) inner_ok.fetch_add(1);
    });
    CHECK(inner_ok.load() == 64);
    // two threads splitting loops at the same time: one gets the crew, the other its own threads
    std::atomic<int> failures{0};
    auto caller = [&] {
        for (int round = 0; round < 200; ++round)
            if (!covers_once(3000, 2, 16)) failures.fetch_add(1);
    };
    std::thread a(caller), b(caller);
    a.join();
    b.join();
    CHECK(failures.load() == 0);
}

TEST_CASE("parallel: a part that throws") {
    // every part still runs to its end, the exception comes out of the call, and the next call
    // works as before
    for (std::size_t bad : {0u, 1u}) {
        INFO("throwing part " << bad);
        std::atomic<int> ran{0};
        CHECK_THROWS_AS(parallel_ranges(4096, 2, 16,
                                        [&](std::size_t b, std::size_t) {
                                            ran.fetch_add(1);
                                            if ((b == 0) == (bad == 0)) throw std::runtime_error("part");
                                        }),
                        std::runtime_error);
        CHECK(ran.load() == 2);
        CHECK(covers_once(4096, 2, 16));
    }
}
