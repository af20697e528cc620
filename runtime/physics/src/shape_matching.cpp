// The solver's shape matching (Hädrich et al., section 4.1 and the appendix): the groups and
// what they keep between steps, masses and ellipsoid moments, each particle's stiffness and goal,
// and the passes of a step that move the particles toward their goals.
#include "plant/physics/world.hpp"

#include "lanes.hpp"
#include "parallel.hpp"

#include <algorithm>

namespace plant::physics {

namespace {

constexpr double kFixedMass = 1e12; // "effectively infinite" inside group sums (docs/physics.md, root)

} // namespace

double World::stiffness(std::uint32_t i) const {
    if (settings_.fixed_stiffness >= 0) return std::min(1.0, settings_.fixed_stiffness);
    // s = t_l / t_m, clamped to [0, 1]; t_l starts at 0.2 (section 4.3)
    return std::clamp((0.2 + age_[i]) / settings_.stiffening_time, 0.0, 1.0);
}

double World::matching_mass(std::uint32_t j) const {
    return fixed_[j] ? kFixedMass : m_[j];
}

glm::dmat3 World::rest_moment(std::uint32_t j) const {
    // Eq. 15's term for one member is 0.2 m R D R̄ᵀ (docs/physics.md); this is its rest part,
    // 0.2 m D R̄ᵀ, which only growth changes
    const glm::dvec3& r = radii_[j];
    glm::dmat3 D(0.0);
    D[0][0] = r.x * r.x, D[1][1] = r.y * r.y, D[2][2] = r.z * r.z;
    return 0.2 * matching_mass(j) * D * glm::transpose(glm::mat3_cast(rest_q_[j]));
}

glm::dmat3 World::ellipsoid_moment(std::uint32_t j) const {
    return glm::mat3_cast(q_[j]) * rest_moment(j);
}

void World::group_moments(const Groups& g, Array<glm::dmat3>& each, Array<glm::dmat3>& sums) const {
    const std::size_t n = x_.size();
    each.resize(n);
    sums.resize(n);
    // Eq. 15's moment R D R̄ᵀ: the rest part D R̄ᵀ (with the mass) changes only with growth and
    // is kept with the groups (refresh_groups()); here only the current rotation enters
    const bool cached = !groups_stale_ && scratch_.rest_moment.size() == n;
    auto one = [&](std::size_t j) {
        if (alive_[j])
            each[j] = cached ? glm::mat3_cast(q_[j]) * scratch_.rest_moment[j]
                             : ellipsoid_moment(static_cast<std::uint32_t>(j));
    };
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        std::size_t j = b;
        if (cached) // two particles at a time, lane by lane as the line above
            for (; j + 1 < e; j += 2) {
                if (!alive_[j] || !alive_[j + 1]) {
                    one(j), one(j + 1);
                    continue;
                }
                const glm::dquat &qa = q_[j], &qb = q_[j + 1];
                const Mat2 R = mat3_cast2(load2(qa, qb));
                const glm::dmat3 &ra = scratch_.rest_moment[j], &rb = scratch_.rest_moment[j + 1];
                for (int c = 0; c < 3; ++c) {
                    const v2 b0{ra[c][0], rb[c][0]}, b1{ra[c][1], rb[c][1]}, b2{ra[c][2], rb[c][2]};
                    for (int r = 0; r < 3; ++r) { // glm's mat3 * mat3
                        const v2 m = R.m[0][r] * b0 + R.m[1][r] * b1 + R.m[2][r] * b2;
                        each[j][c][r] = m[0];
                        each[j + 1][c][r] = m[1];
                    }
                }
            }
        for (; j < e; ++j) one(j);
    });
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) {
            glm::dmat3 M(0.0);
            for (std::uint32_t k = g.start[i]; k < g.start[i + 1]; ++k) M += each[g.member[k].particle];
            sums[i] = M;
        }
    });
}

