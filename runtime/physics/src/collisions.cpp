// Collisions (Hädrich et al., section 5.2): obstacles as signed distance fields, the integration
// that keeps particles out of them, and the contacts between particles.
#include "plant/physics/world.hpp"

#include "cells.hpp"
#include "obstacle_field.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

double Obstacle::distance(const glm::dvec3& p) const {
    return signed_distance(*this, p);
}

double DistanceGrid::sample(const glm::dvec3& p) const {
    if (d.empty()) return 1e300;
    const glm::dvec3 hi = lo + glm::dvec3(n - 1) * cell;
    const glm::dvec3 q = glm::clamp(p, lo, hi);
    const double outside = glm::length(p - q);
    const glm::dvec3 u = (q - lo) / cell;
    const glm::ivec3 c = glm::clamp(glm::ivec3(glm::floor(u)), glm::ivec3(0), glm::max(n - 2, glm::ivec3(0)));
    const glm::dvec3 f = glm::clamp(u - glm::dvec3(c), 0.0, 1.0);
    auto at = [&](int x, int y, int z) {
        x = std::min(x, n.x - 1), y = std::min(y, n.y - 1), z = std::min(z, n.z - 1);
        return d[(static_cast<std::size_t>(z) * n.y + y) * n.x + x];
    };
    auto lerp = [](double a0, double a1, double t) { return a0 + (a1 - a0) * t; };
    const double x00 = lerp(at(c.x, c.y, c.z), at(c.x + 1, c.y, c.z), f.x);
    const double x10 = lerp(at(c.x, c.y + 1, c.z), at(c.x + 1, c.y + 1, c.z), f.x);
    const double x01 = lerp(at(c.x, c.y, c.z + 1), at(c.x + 1, c.y, c.z + 1), f.x);
    const double x11 = lerp(at(c.x, c.y + 1, c.z + 1), at(c.x + 1, c.y + 1, c.z + 1), f.x);
    return lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z) + outside;
}

glm::dvec3 Obstacle::normal(const glm::dvec3& p) const {
    return surface_normal(*this, p);
}

void World::integrate() {
    // Eq. 17-18, with damping; then obstacles: a particle inside one is put back on its surface
    // (its radius off it, never into another obstacle), its velocity losing the normal part (or
    // bouncing by the elasticity) and some of the tangential part (friction)
    const double dt = settings_.dt;
    const std::size_t n = x_.size();
    const Array<glm::dvec3>& old = scratch_.old;
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            if (!alive_[i]) continue;
            v_[i] = fixed_[i] ? glm::dvec3(0.0) : (x_[i] - old[i]) / dt * (1.0 - settings_.damping);
            age_[i] += dt;
            if (fixed_[i]) continue;
            const double r = std::min({radii_[i].x, radii_[i].y, radii_[i].z});
            for (std::size_t k = 0; k < obstacles_.size(); ++k) {
                const Obstacle& o = obstacles_[k];
                if (distance_to(k, x_[i]) - r >= 0) continue;
                // out by the shortest way that does not end in another obstacle (exit_point)
                glm::dvec3 nrm;
                x_[i] = exit_point(x_[i], r, k, &nrm);
                double vn = glm::dot(v_[i], nrm);
                glm::dvec3 tangential = v_[i] - nrm * vn;
                v_[i] = tangential * (1 - o.friction) + (vn < 0 ? -vn * o.elasticity : vn) * nrm;
            }
        }
    });
}

