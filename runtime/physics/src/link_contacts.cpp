// Links of different plants against each other (docs/plant-contacts.md; issue
// 18 item 4). The particles of two plants collide as spheres (collisions.cpp), but a link is
// longer than its stem is thick, so two stems crossing between their particles went through each
// other (up to 7 mm deep with 6 mm stems). Here every link is a capsule of its particle's
// thinnest radius, as against obstacles (segment_contacts.cpp), and two capsules of different
// plants that overlap are pushed apart at their closest points: the four end particles move by
// their barycentric weights and inverse masses, as position-based dynamics projects a collision
// constraint (Müller et al. 2007, section 3.3, the constraint |a(s) - b(t)| - r_a - r_b >= 0).
// Links of one plant are left to the particles' own contacts and the shape matching.
#include "plant/physics/world.hpp"

#include "cells.hpp"
#include "obstacle_field.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

namespace {

// The parameters s, t in [0, 1] of the closest points of segments p1 + s d1 and p2 + t d2
// (Ericson 2005, "Real-Time Collision Detection", section 5.1.9).
void closest_on_segments(const glm::dvec3& p1, const glm::dvec3& d1, const glm::dvec3& p2,
                         const glm::dvec3& d2, double& s, double& t) {
    const glm::dvec3 r = p1 - p2;
    const double a = glm::dot(d1, d1), e = glm::dot(d2, d2), f = glm::dot(d2, r);
    constexpr double tiny = 1e-18;
    if (a <= tiny && e <= tiny) {
        s = t = 0;
        return;
    }
    if (a <= tiny) {
        s = 0;
        t = std::clamp(f / e, 0.0, 1.0);
        return;
    }
    const double c = glm::dot(d1, r);
    if (e <= tiny) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
        return;
    }
    const double b = glm::dot(d1, d2), denom = a * e - b * b;
    s = denom > tiny * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0; // parallel: any s
    t = (b * s + f) / e;
    if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
    } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
    }
}

// how far this pass may stretch (or squash) a link it pushes: the every-grammar length test
// allows 10 %
constexpr double kStretch = 1.02;

// sweeps over the pairs a call at most; they stop once none overlaps by kLinksParted
constexpr int kSweeps = 16;

// rounds of link contacts and obstacles a step at most (part_plants)
constexpr int kLinkRounds = 32;

// Over-relaxation of each push (successive over-relaxation of the Gauss-Seidel sweeps): a stem
// pressed between a support and a heavier stem is parted a little more each sweep when the push
// goes 30 % past contact (docs/plant-contacts.md, "Rounds until parted, over-relaxed")
constexpr double kOverRelax = 1.3;

// The later sweeps of a call visit the pairs its first sweep found closer than this many times
// their contact distance (separate_links); 1.5: half a contact distance apart at most
constexpr double kNearSlack = 1.5;

// A particle within its radius and this much of a support lies on it (part_plants)
constexpr double kOnSupport = 0.002;

// Lists each oversized link (find_link_pairs) with every other link of another plant whose bounds
// it meets.
void pair_oversized(const Array<std::uint32_t>& big, const Array<std::uint32_t>& links,
                    const Array<glm::dvec3>& lo, const Array<glm::dvec3>& hi,
                    const Array<std::uint32_t>& plant,
                    Array<std::pair<std::uint32_t, std::uint32_t>>& pairs) {
    for (std::size_t u = 0; u < big.size(); ++u) {
        const std::uint32_t a = big[u];
        auto consider = [&](std::uint32_t b) {
            const glm::dvec3 low = glm::max(lo[a], lo[b]), high = glm::min(hi[a], hi[b]);
            if (plant[a] != plant[b] && !(low.x > high.x || low.y > high.y || low.z > high.z))
                pairs.push_back({std::min(a, b), std::max(a, b)});
        };
        for (const std::uint32_t b : links) consider(b);
        for (std::size_t v = u + 1; v < big.size(); ++v) consider(big[v]);
    }
}

