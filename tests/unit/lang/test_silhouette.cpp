// Silhouettes (lang/include/plant/silhouette.hpp): Cescatti's envelope, the axis curve, the ray
// to the envelope and the placement of a child silhouette inside its parent's (Boudon et al.
// 2003, sections 2.4 and 3, Fig. 8).
#include "plant/silhouette.hpp"

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

using namespace plant;

namespace {

// An asymmetric crown: every widest point at its own height and distance, different shapes
// above and below the peripheral line.
Envelope crown() {
    std::string error;
    Envelope e = Envelope::make({0, 10, 0}, {0, 2, 0}, {4, 6, 0}, {0, 7, 2}, {-3, 5, 0}, {0, 6.5, -2.5}, 1.5,
                                3, error);
    REQUIRE(error.empty());
    return e;
}

Silhouette silhouette(const Envelope& e, const glm::dvec3& tip) {
    Silhouette s;
    std::string error;
    s.axis = AxisCurve::make(AxisCurve::Kind::Polyline, {e.bottom, e.control_point(0)}, error);
    REQUIRE(error.empty());
    s.envelope = e;
    s.tip = tip;
    return s;
}

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

glm::dvec3 random_unit(std::mt19937& rng) {
    std::normal_distribution<double> n(0, 1);
    for (;;) {
        glm::dvec3 v(n(rng), n(rng), n(rng));
        if (glm::length(v) > 1e-3) return glm::normalize(v);
    }
}

// a point of the envelope's box with level at most `max_level`
glm::dvec3 random_inside(const Envelope& e, std::mt19937& rng, double max_level) {
    std::uniform_real_distribution<double> u(0, 1);
    for (;;) {
        glm::dvec3 p = e.lo() + (e.hi() - e.lo()) * glm::dvec3(u(rng), u(rng), u(rng));
        if (e.level(p) <= max_level) return p;
    }
}

glm::dmat3 random_rotation(std::mt19937& rng) {
    glm::dvec3 x = random_unit(rng), y = random_unit(rng);
    y = glm::normalize(y - x * glm::dot(x, y));
    return glm::dmat3(x, y, glm::cross(x, y));
}

} // namespace

TEST_CASE("silhouette envelope: level 1 at the six control points, below 1 inside", "[silhouette]") {
    Envelope e = crown();
    for (int k = 0; k < 6; ++k) {
        INFO("control point " << k);
        CHECK(std::abs(e.level(e.control_point(k)) - 1) < 1e-12);
    }
    CHECK(e.control_point(2) == glm::dvec3(4, 6, 0));
    CHECK(e.control_point(5) == glm::dvec3(0, 6.5, -2.5));
    CHECK(e.level({0, 6, 0}) < 0.5);
    CHECK(e.contains({1, 6, 0.5}));
    CHECK(!e.contains({3.9, 7, 0}));
    CHECK(e.level({0, 10.5, 0}) == 1e300);
    CHECK(e.level({NAN, 5, 0}) == 1e300);
    // the box holds the envelope
    CHECK(e.lo() == glm::dvec3(-3, 2, -2.5));
    CHECK(e.hi() == glm::dvec3(4, 10, 2));
}

TEST_CASE("silhouette envelope: bad control points are errors", "[silhouette]") {
    std::string error;
    Envelope::make({0, 10, 0}, {0, 2, 0}, {-1, 6, 0}, {0, 6, 2}, {-3, 6, 0}, {0, 6, -2}, 2, 2, error);
    CHECK(error.find("own side") != std::string::npos);
    error.clear();
    Envelope::make({0, 10, 0}, {0, 2, 0}, {4, 11, 0}, {0, 6, 2}, {-3, 6, 0}, {0, 6, -2}, 2, 2, error);
    CHECK(error.find("between the bottom and the top") != std::string::npos);
    error.clear();
    Envelope::make({0, 10, 0}, {0, 2, 0}, {4, 6, 0}, {0, 6, 2}, {-3, 6, 0}, {0, 6, -2}, 0, 2, error);
    CHECK(error == "the shape coefficients must be positive");
}