std::size_t World::fill_contact_grid(double cell, double limit) {
    constexpr std::size_t kTableFactor = 4;
    const std::size_t n = x_.size();
    const auto& thin = scratch_.thin;
    // (cell keys and coordinates: cell_hash, far_floor in cells.hpp)
    // an open-addressing table from a cell's key to its run of particles in `members` (in index
    // order), built by counting: no sort. A slot holds the key and the run's bounds together, so
    // a lookup touches one cache line.
    auto& table = scratch_.table; // begin == end: an empty slot
    auto& used = scratch_.used_cells;
    // Sized for short probes: four slots for each cell the last step filled (a plant fills
    // cells with a few particles each, and a smaller table leaves more of the core's cache to the
    // contact pass's lookups); a fill that reaches half the table starts again with four slots
    // for each particle. Where a cell's slot lies does not change any result.
    std::size_t most = 16;
    while (most < 4 * n) most *= 2;
    std::size_t size = 16;
    while (size < kTableFactor * std::max<std::size_t>(used.size(), 16)) size *= 2;
    size = std::min(size, most);
    auto& slot_of = scratch_.slot_of;
    auto& cell_of = scratch_.cell_of;
    cell_of.resize(n);
    for (;;) {
        // only the slots the last fill used are emptied, and only this one's are turned into
        // runs (a 25,000-particle plant fills about 13,000 cells: clearing and scanning a whole
        // table of 2 MiB each step cost more than that)
        for (const std::uint32_t slot : used)
            if (slot < table.size()) table[slot] = Cell{};
        used.clear();
        if (table.size() != size) table.assign(size, Cell{});
        slot_of.assign(n, ~0u);
        // consecutive particles of a stem often share a cell: the last one's slot is taken
        // again without probing (the same slot the probe would find)
        std::uint64_t last_key = 0;
        std::size_t last_slot = size; // none yet
        const std::size_t full = size / 2;
        for (std::uint32_t i = 0; i < n && used.size() < full; ++i) {
            if (!alive_[i] || thin[i] > limit) continue;
            const glm::dvec3 u = x_[i] / cell;
            cell_of[i] = glm::i64vec3(far_floor(u.x), far_floor(u.y), far_floor(u.z));
            const std::uint64_t k = cell_hash(cell_of[i]);
            std::size_t slot = k & (size - 1);
            if (last_slot < size && k == last_key)
                slot = last_slot;
            else
                while (table[slot].end != 0 && table[slot].key != k) slot = (slot + 1) & (size - 1);
            last_key = k, last_slot = slot;
            if (table[slot].end == 0) used.push_back(static_cast<std::uint32_t>(slot)); // (first: see above)
            table[slot].key = k;
            ++table[slot].end; // counts, for now
            slot_of[i] = static_cast<std::uint32_t>(slot);
        }
        if (used.size() < full || size == most) break;
        size = most; // more cells than the table was sized for: again, in the largest
    }
    std::uint32_t running = 0;
    for (const std::uint32_t slot : used) { // counts to runs; `end` is the fill cursor below
        Cell& c = table[slot];
        const std::uint32_t count = c.end;
        c.begin = c.end = running;
        running += count;
    }
    auto& members = scratch_.members;
    members.resize(running);
    for (std::uint32_t i = 0; i < n; ++i)
        if (slot_of[i] != ~0u) members[table[slot_of[i]].end++] = i;
    return size;
}

