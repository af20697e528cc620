#include "helpers.hpp"
#include "plant/environment_phase.hpp"
#include "plant/skeleton.hpp"

#include <catch2/catch.hpp>

using namespace plant;

namespace {

// Records every segment end and the final state.
struct Recorder : TurtleSink {
    std::vector<glm::dvec3> ends;
    std::vector<int> axes;
    TurtleState last;
    void axis_begin(int axis, int, const TurtleState&) override { axes.push_back(axis); }
    void segment(const TurtleSegment& s) override {
        ends.push_back(s.to);
        last = *s.state;
    }
};

Recorder draw(const std::string& axiom, const std::string& head = "") {
    auto c = test::compile(head + " axiom: " + axiom + ";");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Recorder r;
    interpret(*c->program, d.string(), turtle_options(d), r);
    return r;
}

// The skeleton of a grammar's axiom (0 steps), kept with its program.
struct Drawn {
    std::unique_ptr<test::Compiled> compiled;
    Skeleton skeleton;
};
Drawn skeleton_of(const std::string& grammar) {
    Drawn out;
    out.compiled = test::compile(grammar);
    REQUIRE(out.compiled->program);
    Derivation d(*out.compiled->program, {});
    d.run();
    out.skeleton = build_skeleton(*out.compiled->program, d.string(), TurtleOptions{});
    return out;
}

void near(const glm::dvec3& a, const glm::dvec3& b) {
    CHECK(a.x == Approx(b.x).margin(1e-9));
    CHECK(a.y == Approx(b.y).margin(1e-9));
    CHECK(a.z == Approx(b.z).margin(1e-9));
}

} // namespace

TEST_CASE("the turtle starts at the origin heading +Y, left -X, up +Z", "[turtle]") {
    auto r = draw("F");
    REQUIRE(r.ends.size() == 1);
    near(r.ends[0], {0, 1, 0});
    near(r.last.left, {-1, 0, 0});
    near(r.last.up, {0, 0, 1});
}

TEST_CASE("turns, pitches and rolls", "[turtle]") {
    near(draw("+(90) F").ends[0], {-1, 0, 0}); // '+' turns toward L
    near(draw("-(90) F").ends[0], {1, 0, 0});
    near(draw("&(90) F").ends[0], {0, 0, -1}); // '&' pitches down, away from U
    near(draw("^(90) F").ends[0], {0, 0, 1});
    near(draw("/(90) +(90) F").ends[0], {0, 0, 1}); // '/' rolls L toward U
    near(draw("\\(90) +(90) F").ends[0], {0, 0, -1});
    near(draw("| F").ends[0], {0, -1, 0});
    near(draw("+ F", "angle 90;").ends[0], {-1, 0, 0}); // the grammar's default angle
    near(draw("F(2.5)").ends[0], {0, 2.5, 0});
    near(draw("F", "step 3;").ends[0], {0, 3, 0});
    near(draw("f F").ends[0], {0, 2, 0});
}

TEST_CASE("the frame stays orthonormal and right-handed after many rotations", "[turtle]") {
    auto r = draw("+(17) &(23) /(31) ^(11) \\(7) -(13) F $ F");
    const TurtleState& t = r.last;
    CHECK(glm::length(t.heading) == Approx(1.0));
    CHECK(glm::dot(t.heading, t.left) == Approx(0.0).margin(1e-12));
    near(glm::cross(t.heading, t.left), t.up);
    CHECK(t.left.y == Approx(0.0).margin(1e-12)); // '$' made L horizontal
}

TEST_CASE("a branch saves and restores the turtle state and is a new axis", "[turtle]") {
    auto r = draw("F [ +(90) F ] F");
    REQUIRE(r.ends.size() == 3);
    near(r.ends[1], {-1, 1, 0});
    near(r.ends[2], {0, 2, 0});
    CHECK(r.axes == std::vector<int>{0, 1}); // the main axis continues after the branch
}

TEST_CASE("popping an empty stack is a runtime error naming the module", "[turtle]") {
    auto c = test::compile("axiom: F ] F;");
    Derivation d(*c->program, {});
    d.run();
    Recorder r;
    CHECK_THROWS_WITH(interpret(*c->program, d.string(), TurtleOptions{}, r),
                      "']' at module 2 of the string closes no '[' (the turtle's stack is empty)");
}

TEST_CASE("@M moves, SetHead sets the heading, @O places a sphere", "[turtle]") {
    near(draw("@M(1, 2, 3) F").ends[0], {1, 3, 3});
    near(draw("SetHead(1, 0, 0, 0, 1, 0) F").ends[0], {1, 0, 0});
    Drawn drawn = skeleton_of(
        "axiom: !(4) F @O(2) ~leaf(3); surface leaf = polygon(vec3(0,0,0), vec3(1,0,0), vec3(0,1,0));");
    const Skeleton& sk = drawn.skeleton;
    REQUIRE(sk.axes.size() == 1);
    CHECK(sk.axes[0].points.back().radius == Approx(2.0)); // !(4): width 4, radius 2
    REQUIRE(sk.organs.size() == 2);
    CHECK(sk.organs[0].shape.kind == OrganKind::Sphere);
    CHECK(organ_label(sk.organs[0].shape) == "@O");
    CHECK(sk.organs[0].transform[3][1] == Approx(1.0)); // placed at the turtle's position
    CHECK(glm::length(glm::dvec3(sk.organs[1].transform[1])) == Approx(3.0)); // scaled by 3
}

TEST_CASE("tropism bends the heading toward the tropism vector", "[turtle]") {
    auto r = draw("@Tp(0, -1, 0) @Ts(0.3) -(90) F F F");
    // heading started along +X; each F turns it toward -Y
    CHECK(r.last.heading.y < -0.2);
    CHECK(r.last.heading.x > 0);
    CHECK(glm::length(r.last.heading) == Approx(1.0));
}