TEST_CASE("silhouette envelope: reach lands on the envelope", "[silhouette]") {
    Envelope e = crown();
    std::mt19937 rng(17);
    for (int k = 0; k < 500; ++k) {
        glm::dvec3 p = random_inside(e, rng, 0.98), d = random_unit(rng);
        double s = e.reach(p, d * 3.0); // any length of d
        INFO("p " << p.x << " " << p.y << " " << p.z << " d " << d.x << " " << d.y << " " << d.z);
        REQUIRE(s > 0);
        CHECK(std::abs(e.level(p + d * s) - 1) < 1e-9);
        CHECK(e.level(p + d * (s * (1 + 1e-6))) > 1);
    }
    // straight up from the centre of the peripheral line to the top; along +x to px
    CHECK(e.reach({0, 6, 0}, {0, 1, 0}) == Approx(4).epsilon(1e-12));
    CHECK(e.reach({0, 6, 0}, {1, 0, 0}) == Approx(4).epsilon(1e-12));
    // outside, a zero or broken direction: 0, never NaN
    CHECK(e.reach({0, 12, 0}, {0, -1, 0}) == 0);
    CHECK(e.reach({0, 6, 0}, {0, 0, 0}) == 0);
    CHECK(e.reach({0, 6, 0}, {NAN, 0, 0}) == 0);
    CHECK(e.reach({0, 6, 0}, {INFINITY, 0, 0}) == 0);
}

TEST_CASE("silhouette envelope: reach remembers its answers only for the same envelope and ray",
          "[silhouette]") {
    // For each field of the envelope that shapes it (the top's x and z do not: only its height
    // counts), a ray whose answer the field changes: the base envelope answers first, so a memo
    // that left the field out of its key would hand that answer to the changed envelope.
    const Envelope base = crown();
    std::vector<std::pair<glm::dvec3, glm::dvec3>> rays;
    const glm::dvec3 dirs[] = {{1, 0, 0},  {-1, 0, 0}, {0, 0, 1},   {0, 0, -1},  {0, 1, 0},
                               {0, -1, 0}, {1, 1, 1},  {-1, -1, 1}, {1, -1, -1}, {-1, 0.5, -1}};
    for (const glm::dvec3& at : {glm::dvec3{0, 6, 0}, glm::dvec3{0.3, 5.5, -0.2}, glm::dvec3{0, 3, 0}})
        for (const glm::dvec3& d : dirs) rays.emplace_back(at, d);
    for (int field = 0; field < 16; ++field) {
        if (field == 0 || field == 2) continue;
        Envelope e = base;
        double* v[16] = {&e.top.x,     &e.top.y,     &e.top.z,     &e.bottom.x,  &e.bottom.y,  &e.bottom.z,
                         &e.radius[0], &e.radius[1], &e.radius[2], &e.radius[3], &e.height[0], &e.height[1],
                         &e.height[2], &e.height[3], &e.c_top,     &e.c_bottom};
        *v[field] += field < 6 ? 0.05 : (field < 14 ? 0.1 : 0.3);
        INFO("field " << field);
        bool shaped = false;
        for (const auto& [p, d] : rays) {
            const double before = base.reach(p, d), after = e.reach_uncached(p, d);
            if (before == after) continue;
            shaped = true;
            CHECK(e.reach(p, d) == after);
            CHECK(base.reach(p, d) == before);
        }
        CHECK(shaped);
    }
    // the ray's every component
    const glm::dvec3 p{0.3, 5.5, -0.2}, d{0.4, 0.7, 0.2};
    const double first = base.reach(p, d);
    CHECK(first == base.reach_uncached(p, d));
    for (int c = 0; c < 6; ++c) {
        glm::dvec3 q = p, u = d;
        (c < 3 ? q[c] : u[c - 3]) += 0.05;
        INFO("component " << c);
        CHECK(base.reach_uncached(q, u) != first);
        CHECK(base.reach(q, u) == base.reach_uncached(q, u));
    }
    CHECK(base.reach(p, d) == first);
}