// The candidate pairs of one cell of find_link_pairs' grid: members [begin, end), grouped by
// plant, so that each link meets only the other plants' links of the cell (in Fig. 14 right at
// 100 steps, 96 % of the pairs the runs held were of one plant, 210 of 218 million over the run,
// each looked at only to be skipped; the pairs found are the same, and the caller sorts them). A
// pair is listed here when the cell `at` holds the lower corner of the two boxes' overlap, so
// it is listed once. `per`: cells per unit of length, as grid_link_pairs maps a box to cells.
void pairs_in_cell(const Array<std::uint32_t>& members, std::uint32_t begin, std::uint32_t end,
                   const glm::i64vec3& at, double per, const Array<glm::dvec3>& lo,
                   const Array<glm::dvec3>& hi, const Array<std::uint32_t>& plant,
                   Array<std::pair<std::uint32_t, std::uint32_t>>& pairs) {
    for (std::uint32_t group = begin; group < end;) {
        std::uint32_t others = group + 1; // the first link of the next plant in the run
        while (others < end && plant[members[others]] == plant[members[group]]) ++others;
        for (std::uint32_t u = group; u < others; ++u)
            for (std::uint32_t v = others; v < end; ++v) {
                const std::uint32_t a = members[u], b = members[v];
                const glm::dvec3 low = glm::max(lo[a], lo[b]), high = glm::min(hi[a], hi[b]);
                if (low.x > high.x || low.y > high.y || low.z > high.z) continue;
                const glm::i64vec3 owner(far_floor(low.x * per), far_floor(low.y * per),
                                         far_floor(low.z * per));
                if (owner != at) continue; // found in the cell that owns it
                pairs.push_back({std::min(a, b), std::max(a, b)});
            }
        group = others;
    }
}

} // namespace

void World::build_plants() {
    // the plant of each particle: its root's index (a parent's index is below its children's),
    // and how many plants have a link
    const std::size_t n = x_.size();
    auto& plant = scratch_.plant;
    plant.assign(n, kNone);
    std::size_t with_links = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        const std::uint32_t p = parent_[i];
        plant[i] = p == kNone ? i : plant[p];
        if (p == kNone && !children_[i].empty()) ++with_links;
    }
    scratch_.plants = with_links;
}

void World::find_link_pairs() {
    // Broad phase: each link's box (its capsule's bounds) goes into every cell of a hashed grid it
    // touches; two links are a candidate where their boxes overlap, found once, in the cell that
    // holds the lower corner of the boxes' overlap. Cells are about a link long, and never
    // smaller than a quarter of the largest box, so no link spans more than a few. A box over 64
    // times a typical one (OversizedLimit, cells.hpp) stays out of the grid, which it would make
    // one cell, and is tested against every link instead; without one the cells are as before.
    const std::size_t n = x_.size();
    auto& sc = scratch_;
    auto& links = sc.link_list;
    links.clear();
    sc.link_pairs.clear();
    auto& lo = sc.box_lo;
    auto& hi = sc.box_hi;
    lo.resize(n);
    hi.resize(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        const std::uint32_t p = parent_[i];
        if (!alive_[i] || p == kNone) continue;
        // three radii round the capsule: a push of this pass can bring in a pair apart before it
        const double r = 3 * sc.thin_of(i, radii_);
        lo[i] = glm::min(x_[i], x_[p]) - r;
        hi[i] = glm::max(x_[i], x_[p]) + r;
        const glm::dvec3 e = hi[i] - lo[i];
        if (!std::isfinite(e.x + e.y + e.z)) continue; // a NaN never collides
        links.push_back(i);
    }
    if (links.size() < 2) return;
    auto extent = [&](std::uint32_t i) {
        const glm::dvec3 e = hi[i] - lo[i];
        return std::max({e.x, e.y, e.z});
    };
    OversizedLimit oversized_at(links.size());
    for (const std::uint32_t i : links) oversized_at.offer(extent(i));
    const double limit = oversized_at.limit();
    auto& big = sc.link_big;
    big.clear();
    double total = 0, largest = 0, widest = 0;
    std::size_t kept = 0;
    for (const std::uint32_t i : links) {
        const double size = extent(i);
        if (size > limit) {
            big.push_back(i);
            continue;
        }
        links[kept++] = i;
        total += glm::length(x_[i] - x_[parent_[i]]);
        largest = std::max(largest, size);
        widest = std::max(widest, 3 * sc.thin_of(i, radii_));
    }
    links.resize(kept);
    const auto& plant = sc.plant;
    pair_oversized(big, links, lo, hi, plant, sc.link_pairs);
    if (links.size() < 2) {
        std::sort(sc.link_pairs.begin(), sc.link_pairs.end());
        return;
    }
    grid_link_pairs(std::max({total / static_cast<double>(links.size()) + 2 * widest, largest / 4, 1e-6}));
    std::sort(sc.link_pairs.begin(), sc.link_pairs.end()); // index order, whatever the table's
}

