// Length and bending (docs/physics.md, "Length and bending"): a sweep from the roots to the tips
// after the shape-matching passes. Shape matching over groups of three passes a correction on by
// one particle a pass, so a long stem under gravity stretches and folds however stiff it is
// (issue 18: a free 2 m shoot 6.2 m long at s = 0.2). The sweep carries the whole correction
// from the root to the tip in one go: each particle first moves part of the way to where its
// parent's turn from rest carries its rest offset (bending, by the stiffness), then onto its rest
// distance from the parent (length, always; follow-the-leader as in hair simulation).
#include "plant/physics/world.hpp"

#include "obstacle_field.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

namespace {

// v turned by the shortest rotation taking unit a to unit b (Rodrigues' formula with k = a x b
// unnormalized: v cos + (k x v) + k (k . v) / (1 + cos)); half a turn about an axis across a
// when b is (nearly) opposite to a
inline glm::dvec3 turn_between(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& v) {
    const double c = glm::dot(a, b);
    if (c < -1 + 1e-9) {
        glm::dvec3 k = glm::cross(a, std::fabs(a.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
        k = glm::normalize(k);
        return 2.0 * k * glm::dot(k, v) - v;
    }
    const glm::dvec3 k = glm::cross(a, b);
    return v * c + glm::cross(k, v) + k * (glm::dot(k, v) / (1 + c));
}

} // namespace

glm::dvec3 World::carried(std::uint32_t p, const glm::dvec3& v, bool back) const {
    const std::uint32_t g = parent_[p];
    const glm::dquat own = rotation_from_rest(p);
    if (g == kNone) return back ? glm::inverse(own) * v : own * v;
    const glm::dvec3 rest = rest_x_[p] - rest_x_[g], now = x_[p] - x_[g];
    const double lr = glm::length(rest), ln = glm::length(now);
    if (lr < 1e-12 || ln < 1e-12) return back ? glm::inverse(own) * v : own * v;
    return back ? turn_between(now / ln, rest / lr, v) : turn_between(rest / lr, now / ln, v);
}

void World::build_links() {
    const std::size_t n = x_.size();
    auto& sc = scratch_;
    sc.rest_link.assign(n, glm::dvec3(0.0));
    sc.rest_dir.assign(n, glm::dvec3(0, 1, 0));
    sc.rest_length.assign(n, 0.0);
    sc.dir.assign(n, glm::dvec3(0, 1, 0));
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t p = parent_[i];
        if (!alive_[i] || p == kNone) continue;
        sc.rest_link[i] = rest_x_[i] - rest_x_[p];
        sc.rest_length[i] = glm::length(sc.rest_link[i]);
        if (sc.rest_length[i] > 1e-12) sc.rest_dir[i] = sc.rest_link[i] / sc.rest_length[i];
    }
    build_sweep_order();
}

void World::build_sweep_order() {
    // A particle's place in the sweep depends only on its parent's, which index order puts first.
    // In index order most particles follow their parent directly (a stem's chain), so each waits
    // for the square root and divisions of the one before. Two chains handed out in index order
    // and visited in turn give the processor two independent particles at a time; every particle
    // still sees its parent placed, so the result is the same bit for bit. A chain's first
    // particle may wait for its parent in the other chain, which then goes on alone.
    const auto n = static_cast<std::uint32_t>(x_.size());
    auto& order = scratch_.sweep;
    order.clear();
    order.reserve(n);
    Array<std::uint8_t> placed(n, 0);
    auto chain_end = [&](std::uint32_t s) {
        std::uint32_t e = s + 1;
        while (e < n && parent_[e] == e - 1) ++e;
        return e;
    };
    std::uint32_t at[2] = {0, 0}, end[2] = {0, 0}, next = 0;
    for (;;) {
        bool moved = false;
        for (int l = 0; l < 2; ++l) {
            if (at[l] == end[l] && next < n) at[l] = next, end[l] = next = chain_end(next);
            if (at[l] == end[l]) continue;
            const std::uint32_t i = at[l], p = parent_[i];
            if (p != kNone && (p >= n || !placed[p])) continue; // its parent first
            order.push_back(i);
            placed[i] = 1;
            ++at[l];
            moved = true;
        }
        if (moved) continue;
        // both lanes empty and nothing left, or (were a parent ever after its child) stuck: the
        // rest in index order
        for (std::uint32_t i = 0; i < n; ++i)
            if (!placed[i]) order.push_back(i);
        break;
    }
}

bool World::outside_obstacles(glm::dvec3& x, double r, const glm::dvec3* parent) const {
    // each obstacle the point is inside pushes it out, a radius off the surface; returns whether
    // any did. Along the normal at the point, or, when the parent lies against the same obstacle,
    // along the normal at the parent: a link whose parent is on one face of a thin rail stays on
    // that face instead of being pushed over the rail's edge onto the next face, a stretch away.
    bool moved = false;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
        const Obstacle& o = obstacles_[k];
        double d = distance_to(k, x) - r;
        if (d >= 0) continue;
        moved = true;
        if (parent && distance_to(k, *parent) < 2 * r) {
            const glm::dvec3 n = surface_normal(o, *parent);
            // inside a box the distance is to the nearest face
            for (int round = 0; round < 8 && d < 0; ++round) {
                x -= n * d;
                d = distance_to(k, x) - r;
            }
            if (d >= 0) continue;
        }
        x = exit_point(x, r, k); // not into another obstacle where two meet
    }
    return moved;
}

