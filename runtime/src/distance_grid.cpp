// The climber's distance grid for mesh obstacles: signed distances sampled on a grid, found
// through a bounding-volume hierarchy over the triangles instead of a loop over all of them.
//
// The loop (signed_distance in triangle_mesh.cpp) keeps the first triangle that is nearer than
// the best so far by more than 1e-12, and takes the sign from it, so near ties are decided by the
// triangles' order. The tree reproduces that exactly: it finds the nearest distance d, gathers
// every triangle within d + window, and replays in mesh order those up to a cut past which the
// next distance is more than 2e-12 (plus rounding) away. A triangle beyond the cut can never
// replace one before it in the loop, and every triangle before it replaces any beyond, so the
// loop over all triangles ends with the same triangle as the replay. When no such gap exists
// inside the window (a pathological mesh), the point falls back to the loop.
#include "triangle_mesh.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <system_error>
#include <thread>

namespace plant {

namespace {

double box_distance2(const glm::dvec3& p, const glm::dvec3& lo, const glm::dvec3& hi) {
    const glm::dvec3 d = glm::max(glm::max(lo - p, p - hi), glm::dvec3(0.0));
    return glm::dot(d, d);
}

bool finite3(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

struct Near {
    std::uint32_t index;
    double dist;
    double sign;
};

} // namespace

TriangleTree::TriangleTree(const std::vector<Triangle>& mesh) : mesh_(mesh) {
    std::vector<glm::dvec3> centres;
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const auto& t : mesh) {
        centres.push_back((t.a + t.b + t.c) / 3.0);
        for (const glm::dvec3& v : {t.a, t.b, t.c}) lo = glm::min(lo, v), hi = glm::max(hi, v);
    }
    const double scale = mesh.empty() ? 1.0 : std::max({1.0, glm::length(lo), glm::length(hi)});
    window_ = 1e-9 * scale; // far above rounding (1e-16 of the scale), far below a grid cell
    order_.resize(mesh.size());
    for (std::uint32_t i = 0; i < order_.size(); ++i) order_[i] = i;
    nodes_.reserve(2 * mesh.size() + 1);
    if (!mesh.empty()) build(0, static_cast<std::uint32_t>(mesh.size()), centres);
}

std::uint32_t TriangleTree::build(std::uint32_t first, std::uint32_t count,
                                  std::vector<glm::dvec3>& centres) {
    const auto at = static_cast<std::uint32_t>(nodes_.size());
    nodes_.emplace_back();
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    glm::dvec3 clo = lo, chi = hi;
    for (std::uint32_t k = first; k < first + count; ++k) {
        const Triangle& t = mesh_[order_[k]];
        for (const glm::dvec3& v : {t.a, t.b, t.c}) lo = glm::min(lo, v), hi = glm::max(hi, v);
        clo = glm::min(clo, centres[order_[k]]), chi = glm::max(chi, centres[order_[k]]);
    }
    nodes_[at].lo = lo;
    nodes_[at].hi = hi;
    if (count <= 4) {
        nodes_[at].first = first;
        nodes_[at].count = count;
        return at;
    }
    const glm::dvec3 ext = chi - clo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const std::uint32_t half = count / 2;
    std::nth_element(order_.begin() + first, order_.begin() + first + half, order_.begin() + first + count,
                     [&](std::uint32_t a, std::uint32_t b) { return centres[a][axis] < centres[b][axis]; });
    const std::uint32_t left = build(first, half, centres);
    const std::uint32_t right = build(first + half, count - half, centres);
    nodes_[at].left = left;
    nodes_[at].right = right;
    return at;
}

double TriangleTree::signed_distance(const glm::dvec3& p) const {
    if (mesh_.empty()) return std::numeric_limits<double>::infinity();
    thread_local std::vector<Near> near;
    near.clear();
    double best = std::numeric_limits<double>::infinity();
    // every triangle within best + window is gathered; nodes are pruned only beyond twice that,
    // so rounding in a box's distance cannot lose one (squared distances: no square roots)
    struct Entry {
        std::uint32_t node;
        double d2;
    };
    Entry stack[128];
    int top = 0;
    stack[top++] = {0, box_distance2(p, nodes_[0].lo, nodes_[0].hi)};
    while (top > 0) {
        const Entry e = stack[--top];
        const double reach = best + 2 * window_;
        if (e.d2 > reach * reach) continue;
        const Node& n = nodes_[e.node];
        if (n.count > 0) {
            for (std::uint32_t k = n.first; k < n.first + n.count; ++k) {
                const Triangle& t = mesh_[order_[k]];
                const glm::dvec3 q = closest_on_triangle(p, t);
                const double dist = glm::length(p - q);
                if (dist <= best + window_)
                    near.push_back({order_[k], dist, glm::dot(p - q, t.n) < 0 ? -1.0 : 1.0});
                best = std::min(best, dist);
            }
            continue;
        }
        const Entry l{n.left, box_distance2(p, nodes_[n.left].lo, nodes_[n.left].hi)};
        const Entry r{n.right, box_distance2(p, nodes_[n.right].lo, nodes_[n.right].hi)};
        stack[top++] = l.d2 <= r.d2 ? r : l; // the nearer child is popped first
        stack[top++] = l.d2 <= r.d2 ? l : r;
    }
    std::sort(near.begin(), near.end(), [](const Near& a, const Near& b) { return a.dist < b.dist; });
    double cut = best;
    std::size_t keep = 0;
    for (; keep < near.size(); ++keep) {
        const double gap = 2e-12 + 1e-15 * near[keep].dist; // 1e-12, and the rounding of best - 1e-12
        if (near[keep].dist > cut + gap) break;
        cut = std::max(cut, near[keep].dist);
    }
    if (!(cut + 2e-12 + 1e-15 * cut < best + window_)) return plant::signed_distance(mesh_, p);
    std::sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(keep),
              [](const Near& a, const Near& b) { return a.index < b.index; });
    double d = std::numeric_limits<double>::infinity(), sign = 1;
    for (std::size_t k = 0; k < keep; ++k) // the loop's rule, over the triangles up to the cut
        if (near[k].dist < d - 1e-12) d = near[k].dist, sign = near[k].sign;
    return sign * d;
}

