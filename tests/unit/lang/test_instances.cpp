// Instances as the compiler sees them (docs/language.md, instances): each body its own program,
// what it sees of the outer program, the instance table, cycles and depth, and lod().
#include "helpers.hpp"
#include "plant/instances.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

using namespace plant;
using plant::test::compile;

namespace {

std::string errors(const test::Compiled& c) {
    std::string out;
    for (const auto& d : c.diags.all())
        if (d.severity == Severity::Error) out += d.message + "\n";
    return out;
}

// The string instance `name` derives for `args` at `view_depth`.
std::string derive_instance(const Program& p, const std::string& name, std::vector<double> args,
                            double view_depth = 0, std::uint64_t seed = 0) {
    REQUIRE(p.instances);
    for (std::size_t k = 0; k < p.instances->size(); ++k) {
        const InstanceDef& def = (*p.instances)[k];
        if (def.name != name) continue;
        Derivation d = instance_derivation(def, static_cast<int>(k), args, view_depth, seed, {});
        d.run();
        return format_string(*def.program, d.string());
    }
    FAIL("no instance " << name);
    return {};
}

} // namespace

TEST_CASE("an instance declares its module and compiles its body as a program", "[instances]") {
    auto c = compile(R"(param len = 2;
const k = 3;
fn twice(x) = 2 * x;
curve c = linear(0, 10);
module Y(a);
surface leaf = polygon(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));
instance Leaf(s) {
    axiom: F(len * s) ~leaf Y(twice(k)) X(c(1));
}
instance Branch(n) {
    instance Bud() { axiom: F; }
    axiom: A(n) Bud;
    derive 2;
    rules { A(m) -> F Leaf(m) A(m + 1); }
}
axiom: Branch(1) Branch(1, 0.5);
)");
    REQUIRE(c->program);
    const Program& p = *c->program;
    REQUIRE(p.instance_table);
    REQUIRE(p.instances == p.instance_table.get());
    REQUIRE(p.instances->size() == 3);
    const InstanceDef* leaf = p.instance(*p.symbols.find("Leaf"));
    const InstanceDef* branch = p.instance(*p.symbols.find("Branch"));
    REQUIRE(leaf);
    REQUIRE(branch);
    CHECK(leaf->param_names == std::vector<std::string>{"s"});
    CHECK(leaf->param_slots.size() == 1);
    CHECK(leaf->depth == 1);
    CHECK(branch->depth == 2); // Branch places Bud and Leaf, which place nothing
    CHECK(leaf->program->instances == p.instances);
    CHECK(branch->program->instances == p.instances);
    CHECK(p.symbols[*p.symbols.find("Leaf")].arity == 1);
    // the outer param, const, function, curve, module and surface are visible inside
    CHECK(derive_instance(p, "Leaf", {3}) == "F(6)~leaf Y(6)X(10)");
    CHECK(derive_instance(p, "Branch", {1}) == "FLeaf(1)FLeaf(2)A(3)Bud");
    // the nested Bud is not visible at the top level
    CHECK(!p.instance(*p.symbols.find("Bud")));
    CHECK(branch->program->instance(*branch->program->symbols.find("Bud")));
}

TEST_CASE("outer params, with their -D values, reach instance bodies", "[instances]") {
    CompileOptions o;
    o.defines = {{"len", "5"}};
    auto c = compile("param len = 2; instance Leaf() { axiom: F(len); } axiom: Leaf;", o);
    REQUIRE(c->program);
    CHECK(derive_instance(*c->program, "Leaf", {}) == "F(5)");
}

TEST_CASE("a body's surface replaces the outer one of the same name", "[instances]") {
    auto c = compile(R"(surface leaf = polygon(vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));
instance Big() {
    surface leaf = polygon(vec3(0, 0, 0), vec3(5, 0, 0), vec3(0, 5, 0));
    axiom: ~leaf;
}
axiom: Big ~leaf;
)");
    REQUIRE(c->program);
    CHECK(c->program->surfaces.at(0).points[1][0] == 1);
    const InstanceDef& big = c->program->instances->at(0);
    REQUIRE(big.program->surfaces.size() == 1);
    CHECK(big.program->surfaces[0].points[1][0] == 5);
}

