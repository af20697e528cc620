#include "helpers.hpp"
#include "rewrite/rewriter.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

#include <algorithm>
#include <filesystem>

using namespace plant;
using plant::test::derive;

TEST_CASE("parallel rewriting of a bracketed OL-system (ABOP Fig. 1.24d)", "[derive]") {
    const char* g = "axiom: X; rules { X -> F[+X]F[-X]+X; F -> FF; }";
    DeriveOptions o;
    o.steps = 2;
    CHECK(derive(g, o) == "FF[+F[+X]F[-X]+X]FF[-F[+X]F[-X]+X]+F[+X]F[-X]+X");
    o.steps = 10;
    auto c = test::compile(g);
    Derivation d(*c->program, o);
    d.run();
    CHECK(d.string().size() == 381767); // ABOP Fig. 1.24d at n = 10
}

TEST_CASE("parametric rewriting with conditions (ABOP section 1.10)", "[derive]") {
    // ABOP p. 43: A(x, y) with conditions, the example derivation
    const char* g = R"(
        module A(x, y); module B(x); module C;
        axiom: B(2) A(4, 4);
        derive 3;
        rules {
          A(x, y) : y <= 3 -> A(x * 2, x + y);
          A(x, y) : y > 3 -> B(x) A(x / y, 0);
          B(x) : x < 1 -> C;
          B(x) : x >= 1 -> B(x - 1);
        })";
    // B(2)A(4,4) => B(1)B(4)A(1,0) => B(0)B(3)A(2,1) => C B(2)A(4,3)
    CHECK(derive(g) == "CB(2)A(4,3)");
}

TEST_CASE("identities stay with the first successor module of the same name", "[derive]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: A B; rules { A -> B A A; }", o, true) == "B#3A#1A#4B#2");
}

TEST_CASE("the body form: let, if, for, nproduce, produce and falling through", "[derive]") {
    const char* g = R"(
        module A(n);
        axiom: A(3) A(0) A(-1);
        derive 1;
        rules {
          A(n) {
            if (n > 0) {
              for i in 0..n { nproduce F(i); }
              produce B;
            }
            if (n == 0) { produce; }
          }
          A(n) -> C;
        })";
    CHECK(derive(g) == "F(0)F(1)F(2)BC");
}

TEST_CASE("decomposition applies after the axiom and after every step, up to max_depth", "[derive]") {
    const char* g = R"(
        module A(n); module I(k);
        axiom: A(5);
        derive 0;
        decompose max_depth 10 { A(n) : n > 0 -> I(n) A(n - 1); A(0) -> ; }
    )";
    CHECK(derive(g) == "I(5)I(4)I(3)I(2)I(1)");
    const char* shallow = R"(
        module A(n); module I(k);
        axiom: A(5);
        decompose max_depth 2 { A(n) : n > 0 -> I(n) A(n - 1); }
    )";
    CHECK(derive(shallow) == "I(5)I(4)A(3)");
}

TEST_CASE("cut removes the rest of the branch", "[derive]") {
    DeriveOptions o;
    o.steps = 1;
    CHECK(derive("axiom: F[A F F[G]F]F A B; rules { A -> %; }", o) == "F[]F");
}

TEST_CASE("hooks: vars, groups and stop", "[derive]") {
    const char* g = R"(
        var count = 0;
        axiom: A;
        derive 10;
        rules { A -> A B; }
        rules pinch { A -> C; }
        on after_step { count += 1; if (count == 2) { use pinch; } if (count == 4) { stop; } }
    )";
    // steps 1-2 grow, steps 3-4 pinch, then stop
    auto c = test::compile(g);
    Derivation d(*c->program, {});
    d.run();
    CHECK(d.steps_done() == 4);
    CHECK(format_string(*c->program, d.string()) == "CBB");
}

TEST_CASE("the module limit stops an explosion with an error naming the step", "[derive][limits]") {
    auto c = test::compile("axiom: F; derive 30; rules { F -> FFFFFFFFFF; }");
    DeriveOptions o;
    o.max_modules = 100000;
    o.threads = 2;
    Derivation d(*c->program, o);
    try {
        d.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.message ==
              "step 6: the string grew past the limit of 100000 modules (raise it with --max-modules)");
        CHECK(e.kind == RuntimeErrorKind::ModuleLimit);
        CHECK(e.step == 6);
    }
}

