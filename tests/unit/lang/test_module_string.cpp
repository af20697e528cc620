// The module string keeps no per-module parameter offset: arities and the offset of every
// kBlock-th module (module_string.hpp). These check every way of writing a string against a
// plain list of modules, across block boundaries and with arities from 0 to the limit.
#include "helpers.hpp"
#include "plant/module_string.hpp"

#include <catch2/catch.hpp>

#include <vector>

using namespace plant;

namespace {

struct Plain {
    std::vector<std::vector<double>> args;
};

// module i has arity (i * 7) % 5, except a few at the limit; parameters count up
Plain plain(std::size_t n) {
    Plain p;
    double v = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t k = i % 97 == 3 ? ModuleString::kMaxArity : (i * 7) % 5;
        std::vector<double> a(k);
        for (auto& x : a) x = v++;
        p.args.push_back(a);
    }
    return p;
}

void check_same(const ModuleString& s, const Plain& p, std::size_t from = 0) {
    REQUIRE(s.size() == p.args.size() - from);
    std::size_t total = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto& want = p.args[from + i];
        REQUIRE(s.arity(i) == want.size());
        REQUIRE(s.offset(i) == total);
        for (std::size_t k = 0; k < want.size(); ++k) REQUIRE(s.args(i)[k] == want[k]);
        total += want.size();
    }
    CHECK(s.offset(s.size()) == s.params.size());
    CHECK(total == s.params.size());
}

ModuleString pushed(const Plain& p) {
    ModuleString s;
    s.keep_ids = false;
    for (std::size_t i = 0; i < p.args.size(); ++i)
        s.push(static_cast<SymbolId>(i % 3), p.args[i].data(), static_cast<std::uint32_t>(p.args[i].size()),
               0);
    return s;
}

// Every stored block offset is the sum of the arities before its block (what offset() relies on).
void check_blocks(const ModuleString& s) {
    REQUIRE(s.block_at.size() == (s.size() + ModuleString::kBlock - 1) / ModuleString::kBlock);
    std::size_t sum = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (i % ModuleString::kBlock == 0) REQUIRE(s.block_at[i / ModuleString::kBlock] == sum);
        sum += s.stored(i);
    }
    REQUIRE(sum == s.params.size());
}

} // namespace

TEST_CASE("module string: parameters found from arities and block offsets", "[module_string]") {
    const Plain p = plain(1000);
    const ModuleString s = pushed(p);
    check_same(s, p);

    SECTION("appended in ranges of every length, one module, and whole") {
        const std::size_t lens[] = {1, 2, 63, 64, 65, 200};
        for (std::size_t len : lens) {
            ModuleString t;
            t.keep_ids = false;
            for (std::size_t b = 0; b < s.size(); b += len) t.append_range(s, b, std::min(s.size(), b + len));
            check_same(t, p);
        }
        ModuleString t;
        t.keep_ids = false;
        t.append_range(s, 5, 6);
        t.append_range(s, 6, s.size()); // starts mid-block
        check_same(t, p, 5);
    }
    SECTION("cut back to a prefix, then grown again") {
        const std::size_t sizes[] = {0, 1, 63, 64, 65, 500};
        for (std::size_t m : sizes) {
            ModuleString t = s;
            t.truncate(m);
            Plain q = p;
            q.args.resize(m);
            check_same(t, q);
            t.append_range(s, m, s.size());
            check_same(t, p);
        }
    }
    SECTION("written directly, then indexed in stretches") {
        ModuleString t;
        t.keep_ids = false;
        t.kinds = s.kinds;
        t.use_kinds_of(s); // the counts of numbers come from the kinds
        t.params = s.params;
        t.block_at.assign((t.size() + ModuleString::kBlock - 1) / ModuleString::kBlock, 0xdead);
        // two stretches, the second starting inside a block
        t.index_range(0, 300, 0);
        t.index_range(300, t.size(), s.offset(300));
        check_same(t, p);
        CHECK(t.block_at == s.block_at);
    }
    SECTION("a module with more numbers than a byte counts is refused") {
        ModuleString t;
        std::vector<double> a(ModuleString::kMaxArity + 1, 1.0);
        CHECK_THROWS_AS(t.push(0, a.data(), static_cast<std::uint32_t>(a.size()), 0), std::length_error);
    }
}