TEST_CASE("query modules read the turtle after interpretation rules (the L-Py case)", "[turtle][query]") {
    auto c = test::compile(R"(
        module I(x); module R(x, y, z);
        interpret { I(x) -> F(x); }
        axiom: I(10) ?P(0, 0, 0);
        derive 1;
        rules { ?P(x, y, z) -> R(x, y, z); }
    )");
    REQUIRE(c->program);
    TurtleEnvironmentPhase q;
    DeriveOptions o;
    o.environment_phase = &q;
    Derivation d(*c->program, o);
    d.run();
    CHECK(format_string(*c->program, d.string()) == "I(10)R(0,10,0)");
}

TEST_CASE("?H ?U ?L read the frame, and a vec3 binding reads all three numbers", "[turtle][query]") {
    auto c = test::compile(R"(
        module R(v: vec3);
        axiom: +(90) ?H(0, 0, 0) ?L(0, 0, 0) ?U(0, 0, 0);
        derive 1;
        rules { ?H(v) -> R(v); ?L(v) -> R(v); ?U(v) -> R(v); }
    )");
    REQUIRE(c->program);
    TurtleEnvironmentPhase q;
    DeriveOptions o;
    o.environment_phase = &q;
    Derivation d(*c->program, o);
    d.run();
    const ModuleString& s = d.string();
    REQUIRE(s.size() == 4);
    auto v = [&](std::size_t i) { return glm::dvec3(s.args(i)[0], s.args(i)[1], s.args(i)[2]); };
    near(v(1), {-1, 0, 0}); // heading after turning left by 90 degrees
    near(v(2), {0, -1, 0}); // left
    near(v(3), {0, 0, 1});  // up
}

TEST_CASE("G draws like F, and colors come from the color module and SetColor", "[turtle]") {
    near(draw("G(2)").ends[0], {0, 2, 0});
    Drawn drawn = skeleton_of("axiom: F ;(1) F SetColor(255, 0, 0) F SetColor(0, 0.5, 1) F @R(1, 0, 0) F;");
    const Skeleton& sk = drawn.skeleton;
    REQUIRE(sk.axes.size() == 1);
    const auto& pts = sk.axes[0].points;
    REQUIRE(pts.size() == 6);
    CHECK(pts[1].color == palette_color(0));
    CHECK(pts[2].color == palette_color(1));
    CHECK(pts[3].color == glm::vec3(1, 0, 0)); // 0..255 is scaled to 0..1
    CHECK(pts[4].color == glm::vec3(0, 0.5f, 1));
    near(pts[5].position - pts[4].position, {1, 0, 0}); // @R set the heading to +X
    CHECK(sk.module_name(pts[5]) == "F");
    CHECK(pts[5].id != 0);
}

TEST_CASE("every row of the turtle-symbol table is registered with its operation", "[turtle]") {
    SymbolTable table;
    for (const TurtleSymbol& row : kTurtleSymbols) {
        auto id = table.find(row.name);
        REQUIRE(id);
        const SymbolInfo& info = table[*id];
        CHECK(info.turtle == (row.kind == TurtleKind::Turtle));
        CHECK(info.query == (row.kind == TurtleKind::Query));
        CHECK(info.turtle_op == (row.prefix ? TurtleOp::None : row.op)); // a bare '~' does nothing
        CHECK(row.min_params <= row.max_params);
        CHECK(!row.doc.empty());
    }
    // "~name" places a surface; any other new name has no turtle meaning
    CHECK(table[table.intern("~leaf")].turtle_op == TurtleOp::Surface);
    CHECK(table[table.intern("Apex")].turtle_op == TurtleOp::None);
    CHECK(turtle_symbol(TurtleOp::Sphere)->name == "@O");
}

TEST_CASE("a skeleton's points share one arena, copies go to the heap, names come from symbols",
          "[turtle][skeleton]") {
    // 5,000 segments: enough for an arena (a few points stay on the heap)
    std::string axiom = "F [ + F G ] [ - G ]";
    for (int k = 0; k < 5000; ++k) axiom += " F";
    Drawn drawn = skeleton_of("axiom: " + axiom + ";");
    Skeleton& sk = drawn.skeleton;
    REQUIRE(sk.axes.size() == 3);
    const auto arena = sk.axes[0].points.get_allocator().arena;
    REQUIRE(arena); // sized from the string's segments
    for (const auto& a : sk.axes) CHECK(a.points.get_allocator().arena == arena);
    CHECK(sk.module_name(sk.axes[0].points[0]).empty()); // an axis start
    CHECK(sk.module_name(sk.axes[1].points[1]) == "F");
    CHECK(sk.module_name(sk.axes[1].points[2]) == "G");
    CHECK(sk.axes[0].points.size() == 5002); // grown inside the arena, past its first two
    CHECK_FALSE(skeleton_of("axiom: F [ + F G ] [ - G ] F;").skeleton.axes[0].points.get_allocator().arena);
    // a copy owns its points on the heap and outlives the original
    Skeleton copy = sk;
    CHECK_FALSE(copy.axes[0].points.get_allocator().arena);
    CHECK(copy.axes[0].points.size() == sk.axes[0].points.size());
    CHECK(copy.module_name(copy.axes[1].points[2]) == "G");
    // a moved skeleton keeps the arena alive after the original is gone
    Skeleton moved = std::move(sk);
    drawn.skeleton = Skeleton{};
    CHECK(moved.axes[1].points[2].position == copy.axes[1].points[2].position);
    CHECK(moved.module_name(moved.axes[1].points[2]) == "G");
}
