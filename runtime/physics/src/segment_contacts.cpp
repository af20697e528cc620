// Segments against obstacles (docs/physics.md, "Obstacles"): the link between a particle and its
// parent is a capsule of the particle's thinnest radius, and no capsule may cross an obstacle.
// Resolving particle centres alone let a link pass through a post thinner than the link is long
// (issue 18: 175 of 1,223 links of Fig. 11 crossed a post or a rail, up to 11.6 mm deep).
//
// Hädrich et al. 2017 (section 5.2) keep particles out of obstacles' signed distance fields; for
// the links between them we do what position-based dynamics does for an edge against a surface
// (Müller et al. 2007, section 3.5's "collision constraints", applied at the closest point of an
// edge as in edge-edge contacts): find the point of the segment deepest in the obstacle, and move
// both end particles by their barycentric weights and inverse masses so that point comes out.
//
// All obstacles are resolved together: a point pushed out of one obstacle into another (a post
// standing on the ground, pushed out through its bottom face into the ground plane) leaves the
// first obstacle through the nearest face that is clear of every other one instead, so a seam
// between two supports does not leak.
#include "plant/physics/world.hpp"

#include "obstacle_field.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

namespace {

// how far a link pinched across an obstacle may stretch (or squash) in the contact pass: its ends
// on two sides of a rail thicker than it is long cannot both be clear at its rest length
constexpr double kPinched = 1.2;

// the least move of a link's end that has the contact pass's later sweeps visit the links at that
// particle, and the least gap between a link's length and its rest length that has them visit it
// (World::segment_sweeps): a nanometre, far below any contact's depth
constexpr double kFollow = 1e-9;

// a box's capsule test that needs no search: both ends beyond the same face by r or more
inline bool beyond_one_face(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, double r) {
    const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5;
    const glm::dvec3 qa = a - c, qb = b - c;
    for (int j = 0; j < 3; ++j)
        if ((qa[j] - h[j] >= r && qb[j] - h[j] >= r) || (-qa[j] - h[j] >= r && -qb[j] - h[j] >= r))
            return true;
    return false;
}

// the least of f over [lo, hi] for f convex there: golden-section search
template <class F> double golden_min(F&& f, double lo, double hi, double& at) {
    constexpr double g = 0.6180339887498949;
    double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
    double f1 = f(x1), f2 = f(x2);
    for (int k = 0; k < 24; ++k) { // 0.618^24: within 1e-5 of the segment's length
        if (f1 <= f2) {
            hi = x2, x2 = x1, f2 = f1;
            x1 = hi - g * (hi - lo), f1 = f(x1);
        } else {
            lo = x1, x1 = x2, f1 = f2;
            x2 = lo + g * (hi - lo), f2 = f(x2);
        }
    }
    at = f1 <= f2 ? x1 : x2;
    return std::min(f1, f2);
}

// Where p lies along axis j of a box of half-extents h about the origin: below it (-1), across
// it (0) or above it (1).
int zone(const glm::dvec3& p, const glm::dvec3& h, int j) {
    return p[j] > h[j] ? 1 : p[j] < -h[j] ? -1 : 0;
}

// The least distance outside the box (half-extents h, centre at the origin) over the piece
// [s0, s1] of the segment from pa to pb, all of which lies in the zones of its midpoint along
// each axis (below the box, across it, above it): there the distance is the length of a vector
// whose components along the axes the piece is beyond are linear and the others zero, and its
// least is a point's distance to a segment. Negative when the piece is inside the box.
double least_outside(const glm::dvec3& pa, const glm::dvec3& pb, const glm::dvec3& h, double s0, double s1) {
    const glm::dvec3 m = pa + (pb - pa) * ((s0 + s1) / 2);
    glm::dvec3 u(0.0), v(0.0); // the outside parts at s0 and s1 (signed_distance's q, cut at 0)
    bool outside = false;
    for (int j = 0; j < 3; ++j) {
        const double z = zone(m, h, j);
        if (z == 0) continue;
        u[j] = z * (pa[j] + (pb[j] - pa[j]) * s0) - h[j];
        v[j] = z * (pa[j] + (pb[j] - pa[j]) * s1) - h[j];
        outside = true;
    }
    if (!outside) return -1; // inside the box
    const glm::dvec3 d = v - u;
    const double dd = glm::dot(d, d);
    const double s = dd > 0 ? std::clamp(-glm::dot(u, d) / dd, 0.0, 1.0) : 0.0;
    return glm::length(u + d * s);
}

} // namespace

