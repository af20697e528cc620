// Environment objects against hand-computed values.
#include "helpers.hpp"
#include "plant/environments.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

using namespace plant;

namespace {

std::unique_ptr<Environment> make(const std::string& kind, std::vector<EnvArg> args) {
    std::string error;
    auto env = runtime_environments()(kind, args, error);
    INFO(error);
    REQUIRE(env);
    return env;
}
EnvArg vec_arg(const char* key, double x, double y, double z) {
    EnvArg a;
    a.key = key;
    a.type = ValueType::Vec3;
    a.v[0] = x, a.v[1] = y, a.v[2] = z;
    return a;
}
EnvArg num_arg(const char* key, double v) {
    EnvArg a;
    a.key = key;
    a.v[0] = v;
    return a;
}
double ask(const Environment& e, std::size_t method, std::vector<double> args) {
    double r[3] = {0, 0, 0};
    e.query(method, args.data(), r);
    return r[0];
}

// The skeleton of `source`'s derivation.
Skeleton skeleton_of(const std::string& source) {
    auto c = test::compile(source);
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    return build_skeleton(*c->program, d.string(), TurtleOptions{});
}

} // namespace

TEST_CASE("ellipsoid: containment, scaled containment, level", "[environments]") {
    auto e = make("ellipsoid", {vec_arg("center", 0, 4, 0), vec_arg("radii", 3, 2, 3)});
    CHECK(ask(*e, 0, {0, 5.9, 0}) == 1); // inside: 1.9 / 2 < 1
    CHECK(ask(*e, 0, {0, 6.1, 0}) == 0); // outside the top
    CHECK(ask(*e, 0, {2.9, 4, 0}) == 1);
    CHECK(ask(*e, 1, {2.5, 4, 0, 0.8}) == 0); // 2.5 / 3 = 0.83 > 0.8: outside the shrunk one
    CHECK(ask(*e, 1, {2.3, 4, 0, 0.8}) == 1);
    CHECK(ask(*e, 2, {3, 4, 0}) == Approx(1.0)); // on the surface
    CHECK(ask(*e, 2, {1.5, 5, 0}) == Approx(std::sqrt(0.25 + 0.25)));
    CHECK(ask(*e, 3, {0, 7, 0}) == Approx(1.0));  // 1 above the top (y = 6)
    CHECK(ask(*e, 3, {0, 5, 0}) == Approx(-1.0)); // 1 below it, inside
    CHECK(ask(*e, 3, {0, 4, 0}) == Approx(-2.0)); // the center
}

TEST_CASE("proximity: distance to other stems, the asking stem and its branching point excluded",
          "[environments]") {
    const Skeleton sk = skeleton_of("module S(x); axiom: S(1) F F [ +(90) S(2) F F ] F;");
    REQUIRE(sk.axes.size() == 2);
    auto env = make("proximity", {num_arg("radius", 1.5)});
    Environment* prox = env.get();
    REQUIRE(prox);
    prox->see(sk);
    // the branch goes from (0, 2, 0) to (-2, 2, 0); the main stem from (0, 0, 0) to (0, 3, 0)
    const ModuleId branch_module = sk.axes[1].points[2].id; // the branch's second F
    const ModuleId main_module = sk.axes[0].points[1].id;
    // a point beside the main stem, asked for by the branch: 0.5 from the main stem
    CHECK(ask(*env, 0, {0.5, 1, 0, double(branch_module)}) == Approx(0.5));
    // asked for by the main stem, its own segments do not count: the branch is 1 away
    CHECK(ask(*env, 0, {-1, 1, 0, double(main_module)}) == Approx(1.0));
    // asked for by the branch near its base: the main stem's segments meeting at the branching
    // point (0, 2, 0) do not count, so the nearest is (0, 0)-(0, 1), sqrt(0.25 + 1) away
    CHECK(ask(*env, 0, {-0.5, 2, 0, double(branch_module)}) == Approx(std::sqrt(1.25)));
    // nothing within the radius: the radius comes back
    CHECK(ask(*env, 0, {10, 10, 0, 0}) == Approx(1.5));
}