TEST_CASE("silhouette axis: polyline by arc length, Bezier by de Casteljau", "[silhouette]") {
    std::string error;
    AxisCurve line = AxisCurve::make(AxisCurve::Kind::Polyline, {{0, 0, 0}, {0, 3, 0}, {4, 3, 0}}, error);
    REQUIRE(error.empty());
    CHECK(line.point(0) == glm::dvec3(0, 0, 0));
    CHECK(line.point(1) == glm::dvec3(4, 3, 0));
    CHECK(glm::length(line.point(0.5) - glm::dvec3(0.5, 3, 0)) < 1e-12); // 3.5 of 7 along it
    CHECK(line.heading(0.2) == glm::dvec3(0, 1, 0));
    CHECK(line.heading(0.9) == glm::dvec3(1, 0, 0));
    CHECK(line.point(2) == line.point(1)); // t is clamped

    glm::dvec3 p0(0, 0, 0), p1(0, 2, 0), p2(2, 2, 1);
    AxisCurve bez = AxisCurve::make(AxisCurve::Kind::Bezier, {p0, p1, p2}, error);
    REQUIRE(error.empty());
    for (double t : {0.0, 0.3, 0.5, 1.0}) {
        glm::dvec3 want = p0 * ((1 - t) * (1 - t)) + p1 * (2 * t * (1 - t)) + p2 * (t * t);
        glm::dvec3 tangent = glm::normalize((p1 - p0) * (2 * (1 - t)) + (p2 - p1) * (2 * t));
        CHECK(glm::length(bez.point(t) - want) < 1e-12);
        CHECK(glm::length(bez.heading(t) - tangent) < 1e-12);
    }
    // a repeated first control point: the derivative vanishes at 0, the heading is where it goes
    AxisCurve flat = AxisCurve::make(AxisCurve::Kind::Bezier, {p0, p0, p2}, error);
    CHECK(glm::length(flat.heading(0) - glm::normalize(p2)) < 1e-5);

    AxisCurve bad = AxisCurve::make(AxisCurve::Kind::Polyline, {p0}, error);
    CHECK(error == "an axis needs at least two points");
    error.clear();
    bad = AxisCurve::make(AxisCurve::Kind::Bezier, {p1, p1, p1}, error);
    CHECK(error == "an axis needs two different points");
    error.clear();
    bad = AxisCurve::make(AxisCurve::Kind::Polyline, {p1, {NAN, 0, 0}}, error);
    CHECK(error == "an axis point is not finite");
}

TEST_CASE("silhouette placement: the child's T lies on the parent's envelope", "[silhouette]") {
    Silhouette parent = silhouette(crown(), {0, 10, 0});
    // a slender child crown, T above its top (any T will do: only BT counts)
    std::string error;
    Envelope small = Envelope::make({0, 4, 0}, {0, 0, 0}, {1, 2, 0}, {0, 2.5, 0.8}, {-1, 1.5, 0},
                                    {0, 2, -0.7}, 2, 2, error);
    REQUIRE(error.empty());
    Silhouette child = silhouette(small, {0.3, 4, 0.1});
    std::mt19937 rng(5);
    for (int k = 0; k < 300; ++k) {
        Placement pp;
        pp.rotation = random_rotation(rng);
        pp.scale = 0.5 + 2 * std::uniform_real_distribution<double>(0, 1)(rng);
        pp.translation = random_unit(rng) * 10.0;
        glm::dvec3 base = pp.to_world(random_inside(parent.envelope, rng, 0.95));
        glm::dvec3 dir = random_unit(rng);
        ChildPlacement c = place_child(parent, pp, child, base, dir * 2.0);
        INFO("case " << k << ": " << c.error);
        REQUIRE(c.ok());
        PlacedSilhouette placed{&parent, pp};
        PlacedSilhouette kid{&child, c.placement};
        CHECK(std::abs(placed.level(kid.tip()) - 1) < 1e-9);
        CHECK(glm::length(kid.base() - base) < 1e-9 * (1 + glm::length(base)));
        CHECK(glm::length(glm::normalize(kid.tip() - kid.base()) - dir) < 1e-9);
        CHECK(glm::length(kid.tip() - kid.base()) == Approx(c.reach).epsilon(1e-12));
        // a proper rotation
        CHECK(std::abs(glm::determinant(c.placement.rotation) - 1) < 1e-9);
    }
}

