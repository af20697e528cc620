// Generalized cylinders. Each tube (an axis, possibly continued into a child axis, see
// tube_paths) becomes a ring of `sides` vertices (plus a seam copy for texture coordinates) at
// every point, shared by the segments on both sides of it. A gentle joint gets one ring in the
// bisecting plane, widened along the bend (a miter) so the tube keeps its thickness through the
// joint; a sharp one (past ~45 degrees) is rounded with several rings along a short curve. Ring
// frames are transported along the axis with the smallest rotation from one tangent to the next,
// so the tube does not twist.
#include "plant/mesh.hpp"

#include "geometry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace plant {

namespace {

constexpr double kPi = std::numbers::pi;

struct Ring {
    glm::dvec3 center, tangent;
    double radius;
    glm::dvec3 bend;    // unit direction of the bend in the ring's plane (zero when straight)
    double miter = 1.0; // stretch along `bend`
    glm::vec3 color;
    double slope = 0.0; // d radius / d arc length, for normals of tapering tubes
    int texture = -1;   // SkeletonPoint::texture
};

// Smallest rotation taking unit vector a to unit vector b, applied to v (Rodrigues' formula with
// the sine and cosine of the angle read off the cross and dot products, no trigonometry).
glm::dvec3 transport(const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b) {
    glm::dvec3 axis = glm::cross(a, b);
    double s = glm::length(axis), c = glm::dot(a, b);
    if (s < 1e-12) return c > 0 ? v : -v;
    return rotate(v, axis / s, c, s);
}

glm::dvec3 any_perpendicular(const glm::dvec3& t) {
    glm::dvec3 p =
        std::fabs(t.y) < 0.9 ? glm::cross(t, glm::dvec3(0, 1, 0)) : glm::cross(t, glm::dvec3(1, 0, 0));
    return glm::normalize(p);
}

bool same_point(const glm::dvec3& a, const glm::dvec3& b) {
    return glm::length(a - b) <= 1e-9 * (1.0 + glm::length(a));
}

// Work space reused from tube to tube, so meshing a tree does not allocate per axis.
struct Scratch {
    std::vector<const SkeletonPoint*> pts;
    std::vector<glm::dvec3> dirs; // unit direction of each segment between pts
    std::vector<Ring> rings;
    std::vector<double> cosines, sines; // of 2 pi j / sides
    std::vector<float> us;              // texture coordinate u of vertex j of a ring: j / sides
    int sides = 0;
    double sharp = -1, cos_sharp = 0; // the last sharp-bend angle (radians) and its cosine
};

// Whether a joint whose segments' directions have cosine `cos_theta` bends by at most `sharp`
// radians, which is acos(cos_theta) <= sharp. acos is only evaluated near the threshold: a cosine
// 1e-9 past cos(sharp) either way is an angle at least 1e-9 radians from it, far beyond the
// rounding of either function.
bool gentle(double cos_theta, double sharp, double cos_sharp) {
    if (cos_theta > cos_sharp + 1e-9) return true;
    if (cos_theta < cos_sharp - 1e-9) return false;
    return std::acos(cos_theta) <= sharp;
}

// The rings of a tube, with sharp joints rounded; empty when it has fewer than two distinct
// points.
void rings_of(const TubePath& path, const MeshOptions& o, Scratch& s) {
    // drop points that coincide with the previous one: they have no direction
    auto& pts = s.pts;
    auto& rings = s.rings;
    pts.clear();
    rings.clear();
    for (const SkeletonPoint* p : path)
        if (pts.empty() || glm::length(p->position - pts.back()->position) > 1e-9) pts.push_back(p);
    if (pts.size() < 2) return;
    const double sharp = o.sharp_bend_deg * kPi / 180.0;
    if (sharp != s.sharp) {
        s.sharp = sharp;
        s.cos_sharp = std::cos(sharp);
    }
    const double cos_sharp = s.cos_sharp;
    const std::size_t m = pts.size() - 1;
    s.dirs.resize(m);
    for (std::size_t k = 0; k < m; ++k) s.dirs[k] = glm::normalize(pts[k + 1]->position - pts[k]->position);
    auto dir = [&](std::size_t k) { return s.dirs[k]; };
    auto seg_len = [&](std::size_t k) { return glm::length(pts[k + 1]->position - pts[k]->position); };
    for (std::size_t k = 0; k <= m; ++k) {
        const SkeletonPoint& p = *pts[k];
        double r = std::max(p.radius * o.width_scale, 1e-6);
        if (k == 0 || k == m) {
            rings.push_back(Ring{p.position, k == 0 ? dir(0) : dir(m - 1), r, glm::dvec3(0), 1.0, p.color,
                                 0.0, p.texture});
            continue;
        }
        glm::dvec3 d0 = dir(k - 1), d1 = dir(k);
        double cos_theta = std::clamp(glm::dot(d0, d1), -1.0, 1.0);
        if (gentle(cos_theta, sharp, cos_sharp)) {
            glm::dvec3 t = glm::normalize(d0 + d1);
            glm::dvec3 bend = d1 - d0;
            bend -= t * glm::dot(bend, t);
            double bl = glm::length(bend);
            // 1 / cos(theta / 2), from the half-angle identity
            double miter = 1.0 / std::sqrt(0.5 * (1.0 + cos_theta));
            rings.push_back(Ring{p.position, t, r, bl > 1e-12 ? bend / bl : glm::dvec3(0), miter, p.color,
                                 0.0, p.texture});
            continue;
        }
        // round the corner with a circular arc tangent to both segments, of radius 1.5 tube radii
        // where the segments are long enough (a radius below the tube's folds the inner side)
        const double theta = std::acos(cos_theta);
        const double half = std::min(theta, 3.0) / 2;
        double rho = 1.5 * r;
        double a = rho * std::tan(half);
        const double room = 0.45 * std::min(seg_len(k - 1), seg_len(k));
        if (a > room) {
            a = room;
            rho = a / std::tan(half);
        }
        glm::dvec3 turn = glm::cross(d0, d1);
        double tl = glm::length(turn);
        turn = tl > 1e-12 ? turn / tl : any_perpendicular(d0);
        const glm::dvec3 start = p.position - d0 * a;
        const glm::dvec3 center = start + glm::cross(turn, d0) * rho; // toward the inside of the turn
        int n = std::max(2, static_cast<int>(std::ceil(theta / (22.5 * kPi / 180.0))));
        for (int j = 0; j <= n; ++j) {
            double phi = theta * j / n;
            glm::dvec3 c = center + rotate(start - center, turn, phi);
            glm::dvec3 t = rotate(d0, turn, phi);
            rings.push_back(Ring{c, glm::normalize(t), r, glm::dvec3(0), 1.0, p.color, 0.0, p.texture});
        }
    }
    rings.back().radius *= o.tip_taper; // a tapered tip
    // slopes of the radius along the axis, for the normals
    for (std::size_t k = 0; k < rings.size(); ++k) {
        std::size_t a = k > 0 ? k - 1 : k, b = k + 1 < rings.size() ? k + 1 : k;
        double len = glm::length(rings[b].center - rings[a].center);
        rings[k].slope = len > 1e-12 ? (rings[b].radius - rings[a].radius) / len : 0.0;
    }
}

} // namespace

