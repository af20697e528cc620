// Placements for the glTF writer: decomposing a placement's matrix, finding prototypes that are
// the same mesh, and baking a scene into world space (export_placement.hpp).
#include "export_placement.hpp"

#include "plant/export.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>

namespace plant::detail {

namespace {

bool finite(const glm::dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

} // namespace

std::optional<Trs> decompose(const glm::mat4& given) {
    const glm::dmat4 m(given);
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r])) return std::nullopt;
    if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0) return std::nullopt;

    const glm::dvec3 col[3] = {glm::dvec3(m[0]), glm::dvec3(m[1]), glm::dvec3(m[2])};
    const glm::dvec3 scale(glm::length(col[0]), glm::length(col[1]), glm::length(col[2]));
    if (!finite(scale) || !(scale.x > 0.0) || !(scale.y > 0.0) || !(scale.z > 0.0)) return std::nullopt;
    // The nearest frame to the columns (Gram-Schmidt); a mirror has its third column against it.
    const glm::dvec3 x = col[0] / scale.x;
    glm::dvec3 y = col[1] - glm::dot(col[1], x) * x;
    const double ylen = glm::length(y);
    if (!(ylen > 0.0)) return std::nullopt;
    y /= ylen;
    const glm::dvec3 z = glm::cross(x, y);
    if (!(glm::dot(z, col[2]) > 0.0)) return std::nullopt;
    glm::dquat q = glm::normalize(glm::quat_cast(glm::dmat3(x, y, z)));
    if (q.w < 0.0) q = -q; // one of the two quaternions of a rotation, always the same one

    // The rebuilt matrix must be the given one: no shear beyond the tolerance.
    const glm::dmat3 rotation = glm::mat3_cast(q);
    const double largest = std::max({scale.x, scale.y, scale.z});
    for (int c = 0; c < 3; ++c) {
        const glm::dvec3 rebuilt = rotation[c] * scale[c];
        for (int r = 0; r < 3; ++r)
            if (!(std::abs(rebuilt[r] - col[c][r]) <= kTrsTolerance * largest)) return std::nullopt;
    }

    Trs trs;
    trs.translation = glm::vec3(given[3]);
    trs.rotation = glm::vec4(float(q.x), float(q.y), float(q.z), float(q.w));
    trs.scale = glm::vec3(scale);
    if (!(trs.scale.x > 0.0f) || !(trs.scale.y > 0.0f) || !(trs.scale.z > 0.0f) ||
        !std::isfinite(trs.scale.x) || !std::isfinite(trs.scale.y) || !std::isfinite(trs.scale.z))
        return std::nullopt; // below or beyond single precision
    return trs;
}

