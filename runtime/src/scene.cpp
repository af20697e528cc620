// The scene: tubes of all axes grouped by material, organ prototypes meshed once per shape and
// color, one instance per placement.
#include "plant/mesh.hpp"

#include "plant/export.hpp"

#include "bounds.hpp"
#include "mesh_file.hpp"
#include "openmesh.hpp"
#include "scene_build.hpp"

#include <fmt/format.h>
#include <sys/mman.h>

#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

namespace plant {

namespace {

// Grows [lo, hi] by every point of `scene` drawn with `placed` (placed scenes too, as flatten
// would draw them, without copying them).
void grow_bounds(const Scene& scene, const glm::mat4* placed, glm::vec3& lo, glm::vec3& hi) {
    auto add = [&](const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    };
    if (placed) {
        for (const auto& p : scene.tubes.positions) add(glm::vec3(*placed * glm::vec4(p, 1.0f)));
    } else {
        // the tubes of a whole tree: the same comparisons as glm::min and glm::max (a NaN
        // coordinate leaves the bound as it was), many points at a time
        grow_point_bounds(scene.tubes.positions.data(), scene.tubes.positions.size(), lo, hi);
    }
    for (const auto& inst : scene.instances) {
        const MeshPart& proto = scene.prototypes[inst.prototype];
        const glm::mat4 m = placed ? *placed * inst.transform : inst.transform;
        for (const auto& p : proto.positions) add(glm::vec3(m * glm::vec4(p, 1.0f)));
    }
    for (const auto& inst : scene.scene_instances) {
        if (inst.prototype >= scene.scene_prototypes.size() || !scene.scene_prototypes[inst.prototype])
            throw std::out_of_range("a placement of scene prototype " + std::to_string(inst.prototype) +
                                    " but the scene has " + std::to_string(scene.scene_prototypes.size()));
        const glm::mat4 m = placed ? *placed * inst.transform : inst.transform;
        grow_bounds(*scene.scene_prototypes[inst.prototype], &m, lo, hi);
    }
}

} // namespace

namespace {

DrawnSize drawn_size(const Scene& scene, std::map<const Scene*, DrawnSize>& memo) {
    DrawnSize n{double(scene.tubes.positions.size()), double(scene.tubes.triangle_count()), 0};
    for (const Instance& inst : scene.instances) {
        if (inst.prototype >= scene.prototypes.size()) continue;
        n.vertices += double(scene.prototypes[inst.prototype].positions.size());
        n.triangles += double(scene.prototypes[inst.prototype].triangle_count());
        n.placements += 1;
    }
    for (const Instance& inst : scene.scene_instances) {
        if (inst.prototype >= scene.scene_prototypes.size() || !scene.scene_prototypes[inst.prototype])
            continue;
        const Scene* p = scene.scene_prototypes[inst.prototype].get();
        auto it = memo.find(p);
        if (it == memo.end()) it = memo.emplace(p, drawn_size(*p, memo)).first;
        n.vertices += it->second.vertices;
        n.triangles += it->second.triangles;
        n.placements += it->second.placements + (p->tubes.empty() ? 0 : 1);
    }
    return n;
}

} // namespace

DrawnSize drawn_size(const Scene& scene) {
    std::map<const Scene*, DrawnSize> memo;
    return drawn_size(scene, memo);
}

void Scene::update_bounds() {
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    grow_bounds(*this, nullptr, lo, hi);
    if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
    bounds_min = lo;
    bounds_max = hi;
}

namespace {

const std::string* texture_key(const Scene& s, int texture) {
    return texture >= 0 && static_cast<std::size_t>(texture) < s.textures.size()
               ? s.textures[static_cast<std::size_t>(texture)].bytes.get()
               : nullptr;
}

} // namespace

MaterialMerger::MaterialMerger(Scene& out) : out_(out) {
    for (std::uint32_t m = static_cast<std::uint32_t>(out.materials.size()); m-- > 0;) {
        const Material& mat = out.materials[m];
        // the first material of each colour and texture
        index_[{mat.color.x, mat.color.y, mat.color.z, texture_key(out, mat.texture)}] = m;
    }
}

std::uint32_t MaterialMerger::add(const Scene& from, std::uint32_t m) {
    const Material& mat = from.materials.at(m);
    const std::string* bytes = texture_key(from, mat.texture);
    return add(mat, bytes ? &from.textures[static_cast<std::size_t>(mat.texture)] : nullptr);
}

std::uint32_t MaterialMerger::add(const Material& material, const Texture* texture) {
    const glm::vec3& c = material.color;
    const std::string* bytes = texture ? texture->bytes.get() : nullptr;
    auto [it, added] =
        index_.emplace(std::tuple{c.x, c.y, c.z, bytes}, static_cast<std::uint32_t>(out_.materials.size()));
    if (!added) return it->second;
    Material made{c, -1};
    if (bytes) {
        for (std::size_t t = 0; t < out_.textures.size() && made.texture < 0; ++t)
            if (out_.textures[t].bytes.get() == bytes) made.texture = static_cast<int>(t);
        if (made.texture < 0) {
            made.texture = static_cast<int>(out_.textures.size());
            out_.textures.push_back(*texture);
        }
    }
    out_.materials.push_back(made);
    return it->second;
}

Scene flatten(const Scene& scene) {
    if (!scene.nested()) return scene;
    Scene out = flatten_keeping_bounds(scene);
    out.update_bounds();
    return out;
}

Scene flatten_keeping_bounds(const Scene& scene) {
    if (!scene.nested()) return scene;
    Scene out;
    out.tubes = scene.tubes;
    out.prototypes = scene.prototypes;
    out.prototype_names = scene.prototype_names;
    out.instances = scene.instances;
    out.materials = scene.materials;
    out.textures = scene.textures;
    MaterialMerger merger(out);
    // per scene prototype, once placed: the result's prototype of its tubes (or none) and of each
    // of its own prototypes, and its instances in its own frame
    struct Drawn {
        int tubes = -1;
        std::vector<Instance> instances;
    };
    std::vector<std::optional<Drawn>> drawn(scene.scene_prototypes.size());
    for (const Instance& placement : scene.scene_instances) {
        const std::size_t k = placement.prototype;
        if (k >= scene.scene_prototypes.size() || !scene.scene_prototypes[k])
            throw std::out_of_range("a placement of scene prototype " + std::to_string(k) +
                                    " but the scene has " + std::to_string(scene.scene_prototypes.size()));
        if (!drawn[k]) {
            const Scene inner = flatten_keeping_bounds(*scene.scene_prototypes[k]); // its parts only
            const std::string name =
                k < scene.scene_prototype_names.size() && !scene.scene_prototype_names[k].empty()
                    ? scene.scene_prototype_names[k]
                    : "scene" + std::to_string(k);
            std::vector<std::uint32_t> material(inner.materials.size());
            for (std::size_t m = 0; m < inner.materials.size(); ++m)
                material[m] = merger.add(inner, static_cast<std::uint32_t>(m));
            auto add = [&](MeshPart part, const std::string& part_name) {
                for (auto& p : part.primitives) p.material = material.at(p.material);
                out.prototypes.push_back(std::move(part));
                out.prototype_names.push_back(name + "/" + part_name);
                return static_cast<std::uint32_t>(out.prototypes.size() - 1);
            };
            Drawn d;
            if (!inner.tubes.empty()) d.tubes = static_cast<int>(add(inner.tubes, "tubes"));
            std::vector<std::uint32_t> proto(inner.prototypes.size());
            for (std::size_t p = 0; p < inner.prototypes.size(); ++p)
                proto[p] = add(inner.prototypes[p], p < inner.prototype_names.size()
                                                        ? inner.prototype_names[p]
                                                        : "prototype" + std::to_string(p));
            for (const Instance& i : inner.instances)
                d.instances.push_back(Instance{proto.at(i.prototype), i.transform});
            drawn[k] = std::move(d);
        }
        const Drawn& d = *drawn[k];
        if (d.tubes >= 0)
            out.instances.push_back(Instance{static_cast<std::uint32_t>(d.tubes), placement.transform});
        for (const Instance& i : d.instances)
            out.instances.push_back(Instance{i.prototype, placement.transform * i.transform});
    }
    if (out.materials.empty()) out.materials.push_back(Material{});
    out.bounds_min = scene.bounds_min;
    out.bounds_max = scene.bounds_max;
    return out;
}

namespace {

// A flat polygon, fanned from its first corner, with a front and a back face.
MeshPart polygon_prototype(const SurfaceDef& s) {
    MeshPart m;
    std::vector<glm::vec3> pts;
    for (const auto& p : s.points) pts.emplace_back(p[0], p[1], p[2]);
    glm::vec3 n(0.0f);
    for (std::size_t i = 1; i + 1 < pts.size(); ++i) n += glm::cross(pts[i] - pts[0], pts[i + 1] - pts[0]);
    n = glm::length(n) > 1e-12f ? glm::normalize(n) : glm::vec3(0, 0, 1);
    glm::vec3 lo = pts[0], hi = pts[0];
    for (const auto& p : pts) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    glm::vec3 ext = glm::max(hi - lo, glm::vec3(1e-6f));
    for (int side = 0; side < 2; ++side) {
        auto base = static_cast<std::uint32_t>(m.positions.size());
        for (const auto& p : pts) {
            m.positions.push_back(p);
            m.normals.push_back(side == 0 ? n : -n);
            m.uvs.emplace_back((p.x - lo.x) / ext.x, (p.y - lo.y) / ext.y);
        }
        for (std::uint32_t i = 1; i + 1 < pts.size(); ++i) {
            if (side == 0)
                m.indices.insert(m.indices.end(), {base, base + i, base + i + 1});
            else
                m.indices.insert(m.indices.end(), {base, base + i + 1, base + i});
        }
    }
    m.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(m.indices.size()), 0});
    return m;
}