TEST_CASE("instance cycles are positioned errors naming the chain", "[instances]") {
    auto c = compile("instance Tree(n) {\n    axiom: F Branch(n);\n}\ninstance Branch(n) {\n    axiom: F "
                     "Tree(n);\n}\naxiom: Tree(1);\n");
    REQUIRE(!c->program);
    CHECK(errors(*c) ==
          "instance cycle: Tree -> Branch -> Tree: an instance cannot place itself, directly "
          "or through others; to repeat a shape, place it several times from the outer rules or "
          "give the repeated part its own instance\n");
    CHECK_THAT(c->rendered(), Catch::Contains("test.plant:5:14: error: instance cycle"));

    auto self = compile("instance A() {\n  axiom: F;\n  rules { F -> F A; }\n}\naxiom: A;\n");
    REQUIRE(!self->program);
    CHECK_THAT(self->rendered(), Catch::Contains("test.plant:3:18: error: instance cycle: A -> A"));
}

TEST_CASE("instances nest at most 8 deep", "[instances]") {
    auto chain = [](int first) {
        std::string text;
        for (int k = first; k <= 8; ++k)
            text += fmt::format("instance L{}() {{ axiom: F L{}; }}\n", k, k + 1);
        return text + "instance L9() { axiom: F; }\n" + fmt::format("axiom: L{};\n", first);
    };
    auto ok = compile(chain(2)); // L2 .. L9: 8 deep
    CHECK(ok->program);
    CHECK(ok->program->instances->at(0).depth == 8);
    auto deep = compile(chain(1));
    REQUIRE(!deep->program);
    CHECK(errors(*deep) ==
          "instances nested more than 8 deep: L1 -> L2 -> L3 -> L4 -> L5 -> L6 -> L7 -> L8 -> L9\n");
    CHECK_THAT(deep->rendered(), Catch::Contains("test.plant:8:"));
}

TEST_CASE("errors inside an instance body report the body's own position", "[instances]") {
    auto c =
        compile("param a = 1;\ninstance Leaf(s) {\n    axiom: X;\n    rules { X -> F(a * zz); }\n}\naxiom: "
                "Leaf(1);\n");
    REQUIRE(!c->program);
    CHECK_THAT(c->rendered(), Catch::Contains("test.plant:4:24: error: unknown name 'zz'"));
    auto arity = compile("instance Leaf(s) {\n    axiom: F;\n}\naxiom: Leaf(1, 2, 3);\n");
    REQUIRE(!arity->program);
    CHECK_THAT(
        arity->rendered(),
        Catch::Contains("test.plant:4:8: error: module 'Leaf' takes 1 parameter and an optional scale"));
}

TEST_CASE("instance params cannot be used where the value is needed at compile time", "[instances]") {
    for (const char* use : {"const k = s * 2;", "var v = s;", "param q = view_depth;",
                            "surface l = polygon(vec3(s, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0));",
                            "curve c = linear(0, s);", "interpret max_depth s { X -> F; }"}) {
        auto c =
            compile(fmt::format("instance Leaf(s) {{\n    {}\n    axiom: F;\n}}\naxiom: Leaf(1);\n", use));
        INFO(use);
        REQUIRE(!c->program);
        CHECK_THAT(errors(*c), Catch::Contains("use it in rules or settings instead"));
        CHECK_THAT(c->rendered(), Catch::Contains("test.plant:2:"));
    }
    // in rules and settings it is fine
    auto ok = compile("instance Leaf(s) { derive s; axiom: A; rules { A -> A F(s); } } axiom: Leaf(2);");
    REQUIRE(ok->program);
    CHECK(derive_instance(*ok->program, "Leaf", {2}) == "AF(2)F(2)");
}