// Whether a box's capsule test (deepest_on_segment) would find the capsule clear, told without
// its search: both ends beyond one face by r or more (beyond_one_face, its first test), or else
// the segment cut where it crosses the planes of the box's faces into pieces that each lie in
// one zone along every axis, and the least of each piece's distance (least_outside) at least r.
// That is the exact least of the distance along the segment; the margin of 1e-12 under
// deepest_on_segment's bound covers the rounding of its distances and of the cuts, so this says
// clear only where deepest_on_segment would (and then link_contacts does not push).
bool box_clear(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, double r) {
    if (beyond_one_face(o, a, b, r)) return true;
    const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5;
    const glm::dvec3 pa = a - c, pb = b - c;
    // most links lie in one zone along every axis (along a face, beyond an edge): one piece
    bool one_piece = true;
    for (int j = 0; j < 3; ++j) one_piece = one_piece && zone(pa, h, j) == zone(pb, h, j);
    if (one_piece) return least_outside(pa, pb, h, 0, 1) >= r - 1e-9 + 1e-12;
    double cut[8];
    int cuts = 0;
    cut[cuts++] = 0;
    for (int j = 0; j < 3; ++j) {
        const double step = pb[j] - pa[j];
        if (step == 0 || zone(pa, h, j) == zone(pb, h, j)) continue; // no face plane crossed
        for (const double face : {-h[j], h[j]}) {
            const double s = (face - pa[j]) / step;
            if (s > 0 && s < 1) cut[cuts++] = s;
        }
    }
    for (int k = 2; k < cuts; ++k) // in order (at most six: by insertion)
        for (int l = k; l > 1 && cut[l] < cut[l - 1]; --l) std::swap(cut[l], cut[l - 1]);
    cut[cuts++] = 1;
    for (int k = 0; k + 1 < cuts; ++k)
        if (least_outside(pa, pb, h, cut[k], cut[k + 1]) < r - 1e-9 + 1e-12) return false;
    return true;
}

double deepest_on_segment(const Obstacle& o, const glm::dvec3& a, const glm::dvec3& b, double r, double& t) {
    const glm::dvec3 d = b - a;
    const double len2 = glm::dot(d, d);
    auto at = [&](double s) { return signed_distance(o, a + d * s); };
    switch (o.kind) {
    case Obstacle::Plane: { // linear along the segment: an end is deepest
        const double da = at(0), db = at(1);
        t = da <= db ? 0 : 1;
        return std::min(da, db);
    }
    case Obstacle::Sphere:
        t = len2 > 0 ? std::clamp(glm::dot(o.a - a, d) / len2, 0.0, 1.0) : 0.0;
        return at(t);
    case Obstacle::Box: { // convex along the segment
        if (beyond_one_face(o, a, b, r)) {
            t = 0;
            return r;
        }
        const double da = at(0), db = at(1);
        // convex: when the distance grows from an end into the segment, that end is its least
        // (a link lying along a face, the common case, needs no search)
        constexpr double h = 1e-6;
        const bool rises_a = at(h) >= da, rises_b = at(1 - h) >= db;
        if (rises_a || rises_b) {
            const bool from_a = rises_a && (da <= db || !rises_b);
            t = from_a ? 0 : 1;
            return from_a ? da : db;
        }
        double s = 0;
        const double inner = golden_min(at, 0.0, 1.0, s);
        if (inner < std::min(da, db)) {
            t = s;
            return inner;
        }
        t = da <= db ? 0 : 1;
        return std::min(da, db);
    }
    case Obstacle::Grid: { // not convex: samples half a cell apart, then the best one's neighbourhood
        const double cell = o.grid ? o.grid->cell : 1;
        const int n = std::clamp(static_cast<int>(std::ceil(std::sqrt(len2) / (cell / 2))), 1, 64);
        int best = 0;
        double low = at(0);
        for (int k = 1; k <= n; ++k) {
            const double v = at(static_cast<double>(k) / n);
            if (v < low) low = v, best = k;
        }
        double s = 0;
        const double lo = std::max(0, best - 1) / static_cast<double>(n);
        const double hi = std::min(n, best + 1) / static_cast<double>(n);
        const double refined = golden_min(at, lo, hi, s);
        t = refined < low ? s : static_cast<double>(best) / n;
        return std::min(refined, low);
    }
    }
    t = 0;
    return 1e300;
}