namespace {

template <class T> bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_part(const MeshPart& a, const MeshPart& b) {
    return same_bytes(a.positions, b.positions) && same_bytes(a.normals, b.normals) &&
           same_bytes(a.uvs, b.uvs) && same_bytes(a.indices, b.indices) &&
           a.primitives.size() == b.primitives.size() &&
           std::equal(a.primitives.begin(), a.primitives.end(), b.primitives.begin(),
                      [](const Primitive& p, const Primitive& q) {
                          return p.first == q.first && p.count == q.count && p.material == q.material;
                      });
}

// FNV-1a over the part's arrays and their sizes.
struct Hasher {
    std::uint64_t h = 14695981039346656037ull;
    void bytes(const void* data, std::size_t n) {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    }
    template <class T> void add(const std::vector<T>& v) {
        const std::uint64_t n = v.size();
        bytes(&n, sizeof n);
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
};

std::uint64_t hash_part(const MeshPart& part) {
    Hasher h;
    h.add(part.positions);
    h.add(part.normals);
    h.add(part.uvs);
    h.add(part.indices);
    for (const Primitive& p : part.primitives) {
        const std::uint32_t fields[3] = {p.first, p.count, p.material};
        h.bytes(fields, sizeof fields);
    }
    return h.h;
}

} // namespace

std::vector<std::uint32_t> shared_prototypes(const Scene& scene) {
    std::vector<std::uint32_t> first(scene.prototypes.size());
    std::unordered_map<std::uint64_t, std::vector<std::uint32_t>> seen;
    for (std::uint32_t i = 0; i < scene.prototypes.size(); ++i) {
        first[i] = i;
        auto& candidates = seen[hash_part(scene.prototypes[i])];
        for (std::uint32_t k : candidates)
            if (same_part(scene.prototypes[k], scene.prototypes[i])) {
                first[i] = k;
                break;
            }
        if (first[i] == i) candidates.push_back(i);
    }
    return first;
}

namespace {

std::uint64_t saturating_add(std::uint64_t a, std::uint64_t b) {
    return a > std::numeric_limits<std::uint64_t>::max() - b ? std::numeric_limits<std::uint64_t>::max()
                                                             : a + b;
}

// How many parts the scene draws: its tubes, its organ placements and, through every scene
// prototype it places, theirs (saturating; once per scene prototype however often it is placed).
std::uint64_t part_count(const Scene& s, std::map<const Scene*, std::uint64_t>& memo) {
    if (auto it = memo.find(&s); it != memo.end()) return it->second;
    memo[&s] = 0; // a scene that places itself (never built by plant) counts nothing more
    std::uint64_t n = (s.tubes.empty() ? 0 : 1) + s.instances.size();
    for (const Instance& i : s.scene_instances)
        if (i.prototype < s.scene_prototypes.size() && s.scene_prototypes[i.prototype])
            n = saturating_add(n, part_count(*s.scene_prototypes[i.prototype], memo));
    memo[&s] = n;
    return n;
}

} // namespace

Scene split_nested(const Scene& scene, std::vector<NestedGroup>& groups, const std::string& what) {
    groups.clear();
    const std::size_t n = scene.scene_prototypes.size();
    std::vector<std::uint64_t> placed(n, 0);
    for (const Instance& i : scene.scene_instances) {
        if (i.prototype >= n || !scene.scene_prototypes[i.prototype])
            throw ExportError(what + ": a placement of scene prototype " + std::to_string(i.prototype) +
                              " but the scene has " + std::to_string(n));
        ++placed[i.prototype];
    }
    std::map<const Scene*, std::uint64_t> memo;
    std::vector<int> group_of(n, -1);
    Scene rest = scene; // the placements of nested prototypes taken out below
    rest.scene_instances.clear();
    for (const Instance& i : scene.scene_instances) {
        const std::uint32_t k = i.prototype;
        const std::uint64_t parts = part_count(*scene.scene_prototypes[k], memo);
        const bool nested =
            parts > placed[k] && (parts > kNestedFrom / placed[k] || parts * placed[k] > kNestedFrom);
        if (!nested) {
            rest.scene_instances.push_back(i);
            continue;
        }
        if (group_of[k] < 0) {
            group_of[k] = static_cast<int>(groups.size());
            NestedGroup g;
            g.name = k < scene.scene_prototype_names.size() && !scene.scene_prototype_names[k].empty()
                         ? scene.scene_prototype_names[k]
                         : "scene" + std::to_string(k);
            groups.push_back(std::move(g));
        }
        groups[std::size_t(group_of[k])].placements.push_back(i.transform);
    }
    Scene out;
    try {
        out = flatten_keeping_bounds(rest); // glTF does not read the bounds
    } catch (const std::out_of_range& e) {
        throw ExportError(what + ": " + e.what());
    }
    // each nested prototype's parts join the result's prototypes, their materials by colour and
    // texture
    MaterialMerger merger(out);
    for (std::size_t k = 0; k < n; ++k) {
        if (group_of[k] < 0) continue;
        NestedGroup& g = groups[std::size_t(group_of[k])];
        Scene inner;
        try {
            inner = flatten_keeping_bounds(*scene.scene_prototypes[k]);
        } catch (const std::out_of_range& e) {
            throw ExportError(what + ": " + e.what());
        }
        std::vector<std::uint32_t> material(inner.materials.size());
        for (std::size_t m = 0; m < inner.materials.size(); ++m)
            material[m] = merger.add(inner, static_cast<std::uint32_t>(m));
        auto add = [&](MeshPart part, const std::string& name) {
            for (auto& p : part.primitives) {
                if (p.material >= material.size())
                    throw ExportError(what + ": " + g.name + " uses material " + std::to_string(p.material) +
                                      " but has " + std::to_string(material.size()));
                p.material = material[p.material];
            }
            out.prototypes.push_back(std::move(part));
            out.prototype_names.push_back(g.name + "/" + name);
            return static_cast<std::uint32_t>(out.prototypes.size() - 1);
        };
        if (!inner.tubes.empty()) g.parts.emplace_back(add(inner.tubes, "tubes"), glm::mat4(1.0f));
        std::vector<std::uint32_t> proto(inner.prototypes.size());
        for (std::size_t p = 0; p < inner.prototypes.size(); ++p)
            proto[p] =
                add(inner.prototypes[p], p < inner.prototype_names.size() ? inner.prototype_names[p]
                                                                          : "prototype" + std::to_string(p));
        for (const Instance& i : inner.instances) {
            if (i.prototype >= proto.size())
                throw ExportError(what + ": " + g.name + " places prototype " + std::to_string(i.prototype) +
                                  " but has " + std::to_string(proto.size()));
            g.parts.emplace_back(proto[i.prototype], i.transform);
        }
    }
    if (out.materials.empty()) out.materials.push_back(Material{});
    return out;
}

std::vector<Primitive> drawn_primitives(const MeshPart& part, const std::string& name) {
    std::vector<Primitive> prims = part.primitives;
    if (prims.empty()) prims.push_back({0, static_cast<std::uint32_t>(part.indices.size()), 0});
    for (const Primitive& p : prims)
        if (std::uint64_t(p.first) + p.count > part.indices.size() || p.first % 3 != 0 || p.count % 3 != 0)
            throw ExportError(name + " has a primitive with indices [" + std::to_string(p.first) + ", " +
                              std::to_string(std::uint64_t(p.first) + p.count) + ") that does not fit its " +
                              std::to_string(part.indices.size()) + " indices in whole triangles");
    prims.erase(std::remove_if(prims.begin(), prims.end(), [](const Primitive& p) { return p.count == 0; }),
                prims.end());
    return prims;
}

namespace {

struct Baker {
    MeshPart out;
    bool normals = false, uvs = false;
    std::map<std::uint32_t, std::vector<std::uint32_t>> by_material;
    std::vector<std::uint32_t> material_order;
    std::string what;

