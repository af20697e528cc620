// Mesh invariants, checked on tubes built from real grammars.
#include "helpers.hpp"
#include "plant/mesh.hpp"

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#pragma GCC diagnostic pop

#include <catch2/catch.hpp>

#include <cmath>
#include <map>

using namespace plant;

namespace {

Skeleton skeleton_of(const std::string& grammar, int steps) {
    auto c = test::compile(grammar);
    REQUIRE(c->program);
    DeriveOptions o;
    o.steps = steps;
    Derivation d(*c->program, o);
    d.run();
    return build_skeleton(*c->program, d.interpreted(d.string()), turtle_options(d));
}

MeshPart tube_of(const TubePath& path, const MeshOptions& o) {
    MeshPart part;
    std::vector<std::vector<std::uint32_t>> by_material;
    mesh_tube(path, o, part, by_material, [](const glm::vec3&) { return 0u; });
    for (auto& idx : by_material) part.indices.insert(part.indices.end(), idx.begin(), idx.end());
    return part;
}

// One axis alone, as one tube.
MeshPart tube_of(const SkeletonAxis& axis, const MeshOptions& o) {
    TubePath path;
    for (const auto& p : axis.points) path.push_back(&p);
    return tube_of(path, o);
}

// Boundary loops of a tube, through OpenMesh, with the texture seam welded (its two copies of a
// vertex have the same position).
int boundary_loops(const MeshPart& part, bool& manifold) {
    using Mesh = OpenMesh::TriMesh_ArrayKernelT<>;
    Mesh mesh;
    std::map<std::array<float, 3>, Mesh::VertexHandle> weld;
    std::vector<Mesh::VertexHandle> handle(part.positions.size());
    for (std::size_t i = 0; i < part.positions.size(); ++i) {
        const auto& p = part.positions[i];
        std::array<float, 3> key{p.x, p.y, p.z};
        auto it = weld.find(key);
        if (it == weld.end()) it = weld.emplace(key, mesh.add_vertex(Mesh::Point(p.x, p.y, p.z))).first;
        handle[i] = it->second;
    }
    manifold = true;
    for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3) {
        auto f =
            mesh.add_face(handle[part.indices[t]], handle[part.indices[t + 1]], handle[part.indices[t + 2]]);
        if (!f.is_valid()) manifold = false; // OpenMesh refuses faces that would make it non-manifold
    }
    for (auto v : mesh.vertices())
        if (!mesh.is_manifold(v)) manifold = false;
    int loops = 0;
    std::vector<bool> seen(mesh.n_halfedges(), false);
    for (auto h : mesh.halfedges()) {
        if (!mesh.is_boundary(h) || seen[static_cast<std::size_t>(h.idx())]) continue;
        ++loops;
        auto cur = h;
        do {
            seen[static_cast<std::size_t>(cur.idx())] = true;
            cur = mesh.next_halfedge_handle(cur);
        } while (cur != h);
    }
    return loops;
}

const char* kGrammars[] = {
    // Honda's monopodial tree (ABOP Fig. 2.6a): gentle joints, tapering widths
    R"(param r1 = 0.9; param r2 = 0.6; param a0 = 45; param a2 = 45; const d = 137.5; const wr = 0.707;
       module A(l, w); module B(l, w); module C(l, w); axiom: A(1, 10);
       rules { A(l, w) -> !(w) F(l) [ &(a0) B(l * r2, w * wr) ] /(d) A(l * r1, w * wr);
               B(l, w) -> !(w) F(l) [ -(a2) $ C(l * r2, w * wr) ] C(l * r1, w * wr);
               C(l, w) -> !(w) F(l) [ +(a2) $ B(l * r2, w * wr) ] B(l * r1, w * wr); })",
    // ABOP Fig. 1.24a with widths: many short segments and small turns
    "angle 25.7; axiom: !(0.2) F; rules { F -> F[+F]F[-F]F; }",
    // sharp corners (90 and 120 degrees) get rounded with extra rings
    "axiom: !(0.3) F F +(90) F F -(120) F &(100) F F;",
    // Honda's sympodial tree (ABOP Fig. 2.7a): every axis is one segment, continued into a child
    R"(param r1 = 0.9; param r2 = 0.7; param a1 = 5; param a2 = 65; const wr = 0.707;
       module A(l, w); module B(l, w); axiom: A(1, 10);
       rules { A(l, w) -> !(w) F(l) [ &(a1) B(l * r1, w * wr) ] /(180) [ &(a2) B(l * r2, w * wr) ];
               B(l, w) -> !(w) F(l) [ +(a1) $ B(l * r1, w * wr) ] [ -(a2) $ B(l * r2, w * wr) ]; })",
};

} // namespace

