#include "helpers.hpp"

#include <catch2/catch.hpp>

using namespace plant;
using plant::test::compile;

namespace {
std::vector<std::string> messages(const test::Compiled& c, Severity sev) {
    std::vector<std::string> out;
    for (const auto& d : c.diags.all())
        if (d.severity == sev) out.push_back(d.message);
    return out;
}
} // namespace

TEST_CASE("names are resolved to slots: params, consts, locals and functions", "[compiler]") {
    auto c = compile("param a = 2; const b = a * 3; fn sq(x) = x * x; axiom: A(sq(b)); derive 0;");
    REQUIRE(c->program);
    REQUIRE(c->program->globals.size() == 1);
    CHECK(c->program->globals[0].name == "a");
    CHECK(c->program->global_values[0] == 2);
    CHECK(test::derive("param a = 2; const b = a * 3; fn sq(x) = x * x; axiom: A(sq(b));") == "A(36)");
}

TEST_CASE("unknown names suggest the nearest known one", "[compiler]") {
    auto c = compile("param length = 1; axiom: F(lenght);");
    CHECK(!c->program);
    CHECK(messages(*c, Severity::Error) ==
          std::vector<std::string>{"unknown name 'lenght'; did you mean 'length'?"});
}

TEST_CASE("declared modules fix their arity", "[compiler]") {
    auto c = compile("module A(l, w); axiom: A(1); rules { A(x) -> A(x, 1); }");
    CHECK(!c->program);
    auto errs = messages(*c, Severity::Error);
    REQUIRE(errs.size() == 2);
    CHECK(errs[0] == "module 'A' takes 2 parameters, given 1 (declared at 1:8)");
    CHECK(errs[1] == "module 'A' takes 2 parameters, the pattern gives 1 (declared at 1:8)");
}

TEST_CASE("duplicate definitions name both places", "[compiler]") {
    auto c = compile("param x = 1;\nparam x = 2;\naxiom: F;");
    CHECK(!c->program);
    REQUIRE(c->diags.all().size() == 1);
    const Diagnostic& d = c->diags.all()[0];
    CHECK(d.message == "duplicate definition of param 'x'");
    REQUIRE(d.notes.size() == 1);
    CHECK(c->sources.file(d.notes[0].first.file).line_col(d.notes[0].first.begin).line == 1);
}

TEST_CASE("params and vars are assigned only in hooks", "[compiler]") {
    auto bad = compile("param p = 1; axiom: A; rules { A { p = 2; produce A; } }");
    CHECK(!bad->program);
    CHECK(messages(*bad, Severity::Error)[0].find("'p' is a param: it can be assigned only in hooks") == 0);
    auto good = compile("param p = 1; var v = 0; axiom: A; on after_step { v += 1; p = p * 2; }");
    CHECK(good->program);
}

TEST_CASE("an undeclared letter run without meaning warns and names the nearest module", "[compiler]") {
    auto c = compile("module Bud(x); axiom: Bd(1) Bud(2); rules { Bud(x) -> Bud(x); }");
    REQUIRE(c->program);
    auto w = messages(*c, Severity::Warning);
    REQUIRE(w.size() == 1);
    CHECK(w[0] ==
          "'Bd' is not a declared module and is read as 2 separate letters, none of which has a rule or a "
          "turtle meaning; did you mean 'Bud'?");
    // letters with meaning (F has a turtle meaning) are fine
    auto ok = compile("axiom: FF+X; rules { X -> FX; }");
    CHECK(messages(*ok, Severity::Warning).empty());
}

TEST_CASE("productions that can never apply are reported", "[compiler]") {
    auto c = compile("axiom: A; rules { A -> B; A -> C; Z -> A; A : 1 > 2 -> D; } rules unused { A -> A; }");
    REQUIRE(c->program);
    auto w = messages(*c, Severity::Warning);
    REQUIRE(w.size() == 5);
    CHECK(w[0] == "this production can never apply: the production at 1:19 always applies first to 'A'");
    CHECK(w[1] == "this production can never apply: the production at 1:19 always applies first to 'A'");
    CHECK(w[2] == "this production can never apply: its condition is always false");
    CHECK(w[3] == "this production can never apply: neither the axiom nor any successor produces 'Z'");
    CHECK(w[4] == "rule group 'unused' is never selected: no hook says 'use unused;'");
}

TEST_CASE("letter runs split by longest match over declared names", "[compiler]") {
    // "A" then "B" must be spaced, or reading back would see the declared "AB"
    CHECK(test::derive("module AB; axiom: ABAB A B;") == "AB AB A B");
    CHECK(test::derive("axiom: FbFb;") == "FbFb");
    // a declared multi-letter module followed by a letter is spaced on output
    CHECK(test::derive("module Fb; axiom: F b;") == "F b");
}

TEST_CASE("a -D value overrides a param with an expression, and unknown params are reported", "[compiler]") {
    CompileOptions o;
    o.defines = {{"r", "2 * 3"}};
    auto c = compile("param r = 1; axiom: F(r);", o);
    REQUIRE(c->program);
    CHECK(c->program->global_values[0] == 6);
    CompileOptions bad;
    bad.defines = {{"rr", "1"}};
    auto c2 = compile("param r = 1; axiom: F(r);", bad);
    CHECK(!c2->program);
    CHECK(messages(*c2, Severity::Error)[0] == "-D rr: the grammar has no param 'rr'; did you mean 'r'?");
}

TEST_CASE("types: vectors, members and mismatches", "[compiler]") {
    CHECK(test::derive("param v = vec3(1, 2, 3); axiom: A(v.y, length(v * 2));") == "A(2,7.483314773547883)");
    auto c = compile("param v = vec3(1, 2, 3); axiom: A(v + 1);");
    CHECK(!c->program);
    CHECK(messages(*c, Severity::Error)[0] == "operator '+' cannot be applied to vec3 and number");
}

TEST_CASE("a surface in an importing file replaces the library's, but twice in one file is an error",
          "[compiler]") {
    CompileOptions opts;
    opts.file_texts["/virtual/lib.plant"] =
        "surface leaf = polygon(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));";
    SourceManager sources;
    Diagnostics diags;
    std::uint32_t id =
        sources.add("/virtual/main.plant",
                    "import \"lib.plant\";\n"
                    "surface leaf = polygon(vec3(0, 0, 0), vec3(2, 0, 0), vec3(2, 2, 0), vec3(0, 2, 0));\n"
                    "axiom: ~leaf(1);");
    auto program = compile_source(sources, id, opts, diags);
    INFO(render_all(diags, sources));
    REQUIRE(program);
    REQUIRE(program->surfaces.size() == 1);
    CHECK(program->surfaces[0].points.size() == 4);

    auto twice =
        test::compile("surface leaf = polygon(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));\n"
                      "surface leaf = polygon(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));\naxiom: F;");
    CHECK(!twice->program);
    CHECK(twice->rendered().find("surface 'leaf'") != std::string::npos);
}

TEST_CASE("a program with more module names than symbol ids is refused, not wrapped around", "[compiler]") {
    // symbol ids are 16 bits: 65,534 names at most, the builtins among them
    auto source = [](int n) {
        std::string s = "axiom: M0;\n";
        for (int i = 0; i < n; ++i) s += "module M" + std::to_string(i) + ";";
        return s;
    };
    auto fits = compile(source(60000));
    CHECK(fits->program);
    auto c = compile(source(70000));
    CHECK(!c->program);
    CHECK(messages(*c, Severity::Error) ==
          std::vector<std::string>{
              "the program names more than 65534 different modules, the most plant can tell apart"});
}