MeshPart sphere_prototype() {
    MeshPart m;
    const int slices = 12, stacks = 8;
    const double pi = std::numbers::pi;
    for (int i = 0; i <= stacks; ++i) {
        double v = double(i) / stacks, th = v * pi;
        for (int j = 0; j <= slices; ++j) {
            double u = double(j) / slices, ph = u * 2 * pi;
            glm::vec3 p(static_cast<float>(std::sin(th) * std::cos(ph)), static_cast<float>(std::cos(th)),
                        static_cast<float>(std::sin(th) * std::sin(ph)));
            m.positions.push_back(p);
            m.normals.push_back(p);
            m.uvs.emplace_back(static_cast<float>(u), static_cast<float>(v));
        }
    }
    for (int i = 0; i < stacks; ++i) {
        for (int j = 0; j < slices; ++j) {
            auto a = static_cast<std::uint32_t>(i * (slices + 1) + j), b = a + 1, d = a + slices + 1,
                 c = d + 1;
            // counter-clockwise seen from outside; the pole rows would be degenerate
            if (i != 0) m.indices.insert(m.indices.end(), {a, b, d});
            if (i != stacks - 1) m.indices.insert(m.indices.end(), {b, c, d});
        }
    }
    m.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(m.indices.size()), 0});
    return m;
}

