// The direct path on several threads sizes each thread's stretch from the snapshots the last
// step's writers took (Engine::size_slices, docs/rewriting.md "The direct path") instead of
// counting the whole string: the strings, identities and block offsets are those of one thread,
// and the string is read to count only once (the first step past 20,000 modules) and then only
// the few modules after each snapshot.
#include "helpers.hpp"
#include "plant/module_string.hpp"

#include <catch2/catch.hpp>

#include <algorithm>

using namespace plant;

namespace {

struct Run {
    ModuleString string;
    ModuleId next_id = 0;
    std::uint64_t counted = 0;
};

Run run(const Program& program, int threads, bool ids) {
    DeriveOptions o;
    o.threads = threads;
    o.identities = ids;
    o.seed = 11;
    Derivation d(program, o);
    d.run();
    return {d.string(), d.next_id(), d.modules_counted()};
}

// The block offsets, which the writers fill as they write (ModuleString::block_at), are the
// numbers stored before each block's first module.
void indexed(const ModuleString& s) {
    REQUIRE(s.block_at.size() == (s.size() + ModuleString::kBlock - 1) / ModuleString::kBlock);
    std::size_t sum = 0, wrong = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (i % ModuleString::kBlock == 0 && s.block_at[i / ModuleString::kBlock] != sum) ++wrong;
        sum += s.stored(i);
    }
    CHECK(wrong == 0);
    CHECK(sum == s.params.size());
}

void same(const Run& a, const Run& b) {
    indexed(a.string);
    indexed(b.string);
    REQUIRE(a.string.size() == b.string.size());
    CHECK(std::equal(a.string.kinds.begin(), a.string.kinds.end(), b.string.kinds.begin()));
    CHECK(std::equal(a.string.block_at.begin(), a.string.block_at.end(), b.string.block_at.begin()));
    CHECK(a.string.params == b.string.params);
    CHECK(a.string.ids == b.string.ids);
    CHECK(a.next_id == b.next_id);
}

} // namespace

TEST_CASE("several threads on the direct path size their stretches without counting", "[derive][threads]") {
    // the tree: every step doubles the A's, 9 * 2^16 - 8 = 589,816 modules at the end
    auto c = test::compile("module A(l, w); axiom: A(1, 10); derive 16; "
                           "rules { A(l, w) -> F(l, w) [ &(30) A(l * 0.9, w * 0.707) ] /(137.5) "
                           "[ &(-30) A(l * 0.7, w * 0.707) ]; }");
    REQUIRE(c->program);
    for (bool ids : {false, true}) {
        INFO("identities " << ids);
        const Run one = run(*c->program, 1, ids);
        CHECK(one.counted == 1); // one thread: only the axiom, by the first step
        for (int threads : {2, 3}) {
            INFO("threads " << threads);
            const Run many = run(*c->program, threads, ids);
            same(one, many);
            // steps 13 to 16 (36,856 to 294,904 modules in) run on several threads. Counting
            // their inputs would read 552,928 modules; from the snapshots, each boundary between
            // threads reads what follows the last snapshot before it: the output of at most
            // 8,192 modules, about 16,000 modules here (an A in nine becomes nine)
            CHECK(many.counted > 1);
            CHECK(many.counted < 1 + 4 * static_cast<std::uint64_t>(threads - 1) * 20000);
        }
    }
}

TEST_CASE("stretches sized from bounds that the writers do not fill are counted again", "[derive][threads]") {
    // stochastic and conditional, so the sizes are bounds: an A with l < 0.3 is copied (1
    // module, not 5), so the first step on two threads misses its bounds, writes again after
    // counting, and later steps count
    auto c = test::compile("module A(l); axiom: A(1) A(1) A(1) A(1); derive 15; "
                           "rules { A(l) : l >= 0.3 -> F [ A(l * 0.9) ] A(l * 0.97) : 2; "
                           "A(l) : l >= 0.3 -> F [ A(l * 0.8) ] A(l * 0.99) : 1; F -> F; }");
    REQUIRE(c->program);
    // the same with conditions every A meets: the bounds are exact and nothing is counted again
    auto exact = test::compile("module A(l); axiom: A(1) A(1) A(1) A(1); derive 15; "
                               "rules { A(l) : l >= 0.3 -> F [ A(l * 0.9) ] A(l * 0.97) : 2; "
                               "A(l) : l >= 0.3 -> F [ A(l * 0.8) ] A(l * 0.99) : 1; "
                               "A(l) : l < 0.3 -> F [ A(l) ] A(l) : 1; F -> F; }");
    REQUIRE(exact->program);
    for (bool ids : {false, true}) {
        INFO("identities " << ids);
        const Run one = run(*c->program, 1, ids), two = run(*c->program, 2, ids);
        same(one, two);
        CHECK(one.string.size() > 40000);
        const Run exact_one = run(*exact->program, 1, ids), exact_two = run(*exact->program, 2, ids);
        same(exact_one, exact_two);
        // the missed bounds make every step from the miss on count its whole input, the last
        // step's among them (more than a third of the final string here); exact bounds count a
        // few snapshots' worth a step
        CHECK(3 * two.counted > two.string.size());
        CHECK(4 * exact_two.counted < exact_two.string.size());
    }
}
