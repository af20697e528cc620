#include "helpers.hpp"
#include "plant/random.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

using namespace plant;
using plant::test::derive;

namespace {
std::string run_with(const char* g, std::uint64_t seed, int threads) {
    DeriveOptions o;
    o.seed = seed;
    o.threads = threads;
    return derive(g, o);
}
// A grammar big enough (> 20,000 modules) that the engine really splits it between threads.
const char* kBushy = R"(
    derive 8;
    axiom: F;
    rules {
      F -> F[+F]F[-F]F : 1;
      F -> F[+F]F : 1;
      F -> F[-F]F : 1;
    })";
} // namespace

TEST_CASE("10,000 draws of a 0.3/0.7 rule land within 3 sigma", "[stochastic]") {
    // 10,000 A's, each rewritten once to X (weight 0.3) or Y (weight 0.7)
    auto c = test::compile(
        "axiom: A; derive 1; decompose max_depth 14 { A -> A A; } rules { A -> X : 0.3; A -> Y : 0.7; }");
    REQUIRE(c->program);
    // the decomposition doubles A 14 times: 16,384 draws
    DeriveOptions o;
    o.seed = 12345;
    Derivation d(*c->program, o);
    d.run();
    const auto x = *c->program->symbols.find("X");
    std::size_t n = d.string().size(), xs = 0;
    for (std::size_t i = 0; i < d.string().size(); ++i) xs += d.string().symbol(i) == x;
    REQUIRE(n == 16384);
    double mean = 0.3 * n, sigma = std::sqrt(n * 0.3 * 0.7);
    CHECK(std::fabs(double(xs) - mean) < 3 * sigma);
}

TEST_CASE("the counter-based generator is uniform over 0 <= u < 1", "[stochastic]") {
    int bins[10] = {};
    const int n = 100000;
    for (int i = 0; i < n; ++i) {
        double u = random_unit(random_bits(7, 1, static_cast<std::uint64_t>(i), 0));
        REQUIRE(u >= 0.0);
        REQUIRE(u < 1.0);
        ++bins[static_cast<int>(u * 10)];
    }
    for (int b : bins) CHECK(std::abs(b - n / 10) < 4 * std::sqrt(n * 0.1 * 0.9));
}

TEST_CASE("same seed, same string, and different seeds, different strings", "[stochastic]") {
    std::string a = run_with(kBushy, 1, 1);
    CHECK(a == run_with(kBushy, 1, 1));
    CHECK(a != run_with(kBushy, 2, 1));
    CHECK(run_with(kBushy, 2, 1) != run_with(kBushy, 3, 1));
}

TEST_CASE("1 thread and 2 threads give the same string and identities", "[stochastic][threads]") {
    auto c = test::compile(kBushy);
    REQUIRE(c->program);
    DeriveOptions o1, o2;
    o1.seed = o2.seed = 99;
    o1.threads = 1;
    o2.threads = 2;
    Derivation d1(*c->program, o1), d2(*c->program, o2);
    d1.run();
    d2.run();
    REQUIRE(d1.string().size() > 20000);
    CHECK(d1.string().kinds == d2.string().kinds);
    CHECK(d1.string().ids == d2.string().ids);
    CHECK(d1.string().params == d2.string().params);
}

TEST_CASE("random functions in successors are reproducible across thread counts", "[stochastic][threads]") {
    const char* g = R"(
        derive 6;
        module A(x);
        axiom: A(0);
        rules { A(x) -> F(uniform(0, 1)) [ A(normal(x, 1)) ] A(chance(0.5) ? 1 : 0) A(x); }
    )";
    CHECK(run_with(g, 5, 1) == run_with(g, 5, 2));
    CHECK(run_with(g, 5, 1) != run_with(g, 6, 1));
}

