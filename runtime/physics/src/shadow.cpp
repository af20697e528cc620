// The scene's shade: a ray from a point toward the light, tested against each obstacle
// (light.hpp). Hädrich et al. 2017 light their scenes with shadow maps (section 4.2), so the
// obstacles shade the plant as well as its own leaves; docs/climber-growth.md, "Growth rate".
#include "plant/physics/light.hpp"

#include "obstacle_field.hpp"

#include "cells.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace plant::physics {

namespace {

// The ray p + t d (t > 0) against the box [lo, hi] by slabs: the interval of t inside it, empty
// when t_in > t_out. A ray parallel to a slab it starts outside of misses.
bool slab_interval(const glm::dvec3& lo, const glm::dvec3& hi, const glm::dvec3& p, const glm::dvec3& d,
                   double& t_in, double& t_out) {
    t_in = -1e300;
    t_out = 1e300;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0) {
            if (p[k] <= lo[k] || p[k] >= hi[k]) return false;
            continue;
        }
        double a = (lo[k] - p[k]) / d[k], b = (hi[k] - p[k]) / d[k];
        if (a > b) std::swap(a, b);
        t_in = std::max(t_in, a);
        t_out = std::min(t_out, b);
    }
    return t_in < t_out;
}

// a sampled grid: marched by its distance from where the ray meets the grid's box to where it
// leaves it; inside (a negative sample) is a hit
bool grid_blocks(const Obstacle& o, const glm::dvec3& p, const glm::dvec3& d) {
    if (!o.grid || o.grid->d.empty()) return false;
    const DistanceGrid& g = *o.grid;
    const glm::dvec3 lo = g.lo + o.a, hi = lo + glm::dvec3(g.n - 1) * g.cell;
    double t_in = 0, t_out = 0;
    if (!slab_interval(lo, hi, p, d, t_in, t_out) || t_out <= 0) return false;
    if (signed_distance(o, p) <= 0) return false; // inside: not shaded by it
    double t = std::max(t_in, 0.0);
    const double least = g.cell / 2;
    for (int k = 0; k < 4096 && t <= t_out; ++k) {
        const double s = signed_distance(o, p + d * t);
        if (s < 0) return true;
        t += std::max(s, least);
    }
    return false;
}

} // namespace

bool blocks_light(const Obstacle& o, const glm::dvec3& p, const glm::dvec3& to_light) {
    if (!finite(p) || !finite(to_light)) return false;
    const glm::dvec3& d = to_light;
    switch (o.kind) {
    case Obstacle::Sphere: { // |p + t d - c|^2 = r^2 has a root t > 0, p outside
        const glm::dvec3 m = p - o.a;
        const double c = glm::dot(m, m) - o.b.x * o.b.x, b = glm::dot(m, d);
        return c > 0 && b < 0 && b * b - c > 0;
    }
    case Obstacle::Box: {
        if (signed_distance(o, p) <= 0) return false;
        double t_in = 0, t_out = 0;
        return slab_interval(o.a, o.b, p, d, t_in, t_out) && t_in > 0;
    }
    case Obstacle::Plane: { // above it and the light below its horizon
        const glm::dvec3 n = glm::normalize(o.b);
        return glm::dot(p - o.a, n) > 0 && glm::dot(d, n) < 0;
    }
    case Obstacle::Grid:
        return grid_blocks(o, p, d);
    }
    return false;
}

bool in_shadow(const std::vector<Obstacle>& obstacles, const glm::dvec3& p, const glm::dvec3& to_light) {
    return std::any_of(obstacles.begin(), obstacles.end(),
                       [&](const Obstacle& o) { return blocks_light(o, p, to_light); });
}

const std::vector<glm::dvec3>& sky_directions() {
    static const std::vector<glm::dvec3> sky = [] {
        std::vector<glm::dvec3> d;
        const double golden = std::numbers::pi * (3 - std::sqrt(5.0));
        for (int k = 0; k < kSkyDirections; ++k) {
            const double y = (k + 0.5) / kSkyDirections, r = std::sqrt(1 - y * y);
            d.emplace_back(r * std::cos(golden * k), y, r * std::sin(golden * k));
        }
        return d;
    }();
    return sky;
}

namespace {

// sky_visible, each direction through in_shadow (a scene of many boxes or planes)
double sky_visible_each(const std::vector<Obstacle>& obstacles, const glm::dvec3& p) {
    int open = 0;
    for (const glm::dvec3& d : sky_directions()) open += in_shadow(obstacles, p, d) ? 0 : 1;
    return static_cast<double>(open) / kSkyDirections;
}

} // namespace

