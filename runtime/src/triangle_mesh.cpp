#include "triangle_mesh.hpp"

#include "mesh_file.hpp"
#include "openmesh.hpp"
#include "plant/diagnostics.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace plant {

bool load_triangles(const std::string& path, std::vector<Triangle>& out, const char* who,
                    std::string& error) {
    OpenMeshTriangles mesh;
    OpenMesh::IO::Options options;
    std::string why;
    switch (read_mesh_file(path, mesh, options, why)) {
    case MeshRead::Ok:
        break;
    case MeshRead::Failed:
        error = fmt::format("{}: cannot load the mesh '{}'", who, path);
        return false;
    case MeshRead::Refused:
        throw InputError(fmt::format("{}: cannot read mesh file '{}': {}", who, path, why));
    }
    mesh.triangulate();
    for (auto f : mesh.faces()) {
        glm::dvec3 v[3];
        int k = 0;
        for (auto vh : mesh.fv_range(f)) {
            auto p = mesh.point(vh);
            if (k < 3) v[k++] = glm::dvec3(p[0], p[1], p[2]);
        }
        glm::dvec3 n = glm::cross(v[1] - v[0], v[2] - v[0]);
        if (!(glm::length(n) > 0) || !std::isfinite(glm::length(n))) continue; // degenerate or not finite
        out.push_back({v[0], v[1], v[2], glm::normalize(n)});
    }
    if (out.empty()) {
        error = fmt::format("{}: the mesh '{}' has no faces", who, path);
        return false;
    }
    return true;
}

glm::dvec3 closest_on_triangle(const glm::dvec3& p, const Triangle& t) {
    const glm::dvec3 ab = t.b - t.a, ac = t.c - t.a, ap = p - t.a;
    double d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return t.a;
    const glm::dvec3 bp = p - t.b;
    double d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return t.b;
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return t.a + ab * (d1 / (d1 - d3));
    const glm::dvec3 cp = p - t.c;
    double d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return t.c;
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return t.a + ac * (d2 / (d2 - d6));
    double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return t.b + (t.c - t.b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    double denom = 1 / (va + vb + vc);
    return t.a + ab * (vb * denom) + ac * (vc * denom);
}

double signed_distance(const std::vector<Triangle>& mesh, const glm::dvec3& p) {
    // the nearest triangle gives the distance; the side of its face, the sign
    double best = std::numeric_limits<double>::infinity();
    double sign = 1;
    for (const auto& t : mesh) {
        glm::dvec3 q = closest_on_triangle(p, t);
        double dist = glm::length(p - q);
        if (dist < best - 1e-12) {
            best = dist;
            sign = glm::dot(p - q, t.n) < 0 ? -1 : 1;
        }
    }
    return sign * best;
}

void obstacle_triangles(const physics::Obstacle& o, const glm::dvec3& lo, const glm::dvec3& hi,
                        std::vector<glm::dvec3>& out) {
    auto quad = [&](const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
        out.insert(out.end(), {a, b, c, a, c, d});
    };
    switch (o.kind) {
    case physics::Obstacle::Box: {
        const glm::dvec3 a = o.a, b = o.b;
        auto p = [&](int x, int y, int z) { return glm::dvec3(x ? b.x : a.x, y ? b.y : a.y, z ? b.z : a.z); };
        quad(p(0, 0, 0), p(0, 1, 0), p(1, 1, 0), p(1, 0, 0)); // -z
        quad(p(0, 0, 1), p(1, 0, 1), p(1, 1, 1), p(0, 1, 1)); // +z
        quad(p(0, 0, 0), p(0, 0, 1), p(0, 1, 1), p(0, 1, 0)); // -x
        quad(p(1, 0, 0), p(1, 1, 0), p(1, 1, 1), p(1, 0, 1)); // +x
        quad(p(0, 0, 0), p(1, 0, 0), p(1, 0, 1), p(0, 0, 1)); // -y
        quad(p(0, 1, 0), p(0, 1, 1), p(1, 1, 1), p(1, 1, 0)); // +y
        break;
    }
    case physics::Obstacle::Sphere: {
        const int rings = 12, segments = 24;
        const double r = o.b.x;
        auto at = [&](int i, int j) {
            const double t = 3.14159265358979323846 * i / rings,
                         f = 2 * 3.14159265358979323846 * j / segments;
            return o.a + r * glm::dvec3(std::sin(t) * std::cos(f), std::cos(t), std::sin(t) * std::sin(f));
        };
        for (int i = 0; i < rings; ++i)
            for (int j = 0; j < segments; ++j) quad(at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
        break;
    }
    case physics::Obstacle::Plane: {
        const glm::dvec3 n = glm::normalize(o.b);
        const glm::dvec3 centre = (lo + hi) * 0.5;
        const double half = std::max(0.4 * glm::length(hi - lo), 1e-3); // a little wider than the plant
        const glm::dvec3 c = centre - n * glm::dot(centre - o.a, n);    // the plant's centre on the plane
        const glm::dvec3 u = glm::normalize(std::abs(n.y) < 0.9 ? glm::cross(n, glm::dvec3(0, 1, 0))
                                                                : glm::cross(n, glm::dvec3(1, 0, 0)));
        const glm::dvec3 v = glm::cross(n, u);
        quad(c - u * half - v * half, c + u * half - v * half, c + u * half + v * half,
             c - u * half + v * half);
        break;
    }
    case physics::Obstacle::Grid:
        break;
    }
}

} // namespace plant