void World::build_groups(Groups& g) const {
    const std::size_t n = x_.size();
    // a group is its particle, its parent and its children, and so are a particle's goal sources:
    // counted first, so that the lists are not grown (and copied) a doubling at a time
    std::size_t total = 0;
    for (std::uint32_t i = 0; i < n; ++i)
        if (alive_[i]) total += 1 + (parent_[i] != kNone) + children_[i].size();
    g.start.assign(n + 1, 0);
    g.member.clear();
    if (g.member.capacity() < total) g.member.reserve(total + total / 4); // room for some growth
    g.rest_center.assign(n, glm::dvec3(0.0));
    for (std::uint32_t i = 0; i < n; ++i) {
        g.start[i] = static_cast<std::uint32_t>(g.member.size());
        if (!alive_[i]) continue;
        double M = 0;
        glm::dvec3 rc(0.0);
        for_group(i, [&](std::uint32_t j) {
            const double m = matching_mass(j);
            M += m;
            rc += m * rest_x_[j];
            g.member.push_back({j, m, glm::dvec3(0.0)});
        });
        rc /= M;
        g.rest_center[i] = rc;
        for (std::size_t k = g.start[i]; k < g.member.size(); ++k) {
            auto& e = g.member[k];
            e.mr = e.share * (rest_x_[e.particle] - rc);
            e.share /= M;
        }
    }
    g.start[n] = static_cast<std::uint32_t>(g.member.size());
    // goal sources: its own group, its parent's (twice the weight), its children's (half)
    g.source_start.assign(n + 1, 0);
    g.source.clear();
    if (g.source.capacity() < total) g.source.reserve(total + total / 4);
    for (std::uint32_t j = 0; j < n; ++j) {
        const auto first = static_cast<std::uint32_t>(g.source.size());
        g.source_start[j] = first;
        double W = 0;
        auto add = [&](std::uint32_t i, double w) {
            if (!alive_[i]) return;
            g.source.push_back({i, w, rest_x_[j] - g.rest_center[i]});
            W += w;
        };
        // Eq. 4's weights are all j's mass times these factors; divided by their sum the mass
        // drops out (and a massless particle still has a goal)
        add(j, 1.0);
        if (parent_[j] != kNone) add(parent_[j], 2.0);
        for (std::uint32_t c : children_[j]) add(c, 0.5);
        for (std::size_t k = first; k < g.source.size(); ++k) g.source[k].weight /= W;
    }
    g.source_start[n] = static_cast<std::uint32_t>(g.source.size());
}

glm::dvec3 World::goal_of(std::uint32_t j, const Array<Frame>& frames, const Groups& g) const {
    // Eq. 3: the target of particle j in group i is R_i (x̄_j - c̄_i) + c_i; Eq. 4: j's goal is
    // their mass-weighted mean over the groups j belongs to (its own, its parent's, its
    // children's), its parent's group counting twice as much as its own and its children's half.
    // The weights are divided by their sum already (build_groups); a particle always has its
    // own group.
    double sx = 0, sy = 0, sz = 0; // in local variables, as in group_frame
    const Groups::Source* end = g.source.data() + g.source_start[j + 1];
    for (const auto* k = g.source.data() + g.source_start[j]; k < end; ++k) {
        const Frame& f = frames[k->group];
        const glm::dvec3& o = k->offset;
        // glm's M * o + c, column by column
        const double gx = f.M[0][0] * o.x + f.M[1][0] * o.y + f.M[2][0] * o.z + f.c.x;
        const double gy = f.M[0][1] * o.x + f.M[1][1] * o.y + f.M[2][1] * o.z + f.c.y;
        const double gz = f.M[0][2] * o.x + f.M[1][2] * o.y + f.M[2][2] * o.z + f.c.z;
        sx += k->weight * gx;
        sy += k->weight * gy;
        sz += k->weight * gz;
    }
    return {sx, sy, sz};
}

std::vector<glm::dvec3> World::goals() const {
    Array<Frame> frames;
    Array<glm::dmat3> each, moments;
    Groups groups;
    build_groups(groups);
    group_moments(groups, each, moments);
    match_shapes(frames, moments, 20, groups);
    std::vector<glm::dvec3> goal(x_.size());
    for (std::uint32_t j = 0; j < x_.size(); ++j) goal[j] = goal_of(j, frames, groups);
    return goal;
}

glm::dquat World::group_rotation(std::uint32_t i) const {
    Groups g;
    build_groups(g);
    glm::dmat3 moment(0.0);
    for_group(i, [&](std::uint32_t j) { moment += ellipsoid_moment(j); });
    Frame f;
    group_frame(i, rotation_from_rest(i), moment, 20, g, f);
    return f.R;
}

void World::refresh_groups() {
    if (!groups_stale_) return; // kept from the last step when nothing grew, broke or was cut
    const std::size_t n = x_.size();
    auto& rest_moments = scratch_.rest_moment;
    rest_moments.resize(n);
    for (std::size_t j = 0; j < n; ++j)
        if (alive_[j]) rest_moments[j] = rest_moment(static_cast<std::uint32_t>(j));
    build_groups(scratch_.groups);
    build_links();
    build_plants();
    groups_stale_ = false;
}