TEST_CASE("the direct path (templates written in place) agrees across thread counts", "[threads]") {
    // every module is either copied or rewritten by an unconditional template: the output is
    // counted first and each thread writes its stretch in place
    auto c = test::compile(R"(
        module A(l, w);
        derive 12;
        axiom: A(1, 10);
        rules { A(l, w) -> F(l, w) [ &(30) A(l * 0.9, w * 0.707) ] /(137.5) [ &(-30) A(l * 0.7, w * 0.707) ]; }
    )");
    REQUIRE(c->program);
    DeriveOptions o1, o2;
    o1.threads = 1;
    o2.threads = 2;
    Derivation d1(*c->program, o1), d2(*c->program, o2);
    d1.run();
    d2.run();
    REQUIRE(d1.string().size() == 9 * 4096 - 8);
    CHECK(d1.string().kinds == d2.string().kinds);
    CHECK(d1.string().params == d2.string().params);
    CHECK(d1.string().ids == d2.string().ids);
    CHECK(d1.string().block_at == d2.string().block_at);
    // identities are unique
    std::vector<ModuleId> ids(d1.string().ids.begin(), d1.string().ids.end());
    std::sort(ids.begin(), ids.end());
    CHECK(std::adjacent_find(ids.begin(), ids.end()) == ids.end());
}

TEST_CASE("guarded symbols on the direct path draw as the general path does", "[stochastic][threads]") {
    // `l >= 0.5` and constant weights keep A and F on the direct path (RulePlan::Guarded); the
    // same conditions written `l - 0.5 >= 0` need the stack machine, so the general path
    // rewrites them. Both must give the same strings, with a production that may not apply
    // (F is then copied), one of weight 0 and one that compares the constant first.
    const char* guarded = R"(
        derive 12;
        seed 3;
        module A(l, w);
        axiom: A(1, 10);
        rules {
          A(l, w) : l >= 0.5 -> F(l, w) [ &(30) A(l * 0.9, w * 0.707) ] /(137.5) [ A(l * 0.7, w) ] : 0.6;
          A(l, w) : 0.5 <= l -> F(l, w) [ &(20) A(l * 0.8, w * 0.707) ] : 0.4;
          A(l, w) : l >= 0.5 -> X : 0;
          A(l, w) : l < 0.5 -> F(l, w) [ A(l * 1.3, w) ] A(l * 1.2, w * 0.707) : 1;
          F(l, w) : l > 0.3 -> F(l * 1.02, w);
        })";
    std::string general = guarded;
    for (auto [from, to] : {std::pair{"l >= 0.5", "l - 0.5 >= 0"},
                            {"0.5 <= l", "0.5 - l <= 0"},
                            {"l < 0.5", "l - 0.5 < 0"},
                            {"l > 0.3", "l - 0.3 > 0"}}) {
        for (std::size_t at = general.find(from); at != std::string::npos; at = general.find(from, at))
            general.replace(at, std::string(from).size(), to);
    }
    REQUIRE(general.find("l >= 0.5") == std::string::npos);
    for (int threads : {1, 2}) {
        const std::string a = run_with(guarded, 3, threads), b = run_with(general.c_str(), 3, threads);
        CHECK(a.size() > 100000);
        CHECK(a == b);
    }
    // past RulePlan::kPickBits distinct intervals, pick_unlisted decides without the table: five
    // more productions of A, after the others, that never apply (the first four's three
    // conditions are two intervals, tested once each: 7 in all)
    std::string more = guarded;
    more.insert(more.find("F(l, w) : l > 0.3"), "A(l, w) : l > 100 -> X : 1; A(l, w) : l > 101 -> X : 2; "
                                                "A(l, w) : l > 102 -> X; A(l, w) : l > 103 -> X; "
                                                "A(l, w) : l < -100 -> X : 1;\n");
    CHECK(run_with(more.c_str(), 3, 2) == run_with(general.c_str(), 3, 2));
}