    void add(const MeshPart& part, const glm::mat4& m, const std::string& name) {
        check_mesh_part(part, what + ": " + name);
        const std::vector<Primitive> prims = drawn_primitives(part, what + ": " + name);
        if (prims.empty() || part.positions.empty()) return;
        const std::size_t base = out.positions.size();
        if (base + part.positions.size() > std::numeric_limits<std::uint32_t>::max())
            throw ExportError(what + ": the flattened scene has more than 2^32 vertices");
        const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
        const bool mirrored = glm::determinant(glm::mat3(m)) < 0.0f; // keep the winding outward
        for (std::size_t i = 0; i < part.positions.size(); ++i) {
            out.positions.push_back(glm::vec3(m * glm::vec4(part.positions[i], 1.0f)));
            if (normals)
                out.normals.push_back(part.normals.empty() ? glm::vec3(0.0f)
                                                           : normal_matrix * part.normals[i]);
            if (uvs) out.uvs.push_back(part.uvs.empty() ? glm::vec2(0.0f) : part.uvs[i]);
        }
        const auto b = static_cast<std::uint32_t>(base);
        for (const Primitive& p : prims) {
            auto [it, added] = by_material.try_emplace(p.material);
            if (added) material_order.push_back(p.material);
            for (std::uint32_t t = p.first; t < p.first + p.count; t += 3) {
                const std::uint32_t second = part.indices[t + (mirrored ? 2 : 1)];
                const std::uint32_t third = part.indices[t + (mirrored ? 1 : 2)];
                it->second.insert(it->second.end(), {b + part.indices[t], b + second, b + third});
            }
        }
    }
};

std::string part_name(const Scene& scene, std::uint32_t k) {
    return k < scene.prototype_names.size() && !scene.prototype_names[k].empty()
               ? scene.prototype_names[k]
               : "prototype" + std::to_string(k);
}

} // namespace

MeshPart bake(const Scene& scene, const char* what) {
    Baker baker;
    baker.what = what;
    auto uses = [&](bool (*has)(const MeshPart&)) {
        if (has(scene.tubes)) return true;
        for (const Instance& inst : scene.instances)
            if (has(scene.prototypes.at(inst.prototype))) return true;
        return false;
    };
    baker.normals = uses([](const MeshPart& p) { return !p.normals.empty() && !p.empty(); });
    baker.uvs = uses([](const MeshPart& p) { return !p.uvs.empty() && !p.empty(); });
    baker.add(scene.tubes, glm::mat4(1.0f), "tubes");
    for (const Instance& inst : scene.instances)
        baker.add(scene.prototypes.at(inst.prototype), inst.transform, part_name(scene, inst.prototype));
    std::size_t total = 0;
    for (const auto& [material, indices] : baker.by_material) total += indices.size();
    if (total > std::numeric_limits<std::uint32_t>::max())
        throw ExportError(std::string(what) + ": the flattened scene has more than 2^32 indices");
    for (std::uint32_t material : baker.material_order) {
        const std::vector<std::uint32_t>& indices = baker.by_material[material];
        baker.out.primitives.push_back(Primitive{static_cast<std::uint32_t>(baker.out.indices.size()),
                                                 static_cast<std::uint32_t>(indices.size()), material});
        baker.out.indices.insert(baker.out.indices.end(), indices.begin(), indices.end());
    }
    return std::move(baker.out);
}

} // namespace plant::detail
