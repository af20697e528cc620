// Instances in the scene (docs/language.md, instances and level of detail): derived once per
// tuple and view depth, placed by transform, nested, level of detail per placement, bounded.
#include "helpers.hpp"
#include "plant/export_text.hpp"
#include "plant/mesh.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

using namespace plant;

namespace {

struct Built {
    std::unique_ptr<test::Compiled> compiled;
    Scene scene;
};

Built build(const std::string& grammar, MeshOptions mo = {}, DeriveOptions o = {}) {
    Built b;
    b.compiled = test::compile(grammar);
    INFO(b.compiled->rendered());
    REQUIRE(b.compiled->program);
    const Program& p = *b.compiled->program;
    Derivation d(p, o);
    d.run();
    mo.derivation = &d;
    b.scene = build_scene(p, build_skeleton(p, d.interpreted(d.string()), turtle_options(d)), mo);
    return b;
}

// Every point of every placed organ whose prototype's name ends with `suffix`, in world space,
// sorted.
std::vector<std::array<float, 3>> organ_points(const Scene& flat, const std::string& suffix) {
    std::vector<std::array<float, 3>> out;
    for (const Instance& i : flat.instances) {
        const std::string& name = flat.prototype_names.at(i.prototype);
        if (name.size() < suffix.size() ||
            name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
            continue;
        for (const auto& p : flat.prototypes[i.prototype].positions) {
            const glm::vec3 w(i.transform * glm::vec4(p, 1.0f));
            out.push_back({w.x, w.y, w.z});
        }
    }
    std::sort(out.begin(), out.end());
    return out;
}

const char* kNested = R"(angle 30;
surface leaf = polygon(vec3(0, 0, 0), vec3(0.1, 0.3, 0), vec3(0, 0.6, 0));
instance Leaf() {
    axiom: /(45) ~leaf;
}
instance Branch(n) {
    angle 30;
    axiom: A(n);
    derive 3;
    rules { A(k) : k > 0 -> F(1) [ + Leaf ] [ - Leaf(0.5) ] A(k - 1); }
}
instance Tree() {
    axiom: F(2) [ &(30) Branch(3) ] [ ^(30) Branch(2) ] /(90) F(1) [ &(30) Branch(3, 2) ];
}
axiom: F(1) +(10) Tree;
)";

// The same plant drawn without instances.
const char* kPlain = R"(angle 30;
surface leaf = polygon(vec3(0, 0, 0), vec3(0.1, 0.3, 0), vec3(0, 0.6, 0));
module B(n, s);
axiom: F(1) +(10) [ F(2) [ &(30) B(3, 1) ] [ ^(30) B(2, 1) ] /(90) F(1) [ &(30) B(3, 2) ] ];
derive 3;
rules { B(k, s) : k > 0 -> F(s) [ + /(45) ~leaf(s) ] [ - /(45) ~leaf(0.5 * s) ] B(k - 1, s); }
)";

} // namespace

TEST_CASE("an instance is derived once per distinct argument tuple", "[instances]") {
    Built b = build("instance A(n) { axiom: F(n); } axiom: A(1) A(1) [ + A(2) ] A(1, 3) A(2);");
    CHECK(b.scene.instance_derivations == 2);
    REQUIRE(b.scene.scene_prototypes.size() == 2);
    CHECK(b.scene.scene_instances.size() == 5);
    CHECK(b.scene.scene_prototype_names == std::vector<std::string>{"A(1)", "A(2)"});
    REQUIRE(b.scene.scene_prototype_sources.size() == 2);
    CHECK(b.scene.scene_prototype_sources[1].instance == "A");
    CHECK(b.scene.scene_prototype_sources[1].args == std::vector<double>{2});
    // the placement scale is the extra argument: A(1, 3) is A(1) three times as large
    CHECK(b.scene.scene_instances[3].prototype == 0);
    CHECK(glm::length(glm::vec3(b.scene.scene_instances[3].transform[1])) == Approx(3.0));
    CHECK(glm::length(glm::vec3(b.scene.scene_instances[0].transform[1])) == Approx(1.0));
    // the mesh summary and the skeleton list them; a plant without instances adds nothing
    CHECK(scene_prototype_summary(b.scene) == "scene prototypes 2\nscene placements 5\nplacements drawn 5\n");
    Built plain = build("axiom: F;");
    CHECK(scene_prototype_summary(plain.scene).empty());
    CHECK(plain.scene.instance_derivations == 0);
}