TEST_CASE("NaN and infinity never reach a module parameter", "[derive][limits]") {
    auto c = test::compile("axiom: A(1); derive 1; rules { A(x) -> A(sqrt(-x)); }");
    Derivation d(*c->program, {});
    CHECK_THROWS_WITH(d.run(), "step 1: parameter 1 of 'A' is NaN");
    auto c2 = test::compile("axiom: A(1); derive 1; rules { A(x) -> A(x / (x - 1)); }");
    Derivation d2(*c2->program, {});
    try {
        d2.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.message == "step 1: division by zero");
        CHECK(e.kind == RuntimeErrorKind::Arithmetic);
        CHECK(e.step == 1);
        const std::string& text = c2->sources.file(e.span.file).text();
        CHECK(text.substr(e.span.begin, e.span.end - e.span.begin) == "x / (x - 1)");
    }
}

TEST_CASE("runtime errors say their kind and step beside the message", "[derive][limits]") {
    auto c = test::compile("axiom: A; derive 3; rules { A -> A A; }");
    std::atomic<bool> stop{true};
    DeriveOptions o;
    o.interrupt = &stop;
    Derivation d(*c->program, o);
    try {
        d.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::Interrupted);
        CHECK(e.step == -1);
        CHECK(e.message == "interrupted");
    }
    RuntimeError e{Span{}, "division by zero"};
    CHECK(e.kind == RuntimeErrorKind::General);
    e.at_step(4);
    e.at_step(5); // a step named once stays
    CHECK(e.step == 4);
    CHECK(e.message == "step 4: division by zero");
}

TEST_CASE("recursion in functions is bounded", "[derive][limits]") {
    auto c = test::compile("fn f(x) = f(x + 1); axiom: A(1); derive 1; rules { A(x) -> A(f(x)); }");
    Derivation d(*c->program, {});
    CHECK_THROWS_WITH(d.run(), "step 1: recursion deeper than 256 calls in 'f'");
}

TEST_CASE("one evaluation has one budget of instructions, calls and loops included", "[derive][limits]") {
    auto c = test::compile("fn f(n) = n > 0 ? f(n - 1) + f(n - 1) : 1;\n"
                           "axiom: A(30); derive 1; rules { A(n) -> B(f(n)); }");
    DeriveOptions o;
    o.max_steps = 100000;
    Derivation d(*c->program, o);
    try {
        d.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::StepLimit);
        CHECK(e.message.find("more than 100000 instructions in one evaluation (in function 'f')") !=
              std::string::npos);
    }
    // each module's evaluation starts afresh: a budget one evaluation fits runs any number of them
    auto many =
        test::compile("axiom: A A A A A A A A; derive 3; rules { A { for i in 0..100 { } produce A; } }");
    DeriveOptions small;
    small.max_steps = 5000;
    Derivation fits(*many->program, small);
    CHECK_NOTHROW(fits.run());
}

TEST_CASE("the whole run has one work budget, counted alike on any thread count", "[derive][limits]") {
    // the string reaches 32768 modules (the rewrite is split between threads from 20000), each
    // evaluating a loop; then it is copied
    auto c =
        test::compile("axiom: A(15); derive 30;\n"
                      "rules { A(n) : n > 0 -> A(n - 1) A(n - 1); A(n) { for i in 0..20 { } produce B; } }");
    std::uint64_t work[2] = {0, 0};
    for (int t : {1, 3}) {
        DeriveOptions o;
        o.threads = t;
        Derivation d(*c->program, o);
        d.run();
        work[t == 1 ? 0 : 1] = d.work_done();
    }
    CHECK(work[0] == work[1]);
    // the symbols copied count too: at least one unit per module written
    CHECK(work[0] > 15 * 32768);
    for (int t : {1, 3}) {
        DeriveOptions o;
        o.threads = t;
        o.max_work = work[0] - 1;
        Derivation d(*c->program, o);
        try {
            d.run();
            FAIL("expected an error");
        } catch (const RuntimeError& e) {
            CHECK(e.kind == RuntimeErrorKind::WorkLimit);
            CHECK(e.message.find("step 30: the run did more than") == 0);
            CHECK(e.message.find("raise --max-work") != std::string::npos);
        }
        o.max_work = work[0];
        Derivation fits(*c->program, o);
        CHECK_NOTHROW(fits.run());
    }
    // a hook's loop stops at its budget, and the message names the hook
    auto hook =
        test::compile("var n = 0; derive 1000000; on before_step { for i in 0..1e6 { n += 1; } }\naxiom: F;");
    DeriveOptions o;
    o.max_work = 50'000'000;
    Derivation d(*hook->program, o);
    CHECK_THROWS_WITH(d.run(), Catch::StartsWith("step ") &&
                                   Catch::Contains("on before_step: the run did more than 50000000"));
}