// Section 5.2: plants collide with each other and with themselves. Particles are spheres of
// their thinnest radius; two that overlap and are not joined (parent and child, or children of
// one parent) move apart along the line between them, half each (all of it when the other is a
// fixed root), as Müller and Chentanez 2011 resolve contacts. The pushes are gathered per
// particle from the positions before any moves, so the result does not depend on the order or
// the thread count.
//
// The grid's cells are sized from the widest contact, so one particle far wider than the rest (a
// grammar may give a segment any radius up to 1e6 m) would put every particle in one cell and
// make each step quadratic: one such segment 40 m from 60 plants took a run from 3 s to 229 s.
// A particle whose thinnest radius is over 64 times a typical one (OversizedLimit, cells.hpp: the
// median of at most 65 live particles spread evenly over them) stays out of the grid: it is tested against
// every particle, and every particle against it, after its grid partners. Without such a particle the cells
// and the order of the sums are as before.
void World::separate_particles() {
    const std::size_t n = x_.size();
    auto& thin = scratch_.thin;
    thin.assign(n, 0.0);
    std::size_t live = 0;
    for (std::size_t i = 0; i < n; ++i)
        if (alive_[i]) {
            thin[i] = std::min({radii_[i].x, radii_[i].y, radii_[i].z});
            ++live;
        }
    if (live == 0 || n < 2) return;
    // sampled over the live particles (slots of removed ones are not reused, so the live ones may
    // be a few anywhere among the indices)
    OversizedLimit oversized_at(live);
    for (std::size_t i = 0; i < n; ++i)
        if (alive_[i]) oversized_at.offer(thin[i]);
    const double limit = oversized_at.limit();
    auto& oversized = scratch_.oversized;
    oversized.clear();
    double reach = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (!alive_[i]) continue;
        if (thin[i] > limit)
            oversized.push_back(i);
        else
            reach = std::max(reach, 2 * thin[i]);
    }
    if (reach <= 0 && oversized.empty()) return;
    reach = std::max(reach, 1e-9); // (every radius is at least 1e-4 m; this is for the cell's sake)
    const double cell = 2 * reach; // twice the widest contact: a 2 x 2 x 2 block of cells holds every partner
    const std::size_t size = fill_contact_grid(cell, limit);
    auto& table = scratch_.table;
    auto& members = scratch_.members;
    auto& cell_of = scratch_.cell_of;
    auto& push = scratch_.push;
    push.assign(n, glm::dvec3(0.0));
    // the push on particle i from particle j, when they overlap and are not joined (parent and
    // child, or children of one parent)
    auto contact = [&](std::uint32_t i, const glm::dvec3& xi, double ri, std::uint32_t j,
                       glm::dvec3& pushed) {
        const glm::dvec3 d = xi - x_[j];
        const double dist2 = glm::dot(d, d), want = ri + thin[j];
        if (dist2 >= want * want || dist2 < 1e-24) return; // apart, or itself
        const std::uint32_t pi = parent_[i], pj = parent_[j];
        if (pi == j || pj == i || (pi != kNone && pi == pj)) return;
        const double dist = std::sqrt(dist2);
        pushed += d / dist * ((want - dist) * (fixed_[j] ? 1.0 : 0.5));
    };
    // the eight keys of the 2 x 2 x 2 block of cells on the side of each axis particle i is
    // nearer to (only those can hold a partner), z slowest: the order the pushes are summed in
    auto block_keys = [&](std::size_t i, std::uint64_t* keys) {
        const glm::i64vec3 c = cell_of[i];
        const glm::dvec3 frac = x_[i] / cell - glm::dvec3(c);
        const glm::i64vec3 side(frac.x < 0.5 ? -1 : 1, frac.y < 0.5 ? -1 : 1, frac.z < 0.5 ? -1 : 1);
        // the hash's three terms for the two cells along each axis
        const std::uint64_t hx[2] = {cell_term_x(c.x), cell_term_x(c.x + side.x)};
        const std::uint64_t hy[2] = {cell_term_y(c.y), cell_term_y(c.y + side.y)};
        const std::uint64_t hz[2] = {cell_term_z(c.z), cell_term_z(c.z + side.z)};
        for (int q = 0; q < 8; ++q) keys[q] = hx[q & 1] ^ hy[(q >> 1) & 1] ^ hz[q >> 2];
    };
    auto in_grid = [&](std::size_t i) { return alive_[i] && !fixed_[i] && thin[i] <= limit; };
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        // the eight slots are scattered over a table of megabytes: the next particle's are asked
        // for while this one's contacts are summed, so their cache misses overlap the work
        std::uint64_t keys[8], next[8];
        // `next`: the keys of the first grid particle from `from` on, its slots asked for
        auto look_ahead = [&](std::size_t from) {
            std::size_t ahead = from;
            while (ahead < e && !in_grid(ahead)) ++ahead;
            if (ahead == e) return;
            block_keys(ahead, next);
            for (const std::uint64_t k : next) __builtin_prefetch(&table[k & (size - 1)]);
        };
        look_ahead(b);
        for (std::size_t i = b; i < e; ++i) {
            if (!alive_[i] || fixed_[i]) continue;
            const double ri = thin[i];
            const glm::dvec3 xi = x_[i];
            const auto self = static_cast<std::uint32_t>(i);
            glm::dvec3 pushed(0.0);
            if (ri > limit) { // oversized: every other particle, in index order
                for (std::uint32_t j = 0; j < n; ++j)
                    if (alive_[j]) contact(self, xi, ri, j, pushed);
                push[i] = pushed;
                continue;
            }
            std::copy(next, next + 8, keys); // (i's own: every grid particle is looked ahead at)
            look_ahead(i + 1);
            for (const std::uint64_t k : keys) {
                std::size_t slot = k & (size - 1);
                while (table[slot].end != table[slot].begin && table[slot].key != k)
                    slot = (slot + 1) & (size - 1);
                const Cell& run = table[slot];
                for (std::uint32_t at = run.begin; at < run.end; ++at)
                    contact(self, xi, ri, members[at], pushed);
            }
            for (const std::uint32_t j : oversized) contact(self, xi, ri, j, pushed);
            push[i] = pushed;
        }
    });
    for (std::size_t i = 0; i < n; ++i) x_[i] += push[i];
}

} // namespace plant::physics
