#include "helpers.hpp"

#include <catch2/catch.hpp>

using namespace plant;
using plant::test::derive;

TEST_CASE("ABOP p. 32: BC < S > G[H]M applies in ABC[DE][SG[HI[JK]L]MNO]", "[context]") {
    // The left context steps over '[' to the parent and skips the whole branch [DE]; the right
    // context skips nothing here, matches the branch [H... and the ']' skips the rest of it.
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: ABC[DE][SG[HI[JK]L]MNO]; rules { B C < S > G[H]M -> X; }", o) ==
          "ABC[DE][XG[HI[JK]L]MNO]");
    // any module in place of the pattern's modules breaks the match
    CHECK(derive("axiom: ABC[DE][SG[HI[JK]L]NNO]; rules { B C < S > G[H]M -> X; }", o) ==
          "ABC[DE][SG[HI[JK]L]NNO]");
    CHECK(derive("axiom: ABD[DE][SG[HI[JK]L]MNO]; rules { B C < S > G[H]M -> X; }", o) ==
          "ABD[DE][SG[HI[JK]L]MNO]");
}

TEST_CASE("the right context skips lateral branches the pattern does not name", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: A[B][C]D; rules { A > D -> X; }", o) == "X[B][C]D");
    // a pattern '[' must match a '['
    CHECK(derive("axiom: A[B][C]D; rules { A > [B] D -> X; }", o) == "X[B][C]D");
    CHECK(derive("axiom: A D[B]; rules { A > [B] -> X; }", o) == "AD[B]");
    // the end of the branch ends the right context
    CHECK(derive("axiom: [A]B; rules { A > B -> X; }", o) == "[A]B");
}

TEST_CASE("the left context is the parent module", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: A[B][C]; rules { A < C -> X; A < B -> Y; }", o) == "A[Y][X]");
    CHECK(derive("axiom: A[B]C; rules { A < C -> X; B < C -> Y; }", o) == "A[B]X");
}

TEST_CASE("L-Py axial matching: A(a) < B(b) > [C(c)]D(d)", "[context]") {
    // L-Py's test: with several lateral branches, the one named by the pattern must come first
    const char* g = R"(
        module A(x); module B(x); module C(x); module D(x); module M(a, b, c, d);
        axiom: A(1) B(2) [C(3)] D(5);
        derive 1;
        rules { A(a) < B(b) > [C(c)] D(d) -> M(a, b, c, d); }
    )";
    CHECK(derive(g) == "A(1)M(1,2,3,5)[C(3)]D(5)");
}

TEST_CASE("ignore and consider sets", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("ignore: + -; axiom: A+-B; rules { A < B -> X; }", o) == "A+-X");
    CHECK(derive("axiom: A+-B; rules { A < B -> X; }", o) == "A+-B");
    CHECK(derive("consider: A B; axiom: A+F-B; rules { A < B -> X; }", o) == "A+F-X");
}

TEST_CASE("ABOP Fig. 1.31a: signal propagation with context (letters a/b for 0/1)", "[context]") {
    const char* g = R"(
        ignore: + - F;
        axiom: F b F b F b;
        rules {
          a < a > a -> a;   a < a > b -> b [ + F b F b ];
          a < b > a -> b;   a < b > b -> b;
          b < a > a -> a;   b < a > b -> b F b;
          b < b > a -> a;   b < b > b -> a;
          + -> -;           - -> +;
        })";
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive(g, o) == "FbFaFb");
    o.steps = 2;
    CHECK(derive(g, o) == "FbFbFbFb");
}

TEST_CASE("new context: << reads the string already produced in this step", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    // forward: each B sees the successor of its left neighbour
    CHECK(derive("axiom: A B B B; rules { A -> C; C << B -> C; }", o) == "CCCC");
    // without new context only the first B sees the old A
    CHECK(derive("axiom: A B B B; rules { A -> C; A < B -> C; }", o) == "CCBB");
}

TEST_CASE("new context: >> reads the string already produced to the right", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: B B B A; rules { A -> C; B >> C -> C; }", o) == "CCCC");
}

TEST_CASE("multi-module predecessors consume several modules", "[context]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: A B A A B; rules { A B -> X; }", o) == "XAX");
}

TEST_CASE("the context table gives what trying the productions in turn gives", "[context]") {
    // Productions with one parameterless module of context a side are looked up in a table by
    // the neighbours' symbols. A condition ': 1' changes nothing about which production applies
    // but keeps the table out, so both routes must derive the same strings and identities.
    const char* grammars[] = {
        // ABOP Fig. 1.31a-e's shape: both contexts, ignored symbols, branches
        R"(ignore: + - F; axiom: F b F b F b;
           rules { a < a > a -> a;   a < a > b -> b [ + F b F b ];
                   a < b > a -> b;   a < b > b -> b;
                   b < a > a -> a;   b < a > b -> b F b;
                   b < b > a -> a;   b < b > b -> a;
                   + -> -;           - -> +; })",
        // neighbours with parameters do not match a pattern without them; one side only; a
        // production without context after contextual ones; an unmatched module is kept
        R"(module P(x); axiom: F(2) a F a [ b F(1) a ] a P(1) b a;
           rules { F < a > F -> b;  a < b -> a F;  F < b > a -> F(3) b;  P(x) < b -> c;
                   b > a -> a;  a -> a b;  c -> P(2); })",
        // left context across a branch point, right context past lateral branches
        R"(axiom: x [ y ] [ z y ] y z;
           rules { x < y -> z;  y > z -> x [ y ];  z < y > z -> y y;  z > y -> x; })",
    };
    for (const char* g : grammars) {
        std::string general = g;
        for (std::size_t at = general.find(" ->"); at != std::string::npos; at = general.find(" ->", at + 8))
            general.replace(at, 3, " : 1 ->");
        INFO(general);
        for (int steps = 1; steps <= 6; ++steps) {
            DeriveOptions o;
            o.steps = steps;
            const std::string tabled = derive(g, o, true), tried = derive(general, o, true);
            REQUIRE(tabled.rfind("COMPILE ERROR", 0) != 0);
            CHECK(tabled == tried);
        }
    }
}