std::shared_ptr<const physics::DistanceGrid> distance_grid(const std::vector<Triangle>& mesh, double cell,
                                                           double margin, std::size_t max_points) {
    glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
    for (const auto& t : mesh)
        for (const glm::dvec3& v : {t.a, t.b, t.c}) lo = glm::min(lo, v), hi = glm::max(hi, v);
    lo -= glm::dvec3(margin);
    hi += glm::dvec3(margin);
    if (mesh.empty() || !finite3(lo) || !finite3(hi) || !finite3(hi - lo) || !(cell > 0) ||
        !std::isfinite(cell))
        return nullptr;
    auto points = [&](double c) { return glm::ceil((hi - lo) / c) + 1.0; }; // in double: no overflow
    while (true) {
        glm::dvec3 n = points(cell);
        if (n.x * n.y * n.z <= static_cast<double>(max_points)) break;
        cell *= 1.25;
        if (!std::isfinite(cell)) return nullptr;
    }
    auto g = std::make_shared<physics::DistanceGrid>();
    g->lo = lo;
    g->cell = cell;
    g->n = glm::ivec3(points(cell));
    g->d.resize(static_cast<std::size_t>(g->n.x) * g->n.y * g->n.z);
    const TriangleTree tree(mesh);
    // each sample is independent of the others: layers are shared among threads, the values do
    // not depend on how
    std::atomic<int> next{0};
    std::mutex failure_lock;
    std::exception_ptr failure; // the first exception of any thread (running out of memory)
    auto work = [&] {
        try {
            for (int z = next++; z < g->n.z; z = next++)
                for (int y = 0; y < g->n.y; ++y)
                    for (int x = 0; x < g->n.x; ++x)
                        g->d[(static_cast<std::size_t>(z) * g->n.y + y) * g->n.x + x] =
                            tree.signed_distance(lo + glm::dvec3(x, y, z) * cell);
        } catch (...) {
            next = g->n.z; // the others stop after their layer
            const std::lock_guard<std::mutex> hold(failure_lock);
            if (!failure) failure = std::current_exception();
        }
    };
    const unsigned threads = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
    std::vector<std::thread> pool;
    try {
        for (unsigned i = 1; i < threads && mesh.size() > 64; ++i) pool.emplace_back(work);
    } catch (const std::system_error&) {
        // no more threads: the ones started (and this one) do the work
    }
    work();
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure); // on the caller's thread, where it is reported
    return g;
}

} // namespace plant