TEST_CASE("a guard's condition holds on the direct path exactly where the comparison does", "[stochastic]") {
    // The direct path tests `x OP c` as an interval of x (RulePlan::Guard::holds), strict bounds
    // moved to the next double; `|| 0` keeps the same comparison on the general path. Values on,
    // just below and just above each constant, and both zeros, with every operator both ways.
    const std::string axiom = "axiom: A(0.5) A(0.49999999999999994) A(0.5000000000000001) A(-0) A(0) "
                              "A(-5e-324) A(5e-324) A(-1) A(1);";
    for (const char* op : {"<", "<=", ">", ">=", "==", "!="}) {
        auto grammar = [&](const char* tail) {
            return fmt::format("derive 1; {} rules {{ A(x) : x {} 0.5{} -> B(x); A(x) : 0 {} x{} -> C(x); }}",
                               axiom, op, tail, op, tail);
        };
        const std::string direct = run_with(grammar("").c_str(), 1, 1);
        CAPTURE(op, direct);
        CHECK(direct == run_with(grammar(" || 0").c_str(), 1, 1));
    }
}

TEST_CASE("modules rewritten in place inside copied runs match the general path", "[stochastic][threads]") {
    // G, H and K rewrite a module into one of its own kind, so the direct path copies them with
    // the runs around them and then writes their numbers in place (Rewriter::copy_run): H and K
    // with one production and no draw, G drawn between two. `x - c < 0` keeps the same
    // conditions on the general path.
    const char* direct = R"(
        derive 11;
        seed 4;
        axiom: A(1) G(1, 2) H(1);
        rules {
          A(x) -> [ G(x, x) ] H(x) A(x * 1.1) [ K(x) ] K(x);
          G(x, y) : x < 3 -> G(x * 1.5, y + 1) : 1;
          G(x, y) : x < 3 -> G(x * 0.5, y) : 2;
          H(x) : x < 2 -> H(x + 0.25);
          K(x) : x < 1.5 -> K(x * 1.1);
        })";
    std::string general = direct;
    for (auto [from, to] :
         {std::pair{"x < 3", "x - 3 < 0"}, {"x < 2", "x - 2 < 0"}, {"x < 1.5", "x - 1.5 < 0"}}) {
        for (std::size_t at = general.find(from); at != std::string::npos; at = general.find(from, at))
            general.replace(at, std::string(from).size(), to);
    }
    for (int threads : {1, 2}) {
        const std::string a = run_with(direct, 4, threads);
        CHECK(a.size() > 1000);
        CHECK(a == run_with(general.c_str(), 4, threads));
    }
}

TEST_CASE("output sized from the last step's tallies matches the general path", "[stochastic]") {
    // On one thread the direct path sizes a step's output from what the step before tallied
    // (Engine::counts) rather than counting: here with modules of A that carry no parameter
    // (copied), a guarded symbol whose outcomes differ in size, and decomposition in between.
    const char* direct = R"(
        derive 14;
        seed 5;
        axiom: A(3) A B;
        rules {
          A(n) : n > 1 -> A(n - 1) A B : 1;
          A(n) : n > 1 -> B A(n + 1) [ A ] : 2;
          A(n) : n <= 1 -> A(n + 2);
          B -> A(2) B;
        }
        decompose { A(n) : n > 4 -> A(n - 3) F; })";
    std::string general = direct;
    for (auto [from, to] : {std::pair{"n > 1", "n - 1 > 0"}, {"n <= 1", "n - 1 <= 0"}}) {
        for (std::size_t at = general.find(from); at != std::string::npos; at = general.find(from, at))
            general.replace(at, std::string(from).size(), to);
    }
    const std::string a = run_with(direct, 5, 1);
    CHECK(a.size() > 10000);
    CHECK(a == run_with(general.c_str(), 5, 1));
}