std::vector<TubePath> tube_paths(const Skeleton& skeleton, const MeshOptions& o) {
    const std::size_t n = skeleton.axes.size();
    std::vector<TubePath> tubes;
    if (!o.continue_axes) {
        tubes.reserve(n);
        for (const auto& axis : skeleton.axes) {
            TubePath& t = tubes.emplace_back();
            for (const auto& p : axis.points) t.push_back(&p);
        }
        return tubes;
    }
    // the child each axis continues into: of the children that begin at its last point, the one
    // whose first segment turns least from its last one, if that turn is gentle (no extra rings)
    const double min_cos = std::cos(o.sharp_bend_deg * kPi / 180.0);
    std::vector<int> next(n, -1);
    std::vector<double> best(n, -2.0);
    std::vector<char> continued(n, 0); // this axis is the continuation of its parent
    // the unit direction of an axis's first segment (last = false) or its last one, over points
    // that coincide with that end; false when every point does
    auto end_direction = [](const SkeletonAxis& a, bool last, glm::dvec3& d) {
        const auto& pts = a.points;
        const glm::dvec3 end = last ? pts.back().position : pts.front().position;
        for (std::size_t k = 1; k < pts.size(); ++k) {
            const glm::dvec3 v = pts[last ? pts.size() - 1 - k : k].position - end;
            if (glm::length(v) > 1e-12) {
                d = glm::normalize(last ? -v : v);
                return true;
            }
        }
        return false;
    };
    for (std::size_t c = 0; c < n; ++c) {
        const SkeletonAxis& child = skeleton.axes[c];
        if (child.parent < 0 || static_cast<std::size_t>(child.parent) >= n || child.points.empty()) continue;
        const auto pa = static_cast<std::size_t>(child.parent);
        const SkeletonAxis& parent = skeleton.axes[pa];
        if (parent.points.empty() || !same_point(parent.points.back().position, child.points[0].position))
            continue;
        glm::dvec3 dp, dc;
        if (!end_direction(parent, true, dp) || !end_direction(child, false, dc)) continue;
        double cs = glm::dot(dp, dc);
        if (cs >= min_cos && cs > best[pa]) {
            best[pa] = cs;
            next[pa] = static_cast<int>(c);
        }
    }
    std::size_t starts = n;
    for (std::size_t a = 0; a < n; ++a)
        if (next[a] >= 0) continued[static_cast<std::size_t>(next[a])] = 1, --starts;
    tubes.reserve(starts);
    for (std::size_t a = 0; a < n; ++a) {
        if (continued[a]) continue; // meshed as part of its parent's tube
        TubePath& t = tubes.emplace_back();
        std::size_t length = 0; // the points of the chain, each joint counted once
        for (std::size_t k = a;; k = static_cast<std::size_t>(next[k])) {
            length += skeleton.axes[k].points.size() - (length > 0 ? 1 : 0);
            if (next[k] < 0) break;
        }
        t.reserve(length);
        for (std::size_t k = a;;) {
            const auto& pts = skeleton.axes[k].points;
            // the joint point is the child's first one: its radius and colour start the child's part
            if (!t.empty()) t.pop_back();
            for (const auto& p : pts) t.push_back(&p);
            if (next[k] < 0) break;
            k = static_cast<std::size_t>(next[k]);
        }
    }
    return tubes;
}