TEST_CASE("proximity: a long slanting stem is found all along it", "[environments]") {
    // a branch 40 long, slanting on all three axes, through a grid of cells half a unit wide: it
    // is listed in the cells along it (not its whole bounding box), so a point beside any part of
    // it finds it
    const Skeleton sk = skeleton_of("module S(x); axiom: S(1) F [ &(35) +(50) F(40) ] F;");
    REQUIRE(sk.axes.size() == 2);
    REQUIRE(sk.axes[1].points.size() == 2);
    auto env = make("proximity", {num_arg("radius", 0.5)});
    env->see(sk);
    const glm::dvec3 a = sk.axes[1].points[0].position, b = sk.axes[1].points[1].position;
    const glm::dvec3 along = glm::normalize(b - a);
    REQUIRE(std::fabs(along.x) > 0.1);
    REQUIRE(std::fabs(along.y) > 0.1);
    REQUIRE(std::fabs(along.z) > 0.1);
    const glm::dvec3 across = glm::normalize(glm::cross(along, glm::dvec3(0, 1, 0)));
    const ModuleId main_module = sk.axes[0].points[1].id; // the branch is another stem for it
    int found = 0;
    for (int k = 1; k < 40; ++k) {
        const glm::dvec3 p = a + (b - a) * (k / 40.0) + across * 0.3;
        found += ask(*env, 0, {p.x, p.y, p.z, double(main_module)}) == Approx(0.3);
    }
    CHECK(found == 39);
}

TEST_CASE("proximity: clearance of a stem from older stems only", "[environments]") {
    // main stem (0,0)-(0,4); branch A from (0,1) and branch B from (0,1.5), both to x = -2
    const Skeleton sk = skeleton_of("axiom: F [ +(90) F(2) ] F(0.5) [ +(90) F(2) ] F(2.5);");
    REQUIRE(sk.axes.size() == 3);
    auto env = make("proximity", {num_arg("radius", 1.5)});
    env->see(sk);
    const double main_id = double(sk.axes[0].points[1].id), a_id = double(sk.axes[1].points[1].id),
                 b_id = double(sk.axes[2].points[1].id);
    REQUIRE(a_id < b_id);
    CHECK(ask(*env, 1, {main_id}) == Approx(1.5)); // nothing is older than the main stem
    CHECK(ask(*env, 1, {a_id}) == Approx(1.5));    // the main stem is 2 from A's tip; B is younger
    CHECK(ask(*env, 1, {b_id}) == Approx(0.5));    // B's tip is 0.5 from the older A
    CHECK(ask(*env, 1, {12345}) == Approx(1.5));   // an identity that drew nothing
}

TEST_CASE("obstacles: signed distances to spheres, boxes and planes", "[environments]") {
    auto e = make("obstacles", {vec_arg("sphere", 0, 0, 0), num_arg("sphere_radius", 1),
                                vec_arg("box_min", 4, 0, 0), vec_arg("box_max", 6, 2, 2),
                                vec_arg("plane_point", 0, -3, 0), vec_arg("plane_normal", 0, 1, 0)});
    CHECK(ask(*e, 0, {0, 2, 0}) == Approx(1.0));      // 1 above the sphere
    CHECK(ask(*e, 0, {0, 0.5, 0}) == Approx(-0.5));   // inside the sphere
    CHECK(ask(*e, 0, {5, 1, 1}) == Approx(-1.0));     // at the box's center, 1 from each face
    CHECK(ask(*e, 0, {7, 1, 1}) == Approx(1.0));      // 1 beside the box
    CHECK(ask(*e, 0, {20, -2.5, 20}) == Approx(0.5)); // above the plane y = -3
    CHECK(ask(*e, 1, {0, 0.5, 0}) == 1);
    CHECK(ask(*e, 1, {20, 20, 20}) == 0);
}

TEST_CASE("environment arguments are checked", "[environments]") {
    std::string error;
    CHECK(!runtime_environments()("ellipsoid", {vec_arg("radii", 1, 0, 1)}, error));
    CHECK(error == "ellipsoid: radii must be positive");
    error.clear();
    CHECK(!runtime_environments()("proximity", {num_arg("range", 1)}, error));
    CHECK(error == "proximity: unknown argument 'range' (known: radius)");
}

