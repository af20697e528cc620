// The skeleton and the mesh as numpy arrays (docs/api.md, Python): gathered into vectors while
// the GIL is released, then given to numpy, which frees them with the array.
#include "binding.hpp"

#include "plant/export.hpp"

#include <glm/glm.hpp>

#include <cmath>

namespace plant::python {

namespace {

// A numpy array owning `v` (moved to the heap; a capsule deletes it with the array).
template <class T> py::array_t<T> to_array(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
    auto* owned = new std::vector<T>(std::move(v));
    py::capsule free_it(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
    return py::array_t<T>(shape, owned->data(), free_it);
}

template <class T> py::ssize_t rows(const std::vector<T>& v, std::size_t width) {
    return static_cast<py::ssize_t>(v.size() / width);
}

py::list strings(const std::vector<std::string>& v, bool empty_is_none) {
    py::list out;
    for (const auto& s : v) {
        if (empty_is_none && s.empty())
            out.append(py::none());
        else
            out.append(py::str(s));
    }
    return out;
}

void push3(std::vector<double>& out, const glm::dvec3& v) {
    out.insert(out.end(), {v.x, v.y, v.z});
}

glm::vec3 unit_or_up(glm::vec3 n) {
    const float len = glm::length(n);
    if (!(len > 1e-20f) || !std::isfinite(len)) return {0.0f, 1.0f, 0.0f};
    return n / len;
}

// Appends `part` drawn by `m` to the mesh; its triangles belong to `group`.
void add_part(MeshData& out, const MeshPart& part, const glm::mat4& m, bool identity, std::int32_t group) {
    check_mesh_part(part, "mesh");
    const auto base = static_cast<std::uint32_t>(out.vertices.size() / 3);
    const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
    const bool mirrored = !identity && glm::determinant(glm::mat3(m)) < 0.0f; // keep the winding outward
    for (std::size_t i = 0; i < part.positions.size(); ++i) {
        glm::vec3 p = part.positions[i];
        glm::vec3 n = part.normals.empty() ? glm::vec3(0.0f, 1.0f, 0.0f) : part.normals[i];
        if (!identity) {
            p = glm::vec3(m * glm::vec4(p, 1.0f));
            n = unit_or_up(normal_matrix * n);
        }
        const glm::vec2 uv = part.uvs.empty() ? glm::vec2(0.0f) : part.uvs[i];
        out.vertices.insert(out.vertices.end(), {p.x, p.y, p.z});
        out.normals.insert(out.normals.end(), {n.x, n.y, n.z});
        out.uvs.insert(out.uvs.end(), {uv.x, uv.y});
    }
    const std::size_t first_triangle = out.group.size();
    for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3) {
        std::uint32_t a = part.indices[t], b = part.indices[t + 1], c = part.indices[t + 2];
        if (mirrored) std::swap(b, c);
        out.indices.insert(out.indices.end(), {base + a, base + b, base + c});
        out.group.push_back(group);
        out.material.push_back(0); // a part without primitives is drawn in material 0
    }
    for (const Primitive& p : part.primitives)
        for (std::uint32_t k = p.first / 3; k < (p.first + p.count) / 3; ++k)
            if (first_triangle + k < out.material.size()) out.material[first_triangle + k] = p.material;
}

} // namespace

SkeletonData skeleton_data(const Skeleton& s) {
    SkeletonData d;
    d.axis_start.push_back(0);
    for (std::size_t a = 0; a < s.axes.size(); ++a) {
        d.axis_parent.push_back(s.axes[a].parent);
        for (const SkeletonPoint& p : s.axes[a].points) {
            push3(d.positions, p.position);
            push3(d.headings, p.heading);
            push3(d.lefts, p.left);
            push3(d.ups, p.up);
            d.radii.push_back(p.radius);
            d.colors.insert(d.colors.end(), {p.color.r, p.color.g, p.color.b});
            d.ids.push_back(p.id);
            d.axis.push_back(static_cast<std::int32_t>(a));
        }
        d.axis_start.push_back(static_cast<std::int64_t>(d.radii.size()));
    }
    for (const SkeletonOrgan& o : s.organs) {
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) d.organ_transforms.push_back(o.transform[c][r]); // glm: [column][row]
        d.organ_colors.insert(d.organ_colors.end(), {o.color.r, o.color.g, o.color.b});
        d.organ_ids.push_back(o.id);
        d.organ_names.push_back(organ_label(o.shape));
    }
    return d;
}