void mesh_tube(const TubePath& path, const MeshOptions& o, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&)>& material_of) {
    mesh_tube(path, o, part, indices_by_material,
              [&](const glm::vec3& color, int) { return material_of(color); });
}

void mesh_tube(const TubePath& path, const MeshOptions& o, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&, int)>& material_of) {
    thread_local Scratch s;
    rings_of(path, o, s);
    const std::vector<Ring>& rings = s.rings;
    if (rings.size() < 2) return;
    const int sides = std::max(3, o.sides);
    if (s.sides != sides) {
        s.sides = sides;
        s.cosines.resize(static_cast<std::size_t>(sides) + 1);
        s.sines.resize(static_cast<std::size_t>(sides) + 1);
        s.us.resize(static_cast<std::size_t>(sides) + 1);
        for (int j = 0; j <= sides; ++j) {
            double phi = 2 * kPi * (j % sides) / sides;
            s.cosines[static_cast<std::size_t>(j)] = std::cos(phi);
            s.sines[static_cast<std::size_t>(j)] = std::sin(phi);
            s.us[static_cast<std::size_t>(j)] = static_cast<float>(double(j) / sides);
        }
    }
    // the first frame comes from the turtle's left vector, projected onto the first ring's plane
    const glm::dvec3 left = s.pts[0]->left;
    glm::dvec3 normal = left - rings[0].tangent * glm::dot(left, rings[0].tangent);
    normal = glm::length(normal) > 1e-9 ? glm::normalize(normal) : any_perpendicular(rings[0].tangent);
    const auto stride = static_cast<std::uint32_t>(sides + 1);
    const auto base = static_cast<std::uint32_t>(part.positions.size());
    const std::size_t count = rings.size() * stride;
    // appended one by one into room made first: resize would write every vertex twice (zeros,
    // then the vertex); the caller sized the arrays for the whole skeleton, and when they are
    // short the room doubles, as it would with resize
    const std::size_t room = std::max<std::size_t>(base + count, 2 * std::size_t{base});
    if (part.positions.capacity() < base + count) part.positions.reserve(room);
    if (part.normals.capacity() < base + count) part.normals.reserve(room);
    if (part.uvs.capacity() < base + count) part.uvs.reserve(room);
    auto& pos = part.positions;
    auto& nrm = part.normals;
    auto& uv = part.uvs;
    double arc = 0;
    for (std::size_t k = 0; k < rings.size(); ++k) {
        const Ring& R = rings[k];
        if (k > 0) {
            normal = transport(normal, rings[k - 1].tangent, R.tangent);
            normal = glm::normalize(normal - R.tangent * glm::dot(normal, R.tangent));
            arc += glm::length(R.center - rings[k - 1].center);
        }
        const glm::dvec3 binormal = glm::cross(R.tangent, normal);
        // the normal of a tapering tube tilts toward the thin end; its length is the same for
        // every vertex of the ring
        const double tilt = 1.0 / std::sqrt(1.0 + R.slope * R.slope);
        const glm::dvec3 along = -R.tangent * R.slope;
        const bool mitered = R.miter != 1.0;
        for (std::size_t j = 0; j <= static_cast<std::size_t>(sides); ++j) {
            const glm::dvec3 radial = s.cosines[j] * normal + s.sines[j] * binormal;
            glm::dvec3 offset = radial * R.radius;
            if (mitered) offset += R.bend * (glm::dot(offset, R.bend) * (R.miter - 1.0));
            pos.emplace_back(R.center + offset);
            nrm.emplace_back((radial + along) * tilt);
            uv.emplace_back(s.us[j], static_cast<float>(arc));
        }
    }
    // triangles, grouped by material (looked up only when the colour or texture changes along the
    // tube)
    std::vector<std::uint32_t>* idx = nullptr;
    glm::vec3 last_color(-1.0f);
    int last_texture = -1;
    for (std::size_t k = 0; k + 1 < rings.size(); ++k) {
        if (!idx || rings[k + 1].color != last_color || rings[k + 1].texture != last_texture) {
            last_color = rings[k + 1].color;
            last_texture = rings[k + 1].texture;
            const std::uint32_t material = material_of(last_color, last_texture);
            if (material >= indices_by_material.size()) indices_by_material.resize(material + 1);
            idx = &indices_by_material[material];
        }
        const std::size_t at = idx->size();
        idx->resize(at + 6 * static_cast<std::size_t>(sides));
        std::uint32_t* out = idx->data() + at;
        for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sides); ++j) {
            std::uint32_t a = base + static_cast<std::uint32_t>(k) * stride + j, b = a + 1, d = a + stride,
                          c = d + 1;
            out[0] = a, out[1] = b, out[2] = c, out[3] = a, out[4] = c, out[5] = d;
            out += 6;
        }
    }
}

} // namespace plant