glm::dvec3 World::exit_point(const glm::dvec3& x, double r, std::size_t k, glm::dvec3* normal) const {
    // out of obstacle k along its normal, r off its surface: the shortest way out
    const Obstacle& o = obstacles_[k];
    const double d = signed_distance(o, x) - r;
    const glm::dvec3 nrm = surface_normal(o, x);
    glm::dvec3 out = x - nrm * d;
    // a sampled grid's distance is not exact (in a concave corner it grows more slowly than the
    // distance moved along its normal): a few more steps along the normal there
    for (int more = 0; o.kind == Obstacle::Grid && more < 4; ++more) {
        const double left = signed_distance(o, out) - r;
        if (left >= -1e-5) break;
        out -= surface_normal(o, out) * left;
    }
    if (normal) *normal = nrm;
    auto clear = [&](const glm::dvec3& p) {
        for (std::size_t j = 0; j < obstacles_.size(); ++j)
            if (signed_distance(obstacles_[j], p) < r - 1e-9) return false;
        return true;
    };
    if (o.kind != Obstacle::Box || obstacles_.size() < 2 || clear(out)) return out;
    // that way leads into another obstacle (a post's bottom face into the ground): out through
    // the box's face, and then out of the other obstacles along their normals, that moves x the
    // least and ends clear of every obstacle; when none does, the shortest way
    const glm::dvec3 c = (o.a + o.b) * 0.5, h = (o.b - o.a) * 0.5;
    glm::dvec3 best = out;
    // a face farther than 5 cm beyond the shortest way (the top of a tall post for a point at its
    // foot) is no way out for a particle a step moved
    double best_move = glm::length(out - x) + 0.05;
    bool found = false;
    for (int j = 0; j < 3; ++j)
        for (const double side : {-1.0, 1.0}) {
            glm::dvec3 p = x;
            p[j] = c[j] + side * (h[j] + r);
            for (std::size_t m = 0; m < obstacles_.size(); ++m) {
                if (m == k) continue;
                const double dm = signed_distance(obstacles_[m], p) - r;
                if (dm < 0) p -= surface_normal(obstacles_[m], p) * dm;
            }
            const double move = glm::length(p - x);
            if (move < best_move && clear(p)) best = p, best_move = move, found = true;
        }
    if (normal && found && best_move > 0) *normal = (best - x) / best_move;
    return best;
}

glm::dvec3 World::clear_segment_end(const glm::dvec3& from, const glm::dvec3& to, double r) const {
    // `from` stays and the segment keeps its length: its direction turns, as little as it takes,
    // until the capsule is clear. Against the obstacle it is deepest in, first the part of the
    // direction into the surface (at the deepest point) goes, so a shoot aimed straight at a wall
    // runs along it instead of turning back; then, where the surface curves toward the segment,
    // the deepest point is lifted out along the normal, the direction turned by that much.
    const double length = glm::length(to - from);
    if (!(length > 1e-12)) return to;
    glm::dvec3 dir = (to - from) / length;
    for (int round = 0; round < 8; ++round) {
        double worst = r - 1e-9, at = 0;
        std::size_t hit = obstacles_.size();
        for (std::size_t k = 0; k < obstacles_.size(); ++k) {
            double t = 0;
            const double d = deepest_on_segment(obstacles_[k], from, from + dir * length, r, t);
            if (d < worst) worst = d, at = t, hit = k;
        }
        if (hit == obstacles_.size()) break;
        const glm::dvec3 c = from + dir * (length * at);
        glm::dvec3 n;
        const glm::dvec3 out = exit_point(c, r, hit, &n);
        const double into = glm::dot(dir, n);
        if (into < 0) dir -= n * into; // along the surface
        if (glm::length(dir) < 1e-6) { // straight at it: any way along it
            dir = glm::cross(n, std::fabs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0));
        }
        dir = glm::normalize(dir);
        // the rest of the way out, at the deepest point, bounded where that point is near `from`
        const double lift = glm::length(out - c);
        if (into >= 0 || round > 0) dir = glm::normalize(dir + n * (lift / (length * std::max(at, 0.25))));
    }
    return from + dir * length;
}