MeshPart loaded_prototype(const SurfaceDef& s) {
    OpenMeshTriangles mesh;
    mesh.request_vertex_normals();
    mesh.request_face_normals();
    OpenMesh::IO::Options opt;
    std::string why;
    switch (read_mesh_file(s.path, mesh, opt, why)) { // failures are reported as our own diagnostics
    case MeshRead::Ok:
        break;
    case MeshRead::Failed:
        throw RuntimeError(RuntimeErrorKind::Geometry, s.span,
                           fmt::format("cannot load surface '{}' from '{}'", s.name, s.path));
    case MeshRead::Refused:
        throw RuntimeError(RuntimeErrorKind::Input, s.span,
                           fmt::format("surface '{}': cannot read mesh file '{}': {}", s.name, s.path, why));
    }
    mesh.triangulate();
    mesh.update_normals();
    MeshPart m;
    for (auto v : mesh.vertices()) {
        auto p = mesh.point(v);
        auto n = mesh.normal(v);
        m.positions.emplace_back(p[0], p[1], p[2]);
        glm::vec3 nn(n[0], n[1], n[2]);
        m.normals.push_back(glm::length(nn) > 1e-12f ? glm::normalize(nn) : glm::vec3(0, 0, 1));
        m.uvs.emplace_back(0.0f, 0.0f);
    }
    for (auto f : mesh.faces())
        for (auto v : mesh.fv_range(f)) m.indices.push_back(static_cast<std::uint32_t>(v.idx()));
    if (m.indices.empty())
        throw RuntimeError(RuntimeErrorKind::Geometry, s.span,
                           fmt::format("surface '{}' loaded from '{}' has no faces", s.name, s.path));
    m.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(m.indices.size()), 0});
    return m;
}

