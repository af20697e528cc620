// Generalized cylinders. Each axis becomes one tube: a ring of `sides` vertices (plus a seam
// copy for texture coordinates) at every point, shared by the segments on both sides of it.
// A gentle joint gets one ring in the bisecting plane, widened along the bend (a miter) so the
// tube keeps its thickness through the joint; a sharp one (past ~45 degrees) is rounded with
// several rings along a short curve. Ring frames are transported along the axis with the
// smallest rotation from one tangent to the next, so the tube does not twist.
#include "plant/mesh.hpp"

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
};

// Smallest rotation taking unit vector a to unit vector b, applied to v.
glm::dvec3 transport(const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b) {
    glm::dvec3 axis = glm::cross(a, b);
    double s = glm::length(axis), c = glm::dot(a, b);
    if (s < 1e-12) return c > 0 ? v : -v;
    axis /= s;
    double angle = std::atan2(s, c);
    return v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) + axis * glm::dot(axis, v) * (1 - std::cos(angle));
}

// Rotates v about the unit axis k by phi, right-handed.
glm::dvec3 transport_about(const glm::dvec3& v, const glm::dvec3& k, double phi) {
    return v * std::cos(phi) + glm::cross(k, v) * std::sin(phi) + k * glm::dot(k, v) * (1 - std::cos(phi));
}

glm::dvec3 any_perpendicular(const glm::dvec3& t) {
    glm::dvec3 p = std::fabs(t.y) < 0.9 ? glm::cross(t, glm::dvec3(0, 1, 0)) : glm::cross(t, glm::dvec3(1, 0, 0));
    return glm::normalize(p);
}

// The rings of an axis, with sharp joints rounded.
std::vector<Ring> rings_of(const SkeletonAxis& axis, const MeshOptions& o) {
    // drop points that coincide with the previous one: they have no direction
    std::vector<const SkeletonPoint*> pts;
    for (const auto& p : axis.points)
        if (pts.empty() || glm::length(p.position - pts.back()->position) > 1e-9) pts.push_back(&p);
    std::vector<Ring> rings;
    if (pts.size() < 2) return rings;
    const double sharp = o.sharp_bend_deg * kPi / 180.0;
    const std::size_t m = pts.size() - 1;
    auto dir = [&](std::size_t k) { return glm::normalize(pts[k + 1]->position - pts[k]->position); };
    auto seg_len = [&](std::size_t k) { return glm::length(pts[k + 1]->position - pts[k]->position); };
    for (std::size_t k = 0; k <= m; ++k) {
        const SkeletonPoint& p = *pts[k];
        double r = std::max(p.radius, 1e-6);
        if (k == 0 || k == m) {
            rings.push_back(Ring{p.position, k == 0 ? dir(0) : dir(m - 1), r, glm::dvec3(0), 1.0, p.color});
            continue;
        }
        glm::dvec3 d0 = dir(k - 1), d1 = dir(k);
        double theta = std::acos(std::clamp(glm::dot(d0, d1), -1.0, 1.0));
        if (theta <= sharp) {
            glm::dvec3 t = glm::normalize(d0 + d1);
            glm::dvec3 bend = d1 - d0;
            bend -= t * glm::dot(bend, t);
            double bl = glm::length(bend);
            rings.push_back(Ring{p.position, t, r, bl > 1e-12 ? bend / bl : glm::dvec3(0), 1.0 / std::cos(theta / 2),
                                 p.color});
            continue;
        }
        // round the corner with a circular arc tangent to both segments, of radius 1.5 tube radii
        // where the segments are long enough (a radius below the tube's folds the inner side)
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
            glm::dvec3 c = center + transport_about(start - center, turn, phi);
            glm::dvec3 t = transport_about(d0, turn, phi);
            rings.push_back(Ring{c, glm::normalize(t), r, glm::dvec3(0), 1.0, p.color});
        }
    }
    rings.back().radius *= o.tip_taper; // a tapered tip
    // slopes of the radius along the axis, for the normals
    for (std::size_t k = 0; k < rings.size(); ++k) {
        std::size_t a = k > 0 ? k - 1 : k, b = k + 1 < rings.size() ? k + 1 : k;
        double len = glm::length(rings[b].center - rings[a].center);
        rings[k].slope = len > 1e-12 ? (rings[b].radius - rings[a].radius) / len : 0.0;
    }
    return rings;
}

} // namespace

void mesh_axis(const SkeletonAxis& axis, const MeshOptions& o, MeshPart& part,
               std::vector<std::vector<std::uint32_t>>& indices_by_material,
               const std::function<std::uint32_t(const glm::vec3&)>& material_of) {
    std::vector<Ring> rings = rings_of(axis, o);
    if (rings.size() < 2) return;
    const int sides = std::max(3, o.sides);
    // the first frame comes from the turtle's left vector, projected onto the first ring's plane
    glm::dvec3 normal = axis.points[0].left - rings[0].tangent * glm::dot(axis.points[0].left, rings[0].tangent);
    normal = glm::length(normal) > 1e-9 ? glm::normalize(normal) : any_perpendicular(rings[0].tangent);
    const auto base = static_cast<std::uint32_t>(part.positions.size());
    double arc = 0;
    for (std::size_t k = 0; k < rings.size(); ++k) {
        const Ring& R = rings[k];
        if (k > 0) {
            normal = transport(normal, rings[k - 1].tangent, R.tangent);
            normal = glm::normalize(normal - R.tangent * glm::dot(normal, R.tangent));
            arc += glm::length(R.center - rings[k - 1].center);
        }
        glm::dvec3 binormal = glm::cross(R.tangent, normal);
        for (int j = 0; j <= sides; ++j) {
            double phi = 2 * kPi * (j % sides) / sides;
            glm::dvec3 radial = std::cos(phi) * normal + std::sin(phi) * binormal;
            glm::dvec3 offset = radial * R.radius;
            if (R.miter != 1.0) offset += R.bend * (glm::dot(offset, R.bend) * (R.miter - 1.0));
            part.positions.emplace_back(R.center + offset);
            part.normals.emplace_back(glm::normalize(radial - R.tangent * R.slope));
            part.uvs.emplace_back(static_cast<float>(double(j) / sides), static_cast<float>(arc));
        }
    }
    const auto stride = static_cast<std::uint32_t>(sides + 1);
    for (std::size_t k = 0; k + 1 < rings.size(); ++k) {
        const std::uint32_t material = material_of(rings[k + 1].color);
        if (material >= indices_by_material.size()) indices_by_material.resize(material + 1);
        auto& idx = indices_by_material[material];
        for (std::uint32_t j = 0; j < static_cast<std::uint32_t>(sides); ++j) {
            std::uint32_t a = base + static_cast<std::uint32_t>(k) * stride + j, b = a + 1, d = a + stride, c = d + 1;
            idx.insert(idx.end(), {a, b, c, a, c, d});
        }
    }
}

} // namespace plant