TEST_CASE("module string: indexing stretches, arity 0 and not at block starts", "[module_string]") {
    // arity 0 at every other block start, 1..3 at the others, 0..4 inside blocks
    Plain p;
    double v = 0;
    for (std::size_t i = 0; i < 700; ++i) {
        const std::size_t blk = i / ModuleString::kBlock;
        const std::size_t k = i % ModuleString::kBlock == 0 ? (blk % 2 ? 1 + blk % 3 : 0) : (i * 5 + 1) % 5;
        std::vector<double> a(k);
        for (auto& x : a) x = v++;
        p.args.push_back(a);
    }
    const ModuleString s = pushed(p);
    check_same(s, p);
    check_blocks(s);
    // every module's offset, read in random order
    for (std::size_t i = 0, j = 0; i < s.size(); ++i, j = (j + 389) % s.size()) {
        std::size_t want = 0;
        for (std::size_t k = 0; k < j; ++k) want += p.args[k].size();
        REQUIRE(s.offset(j) == want);
    }
    // written directly, indexed in two stretches split at every point of the first blocks and
    // around later block starts
    std::vector<std::size_t> splits;
    for (std::size_t c = 0; c <= 2 * ModuleString::kBlock + 1; ++c) splits.push_back(c);
    for (std::size_t c : {255u, 256u, 257u, 640u, 699u, 700u}) splits.push_back(c);
    for (std::size_t c : splits) {
        ModuleString t;
        t.keep_ids = false;
        t.resize_arrays(s.size(), s.params.size());
        std::copy(s.kinds.begin(), s.kinds.end(), t.kinds.begin());
        t.use_kinds_of(s);
        std::copy(s.params.begin(), s.params.end(), t.params.begin());
        t.block_at.assign((t.size() + ModuleString::kBlock - 1) / ModuleString::kBlock, 0xdead);
        t.index_range(0, c, 0);
        t.index_range(c, t.size(), s.offset(c));
        INFO("split at " << c);
        CHECK(t.block_at == s.block_at);
        // index_from over a prefix already indexed
        t.block_at.assign(t.block_at.size(), 0xdead);
        t.index_from(0, 0);
        CHECK(t.block_at == s.block_at);
    }
}

// Each rewriting route writes the arrays its own way (direct.cpp, templated.cpp, symbols.cpp,
// general.cpp, engine.cpp for threads): after every step the block offsets must agree with the
// arities, also when a route outgrows the room it reserved (templated's arrays reopened).
TEST_CASE("module string: every rewriting route keeps the block offsets right", "[module_string]") {
    struct Case {
        const char* grammar;
        int steps;
    };
    const Case cases[] = {
        // direct (parametric, no context)
        {"module A(x); module B(x, y); axiom: A(1); rules { A(x) -> B(x, 1) [ A(x + 1) ] C A(x * 2); "
         "B(x, y) -> B(x + y, y); }",
         14},
        // templated: parametric direct templates and a parameterless context table. The R part
        // grows faster than the L part and overtakes it, so the step's growth exceeds the last
        // step's and the arrays are reopened mid-step (on two threads: the second stretch, all
        // R, grows faster than the whole string did)
        {"module L(x); module R(x); axiom: L(0) L(0) L(0) L(0) L(0) L(0) L(0) L(0) R(0) [ X ] Y; "
         "rules { L(x) -> L(x) L(x + 1); R(x) -> R(x) R(x) R(x + 1); X < Y -> Y; }",
         12},
        // general: a condition on a context
        {"module A(x); axiom: A(1) A(2) A(3); rules { A(x) < A(y) : y > x -> A(y) [ A(x) ] A(x + y); "
         "A(x) -> A(x + 1) E(x) A(x); }",
         12},
        // symbols: parameterless with context
        {"axiom: F X G; rules { F < X > G -> X F X; X -> F [ X ] G X; F -> F F; }", 13},
    };
    for (const Case& k : cases) {
        const char* g = k.grammar;
        auto c = test::compile(g);
        INFO(g << "\n" << c->rendered());
        REQUIRE(c->program);
        for (int threads : {1, 2}) {
            for (bool ids : {false, true}) {
                DeriveOptions o;
                o.threads = threads;
                o.steps = k.steps;
                o.identities = ids;
                Derivation d(*c->program, o);
                d.start();
                int steps = 0;
                while (d.step()) {
                    ++steps;
                    INFO("threads " << threads << ", ids " << ids << ", step " << steps);
                    check_blocks(d.string());
                }
                CHECK(steps > 0);
                CHECK(d.string().size() > 40000); // the last steps ran on two threads when asked
            }
        }
    }
}