void World::weigh_particles() {
    // each particle's inverse mass, 0 where it does not move: fixed, or dragged (a dragged
    // particle stays where it is dragged). Neither changes within a step, so the contact passes
    // of the links (segment_sweeps, separate_links) read it from here, not working it out at
    // every visit of a link
    const std::size_t n = x_.size();
    auto& inverse = scratch_.inverse_mass;
    inverse.resize(n);
    for (std::size_t j = 0; j < n; ++j) inverse[j] = fixed_[j] ? 0.0 : 1.0 / std::max(m_[j], 1e-12);
    for (const auto& pull : pulls_)
        if (pull.first < n) inverse[pull.first] = 0.0;
}

void World::resolve_segments(bool fresh) {
    const std::size_t n = x_.size();
    if (obstacles_.empty() || n < 2) return;
    auto& sc = scratch_;
    // the links a sweep of this step found clear, with their ends where they were then. At the
    // same positions a contact sweep does nothing to such a link: its length was brought within
    // the bounds of the contact sweeps just before (so the clamp below leaves it), and the
    // obstacles, the masses and the held particles do not change within a step. So the later
    // calls of a step (after each round of links of different plants, World::part_plants) test only the
    // links some push has moved since; the result is the same bit for bit. Fig. 14 right at 100
    // steps: of 57.9 million visits of a link, 25.5 million are passed over so, and of the
    // remaining 31.8 million contact tests 8.0 million below (the run 1.04 times as fast)
    auto& found_clear = sc.found_clear;
    auto& ends = sc.clear_ends;
    if (fresh || found_clear.size() != n) found_clear.assign(n, 0);
    ends.resize(2 * n);
    // broad phase: a link whose midpoint is farther than half its length and its radius (and a
    // margin of 2 mm for this pass's pushes) from an obstacle cannot reach it (a signed distance
    // changes no faster than the distance). The answer depends only on the link's two ends (the
    // radii and the obstacles stay put within a step), so the later calls of a step work it out
    // again only for the links an end of which has moved since the call before: the same flags
    // (Fig. 14 right: most links are where the last call left them, and this test of every link
    // was 6 % of the run)
    auto& base = sc.near_base; // the test's answer, before the rings below
    auto& seen = sc.near_seen; // each particle where the last call saw it
    auto& moved = sc.near_moved;
    const bool all = fresh || base.size() != n || seen.size() != n;
    if (all) {
        base.assign(n, 0);
        seen.resize(n);
    } else {
        moved.resize(n);
        for (std::size_t i = 0; i < n; ++i) moved[i] = x_[i] != seen[i]; // (NaN: moved)
    }
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            const std::uint32_t p = parent_[i];
            if (!alive_[i] || p == kNone || (!all && !moved[i] && !moved[p])) continue;
            const glm::dvec3 mid = (x_[i] + x_[p]) * 0.5;
            const double reach = 0.5 * glm::length(x_[i] - x_[p]) + sc.thin_of(i, radii_) + 0.002;
            base[i] = 0;
            for (std::size_t k = 0; k < obstacles_.size(); ++k)
                if (distance_to(k, mid) < reach) {
                    base[i] = 1;
                    break;
                }
        }
    });
    std::copy(x_.begin(), x_.end(), seen.begin());
    auto& near = sc.near;
    near.assign(base.begin(), base.end());
    // the links that share a particle with a near link (the link into its parent, its siblings
    // and the links out of its particle) are checked too, as a push can bring them in; and the
    // links sharing a particle with those get their lengths back where the pushes moved them.
    // A sibling or a child of near link i is a link whose parent is i's parent or i: those
    // particles are flagged, and then every link whose parent is flagged is marked, in one pass
    // in index order (reading each particle's list of children instead, a scattered load per
    // link, was a fifth of this function's time in Fig. 14 right). The children lists hold
    // exactly the live particles whose parent is the list's owner (add_particle, detach,
    // remove), and the flagged particles are live, so the marks are the same.
    auto& flag = sc.ring_flag;
    auto ring = [&](std::uint8_t from, std::uint8_t to) {
        flag.assign(n, 0);
        for (std::uint32_t i = 0; i < n; ++i) {
            if (near[i] != from) continue;
            const std::uint32_t p = parent_[i];
            if (parent_[p] != kNone && !near[p]) near[p] = to;
            flag[p] = flag[i] = 1;
        }
        for (std::uint32_t j = 0; j < n; ++j)
            if (!near[j] && parent_[j] != kNone && flag[parent_[j]]) near[j] = to;
    };
    ring(1, 2);
    ring(2, 3);
    auto& links = sc.contact_links;
    links.clear();
    for (std::uint32_t i = 0; i < n; ++i)
        if (near[i]) links.push_back(i);
    if (links.empty()) return;
    segment_sweeps(links);
}