// The mesh of an organ's shape, in its own frame.
MeshPart organ_mesh(const Program& program, const OrganShape& shape) {
    switch (shape.kind) {
    case OrganKind::Sphere:
        return sphere_prototype();
    case OrganKind::Surface:
        for (auto it = program.surfaces.rbegin(); it != program.surfaces.rend(); ++it)
            if (it->name == shape.name)
                return it->kind == SurfaceKind::Load ? loaded_prototype(*it) : polygon_prototype(*it);
        throw RuntimeError(RuntimeErrorKind::Geometry, Span{},
                           fmt::format("'~{}' places a surface that is not declared: add "
                                       "'surface {} = polygon(...);'",
                                       shape.name, shape.name));
    case OrganKind::Instance:
        break;
    }
    throw RuntimeError(RuntimeErrorKind::Geometry, Span{},
                       fmt::format("instance '{}' cannot be meshed as an organ: its prototype is a "
                                   "scene (Scene::scene_prototypes)",
                                   shape.name));
}

} // namespace

void check_surface_files(const Program& program) {
    std::set<std::string> read; // a body sees the surfaces around it: each file is read once
    auto check = [&read](const Program& p) {
        for (const SurfaceDef& s : p.surfaces)
            if (s.kind == SurfaceKind::Load && read.insert(s.path).second) (void)loaded_prototype(s);
    };
    check(program);
    if (program.instances)
        for (const InstanceDef& instance : *program.instances)
            if (instance.program) check(*instance.program);
}

namespace {

// Maps the whole pages of a vector's reserved storage in one call (MADV_POPULATE_WRITE, Linux
// 5.14; a no-op before), instead of one page fault per 4 KiB as the mesh is written: on a tree of
// 260,000 triangles, 2,600 faults whose entry and exit cost more than clearing the pages. Only for
// storage that will be written (nearly) whole.
template <typename T> void populate(const std::vector<T>& v) {
#ifdef MADV_POPULATE_WRITE
    constexpr std::uintptr_t page = 4096;
    const auto b = (reinterpret_cast<std::uintptr_t>(v.data()) + page - 1) / page * page;
    const auto e = reinterpret_cast<std::uintptr_t>(v.data() + v.capacity()) / page * page;
    if (e > b + 16 * page) ::madvise(reinterpret_cast<void*>(b), e - b, MADV_POPULATE_WRITE);
#else
    (void)v;
#endif
}

// Whether every point of the skeleton has the first one's colour and texture: then the tubes
// have one material, and its index list is the whole index array.
bool one_material(const Skeleton& skeleton) {
    const SkeletonPoint* first = nullptr;
    for (const auto& axis : skeleton.axes)
        for (const auto& p : axis.points) {
            if (!first) first = &p;
            if (p.color != first->color || p.texture != first->texture) return false;
        }
    return true;
}

} // namespace