TEST_CASE("envelope: Cescatti's crown, asymmetric sides and shape coefficients", "[environments]") {
    // top at y = 10, bottom at y = 2 on the axis x = z = 0; widest at y = 6 with radii 4 (+x),
    // 2 (+z), 3 (-x), 2 (-z); C1 = C2 = 2 (ellipse-like above and below)
    auto e = make("envelope", {vec_arg("top", 0, 10, 0), vec_arg("bottom", 0, 2, 0), vec_arg("px", 4, 6, 0),
                               vec_arg("pz", 0, 6, 2), vec_arg("nx", -3, 6, 0), vec_arg("nz", 0, 6, -2)});
    CHECK(ask(*e, 1, {4, 6, 0}) == Approx(1.0));                    // on the peripheral line at +x
    CHECK(ask(*e, 1, {-3, 6, 0}) == Approx(1.0));                   // at -x, a different radius
    CHECK(ask(*e, 1, {0, 10, 0}) == Approx(1.0));                   // the top
    CHECK(ask(*e, 1, {2, 8, 0}) == Approx(std::sqrt(0.25 + 0.25))); // (2/4)^2 + (2/4)^2 above the line
    CHECK(ask(*e, 1, {0, 4, 1}) == Approx(std::sqrt(0.25 + 0.25))); // (1/2)^2 + (2/4)^2 below it
    CHECK(ask(*e, 0, {3.9, 6, 0}) == 1);
    CHECK(ask(*e, 0, {-3.1, 6, 0}) == 0);
    CHECK(ask(*e, 0, {0, 11, 0}) == 0);
    // halfway between +x and +z the peripheral line is the quarter ellipse with semi-axes 4 and 2
    double c = std::cos(std::numbers::pi / 4), R = 4 * 2 / std::sqrt((2 * c) * (2 * c) + (4 * c) * (4 * c));
    CHECK(ask(*e, 1, {R * c, 6, R * c}) == Approx(1.0));
}

TEST_CASE("light: exposure falls behind occupied cells toward the light", "[environments]") {
    // a horizontal layer of branches at y = 5 over a stem; light from above
    const Skeleton sk = skeleton_of(R"(
        axiom: F(5) [ +(90) F(2) ] [ -(90) F(2) ] [ &(90) F(2) ] [ ^(90) F(2) ] F(5);
    )");
    auto env =
        make("light", {vec_arg("direction", 0, 1, 0), num_arg("resolution", 10), num_arg("opacity", 0.5)});
    env->see(sk);
    CHECK(ask(*env, 0, {0, 10.5, 0}) == Approx(1.0)); // above the plant: full light
    CHECK(ask(*env, 1, {1.5, 3, 0}) >= 1);            // under the +x... layer at y = 5
    CHECK(ask(*env, 0, {1.5, 3, 0}) < 1.0);
    CHECK(ask(*env, 0, {1.5, 3, 0}) == Approx(std::pow(0.5, ask(*env, 1, {1.5, 3, 0}))));
}

TEST_CASE("obstacles: signed distance to a loaded mesh", "[environments]") {
    EnvArg mesh;
    mesh.key = "mesh";
    mesh.type = ValueType::String;
    mesh.text = std::string(PLANT_TEST_DATA) + "/cube.obj";
    auto e = make("obstacles", {mesh});
    CHECK(ask(*e, 0, {0.5, 0.5, 2}) == Approx(1.0));          // 1 above the top face
    CHECK(ask(*e, 0, {0.5, 0.5, 0.5}) == Approx(-0.5));       // the center, 0.5 from every face
    CHECK(ask(*e, 0, {2, 2, 0.5}) == Approx(std::sqrt(2.0))); // nearest to the edge x = y = 1
    CHECK(ask(*e, 1, {0.2, 0.3, 0.4}) == 1);
    std::string error;
    mesh.text = "/nonexistent.obj";
    CHECK(!runtime_environments()("obstacles", {mesh}, error));
    CHECK(error == "obstacles: cannot load the mesh '/nonexistent.obj'");
}

TEST_CASE("environment_kinds: every kind's method table, without making an environment", "[environments]") {
    std::vector<std::string> names;
    for (const EnvironmentKind* kind : environment_kinds()) {
        names.push_back(kind->name);
        CHECK(std::string(kind->doc) != "");
        CHECK(!kind->methods.empty());
        for (std::size_t m = 0; m < kind->methods.size(); ++m) {
            const EnvMethod& row = kind->methods[m];
            INFO(kind->name << "." << row.name);
            CHECK(row.index == m);
            CHECK(std::string(row.doc) != "");
            CHECK(kind->method(row.name) == &row);
            // only a kind that holds segments (the climber) has edits
            if (row.access == EnvAccess::Edit) CHECK(kind->holds_segments);
        }
    }
    CHECK(names ==
          std::vector<std::string>{"ellipsoid", "envelope", "proximity", "light", "obstacles", "climber"});
    // a made environment answers with its kind's table
    auto e = make("ellipsoid", {});
    CHECK(&e->kind() == environment_kinds()[0]);
    CHECK(e->kind().method("contains_scaled")->args.size() == 2);
}