TEST_CASE("the interrupt stops a runaway hook inside its budget", "[derive][limits]") {
    auto c =
        test::compile("var n = 0; on start { for i in 0..1e7 { for j in 0..1e7 { n += 1; } } }\naxiom: F;");
    std::atomic<bool> stop{false};
    DeriveOptions o;
    o.interrupt = &stop;
    o.max_steps = std::uint64_t{1} << 60; // the budget alone would run for years
    Derivation d(*c->program, o);
    std::thread ctrl_c([&stop] {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        stop.store(true);
    });
    auto t0 = std::chrono::steady_clock::now();
    try {
        d.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::Interrupted);
    }
    ctrl_c.join();
    CHECK(std::chrono::steady_clock::now() - t0 < std::chrono::seconds(5));
}

TEST_CASE("print() hands each line over as it is printed", "[derive][limits]") {
    auto c =
        test::compile("on start { for i in 0..3 { print(\"line\", i); } n = 1 / 0; }\nvar n = 0; axiom: F;");
    std::vector<std::string> lines;
    DeriveOptions o;
    o.on_print = [&lines](const std::string& text) { lines.push_back(text); };
    Derivation d(*c->program, o);
    CHECK_THROWS(d.run());
    CHECK(lines == std::vector<std::string>{"line 0\n", "line 1\n", "line 2\n"});
}

TEST_CASE("numbers print in the shortest form that reads back", "[derive]") {
    CHECK(format_double(0.1 + 0.2) == "0.30000000000000004");
    CHECK(format_double(-0.0) == "0");
    CHECK(format_double(1e21) == "1e21");
    CHECK(format_double(1e-7) == "1e-7");
    CHECK(format_double(-2.5e-300) == "-2.5e-300");
    CHECK(format_double(137.5) == "137.5");
    CHECK(format_double(0.707) == "0.707");
}

TEST_CASE("string output reads back as the same modules", "[derive]") {
    CHECK(derive("axiom: ~ F ;() F;") == "~ F;()F");
    // letter runs split by longest match over declared names, built-in ones included
    CHECK(derive("axiom: F SetColor(1, 0, 0) FSetColor(0, 1, 0);") == "FSetColor(1,0,0)FSetColor(0,1,0)");
    auto c = test::compile("axiom: FSetColor(1, 0, 0);");
    Derivation d(*c->program, {});
    d.run();
    CHECK(d.string().size() == 2);
}

TEST_CASE("string output: modules back to back, parameters in parentheses", "[derive]") {
    CHECK(derive("module B(l, w); axiom: !(10)F(1)[&(45)B(0.6, 7.07)];") == "!(10)F(1)[&(45)B(0.6,7.07)]");
}

namespace {

// Derives `program` with and without identities and checks that only the identities differ.
void same_without_identities(const Program& program, DeriveOptions o) {
    o.identities = true;
    Derivation with(program, o);
    with.run();
    o.identities = false;
    Derivation without(program, o);
    without.run();
    const ModuleString &a = with.string(), &b = without.string();
    REQUIRE(a.size() == b.size());
    CHECK(std::equal(a.kinds.begin(), a.kinds.end(), b.kinds.begin()));
    CHECK(std::equal(a.block_at.begin(), a.block_at.end(), b.block_at.begin()));
    CHECK(std::equal(a.params.begin(), a.params.end(), b.params.begin()));
    CHECK(with.next_id() == without.next_id()); // new modules are still counted
    CHECK(a.keep_ids);
    CHECK(a.ids.size() == a.size());
    CHECK_FALSE(b.keep_ids);
    CHECK(b.ids.empty());
}

} // namespace