namespace detail {

Scene mesh_skeleton(const Program& program, const Skeleton& skeleton, const MeshOptions& options) {
    Scene scene;
    for (const TextureDef& t : program.textures)
        scene.textures.push_back(Texture{t.name, t.mime_type, t.bytes});
    // one material per colour and texture
    std::map<std::tuple<float, float, float, int>, std::uint32_t> material_index;
    auto material_of = [&](const glm::vec3& c, int texture) -> std::uint32_t {
        std::tuple<float, float, float, int> key{c.x, c.y, c.z, texture};
        auto it = material_index.find(key);
        if (it != material_index.end()) return it->second;
        auto id = static_cast<std::uint32_t>(scene.materials.size());
        scene.materials.push_back(Material{c, texture});
        material_index.emplace(key, id);
        return id;
    };
    std::vector<std::vector<std::uint32_t>> by_material;
    const std::vector<TubePath> tubes = tube_paths(skeleton, options);
    {
        // sized from the counts: a ring a point (sharp joints add a few more), 6 indices a side
        // between two rings; the first material's list is sized for every triangle, since most
        // plants have one colour of bark (pages never written are never touched)
        std::size_t points = 0, segments = 0;
        for (const auto& t : tubes) {
            points += t.size();
            segments += t.empty() ? 0 : t.size() - 1;
        }
        const auto sides = static_cast<std::size_t>(std::max(3, options.sides));
        const std::size_t vertices = points * (sides + 1);
        scene.tubes.positions.reserve(vertices);
        scene.tubes.normals.reserve(vertices);
        scene.tubes.uvs.reserve(vertices);
        by_material.emplace_back().reserve(segments * 6 * sides);
        populate(scene.tubes.positions);
        populate(scene.tubes.normals);
        populate(scene.tubes.uvs);
        if (one_material(skeleton)) populate(by_material[0]);
    }
    for (const auto& t : tubes) mesh_tube(t, options, scene.tubes, by_material, material_of);
    std::size_t used = 0;
    for (const auto& list : by_material) used += list.empty() ? 0 : 1;
    for (std::uint32_t m = 0; m < by_material.size(); ++m) {
        if (by_material[m].empty()) continue;
        auto first = static_cast<std::uint32_t>(scene.tubes.indices.size());
        const auto count = static_cast<std::uint32_t>(by_material[m].size());
        // one material: its list becomes the index array, not copied, unless it outgrew the
        // estimate (sharp joints) and holds much more memory than it uses
        if (used == 1 && by_material[m].capacity() <= count + count / 8)
            scene.tubes.indices = std::move(by_material[m]);
        else
            scene.tubes.indices.insert(scene.tubes.indices.end(), by_material[m].begin(),
                                       by_material[m].end());
        scene.tubes.primitives.push_back(Primitive{first, count, m});
    }
    // organs: one prototype per (shape, color), meshed once
    std::map<std::pair<OrganShape, std::uint32_t>, std::uint32_t> prototype_index;
    std::map<OrganShape, MeshPart> shapes;
    for (const auto& organ : skeleton.organs) {
        if (organ.shape.kind == OrganKind::Instance) continue; // placed by build_scene (instances.cpp)
        std::uint32_t material = material_of(organ.color, organ.texture);
        auto key = std::pair{organ.shape, material};
        auto it = prototype_index.find(key);
        if (it == prototype_index.end()) {
            auto sit = shapes.find(organ.shape);
            if (sit == shapes.end())
                sit = shapes.emplace(organ.shape, organ_mesh(program, organ.shape)).first;
            MeshPart proto = sit->second;
            for (auto& p : proto.primitives) p.material = material;
            it = prototype_index.emplace(key, static_cast<std::uint32_t>(scene.prototypes.size())).first;
            scene.prototypes.push_back(std::move(proto));
            scene.prototype_names.push_back(organ_label(organ.shape));
        }
        scene.instances.push_back(Instance{it->second, glm::mat4(organ.transform)});
    }
    if (scene.materials.empty()) scene.materials.push_back(Material{});
    return scene;
}

void check_single_precision(const Scene& scene) {
    // meshes are single precision: a plant beyond its range cannot be meshed
    for (float v : {scene.bounds_min.x, scene.bounds_min.y, scene.bounds_min.z, scene.bounds_max.x,
                    scene.bounds_max.y, scene.bounds_max.z})
        if (!std::isfinite(v))
            throw RuntimeError(RuntimeErrorKind::Geometry, Span{},
                               "the plant reaches coordinates beyond the range of single-precision numbers "
                               "(about 3e38) and cannot be meshed");
}

} // namespace detail

} // namespace plant