TEST_CASE("what an instance body cannot hold says what to write instead", "[instances]") {
    auto c = compile("instance Leaf() {\n    import foo;\n    env e = box(1);\n    axiom: F;\n}\ninstance "
                     "Bare() { derive 1; }\naxiom: Leaf Bare;\n");
    REQUIRE(!c->program);
    const std::string e = errors(*c);
    CHECK_THAT(e,
               Catch::Contains("instance 'Leaf' cannot import: write 'import foo;' at the top of the file"));
    CHECK_THAT(e, Catch::Contains("instance 'Leaf' cannot declare an environment"));
    // a path keeps its quotes
    auto q = compile("instance Leaf() {\n    import \"lib/leaf.plant\";\n    axiom: F;\n}\naxiom: Leaf;\n");
    REQUIRE(!q->program);
    CHECK_THAT(errors(*q), Catch::Contains("write 'import \"lib/leaf.plant\";' at the top of the file"));
    CHECK_THAT(e,
               Catch::Contains("instance 'Bare' has no axiom: add a line such as 'axiom: F;' to its body"));
    CHECK_THAT(c->rendered(), Catch::Contains("test.plant:6:1: error: instance 'Bare' has no axiom"));
    auto scale = compile("instance L() { axiom: F; } axiom: L(vec3(1, 2, 3));");
    CHECK(!scale->program);
    CHECK_THAT(errors(*scale),
               Catch::Contains("the scale of instance 'L' (its last argument) must be a number"));
    auto dup = compile("module Leaf; instance Leaf() { axiom: F; } axiom: Leaf;");
    CHECK(!dup->program);
    CHECK_THAT(errors(*dup), Catch::Contains("duplicate definition of module 'Leaf'"));
}

TEST_CASE("lod(count) follows view_depth and max_view_depth", "[instances]") {
    const std::vector<std::pair<int, int>> expected = {{0, 12}, {5, 9}, {10, 6}, {15, 3}, {20, 0}};
    for (auto [depth, leaves] : expected) {
        CompileOptions o;
        o.defines = {{"view_depth", std::to_string(depth)}};
        auto c = compile("axiom: X(lod(12));", o);
        REQUIRE(c->program);
        Derivation d(*c->program, {});
        d.run();
        CHECK(format_string(*c->program, d.string()) == fmt::format("X({})", leaves));
    }
    // clamped, and without a maximum depth the full count
    CHECK(test::derive("param view_depth = 30; axiom: X(lod(12));") == "X(0)");
    CHECK(test::derive("param view_depth = -5; axiom: X(lod(12));") == "X(12)");
    CHECK(test::derive("param max_view_depth = 0; param view_depth = 5; axiom: X(lod(12));") == "X(12)");
    // a grammar without them has no such globals until it uses them
    auto plain = compile("param a = 1; axiom: F(a);");
    REQUIRE(plain->program);
    CHECK(plain->program->globals.size() == 1);
    // an instance gets its view depth per derivation
    auto inst = compile("instance B() { axiom: X(lod(12)); } axiom: B;");
    REQUIRE(inst->program);
    for (auto [depth, leaves] : expected)
        CHECK(derive_instance(*inst->program, "B", {}, depth) == fmt::format("X({})", leaves));
}

TEST_CASE("an instance's seed follows the outer seed and its tuple", "[instances]") {
    const double one[] = {1}, two[] = {2};
    CHECK(instance_seed(7, 0, one) == instance_seed(7, 0, one));
    CHECK(instance_seed(7, 0, one) != instance_seed(7, 0, two));
    CHECK(instance_seed(7, 0, one) != instance_seed(8, 0, one));
    CHECK(instance_seed(7, 0, one) != instance_seed(7, 1, one));
    auto c = compile("instance R(k) { axiom: X(uniform(0, 1)); } axiom: R(1);");
    REQUIRE(c->program);
    const std::string a = derive_instance(*c->program, "R", {1}, 0, 42);
    CHECK(a == derive_instance(*c->program, "R", {1}, 0, 42));
    CHECK(a != derive_instance(*c->program, "R", {1}, 0, 43));
    CHECK(a != derive_instance(*c->program, "R", {2}, 0, 42));
    CHECK(a == derive_instance(*c->program, "R", {1}, 7, 42)); // levels of one tuple draw alike
}