TEST_CASE("nested instances put every leaf where the plant drawn without instances has it", "[instances]") {
    Built inst = build(kNested);
    Built plain = build(kPlain);
    CHECK(inst.scene.instance_derivations == 4); // Tree, Branch(3), Branch(2), Leaf
    const Scene flat = flatten(inst.scene);
    const auto got = organ_points(flat, "leaf"), want = organ_points(plain.scene, "leaf");
    REQUIRE(want.size() == 6 * 2 * (3 + 2 + 3)); // two-sided triangles
    REQUIRE(got.size() == want.size());
    for (std::size_t k = 0; k < got.size(); ++k)
        for (int c = 0; c < 3; ++c) CHECK(std::fabs(got[k][c] - want[k][c]) < 1e-5);
    // and the bounds agree
    for (int c = 0; c < 3; ++c) {
        CHECK(std::fabs(inst.scene.bounds_max[c] - plain.scene.bounds_max[c]) < 0.1);
        CHECK(std::fabs(inst.scene.bounds_min[c] - plain.scene.bounds_min[c]) < 0.1);
    }
    // the skeleton's JSON lists the four prototypes and the top-level placement
    const std::string json = skeleton_json(Skeleton{}, &inst.scene);
    CHECK_THAT(json, Catch::Contains("\"instance\":\"Branch\",\"args\":[3],\"view_depth\":0"));
    CHECK_THAT(json, Catch::Contains("\"placements\":[\n{\"prototype\":0"));
}

TEST_CASE("query modules inside an instance see the instance's own turtle", "[instances]") {
    Built b = build("instance Q() { derive 1; axiom: F(2) ?P(0, 0, 0); rules { ?P(p) -> F(p.y); } } axiom: "
                    "f(10) Q;");
    REQUIRE(b.scene.scene_prototypes.size() == 1);
    CHECK(b.scene.scene_prototypes[0]->bounds_max.y == Approx(4.0).margin(1e-4)); // F(2) F(2), not F(12)
    CHECK(b.scene.bounds_max.y == Approx(14.0).margin(1e-4));
}

TEST_CASE("the same seed gives the same instances", "[instances]") {
    const std::string g =
        "instance R(k) { axiom: F(uniform(1, 2)) +(uniform(0, 90)) F; } axiom: R(1) f R(1) f R(2);";
    DeriveOptions o;
    o.seed = 5;
    const Scene a = flatten(build(g, {}, o).scene), b = flatten(build(g, {}, o).scene);
    o.seed = 6;
    const Scene c = flatten(build(g, {}, o).scene);
    auto points = [](const Scene& s) {
        std::vector<float> out;
        for (const Instance& i : s.instances)
            for (const auto& p : s.prototypes[i.prototype].positions) {
                const glm::vec3 w(i.transform * glm::vec4(p, 1.0f));
                out.insert(out.end(), {w.x, w.y, w.z});
            }
        return out;
    };
    CHECK(points(a) == points(b));
    CHECK(points(a) != points(c));
}

TEST_CASE("per-placement level of detail: farther placements get fewer leaves", "[instances]") {
    const std::string g = R"(param depth_unit = 4;
surface leaf = polygon(vec3(0, 0, 0), vec3(0.1, 0.3, 0), vec3(0, 0.6, 0));
instance Branch() {
    axiom: A(lod(12));
    derive 12;
    rules { A(n) : n > 0 -> F(0.2) [ + ~leaf ] A(n - 1); }
}
axiom: Branch f(10) Branch f(10) Branch f(10) Branch f(10) Branch f(10) Branch f(10) Branch f(10) Branch;
)";
    MeshOptions mo;
    mo.camera = glm::dvec3(0, -5, 0);
    Built b = build(g, mo);
    REQUIRE(b.scene.scene_instances.size() == 8);
    int last_leaves = 1000;
    double last_depth = -1;
    for (const Instance& i : b.scene.scene_instances) {
        const Scene& proto = *b.scene.scene_prototypes[i.prototype];
        const double depth = b.scene.scene_prototype_sources[i.prototype].view_depth;
        const int leaves = static_cast<int>(proto.instances.size());
        CHECK(depth >= last_depth);
        CHECK(leaves <= last_leaves);
        CHECK(leaves == static_cast<int>(std::lround(12 * (1 - depth / 20))));
        last_depth = depth;
        last_leaves = leaves;
    }
    CHECK(last_depth == 19);                                        // the farthest: 75 / 4 = 18.75
    CHECK(b.scene.scene_prototype_sources.front().view_depth == 1); // 5 / 4 rounds to 1
    CHECK(b.scene.scene_prototype_names.front() == "Branch@1");
    // without a camera every placement has the program's view depth: one prototype
    Built flat = build(g);
    CHECK(flat.scene.scene_prototypes.size() == 1);
    CHECK(flat.scene.instance_derivations == 1);
    // nested placements inherit their parent's level
    Built nested = build(R"(param depth_unit = 4;
instance Leaf() { axiom: X(lod(12)) F; }
instance Branch() { axiom: F Leaf; }
axiom: f(20) Branch;
)",
                         mo);
    REQUIRE(nested.scene.scene_prototypes.size() == 1);
    const Scene& branch = *nested.scene.scene_prototypes[0];
    REQUIRE(branch.scene_prototype_sources.size() == 1);
    CHECK(branch.scene_prototype_sources[0].view_depth == nested.scene.scene_prototype_sources[0].view_depth);
    CHECK(branch.scene_prototype_sources[0].view_depth == 6); // 25 / 4 = 6.25
}