TEST_CASE("silhouette placement: the child keeps its parent's roll", "[silhouette]") {
    Silhouette parent = silhouette(crown(), {0, 10, 0});
    Silhouette child = silhouette(crown(), {1, 8, 0}); // BT leans toward +x
    std::mt19937 rng(11);
    for (int k = 0; k < 200; ++k) {
        Placement pp;
        pp.rotation = random_rotation(rng);
        const glm::dvec3 base = pp.to_world(random_inside(parent.envelope, rng, 0.9));
        const glm::dvec3 a = glm::normalize(pp.rotation * (child.tip - child.base()));
        // BT along the parent's frame already: the child takes the parent's rotation unchanged
        ChildPlacement same = place_child(parent, pp, child, base, a);
        REQUIRE(same.ok());
        for (int i = 0; i < 3; ++i) CHECK(glm::length(same.placement.rotation[i] - pp.rotation[i]) < 1e-12);
        // otherwise the turn is about the axis perpendicular to both: it stays where it was
        const glm::dvec3 dir = random_unit(rng);
        ChildPlacement c = place_child(parent, pp, child, base, dir);
        REQUIRE(c.ok());
        glm::dvec3 k_axis = glm::cross(a, dir);
        if (glm::length(k_axis) < 1e-6) continue;
        k_axis = glm::normalize(k_axis);
        const glm::dmat3 turn = c.placement.rotation * glm::transpose(pp.rotation);
        CHECK(glm::length(turn * k_axis - k_axis) < 1e-9);
    }
    // straight against BT: a half turn, still on the envelope
    Placement id;
    ChildPlacement back =
        place_child(parent, id, child, {0, 6, 0}, -glm::normalize(child.tip - child.base()));
    REQUIRE(back.ok());
    CHECK(std::abs(glm::determinant(back.placement.rotation) - 1) < 1e-9);
    CHECK(std::abs(parent.envelope.level(PlacedSilhouette{&child, back.placement}.tip()) - 1) < 1e-9);
}

// A child no larger than its parent, placed from a base well inside it (parent level at most
// 0.5): the part of the child's envelope within a tenth of |BT| of its base is inside the
// parent's envelope, level at most 1 exactly (no tolerance).
TEST_CASE("silhouette placement: a child's envelope near its base is inside the parent", "[silhouette]") {
    Silhouette parent = silhouette(crown(), {0, 10, 0});
    std::string error;
    Envelope small = Envelope::make({0, 4, 0}, {0, 0, 0}, {1, 2, 0}, {0, 2.5, 0.8}, {-1, 1.5, 0},
                                    {0, 2, -0.7}, 2, 2, error);
    Silhouette child = silhouette(small, {0, 4, 0});
    std::mt19937 rng(23);
    int checked = 0;
    for (int k = 0; k < 200; ++k) {
        const glm::dvec3 base = random_inside(parent.envelope, rng, 0.5);
        ChildPlacement c = place_child(parent, Placement{}, child, base, random_unit(rng));
        REQUIRE(c.ok());
        const double bt = glm::length(child.tip - child.base());
        for (int j = 0; j < 20; ++j) {
            glm::dvec3 local = child.base() + random_unit(rng) * (0.1 * bt * std::cbrt(0.999 * j / 20.0));
            if (!small.contains(local)) continue;
            ++checked;
            CHECK(parent.envelope.level(c.placement.to_world(local)) <= 1.0);
        }
    }
    CHECK(checked > 100);
}

TEST_CASE("silhouette placement: degenerate input is an error, never NaN", "[silhouette]") {
    Silhouette parent = silhouette(crown(), {0, 10, 0});
    Silhouette child = silhouette(crown(), {0, 10, 0});
    Placement id;
    auto no_nan = [](const ChildPlacement& c) {
        CHECK(!c.ok());
        CHECK(std::isfinite(c.reach));
        CHECK(finite(c.placement.translation));
        CHECK(std::isfinite(c.placement.scale));
    };
    ChildPlacement c = place_child(parent, id, child, {0, 12, 0}, {1, 0, 0});
    CHECK(c.error.find("outside the parent's envelope") != std::string::npos);
    no_nan(c);
    c = place_child(parent, id, child, {0, 6, 0}, {0, 0, 0});
    CHECK(c.error.find("direction is zero") != std::string::npos);
    no_nan(c);
    c = place_child(parent, id, child, {0, 6, 0}, {NAN, 1, 0});
    CHECK(c.error.find("finite") != std::string::npos);
    no_nan(c);
    Silhouette point_child = child;
    point_child.tip = point_child.base();
    c = place_child(parent, id, point_child, {0, 6, 0}, {1, 0, 0});
    CHECK(c.error.find("BT has no direction") != std::string::npos);
    no_nan(c);
    // on the envelope, pointing out: the ray leaves at once
    c = place_child(parent, id, child, {4, 6, 0}, {1, 0, 0});
    CHECK(c.error.find("leaves the parent's envelope at once") != std::string::npos);
    no_nan(c);
    Placement flat;
    flat.scale = 0;
    c = place_child(parent, flat, child, {0, 6, 0}, {1, 0, 0});
    CHECK(!c.ok());
    no_nan(c);
}