void World::move_one(std::uint32_t i) {
    // x'_g = x_p + s (x_g - x_p) (section 4.3)
    const double st = scratch_.stiffness[i];
    const glm::dvec3 goal = goal_of(i, scratch_.frames, scratch_.groups);
    x_[i] = x_[i] + st * (goal - x_[i]);
}

void World::move_pair(std::uint32_t i, std::uint32_t j) {
    // move_one for two particles with the same number of goal sources, lane by lane (goal_of's
    // operations in its order)
    const Groups& g = scratch_.groups;
    const Groups::Source* a = g.source.data() + g.source_start[i];
    const Groups::Source* b = g.source.data() + g.source_start[j];
    const std::uint32_t count = g.source_start[i + 1] - g.source_start[i];
    const auto& frames = scratch_.frames;
    v2 sx = both(0), sy = both(0), sz = both(0);
    for (std::uint32_t k = 0; k < count; ++k) {
        const Frame &fa = frames[a[k].group], &fb = frames[b[k].group];
        const v2 ox{a[k].offset.x, b[k].offset.x}, oy{a[k].offset.y, b[k].offset.y},
            oz{a[k].offset.z, b[k].offset.z};
        auto row = [&](int r) {
            return v2{fa.M[0][r], fb.M[0][r]} * ox + v2{fa.M[1][r], fb.M[1][r]} * oy +
                   v2{fa.M[2][r], fb.M[2][r]} * oz + v2{fa.c[r], fb.c[r]};
        };
        const v2 w{a[k].weight, b[k].weight};
        sx += w * row(0);
        sy += w * row(1);
        sz += w * row(2);
    }
    const v2 st{scratch_.stiffness[i], scratch_.stiffness[j]};
    glm::dvec3 &xa = x_[i], &xb = x_[j];
    const v2 px{xa.x, xb.x}, py{xa.y, xb.y}, pz{xa.z, xb.z};
    const v2 nx = px + st * (sx - px), ny = py + st * (sy - py), nz = pz + st * (sz - pz);
    xa = glm::dvec3(nx[0], ny[0], nz[0]);
    xb = glm::dvec3(nx[1], ny[1], nz[1]);
}

void World::match_shapes_passes() {
    // Shape matching on the predictions. Small overlapping groups pass a correction on by one
    // particle per pass, so a chain needs several passes to hold its shape; the positions move
    // in every pass, the orientations once, after the last. The ellipsoid moments (Eq. 15) read
    // only the orientations, so they are summed per group once a step. The scratch is kept
    // across steps: no allocation in a step, and each group's rotation is warm-started from the
    // last pass, also the previous step's.
    const std::size_t n = x_.size();
    auto& frames = scratch_.frames;
    auto& stiff = scratch_.stiffness; // ages change only after the passes
    stiff.resize(n);
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) stiff[i] = stiffness(static_cast<std::uint32_t>(i));
    });
    group_moments(scratch_.groups, scratch_.moments, scratch_.group_moment);
    const int passes = settings_.iterations;
    for (int it = 0; it < passes; ++it) {
        match_shapes(frames, scratch_.group_moment, settings_.rotation_iterations, scratch_.groups);
        // each particle's goal, and the move toward it: the goals read only the frames, so a
        // particle can move as soon as its own goal is known. Particles with as many sources
        // go two at a time (move_pair), each exactly as alone; the order does not matter, since
        // a move reads only the particle's own position and the frames.
        parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
            constexpr std::uint32_t kMaxPaired = 8;
            std::uint32_t waiting[kMaxPaired + 1];
            std::fill(std::begin(waiting), std::end(waiting), kNone);
            const auto& start = scratch_.groups.source_start;
            for (std::size_t k = b; k < e; ++k) {
                const auto i = static_cast<std::uint32_t>(k);
                if (!alive_[i]) continue;
                if (fixed_[i]) {
                    x_[i] = rest_x_[i];
                    continue;
                }
                const std::uint32_t count = start[i + 1] - start[i];
                if (count > kMaxPaired) {
                    move_one(i);
                } else if (waiting[count] == kNone) {
                    waiting[count] = i;
                } else {
                    move_pair(waiting[count], i);
                    waiting[count] = kNone;
                }
            }
            for (const std::uint32_t i : waiting)
                if (i != kNone) move_one(i);
        });
        if (it + 1 == passes) blend_orientations();            // (orient.cpp)
        for (const auto& [i, target] : pulls_) x_[i] = target; // a dragged particle goes where it is dragged
        keep_shape(it + 1 == passes); // root to tip: bending and rest lengths (length.cpp)
    }
}

} // namespace plant::physics