void World::keep_shape(bool orient, bool bend) {
    // every parent comes before its children in the sweep's order (build_sweep_order), so one
    // pass sees every parent already placed; it runs on one thread, so the result does not
    // depend on the count
    auto& sc = scratch_;
    const auto& stiff = sc.stiffness;
    sc.oriented.clear(); // the particles whose orientation follows their link, after the sweep
    for (const std::uint32_t i : sc.sweep) { // (build_sweep_order)
        const std::uint32_t p = parent_[i];
        if (!alive_[i] || p == kNone) continue;
        const glm::dvec3& rest = sc.rest_link[i];
        const double want = sc.rest_length[i];
        const bool free =
            !fixed_[i] &&
            (pulls_.empty() || std::none_of(pulls_.begin(), pulls_.end(), [&](const auto& pull) {
                 return pull.first == i;
             })); // a dragged particle stays where it is dragged: its link stretches, and may break
        if (free) {
            const double s = stiff[i];
            const double b = bend ? settings_.bending * s * s * s : 0.0;
            if (b > 0) {
                // where the parent's turn from rest carries the rest link
                const glm::dvec3 link = parent_[p] == kNone ? rotation_from_rest(p) * rest
                                                            : turn_between(sc.rest_dir[p], sc.dir[p], rest);
                x_[i] += std::min(b, 1.0) * (x_[p] + link - x_[i]);
            }
        }
        glm::dvec3 d = x_[i] - x_[p];
        const double len = glm::length(d);
        if (len < 1e-12 || want < 1e-12) {
            sc.dir[i] = sc.rest_dir[i];
            continue;
        }
        d /= len;
        if (free) {
            x_[i] = x_[p] + d * want;
            // after the contacts (no bending): out of the obstacles too, then back to the rest
            // length along the new direction (up to four times), so a link lying on a surface
            // keeps both; integrate() then meets the obstacles as before (friction, elasticity)
            if (!bend)
                for (int round = 0; round < 4 && outside_obstacles(x_[i], sc.thin_of(i, radii_), &x_[p]);
                     ++round) {
                    const glm::dvec3 e = x_[i] - x_[p];
                    const double l = glm::length(e);
                    if (l < 1e-12) break;
                    d = e / l;
                    x_[i] = x_[p] + d * want;
                    // the obstacles have the last word: a link whose parent a moved obstacle
                    // engulfed stretches rather than enter it
                    if (round == 3) outside_obstacles(x_[i], sc.thin_of(i, radii_));
                }
        }
        sc.dir[i] = d;
        if (orient) sc.oriented.push_back(i);
    }
    if (orient) orient_along_links(); // (orient.cpp)
}

} // namespace plant::physics
