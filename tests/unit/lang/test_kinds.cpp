// Module kinds (docs/architecture.md, memory): a successor template's module with constant
// numbers gets a kind whose constants live in the program's kind table, and the string stores
// only its computed numbers. The strings read back the same on every rewriting route.
#include "helpers.hpp"
#include "plant/module_string.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace plant;

namespace {

std::string text_of(const Program& p, const Derivation& d) {
    return format_string(p, d.string());
}

// The numbers the string's modules carry, whether stored or constant.
std::size_t all_numbers(const ModuleString& s) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i) n += s.arity(i);
    return n;
}

} // namespace

TEST_CASE("kinds: constants of a template are kept in the kind table", "[kinds]") {
    const char* g =
        "module A(l, w); axiom: A(1, 10); derive 1; rules { A(l, w) -> F(l, w) [ &(30) A(l * 0.9, w) ] "
        "/(137.5) [ &(-30) A(l * 0.7, w) ]; }";
    auto c = test::compile(g);
    REQUIRE(c->program);
    const Program& p = *c->program;
    Derivation d(p, DeriveOptions{});
    d.run();
    CHECK(text_of(p, d) == "F(1,10)[&(30)A(0.9,10)]/(137.5)[&(-30)A(0.7,10)]");
    const ModuleString& s = d.string();
    REQUIRE(s.size() == 10);
    CHECK(s.params.size() == 6); // F, A and A: two each; &, / and & store nothing
    CHECK(all_numbers(s) == 9);
    CHECK(p.kinds.size() == 3); // &(30), /(137.5), &(-30)
    CHECK(p.symbols[s.symbol(2)].name == "&");
    CHECK(s.kinds[2] >= p.symbols.size());
    CHECK(s.arity(2) == 1);
    CHECK(s.stored(2) == 0);
    CHECK(s.args(2)[0] == 30);
    CHECK(s.args(7)[0] == -30);
    CHECK(s.kinds[0] == s.symbol(0)); // F(l, w): every number computed, a plain kind
    CHECK(s.args(3)[1] == 10);
}

TEST_CASE("kinds: a module of computed numbers stores them all, a query module too", "[kinds]") {
    // (a template computes all of a module's numbers when it computes one: B(x + 1, 5))
    const char* g = "derive 1; module B(x, y); axiom: B(0, 0) X; rules { B(x, y) : x < 2 -> B(x + 1, 5) "
                    "B(7, 3); X -> F ?P(0, 0, 0); }";
    auto c = test::compile(g);
    REQUIRE(c->program);
    const Program& p = *c->program;
    Derivation d(p, DeriveOptions{});
    d.run();
    CHECK(text_of(p, d) == "B(1,5)B(7,3)F?P(0,0,0)");
    const ModuleString& s = d.string();
    CHECK(s.stored(0) == 2);
    CHECK(s.kinds[0] == s.symbol(0));
    CHECK(s.stored(1) == 0); // B(7, 3): all constants
    CHECK(s.args(1)[0] == 7);
    CHECK(s.args(1)[1] == 3);
    CHECK(s.kinds[1] != s.kinds[0]);
    CHECK(s.stored(3) == 3); // ?P(0, 0, 0): the environment phase writes its numbers in place
    CHECK(s.kinds[3] == s.symbol(3));
    CHECK(s.params.size() == 5);
}

TEST_CASE("kinds: every route reads and writes constant kinds alike", "[kinds]") {
    struct Case {
        const char* grammar;
        const char* want; // at 3 steps, from plant before kinds existed
    };
    const Case cases[] = {
        // direct
        {"module A(x); module B(x, y); axiom: A(1); rules { A(x) -> B(x, 1) [ &(30) A(x + 1) ] /(137.5) "
         "A(x * 2); B(x, y) -> B(x + y, y) &(-2); }",
         "B(3,1)&(-2)&(-2)[&(30)B(3,1)&(-2)[&(30)B(3,1)[&(30)A(4)]/(137.5)A(6)]/(137.5)B(4,1)[&(30)A(5)]/"
         "(137.5)A(8)]/(137.5)B(3,1)&(-2)[&(30)B(3,1)[&(30)A(4)]/(137.5)A(6)]/(137.5)B(4,1)[&(30)A(5)]/"
         "(137.5)A(8)"},
        // templated: parametric templates and a parameterless context table
        {"module L(x); module R(x); axiom: L(0) R(0) [ X ] Y; rules { L(x) -> L(x) +(5) L(x + 1); R(x) -> "
         "R(x) R(1) R(x + 1); X < Y -> Y; }",
         "L(0)+(5)L(1)+(5)L(1)+(5)L(2)+(5)L(1)+(5)L(2)+(5)L(2)+(5)L(3)R(0)R(1)R(1)R(1)R(1)R(2)R(1)R(1)R(2)R("
         "1)R(1)R(2)R(1)R(1)R(2)R(2)R(1)R(3)R(1)R(1)R(2)R(1)R(1)R(2)R(2)R(1)R(3)[X]Y"},
        // general: context with a condition that reads a constant kind's number; guards that do
        {"module A(x); module B(x); axiom: A(1); rules { A(x) < B(y) : y > 1 -> A(y) B(3); A(x) : x < 4 -> "
         "A(x + 1) B(2) &(1); B(x) : x > 2 -> B(x) +(7); B(x) -> C; }",
         "A(4)B(2)&(1)A(2)B(3)&(1)A(3)B(2)&(1)A(3)B(3)&(1)"},
    };
    for (const Case& k : cases) {
        auto c = test::compile(std::string("derive 3; ") + k.grammar);
        INFO(k.grammar);
        REQUIRE(c->program);
        const Program& p = *c->program;
        CHECK(p.kinds.size() > 0);
        std::string longer;
        for (int threads : {1, 2}) {
            for (bool ids : {false, true}) {
                INFO("threads " << threads << ", ids " << ids);
                DeriveOptions o;
                o.threads = threads;
                o.identities = ids;
                Derivation d(p, o);
                d.run();
                CHECK(text_of(p, d) == k.want);
                CHECK(d.string().params.size() < all_numbers(d.string()));
                o.steps = 12; // long enough for two threads to share a step
                Derivation e(p, o);
                e.run();
                const std::string t = text_of(p, e);
                if (longer.empty()) longer = t;
                CHECK(t == longer);
            }
        }
    }
}