TEST_CASE("instances see the params as compiled: a hook's assignment does not reach them", "[instances]") {
    // view_depth, max_view_depth and any other param alike (docs/language.md, instances: visibility)
    Built b = build(R"(param view_depth = 5;
param max_view_depth = 20;
param length = 4;
instance Branch() { axiom: F(length) f(lod(12)) F(1); }
on end { view_depth = 10; max_view_depth = 10; length = 7; }
axiom: Branch;
)");
    REQUIRE(b.scene.scene_prototypes.size() == 1);
    CHECK(b.scene.scene_prototype_names[0] == "Branch@5");
    // 4 + lod(12) at 5 of 20 (9) + 1; the hook's values would give 7 + 0 + 1
    CHECK(b.scene.scene_prototypes[0]->bounds_max.y == Approx(14.0f));
}

TEST_CASE("hostile instance use ends with a clear error", "[instances]") {
    // too many distinct tuples
    MeshOptions few;
    few.max_instance_derivations = 50;
    const std::string many =
        "instance Leaf(k) { axiom: F(k); } axiom: A; derive 8; rules { A -> [ Leaf(uniform(0, "
        "1)) ] [ A ] A; }";
    try {
        build(many, few);
        FAIL("no error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::Memory);
        CHECK_THAT(e.message, Catch::Contains("more than 50 distinct instance derivations"));
    }
    // a few instances whose placements multiply past the memory budget when drawn out
    std::string deep;
    for (int k = 1; k < 8; ++k) {
        deep += fmt::format("instance L{}() {{ axiom: F", k);
        for (int j = 0; j < 20; ++j) deep += fmt::format(" [L{}]", k + 1);
        deep += "; }\n";
    }
    deep += "instance L8() { axiom: F; }\naxiom: L1;\n";
    MeshOptions small;
    small.max_memory = 64 << 20;
    try {
        build(deep, small);
        FAIL("no error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::Memory);
        CHECK_THAT(e.message, Catch::Contains("--max-memory"));
    }
    // instance derivations share one module budget
    DeriveOptions limited;
    limited.max_modules = 2000;
    try {
        build("instance Gr(k) { derive 9; axiom: A; rules { A -> A A; } } axiom: Gr(1) Gr(2) Gr(3) Gr(4);",
              {}, limited);
        FAIL("no error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::ModuleLimit);
        CHECK_THAT(e.message, Catch::StartsWith("instance Gr(4) (with the instances before it): "));
    }
    // the first instance has no instances before it
    limited.max_modules = 200;
    try {
        build("instance Gr(k) { derive 9; axiom: A; rules { A -> A A; } } axiom: Gr(1);", {}, limited);
        FAIL("no error");
    } catch (const RuntimeError& e) {
        CHECK(e.kind == RuntimeErrorKind::ModuleLimit);
        CHECK_THAT(e.message, Catch::StartsWith("instance Gr(1): "));
    }
    // an error inside an instance's derivation names the instance
    try {
        build("instance Z(k) { axiom: F(1 / k); } axiom: Z(0);");
        FAIL("no error");
    } catch (const RuntimeError& e) {
        CHECK_THAT(e.message, Catch::StartsWith("instance Z(0): "));
    }
}