TEST_CASE("without identities a derivation writes the same string, every grammar of grammars/abop and lpy",
          "[derive][ids]") {
    namespace fs = std::filesystem;
    int grammars = 0;
    for (const char* dir : {"abop", "lpy", "demo"})
        for (const auto& entry : fs::directory_iterator(fs::path(PLANT_SOURCE_DIR) / "grammars" / dir)) {
            if (entry.path().extension() != ".plant") continue;
            INFO(entry.path().string());
            SourceManager sources;
            Diagnostics diags;
            auto program = compile_file(sources, entry.path().string(), {}, diags);
            REQUIRE(program);
            same_without_identities(*program, {});
            ++grammars;
        }
    CHECK(grammars >= 30);
}

TEST_CASE("without identities: every rewriting route, on one and two threads", "[derive][ids]") {
    const char* grammars[] = {
        // the direct route (every production applies at once), parameters computed
        "module A(l, w); axiom: A(1, 1); derive 13; "
        "rules { A(l, w) -> F(l) [ &(30) A(l * 0.9, w) ] /(137.5) [ &(-30) A(l * 0.7, w) ]; }",
        // the general route: conditions, a body with nproduce, context, cut and decomposition
        "module A(x); module B(x); module C; axiom: A(0); derive 18; "
        "rules { A(x) : x < 2 -> A(x + 1) [ B(x) C ] A(x + 1); A(x) -> [ % A(9) ] B(x) A(0); "
        "        B(x) < B(y) -> B(x + y); B(x) { nproduce F; if (x > 2) { produce B(x - 1) C; } } } "
        "decompose { C -> F F; }",
        // backward new context
        "axiom: A B B B B; derive 4; rules { A >> B -> A; B -> B B; }",
        // a table-driven context-sensitive system
        // (the first, second and last grow past 20,000 modules, where two threads split the work;
        // the last only with identities kept: without them the symbol kernel takes it whole)
        "ignore: + - F; axiom: F b F b F b; derive 36; "
        "rules { a < a > a -> a; a < a > b -> b [ + F b F b ]; a < b > a -> b; a < b > b -> b; "
        "        b < a > a -> a; b < a > b -> b F b; b < b > a -> a; b < b > b -> a; + -> -; - -> +; }",
    };
    for (const char* g : grammars)
        for (int threads : {1, 2}) {
            INFO(g << " threads " << threads);
            auto c = test::compile(g);
            REQUIRE(c->program);
            DeriveOptions o;
            o.threads = threads;
            same_without_identities(*c->program, o);
        }
}

