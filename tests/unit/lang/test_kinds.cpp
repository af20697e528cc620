// Module kinds (docs/rewriting.md, memory): a successor template's module with constant
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

// Whether module i has its symbol's plain kind for its arity (all its numbers stored).
bool plain_kind(const ModuleString& s, std::size_t i) {
    return s.kinds[i] == s.kind_table->find_plain(s.symbol(i), s.arity(i)) && s.stored(i) == s.arity(i);
}

// The table's kinds of constant numbers.
std::size_t constant_kinds(const KindTable& t) {
    std::size_t n = 0;
    for (std::uint32_t l : t.layout_at) n += l != KindTable::kAllStored;
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
    CHECK(constant_kinds(p.kinds) == 3); // &(30), /(137.5), &(-30)
    CHECK(p.symbols[s.symbol(2)].name == "&");
    CHECK(s.kinds[2] >= p.symbols.size());
    CHECK(s.arity(2) == 1);
    CHECK(s.stored(2) == 0);
    CHECK(s.args(2)[0] == 30);
    CHECK(s.args(7)[0] == -30);
    CHECK(plain_kind(s, 0));               // F(l, w): every number computed, a plain kind
    CHECK(s.kinds[0] >= p.symbols.size()); // of arity 2, not the symbol's id
    CHECK(s.kinds[1] == s.symbol(1));      // '[' without numbers: the symbol's id
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
    CHECK(plain_kind(s, 0));
    CHECK(s.stored(1) == 0); // B(7, 3): all constants
    CHECK(s.args(1)[0] == 7);
    CHECK(s.args(1)[1] == 3);
    CHECK(s.kinds[1] != s.kinds[0]);
    CHECK(s.stored(3) == 3); // ?P(0, 0, 0): the environment phase writes its numbers in place
    CHECK(plain_kind(s, 3));
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
        CHECK(constant_kinds(p.kinds) > 0);
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

TEST_CASE("kinds: a string made without a program grows a table of its own", "[kinds]") {
    ModuleString s;
    const double v[3] = {1, 2, 3};
    s.push(4, nullptr, 0, 0);
    CHECK(s.kinds[0] == 4); // no numbers: the symbol's id, no table needed
    CHECK(!s.own_table);
    s.push(4, v, 2, 0);
    s.push(5, v, 3, 0);
    s.push(4, v + 1, 2, 0);
    REQUIRE(s.own_table);
    CHECK(s.kinds[1] == s.kinds[3]);
    CHECK(s.kinds[1] != s.kinds[2]);
    CHECK(s.symbol(2) == 5);
    CHECK(s.arity(2) == 3);
    CHECK(s.stored(1) == 2);
    CHECK(s.offset(3) == 5);
    CHECK(s.args(3)[1] == 3);
    // a copy shares the table; growing either gives it a table of its own
    ModuleString t = s;
    t.push(6, v, 1, 0);
    CHECK(t.kind_table != s.kind_table);
    CHECK(s.kind_table->find_plain(6, 1) == KindTable::kNoKind);
    CHECK(t.symbol(4) == 6);
    CHECK(t.args(3)[0] == 2);
    // appending from a string of another table translates the kinds
    ModuleString u;
    u.push(7, v, 1, 0);
    u.append(s);
    REQUIRE(u.size() == 5);
    CHECK(u.symbol(3) == 5);
    CHECK(u.arity(3) == 3);
    CHECK(u.args(4)[0] == 2);
    CHECK(u.offset(4) == 1 + 2 + 3);
}

TEST_CASE("kinds: every module a program can write has a kind at compile time", "[kinds]") {
    // bodies and the axiom write through the VM: their (symbol, arity) pairs are known
    const char* g = "derive 2; module A(x); module B(x, y); axiom: A(1) B(1, 2) C; "
                    "rules { A(x) { produce A(x + 1) C(x); } B(x, y) -> B(y, x) C; }";
    auto c = test::compile(g);
    REQUIRE(c->program);
    const Program& p = *c->program;
    Derivation d(p, DeriveOptions{});
    d.run();
    const ModuleString& s = d.string();
    CHECK(s.kind_table == &p.kinds);
    CHECK(!s.own_table);
    for (std::size_t i = 0; i < s.size(); ++i) CHECK(plain_kind(s, i));
    CHECK(text_of(p, d) == "A(3)C(2)C(1)B(1,2)CCC");
}