void World::segment_sweeps(const Array<std::uint32_t>& links) {
    const std::size_t n = x_.size();
    auto& sc = scratch_;
    const auto& near = sc.near;
    auto& found_clear = sc.found_clear;
    auto& ends = sc.clear_ends;
    const auto& inverse = sc.inverse_mass; // (weigh_particles, once a step)
    // Gauss-Seidel in index order (one thread: the same result on any thread count). A first
    // sweep of contacts alone over every near link: when no capsule is in an obstacle, nothing
    // more. Else sweeps of each link's rest length (a distance constraint, both ends by inverse
    // mass) and then its contacts, until no capsule is in any obstacle or after four, and up to
    // three last sweeps of contacts alone, so the obstacles have the last word.
    // These later sweeps follow the pushes instead of going over every near link: a sweep visits,
    // in index order, the links an end of which moved by more than kFollow since their last
    // visit (those after the link that moved them in the same sweep, the others in the next, as
    // a sweep over all of them would reach them) and the links the first sweep found off their
    // rest length by more than that. A link no push reached is where the length sweep of the
    // step left it (keep_shape), and going over it again only rounded it anew; but one contact
    // anywhere had every link on a wall swept seven more times (Fig. 14 right: a quarter of the
    // calls, most of this pass's time).
    // Flags by link index for this sweep and the next, each with the range it has flags in: a
    // sweep scans its range in index order (a byte a link), so a link flagged ahead of the one
    // being visited is visited in the same sweep
    auto& now = sc.woken_now;
    auto& next = sc.woken_next;
    now.assign(n, 0);
    next.assign(n, 0);
    std::size_t next_lo = n, next_hi = 0, now_hi = 0;
    std::uint32_t at = 0; // the link being visited
    bool first = true;    // the first sweep goes over every near link anyway
    auto add = [&](std::uint32_t j, bool in_this) {
        if (!near[j]) return;
        if (in_this && j > at) {
            now[j] = 1, now_hi = std::max<std::size_t>(now_hi, j);
        } else if (!next[j]) {
            next[j] = 1, next_lo = std::min<std::size_t>(next_lo, j),
            next_hi = std::max<std::size_t>(next_hi, j);
        }
    };
    auto wake = [&](std::uint32_t q, const glm::dvec3& before) { // the links at q, when it moved
        const glm::dvec3 by = x_[q] - before;
        if (glm::dot(by, by) <= kFollow * kFollow) return;
        if (parent_[q] != kNone) add(q, !first);
        for (const std::uint32_t c : children_[q]) add(c, !first);
    };
    // found clear, and neither end has moved since (then its contact test would find it clear)
    auto still_clear = [&](std::uint32_t i, std::uint32_t p) {
        return found_clear[i] && x_[i] == ends[2 * i + 1] && x_[p] == ends[2 * i];
    };
    auto visit = [&](std::uint32_t i, bool lengths) { // whether it found a contact
        at = i;
        const std::uint32_t p = parent_[i];
        const double wp = inverse[p], wi = inverse[i];
        if (wp + wi <= 0) return false;
        const glm::dvec3 was_p = x_[p], was_i = x_[i], d = x_[i] - x_[p];
        const double len = glm::length(d), want = sc.rest_length[i];
        if (first && len > 1e-12 && want > 1e-12 && std::fabs(len - want) > kFollow) add(i, false);
        if (!lengths && still_clear(i, p)) return false;
        if (len > 1e-12 && want > 1e-12) {
            // the length sweeps put the link back to its rest length; the last sweeps, of
            // contacts, keep it within kPinched of it: a contact on a neighbouring link (its
            // parent's or a child's) moves one of its ends and can stretch it further than a
            // contact on the link itself does (link_contacts bounds that one)
            const double to = lengths ? want : std::clamp(len, want / kPinched, want * kPinched);
            if (to != len) {
                const glm::dvec3 fix = d * ((len - to) / (len * (wp + wi)));
                x_[p] += fix * wp;
                x_[i] -= fix * wi;
            }
        }
        bool hit = false;
        // the same in a length sweep, where the fix above left both ends as they were (a link
        // at its rest length to the last bit)
        if (near[i] < 3 && !still_clear(i, p)) {
            hit = link_contacts(i, wp, wi);
            found_clear[i] = !hit;
            if (!hit) ends[2 * i] = x_[p], ends[2 * i + 1] = x_[i];
        }
        wake(p, was_p);
        wake(i, was_i);
        return hit;
    };
    bool any = false;
    for (const std::uint32_t i : links) any = visit(i, false) || any;
    first = false;
    for (int sweep = 1; sweep < 8 && any && next_lo < n; ++sweep) {
        const bool lengths = sweep < 5;
        now.swap(next);
        const std::size_t lo = next_lo;
        now_hi = next_hi, next_lo = n, next_hi = 0;
        any = false;
        for (std::size_t j = lo; j <= now_hi; ++j) // (now_hi grows as links ahead are flagged)
            if (now[j]) {
                now[j] = 0;
                any = visit(static_cast<std::uint32_t>(j), lengths) || any;
            }
    }
}