// Strings without parameters under parameterless context rules go through the symbol kernel
// (Rewriter::run_symbols) when identities are dropped, and through the general templated route
// when they are kept: the two must agree module for module.
TEST_CASE("the symbol kernel writes what the general route writes", "[derive][ids][kernel]") {
    const char* grammars[] = {
        // ABOP Fig. 1.31b and e at depth: the right context skips lateral branches
        "ignore: + - F; axiom: F b F b F b; derive 30; "
        "rules { a < a > a -> b; a < a > b -> b [ - F b F b ]; a < b > a -> b; a < b > b -> b; "
        "        b < a > a -> a; b < a > b -> b F b; b < b > a -> b; b < b > b -> a; + -> -; - -> +; }",
        "ignore: + - F; axiom: F b F b F b; derive 30; "
        "rules { a < a > a -> b; a < a > b -> a [ + F b F b ]; a < b > a -> a; a < b > b -> a; "
        "        b < a > a -> a; b < a > b -> b F b; b < b > a -> b; b < b > b -> a; + -> -; - -> +; }",
        // unbalanced brackets: a ']' without its '[' and a '[' without its ']'
        "axiom: b a ] a b [ a b a [ b; derive 8; rules { a < a -> b; b < a > b -> a a; a > b -> b [ a ]; b > "
        "a -> a; }",
        // a left context only, a right context only, ignored symbols that are rewritten
        "ignore: x; axiom: a x b x a; derive 12; rules { a < b -> b x a; b > a -> a; x -> y; y -> x x; }",
    };
    // deep nesting, 300 levels of saved left keys: a [ b [ b ... b ] b ] b ..., where
    // each b after a ']' has for left neighbour the b before that branch's '['. The kernel's
    // stack of saved keys starts with room for 256 and grows; then the same opened 300 times and
    // never closed, and closed 300 times without an opening
    auto nested = [](int opens, int closes) {
        std::string g = "axiom: a";
        for (int k = 0; k < opens; ++k) g += " [ b";
        for (int k = 0; k < closes; ++k) g += " ] b";
        return g + "; derive 5; rules { a < b -> b a; b < b -> c; c < b -> b [ c ]; c -> b; b > c -> a; }";
    };
    std::vector<std::string> all(std::begin(grammars), std::end(grammars));
    for (auto [opens, closes] : {std::pair{300, 300}, std::pair{300, 0}, std::pair{0, 300}})
        all.push_back(nested(opens, closes));
    for (const std::string& g : all) {
        INFO(g);
        auto c = test::compile(g);
        REQUIRE(c->program);
        RulePlan plan(*c->program, {&c->program->rules});
        CHECK(plan.symbol_kernel);
        same_without_identities(*c->program, {});
    }
    // a string with parameters under such rules goes the general way: F(1) is stepped over
    CHECK(derive("ignore: F; axiom: a F(1) b; derive 4; rules { a < b -> b a; b > a -> a; }") ==
          "aF(1)baaaa");
}

// Two threads split a step's string in two; the kernel then settles the brackets whose partners
// lie outside its stretch with the bracket table. Every split must give the whole run's output.
TEST_CASE("the symbol kernel writes the same for any split of the string", "[derive][kernel]") {
    const char* grammars[] = {
        "ignore: + - F; axiom: F b F b F b; derive 14; "
        "rules { a < a > a -> a; a < a > b -> b [ + F b F b ]; a < b > a -> b; a < b > b -> b; "
        "        b < a > a -> a; b < a > b -> b F b; b < b > a -> a; b < b > b -> a; + -> -; - -> +; }",
        "axiom: b a ] a b [ a b a [ b; derive 5; rules { a < a -> b; b < a > b -> a a; a > b -> b [ a ]; b > "
        "a -> a; }",
    };
    for (const char* g : grammars) {
        INFO(g);
        auto c = test::compile(g);
        REQUIRE(c->program);
        DeriveOptions o;
        o.identities = false;
        Derivation d(*c->program, o);
        d.run();
        const ModuleString& in = d.string();
        RulePlan plan(*c->program, {&c->program->rules});
        REQUIRE(plan.symbol_kernel);
        auto run = [&](std::size_t b, std::size_t e) {
            Rewriter rw(plan, in);
            Worker w;
            w.env.prog = c->program.get();
            w.env.max_output = 1u << 30;
            w.env.max_params = 1u << 30;
            w.out.keep_ids = false;
            rw.run_range(w, b, e);
            return std::vector<SymbolId>(w.out.kinds.begin(), w.out.kinds.end());
        };
        const auto whole = run(0, in.size());
        REQUIRE(in.size() >= 10);
        REQUIRE(whole != std::vector<SymbolId>(in.kinds.begin(), in.kinds.end())); // the step rewrites
        for (std::size_t k = 1; k < in.size(); ++k) {
            auto split = run(0, k);
            const auto rest = run(k, in.size());
            split.insert(split.end(), rest.begin(), rest.end());
            INFO("split at " << k);
            CHECK(split == whole);
        }
    }
}

