// .obj, .ply and .off export through OpenMesh: the tubes and every placed prototype flattened into
// one triangle mesh with vertex normals (and texture coordinates for .obj and .ply).
#include "geometry.hpp"
#include "plant/export.hpp"

#include "openmesh.hpp"
#include "texture_image.hpp"

#include <glm/glm.hpp>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <system_error>
#include <unistd.h>

namespace plant {

namespace {

namespace fs = std::filesystem;
using Mesh = OpenMeshTriangles;

std::string quoted(const std::string& s) {
    return "'" + s + "'";
}

class Flattener {
  public:
    explicit Flattener(Mesh& mesh) : mesh_(mesh) {}

    // Per material, the colour PLY vertices carry (detail::flat_colors); empty: no colours.
    std::vector<glm::vec3> colors;

    void add(const MeshPart& part, const glm::mat4& m, bool identity, const std::string& name) {
        const std::size_t nv = part.positions.size();
        check_mesh_part(part, "mesh export: " + name);
        if (part.indices.empty()) return;

        const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
        const bool mirrored = glm::determinant(glm::mat3(m)) < 0.0f; // keep the winding outward

        color_.assign(nv, glm::vec3(Material{}.color));
        if (!colors.empty()) // a vertex takes the colour of the last primitive that uses it
            for (const Primitive& prim : part.primitives)
                for (std::size_t t = prim.first;
                     t < std::size_t(prim.first) + prim.count && t < part.indices.size(); ++t)
                    if (part.indices[t] < nv)
                        color_[part.indices[t]] = colors[prim.material < colors.size() ? prim.material : 0];
        std::vector<Mesh::VertexHandle> handle(nv);
        for (std::uint32_t i = 0; i < nv; ++i) handle[i] = new_vertex(part, m, normal_matrix, identity, i);

        for (std::size_t t = 0; t + 2 < part.indices.size(); t += 3) {
            std::uint32_t a = part.indices[t], b = part.indices[t + 1], c = part.indices[t + 2];
            if (a == b || b == c || a == c) continue; // no area, and OpenMesh refuses it
            if (mirrored) std::swap(b, c);
            if (!mesh_.add_face(handle[a], handle[b], handle[c]).is_valid()) {
                // A non-manifold configuration (a complex edge or vertex) that the half-edge
                // structure cannot hold: give this triangle vertices of its own.
                const auto va = new_vertex(part, m, normal_matrix, identity, a);
                const auto vb = new_vertex(part, m, normal_matrix, identity, b);
                const auto vc = new_vertex(part, m, normal_matrix, identity, c);
                mesh_.add_face(va, vb, vc);
            }
        }
    }

  private:
    Mesh::VertexHandle new_vertex(const MeshPart& part, const glm::mat4& m, const glm::mat3& nm,
                                  bool identity, std::uint32_t i) {
        glm::vec3 p = part.positions[i];
        if (!identity) p = glm::vec3(m * glm::vec4(p, 1.0f));
        const auto vh = mesh_.add_vertex(Mesh::Point(p.x, p.y, p.z));
        glm::vec3 n = part.normals.empty() ? glm::vec3(0.0f, 1.0f, 0.0f) : part.normals[i];
        n = unit_or_up(identity ? n : nm * n);
        mesh_.set_normal(vh, Mesh::Normal(n.x, n.y, n.z));
        const glm::vec2 uv = part.uvs.empty() ? glm::vec2(0.0f) : part.uvs[i];
        mesh_.set_texcoord2D(vh, Mesh::TexCoord2D(uv.x, uv.y));
        if (!colors.empty()) {
            const glm::vec3 c = glm::clamp(color_[i], 0.0f, 1.0f) * 255.0f + 0.5f;
            mesh_.set_color(vh, Mesh::Color(static_cast<unsigned char>(c.r), static_cast<unsigned char>(c.g),
                                            static_cast<unsigned char>(c.b)));
        }
        return vh;
    }

    Mesh& mesh_;
    std::vector<glm::vec3> color_; // per vertex of the part being added
};

} // namespace

void write_mesh_stream(const Scene& given, MeshFileFormat format, const std::string& path,
                       std::ostream& out) {
    // OpenMesh picks its writer by an extension, whatever the file is called
    static constexpr const char* kOpenMeshExtension[] = {".obj", ".ply", ".off"};
    const std::string ext = kOpenMeshExtension[static_cast<int>(format)];
    quiet_openmesh();
    Scene flattened;
    const Scene& scene = exported_scene(given, flattened, "mesh export");
    const bool ply = format == MeshFileFormat::Ply;

    Mesh mesh;
    mesh.request_vertex_normals();
    mesh.request_vertex_texcoords2D();
    if (ply) mesh.request_vertex_colors();
    {
        std::size_t nv = scene.tubes.positions.size(), nf = scene.tubes.triangle_count();
        for (const Instance& inst : scene.instances) {
            nv += scene.prototypes[inst.prototype].positions.size();
            nf += scene.prototypes[inst.prototype].triangle_count();
        }
        mesh.reserve(nv, nv + nf, nf); // edges: about V + F for a triangle mesh
    }

    Flattener flat(mesh);
    if (ply) flat.colors = detail::flat_colors(scene);
    flat.add(scene.tubes, glm::mat4(1.0f), true, "tubes");
    for (const Instance& inst : scene.instances) {
        const std::size_t k = inst.prototype;
        const std::string name = k < scene.prototype_names.size() && !scene.prototype_names[k].empty()
                                     ? scene.prototype_names[k]
                                     : "prototype " + std::to_string(k);
        flat.add(scene.prototypes[k], inst.transform, false, name);
    }

    OpenMesh::IO::Options options(OpenMesh::IO::Options::VertexNormal);
    // OFF stays plain NOFF: few readers understand texture coordinates in OFF files.
    if (format != MeshFileFormat::Off) options += OpenMesh::IO::Options::VertexTexCoord;
    if (ply) options += OpenMesh::IO::Options::VertexColor;

    if (!OpenMesh::IO::write_mesh(mesh, out, ext, options, 7))
        throw ExportError("cannot write " + quoted(path) + ": OpenMesh failed to write the " + ext.substr(1) +
                          " file");
    // OpenMesh reports success whatever the stream did: a stream that could not take everything
    // (out of memory, a full disk) is a failed write, not a shorter file
    if (!out.flush())
        throw ExportError("cannot write " + quoted(path) + ": the " + ext.substr(1) +
                          " file could not be written in full (out of memory?)");
}

std::string mesh_file_bytes(const Scene& scene, MeshFileFormat format, const std::string& path) {
    std::ostringstream out(std::ios::out | std::ios::binary);
    write_mesh_stream(scene, format, path, out);
    return std::move(out).str();
}

void write_mesh_file(const Scene& scene, const std::string& path, MeshFileFormat format) {
    write_file_atomically(path, mesh_file_bytes(scene, format, path));
}

} // namespace plant
