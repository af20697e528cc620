// Wavefront OBJ and its material library: objects per organ kind, materials in the preview's
// colours (plant/export.hpp, obj_file_bytes).
#include "plant/export.hpp"

#include "geometry.hpp"
#include "texture_image.hpp"

#include <fmt/format.h>
#include <glm/glm.hpp>

#include <cctype>
#include <cmath>
#include <iterator>
#include <vector>

namespace plant {

namespace {

// A name OBJ readers take as one word.
std::string obj_name(const std::string& name, const std::string& fallback) {
    std::string out;
    for (const char c : name) out += std::isgraph(static_cast<unsigned char>(c)) ? c : '_';
    return out.empty() ? fallback : out;
}

class ObjWriter {
  public:
    explicit ObjWriter(std::string& out) : out_(out) {}

    // One placement of `part` by `m` (nullptr: as it is).
    void add(const MeshPart& part, const glm::mat4* m) {
        const glm::mat3 normal_matrix = m ? glm::transpose(glm::inverse(glm::mat3(*m))) : glm::mat3(1.0f);
        const bool mirrored = m && glm::determinant(glm::mat3(*m)) < 0.0f; // keep the winding outward
        auto it = std::back_inserter(out_);
        for (std::size_t i = 0; i < part.positions.size(); ++i) {
            const glm::vec3 p = m ? glm::vec3(*m * glm::vec4(part.positions[i], 1.0f)) : part.positions[i];
            const glm::vec2 uv = i < part.uvs.size() ? part.uvs[i] : glm::vec2(0.0f);
            const glm::vec3 n = unit_or_up(i < part.normals.size() ? normal_matrix * part.normals[i]
                                                                   : glm::vec3(0.0f, 1.0f, 0.0f));
            fmt::format_to(it, "v {} {} {}\nvt {} {}\nvn {} {} {}\n", p.x, p.y, p.z, uv.x, uv.y, n.x, n.y,
                           n.z);
        }
        auto face = [&](std::size_t first, std::size_t end, std::uint32_t material) {
            if (material != current_) {
                fmt::format_to(it, "usemtl m{}\n", material);
                current_ = material;
            }
            for (std::size_t t = first; t + 2 < end && t + 2 < part.indices.size(); t += 3) {
                std::uint32_t a = part.indices[t], b = part.indices[t + 1], c = part.indices[t + 2];
                if (a == b || b == c || a == c) continue; // no area
                if (mirrored) std::swap(b, c);
                const std::size_t ia = base_ + a + 1, ib = base_ + b + 1, ic = base_ + c + 1;
                fmt::format_to(it, "f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}\n", ia, ib, ic);
            }
        };
        if (part.primitives.empty())
            face(0, part.indices.size(), 0);
        else
            for (const Primitive& prim : part.primitives)
                face(prim.first, std::size_t(prim.first) + prim.count, prim.material);
        base_ += part.positions.size();
    }

    void object(const std::string& name) {
        fmt::format_to(std::back_inserter(out_), "o {0}\ng {0}\n", name);
        current_ = ~0u; // each object names its material again
    }

  private:
    std::string& out_;
    std::size_t base_ = 0;
    std::uint32_t current_ = ~0u;
};

} // namespace

std::string obj_file_bytes(const Scene& given, const std::string& path, const std::string& mtl_name) {
    Scene flattened;
    const Scene& scene = exported_scene(given, flattened, "OBJ export of " + path);
    check_mesh_part(scene.tubes, "OBJ export: tubes");
    for (std::size_t k = 0; k < scene.prototypes.size(); ++k)
        check_mesh_part(scene.prototypes[k], "OBJ export: prototype " + std::to_string(k));
    std::string out =
        fmt::format("# plant: {} triangles\nmtllib {}\n", scene.tubes.triangle_count(), mtl_name);
    ObjWriter w(out);
    if (!scene.tubes.empty()) {
        w.object("branches");
        w.add(scene.tubes, nullptr);
    }
    // every placement of one prototype in one object, prototypes in order
    std::vector<std::vector<const Instance*>> placed(scene.prototypes.size());
    for (const Instance& inst : scene.instances)
        if (inst.prototype < placed.size()) placed[inst.prototype].push_back(&inst);
    for (std::size_t k = 0; k < placed.size(); ++k) {
        if (placed[k].empty() || scene.prototypes[k].empty()) continue;
        const std::string fallback = "prototype" + std::to_string(k);
        w.object(obj_name(k < scene.prototype_names.size() ? scene.prototype_names[k] : "", fallback));
        for (const Instance* inst : placed[k]) w.add(scene.prototypes[k], &inst->transform);
    }
    return out;
}

std::string mtl_file_bytes(const Scene& given) {
    Scene flattened; // the materials of placed scenes join the OBJ's as they do here
    const Scene& scene = exported_scene(given, flattened, "OBJ materials");
    std::string out = "# plant: the preview's colours, linear RGB\n";
    const std::vector<glm::vec3> colors = detail::flat_colors(scene);
    for (std::size_t m = 0; m < colors.size(); ++m)
        fmt::format_to(std::back_inserter(out),
                       "newmtl m{}\nKd {:.4f} {:.4f} {:.4f}\nKa 0 0 0\nKs 0 0 0\nillum 1\n", m, colors[m].r,
                       colors[m].g, colors[m].b);
    return out;
}

} // namespace plant