double sky_visible(const std::vector<Obstacle>& obstacles, const glm::dvec3& p) {
    const std::vector<glm::dvec3>& sky = sky_directions();
    if (!finite(p)) return 1.0; // (blocks_light: nothing shades such a point)
    // Each direction goes through blocks_light's tests, but what they need of p alone is worked
    // out once (a plane's unit normal, whether p is above it), and an obstacle that can hide no
    // direction of the sky is left out: a box p is inside or that lies wholly below p (every
    // direction rises), a plane p is not above. The same tests on the same numbers: the same
    // answer for every direction (Fig. 14 right: 32 directions for each apex, each step). A box
    // whose distance is NaN stays in (blocks_light leaves out only those with a distance <= 0),
    // and a scene with a box whose corners are not finite goes through in_shadow direction by
    // direction.
    struct Box {
        const Obstacle* o;
        glm::dvec3 lo, hi; // its corners sorted
    };
    constexpr std::size_t kMostEach = 16; // boxes, and planes, worked out ahead (more: in_shadow)
    Box boxes[kMostEach];
    glm::dvec3 above[kMostEach];                           // the unit normals of the planes p is above
    std::size_t box_count = 0, plane_count = 0, other = 0; // other: spheres and grids (blocks_light)
    for (const Obstacle& o : obstacles) {
        if (o.kind == Obstacle::Plane) {
            const glm::dvec3 n = glm::normalize(o.b);
            if (!(glm::dot(p - o.a, n) > 0)) continue; // (the light below its horizon: p is not above it)
            if (plane_count == kMostEach) return sky_visible_each(obstacles, p);
            above[plane_count++] = n;
        } else if (o.kind != Obstacle::Box) {
            ++other;
        } else if (!finite(o.a) || !finite(o.b)) {
            return sky_visible_each(obstacles, p); // (the shortcuts below reason on finite corners)
        } else if (!(signed_distance(o, p) <= 0) && std::max(o.a.y, o.b.y) > p.y) {
            if (box_count == kMostEach) return sky_visible_each(obstacles, p);
            boxes[box_count++] = Box{&o, glm::min(o.a, o.b), glm::max(o.a, o.b)};
        }
    }
    auto box_blocks = [&](const Box& b, const glm::dvec3& d) {
        // along x and z, a box wholly behind p hides nothing ahead (slab_interval's interval would
        // end before p)
        if ((d.x > 0 && b.hi.x <= p.x) || (d.x < 0 && b.lo.x >= p.x) || (d.z > 0 && b.hi.z <= p.z) ||
            (d.z < 0 && b.lo.z >= p.z))
            return false;
        double t_in = 0, t_out = 0;
        return slab_interval(b.o->a, b.o->b, p, d, t_in, t_out) && t_in > 0;
    };
    int open = 0;
    for (const glm::dvec3& d : sky) {
        bool hidden = false;
        for (std::size_t k = 0; k < plane_count && !hidden; ++k) hidden = glm::dot(d, above[k]) < 0;
        for (std::size_t k = 0; k < box_count && !hidden; ++k) hidden = box_blocks(boxes[k], d);
        for (auto o = obstacles.begin(); other > 0 && !hidden && o != obstacles.end(); ++o)
            if (o->kind != Obstacle::Box && o->kind != Obstacle::Plane) hidden = blocks_light(*o, p, d);
        open += hidden ? 0 : 1;
    }
    return static_cast<double>(open) / kSkyDirections;
}

double scene_occlusion(const LightGrid& grid, const std::vector<Obstacle>& obstacles, bool obstacles_shade,
                       const glm::dvec3& p, const glm::dvec3& to_light, double opacity, double diffuse) {
    const bool shaded = obstacles_shade && in_shadow(obstacles, p, to_light);       // an obstacle is opaque
    if (!(diffuse > 0)) return shaded ? 1.0 : grid.occlusion(p, to_light, opacity); // (NaN: none)
    diffuse = std::min(diffuse, 1.0);
    const double through_plant = 1 - grid.occlusion(p, to_light, opacity);
    if (through_plant <= 0) return 1.0; // the plants let nothing through: no sky to look for
    const double sky = obstacles_shade ? sky_visible(obstacles, p) : 1.0;
    return 1 - through_plant * ((1 - diffuse) * (shaded ? 0.0 : 1.0) + diffuse * sky);
}

} // namespace plant::physics
