// Frames and orientations: each shape-matching group's mass center and rotation (Hädrich et al.,
// Eq. 14-15), the rotation extracted by Müller et al. 2016's iterations, one group at a time or
// two groups at once lane by lane, and the pass that computes every group's frame.
#include "plant/physics/world.hpp"

#include "lanes.hpp"
#include "parallel.hpp"

#include <algorithm>
#include <cmath>

namespace plant::physics {

namespace {

// The turn by |omega| about omega as a quaternion (cos(w/2), sin(w/2) omega / w), given
// w2 = |omega|^2: cw = cos(w/2), sw = sin(w/2) / w. Warm-started, the turns are small; below
// w2 = 1e-4 the series to w^6 is exact to double precision (the next terms are below 1e-22)
// and needs neither sqrt nor sincos. A template so that frame_pair's lanes (v2) compute it with
// the same operations as the scalar code.
template <class T> void small_turn(T w2, T& cw, T& sw) {
    cw = 1.0 - w2 * (1.0 / 8.0 - w2 * (1.0 / 384.0 - w2 * (1.0 / 46080.0)));
    sw = 0.5 - w2 * (1.0 / 48.0 - w2 * (1.0 / 3840.0 - w2 * (1.0 / 645120.0)));
}
void large_turn(double w2, double& cw, double& sw) {
    const double w = std::sqrt(w2);
    cw = std::cos(0.5 * w);
    sw = std::sin(0.5 * w) / w;
}

// Müller et al. 2016, Eq. 10-12: turn R toward the columns of A about omega. Also gives R as a
// matrix: the last one computed when the iterations stop on convergence. With `have_matrix`,
// `matrix` holds q's already (a warm start from the last pass keeps it).
glm::dquat rotation_of(const glm::dmat3& A, glm::dquat q, int iterations, glm::dmat3& matrix,
                       bool have_matrix = false) {
    bool current = have_matrix; // whether `matrix` is q's
    for (int k = 0; k < iterations; ++k) {
        if (!current) matrix = glm::mat3_cast(q);
        current = true;
        glm::dvec3 omega =
            glm::cross(matrix[0], A[0]) + glm::cross(matrix[1], A[1]) + glm::cross(matrix[2], A[2]);
        double denom =
            std::fabs(glm::dot(matrix[0], A[0]) + glm::dot(matrix[1], A[1]) + glm::dot(matrix[2], A[2])) +
            1e-9;
        omega *= 1.0 / denom;
        const double w2 = glm::dot(omega, omega);
        if (!(w2 >= 1e-18)) break; // |omega| below 1e-9: converged, or nothing to match (zero A), or NaN
        double cw, sw;
        if (w2 < 1e-4)
            small_turn(w2, cw, sw);
        else
            large_turn(w2, cw, sw);
        q = glm::normalize(glm::dquat(cw, omega.x * sw, omega.y * sw, omega.z * sw) * q);
        current = false;
    }
    if (!current) matrix = glm::mat3_cast(q);
    return q;
}

} // namespace

glm::dquat extract_rotation(const glm::dmat3& A, glm::dquat q, int iterations) {
    glm::dmat3 matrix;
    return rotation_of(A, q, iterations, matrix);
}

void World::group_frame(std::uint32_t i, glm::dquat warm, const glm::dmat3& moment, int iterations,
                        const Groups& g, Frame& out, bool warm_matrix) const {
    // Eq. 14 with Eq. 15's ellipsoid moments (summed over the group already), positions
    // relative to the centers to keep the sums well conditioned
    const Groups::Member* from = g.member.data() + g.start[i];
    const Groups::Member* to = g.member.data() + g.start[i + 1];
    // (In local variables: written through glm's operators into `out`, every sum is stored
    // and loaded again, since `out` might alias the positions.)
    const glm::dvec3* x = x_.data();
    double cx = 0, cy = 0, cz = 0;
    for (const auto* k = from; k < to; ++k) {
        const glm::dvec3& p = x[k->particle];
        cx += k->share * p.x;
        cy += k->share * p.y;
        cz += k->share * p.z;
    }
    // A = moment + the sum of outer(x_k - c, mr_k), column j being (x_k - c) mr_k[j]
    double a00 = moment[0][0], a01 = moment[0][1], a02 = moment[0][2], a10 = moment[1][0], a11 = moment[1][1],
           a12 = moment[1][2], a20 = moment[2][0], a21 = moment[2][1], a22 = moment[2][2];
    for (const auto* k = from; k < to; ++k) {
        const glm::dvec3& p = x[k->particle];
        const double dx = p.x - cx, dy = p.y - cy, dz = p.z - cz;
        const glm::dvec3& mr = k->mr;
        a00 += dx * mr.x, a01 += dy * mr.x, a02 += dz * mr.x;
        a10 += dx * mr.y, a11 += dy * mr.y, a12 += dz * mr.y;
        a20 += dx * mr.z, a21 += dy * mr.z, a22 += dz * mr.z;
    }
    const glm::dmat3 A(a00, a01, a02, a10, a11, a12, a20, a21, a22);
    out.c = glm::dvec3(cx, cy, cz);
    out.R = rotation_of(A, warm, iterations, out.M, warm_matrix);
    out.valid = true;
}

void World::frame_pair(const std::uint32_t (&group)[2], const Array<glm::dmat3>& moments, const Groups& g,
                       Array<Frame>& frames) const {
    // group_frame with one rotation iteration from the last pass's frame, for two groups with
    // the same number of members at once (equal counts: no lane needs padding)
    const Groups::Member* from[2] = {g.member.data() + g.start[group[0]],
                                     g.member.data() + g.start[group[1]]};
    const std::uint32_t count = g.start[group[0] + 1] - g.start[group[0]];
    const glm::dvec3* x = x_.data();
    v2 cx = both(0), cy = both(0), cz = both(0);
    for (std::uint32_t k = 0; k < count; ++k) {
        const Groups::Member &a = from[0][k], &b = from[1][k];
        const glm::dvec3 &pa = x[a.particle], &pb = x[b.particle];
        const v2 share{a.share, b.share};
        cx += share * v2{pa.x, pb.x};
        cy += share * v2{pa.y, pb.y};
        cz += share * v2{pa.z, pb.z};
    }
    v2 A[3][3];
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) A[c][r] = v2{moments[group[0]][c][r], moments[group[1]][c][r]};
    for (std::uint32_t k = 0; k < count; ++k) {
        const Groups::Member &a = from[0][k], &b = from[1][k];
        const glm::dvec3 &pa = x[a.particle], &pb = x[b.particle];
        const v2 d[3] = {v2{pa.x, pb.x} - cx, v2{pa.y, pb.y} - cy, v2{pa.z, pb.z} - cz};
        const v2 mr[3] = {v2{a.mr.x, b.mr.x}, v2{a.mr.y, b.mr.y}, v2{a.mr.z, b.mr.z}};
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) A[c][r] += d[r] * mr[c];
    }
    // rotation_of, one iteration, warm-started from the frames' rotations and their matrices
    Frame* f[2] = {&frames[group[0]], &frames[group[1]]};
    const Quat2 q = load2(f[0]->R, f[1]->R);
    Mat2 M;
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) M.m[c][r] = v2{f[0]->M[c][r], f[1]->M[c][r]};
    v2 omega[3] = {both(0), both(0), both(0)};
    v2 dots = both(0);
    for (int c = 0; c < 3; ++c) {
        const v2* m = M.m[c];
        const v2* a = A[c];
        // glm::cross(m, a), summed column after column as (c0 + c1) + c2
        const v2 cr[3] = {m[1] * a[2] - a[1] * m[2], m[2] * a[0] - a[2] * m[0], m[0] * a[1] - a[0] * m[1]};
        const v2 dt = (m[0] * a[0] + m[1] * a[1]) + m[2] * a[2];
        for (int r = 0; r < 3; ++r) omega[r] = c == 0 ? cr[r] : omega[r] + cr[r];
        dots = c == 0 ? dt : dots + dt;
    }
    const v2 denom = v2{std::fabs(dots[0]), std::fabs(dots[1])} + both(1e-9);
    const v2 inv = both(1.0) / denom;
    for (auto& o : omega) o *= inv;
    const v2 w2 = (omega[0] * omega[0] + omega[1] * omega[1]) + omega[2] * omega[2];
    const m2 turn = w2 >= both(1e-18); // false: converged or NaN, the lane keeps its frame
    Quat2 n{};
    Mat2 nm{};
    v2 len{};
    if (turn[0] || turn[1]) {
        v2 cw, sw;
        small_turn(w2, cw, sw);
        for (int l = 0; l < 2; ++l)
            if (turn[l] && !(w2[l] < 1e-4)) { // as rotation_of
                // through scalars: binding a reference to a vector lane is a GCC extension
                double c = 0, s = 0;
                large_turn(w2[l], c, s);
                cw[l] = c;
                sw[l] = s;
            }
        const Quat2 p{cw, omega[0] * sw, omega[1] * sw, omega[2] * sw};
        // p * q as glm multiplies quaternions, then glm::normalize
        n = mul2(p, q);
        const v2 len2 = dot2(n, n);
        len = v2{std::sqrt(len2[0]), std::sqrt(len2[1])};
        const v2 one_over = both(1.0) / len;
        n = {n.w * one_over, n.x * one_over, n.y * one_over, n.z * one_over};
        nm = mat3_cast2(n);
    }
    for (int l = 0; l < 2; ++l) {
        Frame& out = *f[l];
        out.c = glm::dvec3(cx[l], cy[l], cz[l]);
        out.valid = true;
        if (!turn[l]) continue;
        if (len[l] <= 0) { // glm::normalize's answer to a zero quaternion (a NaN length stays NaN, as there)
            out.R = glm::dquat(1, 0, 0, 0);
            out.M = glm::mat3_cast(out.R);
            continue;
        }
        out.R = glm::dquat(n.w[l], n.x[l], n.y[l], n.z[l]);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) out.M[c][r] = nm.m[c][r][l];
    }
}