TEST_CASE("ring centers are the turtle's points and ring vertices lie at the radius", "[mesh]") {
    Skeleton sk = skeleton_of("axiom: !(0.5) F +(20) F(2) !(0.3) -(30) F;", 0);
    REQUIRE(sk.axes.size() == 1);
    const SkeletonAxis& axis = sk.axes[0];
    MeshOptions o;
    o.sides = 8;
    MeshPart m = tube_of(axis, o);
    const std::size_t stride = 9;
    REQUIRE(m.positions.size() == axis.points.size() * stride);
    for (std::size_t k = 0; k < axis.points.size(); ++k) {
        glm::dvec3 center(0.0);
        for (std::size_t j = 0; j < 8; ++j) center += glm::dvec3(m.positions[k * stride + j]);
        center /= 8.0;
        CHECK(glm::length(center - axis.points[k].position) < 1e-5);
        if (k == 0 || k + 1 == axis.points.size()) {
            // end rings are perpendicular to the axis: every vertex at the radius
            double r = axis.points[k].radius * (k + 1 == axis.points.size() ? o.tip_taper : 1.0);
            for (std::size_t j = 0; j < 8; ++j)
                CHECK(glm::length(glm::dvec3(m.positions[k * stride + j]) - axis.points[k].position) ==
                      Approx(r).epsilon(1e-5));
        } else {
            // joint rings are widened along the bend (a miter): no vertex comes closer than the radius
            for (std::size_t j = 0; j < 8; ++j)
                CHECK(glm::length(glm::dvec3(m.positions[k * stride + j]) - axis.points[k].position) >=
                      axis.points[k].radius * (1 - 1e-5));
        }
    }
}

TEST_CASE("every tube is a manifold with two boundary loops, unit normals and no degenerate triangles",
          "[mesh]") {
    for (const char* g : kGrammars) {
        INFO(g);
        Skeleton sk = skeleton_of(g, 4);
        REQUIRE(!sk.axes.empty());
        MeshOptions o;
        o.sides = 6;
        int tubes = 0;
        for (const TubePath& path : tube_paths(sk, o)) {
            MeshPart m = tube_of(path, o);
            if (m.empty()) continue;
            ++tubes;
            bool manifold = false;
            INFO("tube through " << path.size() << " points");
            CHECK(boundary_loops(m, manifold) == 2);
            CHECK(manifold);
            for (const auto& n : m.normals) {
                REQUIRE(std::isfinite(n.x));
                CHECK(glm::length(n) == Approx(1.0f).epsilon(1e-4));
            }
            for (std::size_t t = 0; t < m.indices.size(); t += 3) {
                const auto& a = m.positions[m.indices[t]];
                const auto& b = m.positions[m.indices[t + 1]];
                const auto& c = m.positions[m.indices[t + 2]];
                REQUIRE(std::isfinite(a.x));
                CHECK((a != b && b != c && a != c));
            }
        }
        CHECK(tubes > 0);
    }
}