// Strings without parameters under rules that are all direct templates storing no numbers go
// through the copy kernel (Engine::rewrite_copies) when identities are dropped, and through the
// direct route when they are kept: the two must agree module for module, new identities counted.
TEST_CASE("the copy kernel writes what the direct route writes", "[derive][ids][kernel]") {
    const char* grammars[] = {
        // ABOP Fig. 1.24d, and an erasing production
        "derive 9; axiom: X; rules { X -> F [ + X ] F [ - X ] + X; F -> F F; }",
        "derive 12; axiom: A B; rules { A -> A B C; B -> ; C -> B A; }",
        // kinds of constant numbers (the string stores none): &(30) and /(137.5) are table kinds
        "derive 8; axiom: X; rules { X -> F [ &(30) X ] /(137.5) [ &(-30) X ]; F -> F F; }",
        // the longest successor the kernel takes (16 modules), decomposition, a cut
        "derive 5; axiom: A; rules { A -> A F F F F F F F F F F F F F F B; B -> %; } decompose { F -> G; }",
        // a group switch between two plans, and interpretation rules
        "var k = 0; derive 9; axiom: A; rules { A -> A B; B -> A; } rules two { A -> B B A; } "
        "interpret { B -> F; } on after_step { k += 1; if (k == 4) { use two; } }",
    };
    for (const char* g : grammars)
        for (int threads : {1, 2}) {
            INFO(g << " threads " << threads);
            auto c = test::compile(g);
            REQUIRE(c->program);
            RulePlan plan(*c->program, {&c->program->rules});
            CHECK(plan.copy_kernel);
            DeriveOptions o;
            o.threads = threads;
            same_without_identities(*c->program, o);
        }
    // a successor of 17 modules, a pattern with parameters, a condition: not the copy kernel's
    // (a condition that is always true, `A : 1 < 2`, makes the production unconditional)
    for (const char* g : {"axiom: A; rules { A -> A F F F F F F F F F F F F F F F B; }",
                          "module A(x); axiom: A(1); rules { A(x) -> A(x) B; }",
                          "var v = 0; axiom: A; rules { A : v < 2 -> A B; }"}) {
        INFO(g);
        auto c = test::compile(g);
        REQUIRE(c->program);
        RulePlan plan(*c->program, {&c->program->rules});
        CHECK_FALSE(plan.copy_kernel);
    }
}

TEST_CASE("identities are kept when the program reads them, whatever the options say", "[derive][ids]") {
    auto c = test::compile("module A(x); axiom: A(0) B; derive 3; rules { A(x) -> A(id()) B; B -> B B; }");
    REQUIRE(c->program);
    CHECK(c->program->uses_id);
    DeriveOptions o;
    o.identities = false;
    Derivation d(*c->program, o);
    d.run();
    CHECK(d.keeps_identities());
    CHECK(d.string().ids.size() == d.string().size());
    o.identities = true;
    Derivation e(*c->program, o);
    e.run();
    CHECK(format_string(*c->program, d.string(), true) == format_string(*c->program, e.string(), true));
}

TEST_CASE("a param no hook assigns is compiled as a constant, one a hook assigns is read as it changes",
          "[derive][params]") {
    // the successor's numbers of A(x * r) are the module's own times a constant only when r is
    // folded: that is what puts the production on the direct writer's affine path
    const char* fixed = R"(
        param r = 0.5;
        module A(x); module B(x);
        axiom: A(8);
        derive 2;
        rules { A(x) -> A(x * r) B(r); })";
    auto c = test::compile(fixed);
    REQUIRE(c->program);
    CHECK(c->program->rules.productions[0].tmpl.affine.size() == 1);
    CHECK(test::derive(fixed) == "A(2)B(0.5)B(0.5)");

    CompileOptions o;
    o.defines.emplace_back("r", "0.25"); // -D r=0.25: folded with the value it overrides to
    auto d = test::compile(fixed, o);
    REQUIRE(d->program);
    Derivation run(*d->program, {});
    run.run();
    CHECK(format_string(*d->program, run.string()) == "A(0.5)B(0.25)B(0.25)");

    // a hook halves r after every step: the rules read the new value each step
    const char* assigned = R"(
        param r = 0.5;
        module A(x); module B(x);
        axiom: A(8);
        derive 2;
        rules { A(x) -> A(x * r) B(r); }
        on after_step { r = r / 2; })";
    auto e = test::compile(assigned);
    REQUIRE(e->program);
    CHECK(e->program->rules.productions[0].tmpl.affine.empty());
    CHECK(test::derive(assigned) == "A(1)B(0.25)B(0.5)");
}
