// Links against a box (runtime/physics/src/segment_contacts.cpp): box_clear tells link_contacts
// that a capsule is clear without deepest_on_segment's search, so it must never say clear where
// the search would find the capsule in the box, and it should say clear wherever the capsule
// plainly is (else the search runs for nothing). Checked on random links around a box: lying
// along faces, round edges and corners, across the face planes, through the box and inside it.
#include "obstacle_field.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <utility>

using namespace plant::physics;

namespace {

// the least signed distance along the segment, by dense sampling (an upper bound of the least;
// the distance changes by at most the step between samples)
double sampled_least(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, int samples) {
    double least = 1e300;
    for (int k = 0; k <= samples; ++k)
        least = std::min(least, signed_distance(o, a + (b - a) * (double(k) / samples)));
    return least;
}

} // namespace

TEST_CASE("a box tells a clear link exactly, and never one in contact", "[physics][segments]") {
    Obstacle o;
    o.kind = Obstacle::Box;
    o.a = glm::dvec3(-0.5, 0.0, -0.2);
    o.b = glm::dvec3(0.7, 1.5, 0.1);
    std::mt19937_64 rng(18);
    std::uniform_real_distribution<double> around(-1.0, 1.0), unit(0.0, 1.0);
    const double r = 0.01;
    int clear = 0, contact = 0, missed = 0;
    for (int n = 0; n < 20000; ++n) {
        // one end near the box (scaled round it), the other a link's length away, in any direction
        const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5;
        glm::dvec3 a = c + h * glm::dvec3(around(rng), around(rng), around(rng)) * (1.0 + 0.1 * unit(rng));
        // a third of the links are put on a face plane's offset of r, as the obstacle pass leaves them
        if (n % 3 == 0) {
            const int j = static_cast<int>(unit(rng) * 3) % 3;
            a[j] = c[j] + (unit(rng) < 0.5 ? -1 : 1) * (h[j] + r);
        }
        glm::dvec3 d(around(rng), around(rng), around(rng));
        if (n % 3 == 0) d[static_cast<int>(unit(rng) * 3) % 3] = 0; // along the face
        if (glm::length(d) < 1e-6) continue;
        const glm::dvec3 b = a + glm::normalize(d) * (0.01 + 0.1 * unit(rng));
        const bool said_clear = box_clear(o, a, b, r);
        double t = 0;
        const double deepest = deepest_on_segment(o, a, b, r, t);
        const double sampled = sampled_least(o, a, b, 4000);
        INFO("a " << a.x << " " << a.y << " " << a.z << ", b " << b.x << " " << b.y << " " << b.z);
        if (said_clear) {
            ++clear;
            // never where the search finds it in contact, nor where the samples do
            REQUIRE(deepest >= r - 1e-9);
            REQUIRE(sampled >= r - 1e-9);
        } else {
            ++contact;
            // clearly clear links (a sampled least over a tenth of a millimetre beyond r, more
            // than the samples can miss) are told so
            if (sampled > r + 1e-4) ++missed;
        }
    }
    CHECK(missed == 0);
    // the random links include both kinds, many of each
    CHECK(clear > 5000);
    CHECK(contact > 2000);
}

TEST_CASE("a box's signed distance and normal are the full formula's, bit for bit", "[physics][segments]") {
    // signed_distance skips the square root where at most one axis is outside the box, and
    // surface_normal works out only the moved axis for each of its six distances; the values
    // must be the ones the full formulas give (the climber goldens and the bench's state hash
    // rest on them): points all round boxes (corners either way round), on the faces and the
    // edges, far off and inside, compared as bits
    auto full = [](const Obstacle& o, const glm::dvec3& p) {
        const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5, q = glm::abs(p - c) - h;
        return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
    };
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> around(-2.0, 2.0), unit(0.0, 1.0);
    std::uniform_int_distribution<int> pick(0, 5);
    const double scales[] = {1e-3, 1.0, 1e3, 1e140};
    std::size_t beside = 0, inside = 0, compared = 0;
    for (const double s : scales)
        for (int n = 0; n < 20000; ++n) {
            Obstacle o;
            o.kind = Obstacle::Box;
            o.a = glm::dvec3(around(rng), around(rng), around(rng)) * s;
            o.b = o.a + glm::dvec3(unit(rng), unit(rng), unit(rng)) * (n % 7 == 0 ? -s : s);
            glm::dvec3 p = glm::dvec3(around(rng), around(rng), around(rng)) * s;
            // some points exactly on a face's plane or an edge of the box
            const int on = pick(rng);
            if (on < 3) p[on] = unit(rng) < 0.5 ? o.a[on] : o.b[on];
            if (on == 0) p[1] = o.b[1];
            const double got = signed_distance(o, p), want = full(o, p);
            CHECK(std::memcmp(&got, &want, sizeof got) == 0);
            // and the normal, whose six distances share all but one axis of q: as central
            // differences of the full formula at the six points
            const double e = 1e-6;
            auto d = [&](const glm::dvec3& at) { return full(o, at); };
            const glm::dvec3 g(d(p + glm::dvec3(e, 0, 0)) - d(p - glm::dvec3(e, 0, 0)),
                               d(p + glm::dvec3(0, e, 0)) - d(p - glm::dvec3(0, e, 0)),
                               d(p + glm::dvec3(0, 0, e)) - d(p - glm::dvec3(0, 0, e)));
            const double l = glm::length(g);
            const glm::dvec3 normal = surface_normal(o, p), n_want = l > 0 ? g / l : glm::dvec3(0, 1, 0);
            CHECK(std::memcmp(&normal, &n_want, sizeof normal) == 0);
            const glm::dvec3 q = glm::abs(p - (o.a + o.b) * 0.5) - glm::abs(o.b - o.a) * 0.5;
            const int outside = (q.x > 0) + (q.y > 0) + (q.z > 0);
            beside += outside == 1, inside += outside == 0, ++compared;
        }
    // points with a NaN coordinate, and a flat box (both corners at 0 on an axis) met at -0 there
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Obstacle flat;
    flat.kind = Obstacle::Box;
    flat.a = glm::dvec3(-1, 0, -1);
    flat.b = glm::dvec3(1, 0, 1);
    Obstacle unit_box;
    unit_box.kind = Obstacle::Box;
    unit_box.a = glm::dvec3(0.0);
    unit_box.b = glm::dvec3(1.0);
    const std::pair<const Obstacle*, glm::dvec3> odd[] = {
        {&unit_box, {4.5, nan, 0.5}}, {&unit_box, {0.2, 0.3, nan}}, {&unit_box, {nan, 0.5, 0.5}},
        {&unit_box, {2.0, 0.5, nan}}, {&flat, {0.5, -0.0, 0.25}},   {&flat, {-0.0, -0.0, -0.0}},
        {&flat, {3.0, -0.0, 0.0}},
    };
    for (const auto& [box, p] : odd) {
        const double got = signed_distance(*box, p), want = full(*box, p);
        INFO("point " << p.x << ", " << p.y << ", " << p.z << ": " << got << " against " << want);
        CHECK(std::memcmp(&got, &want, sizeof got) == 0);
    }
    CHECK(compared == 80000);
    CHECK(beside > 10000); // (the shortcut's cases were met)
    CHECK(inside > 1000);
}