MeshData mesh_data(const Scene& given) {
    Scene storage;
    const Scene& scene = exported_scene(given, storage, "mesh"); // placed scenes drawn out
    MeshData d;
    add_part(d, scene.tubes, glm::mat4(1.0f), true, -1);
    for (std::size_t k = 0; k < scene.instances.size(); ++k) {
        const Instance& inst = scene.instances[k];
        if (inst.prototype >= scene.prototypes.size())
            throw ExportError("mesh: an instance places no prototype");
        add_part(d, scene.prototypes[inst.prototype], inst.transform, false, static_cast<std::int32_t>(k));
        d.group_names.push_back(inst.prototype < scene.prototype_names.size()
                                    ? scene.prototype_names[inst.prototype]
                                    : "prototype " + std::to_string(inst.prototype));
    }
    for (const Material& m : scene.materials) {
        d.colors.insert(d.colors.end(), {m.color.r, m.color.g, m.color.b});
        const bool textured = m.texture >= 0 && static_cast<std::size_t>(m.texture) < scene.textures.size();
        d.textures.push_back(textured ? scene.textures[static_cast<std::size_t>(m.texture)].name : "");
    }
    for (int k = 0; k < 3; ++k) {
        d.bounds[k] = scene.bounds_min[k];
        d.bounds[3 + k] = scene.bounds_max[k];
    }
    return d;
}

py::dict skeleton_arrays(SkeletonData&& d) {
    py::dict out;
    const py::ssize_t n = rows(d.radii, 1), organs = rows(d.organ_ids, 1), axes = rows(d.axis_parent, 1);
    out["positions"] = to_array(std::move(d.positions), {n, 3});
    out["headings"] = to_array(std::move(d.headings), {n, 3});
    out["lefts"] = to_array(std::move(d.lefts), {n, 3});
    out["ups"] = to_array(std::move(d.ups), {n, 3});
    out["radii"] = to_array(std::move(d.radii), {n});
    out["colors"] = to_array(std::move(d.colors), {n, 3});
    out["ids"] = to_array(std::move(d.ids), {n});
    out["axis"] = to_array(std::move(d.axis), {n});
    out["axis_parent"] = to_array(std::move(d.axis_parent), {axes});
    out["axis_start"] = to_array(std::move(d.axis_start), {axes + 1});
    out["organ_transforms"] = to_array(std::move(d.organ_transforms), {organs, 4, 4});
    out["organ_colors"] = to_array(std::move(d.organ_colors), {organs, 3});
    out["organ_ids"] = to_array(std::move(d.organ_ids), {organs});
    out["organ_names"] = strings(d.organ_names, false);
    return out;
}

py::dict mesh_arrays(MeshData&& d) {
    py::dict out;
    const py::ssize_t v = rows(d.vertices, 3), t = rows(d.indices, 3), materials = rows(d.colors, 3);
    out["vertices"] = to_array(std::move(d.vertices), {v, 3});
    out["normals"] = to_array(std::move(d.normals), {v, 3});
    out["uvs"] = to_array(std::move(d.uvs), {v, 2});
    out["indices"] = to_array(std::move(d.indices), {t, 3});
    out["material"] = to_array(std::move(d.material), {t});
    out["group"] = to_array(std::move(d.group), {t});
    out["group_names"] = strings(d.group_names, false);
    out["colors"] = to_array(std::move(d.colors), {materials, 3});
    out["textures"] = strings(d.textures, true);
    out["bounds"] = to_array(std::vector<float>(d.bounds, d.bounds + 6), {2, 3});
    return out;
}

} // namespace plant::python