TEST_CASE("a sympodial axis goes on into its straightest child when the turn is gentle", "[mesh]") {
    // Fig. 2.7a: each A/B draws one segment, then two laterals turned by a1 = 5 and a2 = 65
    // degrees. The 5-degree one continues the tube; the 65-degree one (past the 45-degree sharp
    // bend) starts a new tube inside the joint.
    Skeleton sk = skeleton_of(kGrammars[3], 5);
    const std::size_t axes = sk.axes.size();
    REQUIRE(axes == 31); // 1 + 2 + 4 + 8 + 16 segments, one axis each
    MeshOptions o;
    std::vector<TubePath> tubes = tube_paths(sk, o);
    // every fork with drawn branches hands on one of them: the tubes are the root's and the 15
    // weak branches' (the 16 apices of the last generation have not drawn anything yet)
    CHECK(tubes.size() == 16);
    std::size_t points = 0;
    for (const TubePath& t : tubes) {
        points += t.size();
        for (std::size_t k = 1; k < t.size(); ++k)
            CHECK(glm::length(t[k]->position - t[k - 1]->position) > 1e-9);
        for (std::size_t k = 1; k + 1 < t.size(); ++k) {
            // every joint in a tube is gentle: a 5 degree turn
            glm::dvec3 d0 = glm::normalize(t[k]->position - t[k - 1]->position);
            glm::dvec3 d1 = glm::normalize(t[k + 1]->position - t[k]->position);
            CHECK(glm::degrees(std::acos(std::clamp(glm::dot(d0, d1), -1.0, 1.0))) ==
                  Approx(5.0).margin(1e-6));
        }
    }
    // each axis contributes its two points, minus the shared joint where it continues a parent
    CHECK(points == 2 * axes - (axes - tubes.size()));
    // the longest tube follows the strong branch from the root to the last generation
    std::size_t longest = 0;
    for (const TubePath& t : tubes) longest = std::max(longest, t.size());
    CHECK(longest == 6); // five segments
    // the same skeleton, one tube per axis, when continuation is off
    o.continue_axes = false;
    CHECK(tube_paths(sk, o).size() == axes);
    // a continued tube shares a ring per joint: fewer vertices, the same triangles
    Scene joined = build_scene(*test::compile(kGrammars[3])->program, sk, MeshOptions{});
    Scene apart = build_scene(*test::compile(kGrammars[3])->program, sk, o);
    CHECK(joined.tubes.triangle_count() == apart.tubes.triangle_count());
    CHECK(joined.tubes.positions.size() == apart.tubes.positions.size() - 9 * (axes - tubes.size()));
}

TEST_CASE("the scene shares organ prototypes between placements and bounds include them", "[mesh]") {
    auto c = test::compile(R"(
        surface leaf = polygon(vec3(0, 0, 0), vec3(0.5, 1, 0), vec3(0, 2, 0), vec3(-0.5, 1, 0));
        axiom: F [ +(45) ~leaf(1) ] F [ -(45) ~leaf(1) ] F ;(1) ~leaf(2) @O(0.5);
    )");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Skeleton sk = build_skeleton(*c->program, d.string(), TurtleOptions{});
    Scene s = build_scene(*c->program, sk, MeshOptions{});
    CHECK(s.instances.size() == 4);
    CHECK(s.prototypes.size() == 3);                     // leaf in two colors, one sphere
    CHECK(s.prototypes[0].triangle_count() == 4);        // a quad, front and back
    CHECK(s.bounds_max.y >= 3.0f + 2.0f * 1.0f - 1e-4f); // the top leaf (length 2, scale 2) reaches y = 3 + 4
    CHECK(s.tubes.triangle_count() > 0);
}

TEST_CASE("sphere faces are wound outward, like their normals", "[mesh]") {
    auto c = test::compile("axiom: @O(1);");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Scene s =
        build_scene(*c->program, build_skeleton(*c->program, d.string(), TurtleOptions{}), MeshOptions{});
    REQUIRE(s.prototypes.size() == 1);
    const MeshPart& m = s.prototypes[0];
    REQUIRE(m.triangle_count() > 0);
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        glm::vec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]],
                  c2 = m.positions[m.indices[t + 2]];
        glm::vec3 face = glm::cross(b - a, c2 - a);
        CHECK(glm::dot(face, a + b + c2) > 0); // the face normal points away from the center
    }
}

TEST_CASE("a surface loaded from a file is meshed once and placed by transform", "[mesh]") {
    auto c = test::compile(std::string("surface leaf = load(\"") + PLANT_TEST_DATA +
                           "/leaf.obj\"); axiom: F ~leaf(2) F ~leaf(1);");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    d.run();
    Skeleton sk = build_skeleton(*c->program, d.string(), TurtleOptions{});
    Scene s = build_scene(*c->program, sk, MeshOptions{});
    REQUIRE(s.prototypes.size() == 1);
    CHECK(s.prototypes[0].triangle_count() == 2);
    CHECK(s.instances.size() == 2);
    CHECK(s.bounds_max.y ==
          Approx(1.0f + 2 * 1.2f)); // the first leaf, at y = 1 and scaled by 2, reaches highest
    auto bad = test::compile("surface leaf = load(\"/nonexistent/leaf.obj\"); axiom: ~leaf(1);");
    REQUIRE(bad->program);
    Derivation d2(*bad->program, {});
    d2.run();
    Skeleton sk2 = build_skeleton(*bad->program, d2.string(), TurtleOptions{});
    CHECK_THROWS_WITH(build_scene(*bad->program, sk2, MeshOptions{}),
                      "cannot load surface 'leaf' from '/nonexistent/leaf.obj'");
}