TEST_CASE("the direct path computes a template's numbers from the module's own, in any order", "[derive]") {
    // A's numbers reach its successors swapped, repeated, scaled and shifted, -0 among them: the
    // direct path reads them straight from the module (RulePlan::outcome_args); with a condition
    // the plan cannot read (`a == a`), the general path binds them by name first and runs the
    // template's code. Both must give the same numbers, bit for bit.
    const std::string rules = R"(
          A(a, b, c) COND -> B(c) A(b + 0.5, a * 1.5, c) [ A(c, c * -1, a + -2) ];
          B(x) -> B(x * 0.5);
        })";
    const std::string head = R"(
        derive 9;
        module A(a, b, c);
        axiom: A(1, -0, 3) B(2);
        rules {)";
    auto make = [&](const std::string& cond) {
        std::string r = rules;
        r.replace(r.find("COND"), 4, cond);
        return test::compile(head + r);
    };
    auto direct = make(""), general = make(": a == a");
    REQUIRE(direct->program);
    REQUIRE(general->program);
    Derivation d1(*direct->program, {}), d2(*general->program, {});
    d1.run();
    d2.run();
    const ModuleString &s1 = d1.string(), &s2 = d2.string();
    REQUIRE(s1.size() == s2.size());
    REQUIRE(s1.size() > 1000);
    CHECK(s1.same_modules(s2));
    std::size_t negative_zeros = 0;
    for (std::size_t i = 0; i < s1.size(); ++i)
        for (std::uint32_t k = 0; k < s1.arity(i); ++k) {
            const double x = s1.args(i)[k], y = s2.args(i)[k];
            CHECK(std::memcmp(&x, &y, sizeof x) == 0);
            negative_zeros += x == 0 && std::signbit(x);
        }
    CHECK(negative_zeros > 0);
}

TEST_CASE("a number that overflows on the direct path is named as on the general path", "[derive][limits]") {
    // Each successor's first computed number stays finite and a later one overflows (a product,
    // then a sum): the error names the first number that is not finite, on either path.
    for (const char* cond : {"", ": x == x "}) {
        const std::string product = std::string("axiom: A(1e300, 1); derive 3; rules { A(x, y) ") + cond +
                                    "-> B(y) A(x * 1e5, y + 1); }";
        const std::string sum = std::string("axiom: A(1e300, 1); derive 4; rules { A(x, y) ") + cond +
                                "-> B(x) A(y, x + 1.7e308); }";
        auto c1 = test::compile(product), c2 = test::compile(sum);
        REQUIRE(c1->program);
        REQUIRE(c2->program);
        Derivation d1(*c1->program, {}), d2(*c2->program, {});
        CHECK_THROWS_WITH(d1.run(), "step 2: parameter 1 of 'A' is infinite");
        CHECK_THROWS_WITH(d2.run(), "step 3: parameter 2 of 'A' is infinite");
    }
    // a module rewritten in place inside a copied run (one guard, no draw: Rewriter::put_moved),
    // and on the general path (`x - 0 > 0`)
    for (const char* cond : {"x > 0", "x - 0 > 0"}) {
        auto c = test::compile(std::string("axiom: X G(1e300, 1) X; derive 3; rules { G(x, y) : ") + cond +
                               " -> G(x * 1e5, y); }");
        REQUIRE(c->program);
        Derivation d(*c->program, {});
        CHECK_THROWS_WITH(d.run(), "step 2: parameter 1 of 'G' is infinite");
    }
    // two finite numbers whose sum overflows: the test of the sum is only a first look, and no
    // number is reported
    for (const char* cond : {"x > 0", "x - 0 > 0"}) {
        auto c = test::compile(std::string("axiom: X G(1.7e308, 1.7e308) X; derive 2; rules { G(x, y) : ") +
                               cond + " -> G(x + 0.5, y + 0.5); }");
        REQUIRE(c->program);
        Derivation d(*c->program, {});
        CHECK_NOTHROW(d.run());
        CHECK(d.string().size() == 3);
    }
}