// find_link_pairs' grid, of cells `cell` wide: the candidate pairs of the links in
// scratch_.link_list (none oversized), appended to scratch_.link_pairs.
void World::grid_link_pairs(double cell) {
    auto& sc = scratch_;
    auto& links = sc.link_list;
    const auto& lo = sc.box_lo;
    const auto& hi = sc.box_hi;
    const auto& plant = sc.plant;
    // A box goes into the cells from floor(lo * per) to floor(hi * per) on each axis, and a pair
    // is listed by the cell of floor(low * per), low the lower corner of their overlap. Any
    // mapping that keeps the order of points along an axis (multiplying by a positive number
    // does) puts that cell among both boxes' cells, so every overlapping pair is listed exactly
    // once whatever the cells' bounds are: the reciprocal's rounding moves no pair. (Divisions,
    // six a link in each of three passes, were a third of this function's time.)
    const double per = 1.0 / cell;
    // each cell's run grouped by plant: the links taken in plant order, then index order. They
    // come in index order, and the plants (their roots' indices) are few: counted into place by
    // plant, each plant's links keep their order (a comparison sort was 1.4 % of Fig. 14 right)
    {
        auto& start = sc.plant_start; // by root: its count of links, then where the next goes
        auto& roots = sc.plant_roots;
        start.assign(x_.size(), 0);
        roots.clear();
        for (const std::uint32_t i : links)
            if (start[plant[i]]++ == 0) roots.push_back(plant[i]);
        std::sort(roots.begin(), roots.end());
        std::uint32_t running = 0;
        for (const std::uint32_t root : roots) {
            const std::uint32_t count = start[root];
            start[root] = running;
            running += count;
        }
        auto& sorted = sc.link_sorted;
        sorted.resize(links.size());
        for (const std::uint32_t i : links) sorted[start[plant[i]]++] = i;
        links.swap(sorted);
    }
    // the cells a link's box touches (its range of cells, worked out once), one entry each
    auto& range_lo = sc.link_range_lo;
    auto& range_hi = sc.link_range_hi;
    range_lo.resize(links.size());
    range_hi.resize(links.size());
    std::size_t entries = 0;
    for (std::size_t k = 0; k < links.size(); ++k) {
        const std::uint32_t i = links[k];
        glm::i64vec3& a = range_lo[k];
        glm::i64vec3& b = range_hi[k];
        for (int axis = 0; axis < 3; ++axis)
            a[axis] = far_floor(lo[i][axis] * per), b[axis] = far_floor(hi[i][axis] * per);
        entries += static_cast<std::size_t>((b.x - a.x + 1) * (b.y - a.y + 1) * (b.z - a.z + 1));
    }
    // The cells that hold an entry, each with its run of links in `members` (filled by counting,
    // no sort), and an open-addressing table from a cell to its index there (+1; 0: none). A
    // link spans several cells and a cell holds about fifteen, so the cells are few (Fig. 14
    // right: about 2,800 a call for 41,000 entries): the table is of 4-byte indices, at most half
    // full in entries, and only the slots the last call filled are emptied. (The cells and their
    // runs in the table's slots, 40 bytes each and four slots an entry, was a 10 MB table filled
    // and scanned whole each call, most of this function's time.)
    std::size_t size = 16;
    while (size < 2 * entries) size *= 2;
    auto& table = sc.link_table;
    auto& cells = sc.link_cells;
    auto& used = sc.link_used; // the slot of each cell
    for (const std::uint32_t slot : used)
        if (slot < table.size()) table[slot] = 0;
    used.clear();
    cells.clear();
    if (table.size() != size) table.assign(size, 0);
    auto cell_at = [&](const glm::i64vec3& c) { // c's index in `cells`, added if new
        std::size_t slot = cell_hash(c) & (size - 1);
        while (table[slot] != 0 && cells[table[slot] - 1].cell != c) slot = (slot + 1) & (size - 1);
        if (table[slot] == 0) {
            used.push_back(static_cast<std::uint32_t>(slot)); // first: the next call empties it
            cells.push_back(LinkCell{c, 0, 0, 0});
            table[slot] = static_cast<std::uint32_t>(cells.size());
        }
        return table[slot] - 1;
    };
    auto& entry_cell = sc.link_entry_cell; // each entry's cell and link, in link order
    auto& entry_link = sc.link_entry_link;
    entry_cell.resize(entries);
    entry_link.resize(entries);
    std::size_t e = 0;
    for (std::size_t k = 0; k < links.size(); ++k) {
        const glm::i64vec3 a = range_lo[k], b = range_hi[k];
        for (std::int64_t z = a.z; z <= b.z; ++z)
            for (std::int64_t y = a.y; y <= b.y; ++y)
                for (std::int64_t x = a.x; x <= b.x; ++x) {
                    const std::uint32_t c = cell_at(glm::i64vec3(x, y, z));
                    ++cells[c].count;
                    entry_cell[e] = c;
                    entry_link[e++] = links[k];
                }
    }
    std::uint32_t running = 0;
    for (LinkCell& s : cells) {
        s.begin = s.fill = running;
        running += s.count;
    }
    auto& members = sc.link_members;
    members.resize(running);
    for (std::size_t k = 0; k < entries; ++k) members[cells[entry_cell[k]].fill++] = entry_link[k];
    for (const LinkCell& s : cells)
        pairs_in_cell(members, s.begin, s.begin + s.count, s.cell, per, lo, hi, plant, sc.link_pairs);
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> World::link_candidates() {
    refresh_groups(); // (the plants of the particles)
    find_link_pairs();
    return {scratch_.link_pairs.begin(), scratch_.link_pairs.end()};
}

double World::separate_links(bool find) {
    if (scratch_.plants < 2 || x_.size() < 4) return 0; // one plant: nothing of another to meet
    if (find) find_link_pairs();
    const auto& pairs = scratch_.link_pairs;
    if (pairs.empty()) return 0;
    // a particle's inverse mass, 0 when it does not move (weigh_particles, once a step)
    const auto& mobility = scratch_.inverse_mass;
    // and for a push along `dir`: 0 too for a particle lying on a support (within a millimetre)
    // that the push would move into it; the other link gives way (two stems crossing on a wall:
    // the one on top lifts)
    auto weight = [&](std::uint32_t j, const glm::dvec3& dir) {
        const double w = mobility[j];
        if (w == 0) return 0.0;
        const double r = scratch_.thin_of(j, radii_) + 0.001;
        for (const Obstacle& o : obstacles_)
            if (signed_distance(o, x_[j]) < r && glm::dot(dir, surface_normal(o, x_[j])) < 0) return 0.0;
        return w;
    };
    // (the length and obstacle fixes below move along no one direction: mobility, the weight of
    // a push along none, without the supports' normals, six distances each for a box)
    auto keep_length = [&](std::uint32_t j) {
        const std::uint32_t p = parent_[j];
        if (p == kNone) return;
        const double wp = mobility[p], wj = mobility[j];
        const glm::dvec3 e = x_[j] - x_[p];
        const double len = glm::length(e), rest = scratch_.rest_length[j];
        if (wp + wj <= 0 || len < 1e-12 || rest < 1e-12) return;
        const double to = std::clamp(len, rest / kStretch, rest * kStretch);
        if (to == len) return;
        const glm::dvec3 fix = e * ((len - to) / (len * (wp + wj)));
        x_[p] += fix * wp;
        x_[j] -= fix * wj;
    };
    auto out_of_obstacles = [&](std::uint32_t j) {
        const std::uint32_t p = parent_[j];
        if (p == kNone) return;
        const double wp = mobility[p], wj = mobility[j];
        if (wp + wj > 0) link_contacts(j, wp, wj);
    };
    // Gauss-Seidel over the pairs in index order, on one thread (the same result on any thread
    // count), sweeps until no pair overlaps by 0.1 mm, at most 16: stems piled three deep
    // where several plants meet need several. The first sweep visits every pair; the later ones
    // only those it found within kNearSlack times their contact distance (where plants pile,
    // most candidate pairs lie farther apart: fig10_dome's sweeps visited about 12 a link). A
    // pair the later sweeps' pushes bring together is met by the next round's first sweep, which
    // also decides whether the rounds go on (part_plants).
    double first = 0; // the deepest overlap the first sweep met
    auto& near = scratch_.link_near;
    near.clear();
    for (int sweep = 0; sweep < kSweeps; ++sweep) {
        double worst = 0;
        const std::size_t count = sweep == 0 ? pairs.size() : near.size();
        for (std::size_t q = 0; q < count; ++q) {
            const std::size_t pair = sweep == 0 ? q : near[q];
            const auto [a, b] = pairs[pair];
            const std::uint32_t pa = parent_[a], pb = parent_[b];
            const glm::dvec3 da = x_[a] - x_[pa], db = x_[b] - x_[pb];
            double s = 0, t = 0;
            closest_on_segments(x_[pa], da, x_[pb], db, s, t);
            const glm::dvec3 d = (x_[pa] + da * s) - (x_[pb] + db * t);
            const double want = scratch_.thin_of(a, radii_) + scratch_.thin_of(b, radii_);
            const double dist2 = glm::dot(d, d);
            if (sweep == 0 && dist2 < want * want * (kNearSlack * kNearSlack))
                near.push_back(static_cast<std::uint32_t>(pair));
            if (dist2 >= want * want) continue; // apart
            const double dist = std::sqrt(dist2);
            // the way from b to a; where the axes meet (two stems crossing on one surface), across both
            glm::dvec3 nrm = dist > 1e-12 ? d / dist : glm::cross(da, db);
            if (dist <= 1e-12 && glm::dot(nrm, nrm) < 1e-24)
                nrm = glm::cross(da, std::fabs(da.x) < 0.9 * glm::length(da) ? glm::dvec3(1, 0, 0)
                                                                             : glm::dvec3(0, 1, 0));
            if (dist <= 1e-12) {
                if (glm::dot(nrm, nrm) < 1e-24) continue; // a link of no length: nothing to part
                nrm = glm::normalize(nrm);
            }
            // the constraint's gradients are (1 - s) n, s n, -(1 - t) n, -t n
            const double w0 = weight(pa, nrm), w1 = weight(a, nrm), w2 = weight(pb, -nrm),
                         w3 = weight(b, -nrm);
            const double sum = w0 * (1 - s) * (1 - s) + w1 * s * s + w2 * (1 - t) * (1 - t) + w3 * t * t;
            if (sum <= 0) continue;
            // (only the overlaps a push can part count toward more sweeps and rounds: a pair no
            // end of which may move would keep them going to their limits every step)
            worst = std::max(worst, want - dist);
            double lambda = kOverRelax * (want - dist) / sum;
            // a closest point near an end that cannot move would swing the other end far: no end
            // moves more than twice the overlap in one push (as segment_contacts.cpp bounds it)
            const double most = lambda * std::max({w0 * (1 - s), w1 * s, w2 * (1 - t), w3 * t});
            if (most > 2 * (want - dist)) lambda *= 2 * (want - dist) / most;
            x_[pa] += nrm * (lambda * w0 * (1 - s));
            x_[a] += nrm * (lambda * w1 * s);
            x_[pb] -= nrm * (lambda * w2 * (1 - t));
            x_[b] -= nrm * (lambda * w3 * t);
            // the pushed links, the links into their parents and out of their particles within kStretch of
            // their rest lengths (a distance constraint, both ends by inverse mass), as the pushes add up
            for (const std::uint32_t j : {a, pa, b, pb}) {
                keep_length(j);
                for (const std::uint32_t c : children_[j]) keep_length(c);
            }
            // and those links out of the obstacles again, so that the obstacles keep the last word
            if (!obstacles_.empty())
                for (const std::uint32_t j : {a, pa, b, pb}) {
                    out_of_obstacles(j);
                    for (const std::uint32_t c : children_[j]) out_of_obstacles(c);
                }
        }
        if (sweep == 0) first = worst;
        if (worst < kLinksParted) break;
    }
    return first;
}

void World::part_plants() {
    // The rounds alternate with the obstacles (the pairs' own pushes keep only the pushed links
    // out of them): a stem pressed between another plant's stem and a thin rail is parted from
    // both within a few rounds, the obstacles having the last word. Stems stacked on a support
    // need more: rounds follow until the first sweep of one finds every pair within kLinksParted
    // (docs/plant-contacts.md, "Rounds until parted, over-relaxed").
    auto& before = scratch_.anchored_before;
    before.resize(anchors_.size());
    for (std::size_t k = 0; k < anchors_.size(); ++k) before[k] = x_[anchors_[k].particle];
    for (int round = 0; round < kLinkRounds; ++round) {
        const double met = separate_links(round == 0); // the candidate pairs are found once a step
        if (met > 0) resolve_segments(false);          // after any push
        if (met < kLinksParted) break;                 // parted: no more rounds
    }
    // An anchored particle that the rounds moved holds on where they left it, to the stem that
    // pushed it (as ivy climbs over ivy): its anchor point moves as far. Held where it was made,
    // the anchor pulled the particle back into the other plant's stem at every step (a stem born
    // on top of another, or pushed off its hold), the rounds pushed it out again, and where
    // plants pile the stems jittered by centimetres and overlapped by millimetres
    // (docs/plant-contacts.md, "Anchors give way to other plants").
    for (std::size_t k = 0; k < anchors_.size(); ++k) {
        const glm::dvec3 moved = x_[anchors_[k].particle] - before[k];
        if (finite(moved)) anchors_[k].point += moved;
    }
    // A particle lying on a support (within its radius and kOnSupport of the nearest) whose
    // anchor, made on a support, the pushes of earlier steps lifted off every support holds on to
    // that support where it lies: the lifted anchor would pull it off the support again
    // (docs/plant-contacts.md, "Back on a support"). The anchor goes to the particle itself (out
    // to its radius, were it a little inside), not down onto the support: the rounds may just
    // have lifted the particle onto a stem beside it.
    for (Anchor& a : anchors_) {
        if (a.obstacle >= obstacles_.size()) continue; // (a fixed point in the world stays one)
        const glm::dvec3 x = x_[a.particle];
        const double r = scratch_.thin_of(a.particle, radii_);
        std::size_t under = ~std::size_t{0};
        double gap = 0, nearest = kOnSupport;
        for (std::size_t o = 0; o < obstacles_.size(); ++o)
            if (const double d = distance_to(o, x); std::fabs(d - r) <= nearest)
                nearest = std::fabs(d - r), under = o, gap = d;
        if (under == ~std::size_t{0}) continue;
        const glm::dvec3 p = anchor_point(a);
        bool on_one = false;
        for (std::size_t o = 0; o < obstacles_.size() && !on_one; ++o)
            on_one = std::fabs(distance_to(o, p)) <= r + kOnSupport;
        if (on_one || !finite(p)) continue;
        a.obstacle = under;
        a.origin = obstacles_[under].a;
        a.point = x - surface_normal(obstacles_[under], x) * std::min(gap - r, 0.0);
    }
}

} // namespace plant::physics