void World::match_shapes(Array<Frame>& frames, const Array<glm::dmat3>& moments, int iterations,
                         const Groups& g) const {
    const std::size_t n = x_.size();
    frames.resize(n);
    parallel_ranges(n, settings_.threads, 2048, [&](std::size_t b, std::size_t e) {
        // groups warm-started with one iteration go two at a time (frame_pair), paired by their
        // number of members: a group waits in `pending` for a partner of its size
        constexpr std::uint32_t kMaxPaired = 8, kNoGroup = ~0u;
        std::uint32_t pending[kMaxPaired + 1];
        std::fill(std::begin(pending), std::end(pending), kNoGroup);
        for (std::size_t k = b; k < e; ++k) {
            const auto i = static_cast<std::uint32_t>(k);
            if (!alive_[i]) continue;
            // warm start from the last pass's rotation when there is one, else from the
            // particle's own rotation from rest; the last pass's matrix goes with its rotation
            const bool last = frames[i].valid;
            const std::uint32_t size = g.start[i + 1] - g.start[i];
            if (last && iterations == 1 && size <= kMaxPaired) {
                if (pending[size] == kNoGroup) {
                    pending[size] = i;
                } else {
                    frame_pair({pending[size], i}, moments, g, frames);
                    pending[size] = kNoGroup;
                }
                continue;
            }
            const glm::dquat warm = last ? frames[i].R : rotation_from_rest(i);
            group_frame(i, warm, moments[i], iterations, g, frames[i], last);
        }
        for (std::uint32_t i : pending)
            if (i != kNoGroup) group_frame(i, frames[i].R, moments[i], iterations, g, frames[i], true);
    });
}

} // namespace plant::physics