bool World::link_contacts(std::uint32_t i, double wp, double wi) {
    // the link from i's parent to i against each obstacle: the point deepest in it comes out
    // (exit_point), the two ends moved by their barycentric weights a = 1 - t, b = t and inverse
    // masses (friction stays with the particles' own contacts, integrate())
    const std::uint32_t p = parent_[i];
    const double r = scratch_.thin_of(i, radii_);
    bool any = false;
    for (std::size_t k = 0; k < obstacles_.size(); ++k) {
        // most links are clear, and most of those can be told without deepest_on_segment: a
        // plane's distance at the ends with its kept unit normal (the same values), a box's
        // faces (box_clear). Fig. 14 right: the broad phase keeps most links (they lie on the
        // ground or the wall), and about one in 250 of these tests finds a contact
        const Obstacle& o = obstacles_[k];
        if (o.kind == Obstacle::Plane) {
            if (std::min(distance_to(k, x_[p]), distance_to(k, x_[i])) >= r - 1e-9) continue;
        } else if (o.kind == Obstacle::Box && box_clear(o, x_[p], x_[i], r)) {
            continue;
        }
        double t = 0;
        if (deepest_on_segment(o, x_[p], x_[i], r, t) >= r - 1e-9) continue;
        const double a = 1 - t, b = t, sum = a * a * wp + b * b * wi;
        if (sum < 1e-12 * (wp + wi)) continue; // only a fixed end is inside
        const glm::dvec3 c = x_[p] * a + x_[i] * b;
        const glm::dvec3 dc = exit_point(c, r, k) - c;
        glm::dvec3 move_p = dc * (a * wp / sum), move_i = dc * (b * wi / sum);
        // a point near an end that cannot move would swing the other end far: at most twice the
        // push a sweep; the next sweeps or steps finish it
        const double most = std::max(glm::length(move_p), glm::length(move_i)), bound = 2 * glm::length(dc);
        if (most > bound) move_p *= bound / most, move_i *= bound / most;
        x_[p] += move_p;
        x_[i] += move_i;
        any = true;
        // a link pinched across an obstacle (its ends on two sides of a rail thicker than it is
        // long) cannot come out by its contact alone: it stretches at most 20 % here, and the
        // length constraint pulls it back over the following steps
        const glm::dvec3 e = x_[i] - x_[p];
        const double len = glm::length(e), most_len = kPinched * scratch_.rest_length[i];
        if (most_len > 0 && len > most_len) {
            const glm::dvec3 fix = e * ((len - most_len) / (len * (wp + wi)));
            x_[p] += fix * wp;
            x_[i] -= fix * wi;
        }
    }
    return any;
}

} // namespace plant::physics
