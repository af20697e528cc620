// An obstacle's signed distance and its normal, inline for the loops that test every particle
// against every obstacle (integrate() and the length sweep's outside_obstacles()); internal to
// plant_physics. Obstacle::distance and Obstacle::normal are these.
#pragma once

#include "plant/physics/world.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

// A box's signed distance from q = |p - c| - h (c its centre, h its half sizes), as
// signed_distance works it out. Inside (no axis outside) or beside a face (one), the length below
// is 0 or that axis's q, found without its square root: sqrt(x * x) rounds to x for any x whose
// square neither overflows nor underflows (binary floating point, rounding to nearest), and the
// zeros add nothing to x * x. The same value, bit for bit (test_segment_box.cpp), and the square
// root off the chain of the length sweep, which waits on each particle's distance.
[[gnu::always_inline]] inline double box_distance(const glm::dvec3& q) {
    const double most = std::max(q.x, std::max(q.y, q.z));
    // (a NaN in q makes the length NaN, which std::max above would pass over: the full formula)
    if (q.x == q.x && q.y == q.y && q.z == q.z) {
        const int outside = (q.x > 0) + (q.y > 0) + (q.z > 0);
        if (outside == 0)
            return 0.0 + std::min(most, 0.0); // (0.0 +: -0 comes out +0, as the length's 0 + -0)
        if (outside == 1 && most > 1e-150 && most < 1e150) return most;
    }
    return glm::length(glm::max(q, glm::dvec3(0.0))) + std::min(most, 0.0);
}

// declared inline: GCC allows a function declared inline a larger inlining budget, and the
// loops over the obstacles want it inlined, as it was when the whole step was one file (forced:
// left to itself, GCC kept it a call in the length sweep)
[[gnu::always_inline]] inline double signed_distance(const Obstacle& o, const glm::dvec3& p) {
    const glm::dvec3 &a = o.a, &b = o.b;
    switch (o.kind) {
    case Obstacle::Sphere:
        return glm::length(p - a) - b.x;
    case Obstacle::Box: {
        glm::dvec3 c = (a + b) * 0.5, h = (b - a) * 0.5;
        return box_distance(glm::abs(p - c) - h);
    }
    case Obstacle::Plane:
        return glm::dot(p - a, glm::normalize(b));
    case Obstacle::Grid:
        return o.grid ? o.grid->sample(p - a) : 1e300;
    }
    return 1e300;
}

// World::distance_to: signed_distance with a plane's unit normal normalized once (the same value)
[[gnu::always_inline]] inline double World::distance_to(std::size_t k, const glm::dvec3& p) const {
    const Obstacle& o = obstacles_[k];
    if (o.kind == Obstacle::Plane) return glm::dot(p - o.a, unit_[k]);
    return signed_distance(o, p);
}

inline glm::dvec3 surface_normal(const Obstacle& o, const glm::dvec3& p) {
    if (o.kind == Obstacle::Plane) return glm::normalize(o.b);
    // central differences of the distance (over half a cell for a sampled grid)
    const double e = o.kind == Obstacle::Grid && o.grid ? o.grid->cell / 2 : 1e-6;
    glm::dvec3 g;
    if (o.kind == Obstacle::Box) {
        // p moved along one axis changes only that axis of the box's q (adding 0 leaves the
        // others, or turns -0 into +0, whose |p - c| is the same): the six distances share the
        // rest, with the values signed_distance gives at the six points
        const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5, q = glm::abs(p - c) - h;
        auto moved = [&](int axis, double by) {
            glm::dvec3 m = q;
            m[axis] = std::abs(p[axis] + by - c[axis]) - h[axis];
            return box_distance(m);
        };
        g = glm::dvec3(moved(0, e) - moved(0, -e), moved(1, e) - moved(1, -e), moved(2, e) - moved(2, -e));
    } else {
        auto d = [&](const glm::dvec3& q) { return signed_distance(o, q); };
        g = glm::dvec3(d(p + glm::dvec3(e, 0, 0)) - d(p - glm::dvec3(e, 0, 0)),
                       d(p + glm::dvec3(0, e, 0)) - d(p - glm::dvec3(0, e, 0)),
                       d(p + glm::dvec3(0, 0, e)) - d(p - glm::dvec3(0, 0, e)));
    }
    double l = glm::length(g);
    return l > 0 ? g / l : glm::dvec3(0, 1, 0);
}

// The least signed distance of obstacle o along the segment from a to b, and where (t in [0, 1]
// from a): exact for planes and spheres, a golden-section search for boxes (convex along a line;
// none when both ends are beyond one face by r or more, which returns r), samples half a cell
// apart refined by a search for a sampled grid (segment_contacts.cpp).
double deepest_on_segment(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, double r, double& t);

// Whether deepest_on_segment would find the capsule of radius r from a to b clear of box o (its
// least at least r - 1e-9), told without its search: exactly, from the pieces of the segment
// between the planes of the box's faces, with a margin of 1e-12 for rounding
// (segment_contacts.cpp). False also where it cannot tell so closely.
bool box_clear(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, double r);

} // namespace plant::physics
