#include "outputs.hpp"
#include "pending_files.hpp"
#include "run_progress.hpp"

#include "plant/diagnostics.hpp"
#include "plant/environment.hpp"

#include "plant/export.hpp"
#include "plant/export_text.hpp"
#include "plant/memory_budget.hpp"
#include "plant/mesh.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <set>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

// The names of the textures the scene's materials use, its scene prototypes' included.
void used_textures(const Scene& s, std::set<std::string>& names, std::set<const Scene*>& seen) {
    if (!seen.insert(&s).second) return;
    for (const Material& m : s.materials)
        if (m.texture >= 0 && static_cast<std::size_t>(m.texture) < s.textures.size())
            names.insert(s.textures[static_cast<std::size_t>(m.texture)].name);
    for (const auto& p : s.scene_prototypes)
        if (p) used_textures(*p, names, seen);
}

// Counts and bounds of the meshed scene in a fixed format, for golden files; a line naming the
// textures used, when there are any.
std::string mesh_summary(const Scene& s) {
    std::size_t vertices = s.tubes.positions.size(), triangles = s.tubes.triangle_count();
    for (const auto& p : s.prototypes) {
        vertices += p.positions.size();
        triangles += p.triangle_count();
    }
    std::string out = fmt::format(
        "vertices {}\ntriangles {}\nprototypes {}\ninstances {}\nbounds {:.4f} {:.4f} {:.4f} {:.4f} "
        "{:.4f} {:.4f}\n",
        vertices, triangles, s.prototypes.size(), s.instances.size(), s.bounds_min.x, s.bounds_min.y,
        s.bounds_min.z, s.bounds_max.x, s.bounds_max.y, s.bounds_max.z);
    std::set<std::string> textures;
    std::set<const Scene*> seen;
    used_textures(s, textures, seen);
    if (!textures.empty()) out += fmt::format("textures {}\n", fmt::join(textures, " "));
    return out + scene_prototype_summary(s); // nothing without instances
}

std::string glb_bytes(const OutputSources& from, const std::string& target) {
    return gltf_bytes(from.scene, GltfContainer::Binary, target, from.options.gltf_layout);
}
void glb_stream(const OutputSources& from, const std::string& target, const ByteSink& sink) {
    gltf_to(from.scene, GltfContainer::Binary, target, from.options.gltf_layout, sink);
}
std::string gltf_json_bytes(const OutputSources& from, const std::string& target) {
    return gltf_bytes(from.scene, GltfContainer::Json, target, from.options.gltf_layout);
}
std::string obj_bytes(const OutputSources& from, const std::string& target) {
    return obj_file_bytes(from.scene, target, fs::path(sidecar_path(target, ".mtl")).filename().string());
}
std::string mtl_sidecar_bytes(const OutputSources& from, const std::string&) {
    return mtl_file_bytes(from.scene);
}
std::string ply_bytes(const OutputSources& from, const std::string& target) {
    return mesh_file_bytes(from.scene, MeshFileFormat::Ply, target);
}
std::string off_bytes(const OutputSources& from, const std::string& target) {
    return mesh_file_bytes(from.scene, MeshFileFormat::Off, target);
}
// What drawn widths are multiplied by: --width-scale, else the grammar's `width_scale`.
double width_scale_of(const OutputOptions& options, const Derivation& d) {
    return options.width_scale.value_or(d.width_scale());
}

std::string scene_png_bytes(const OutputSources& from, const std::string& target) {
    PngOptions po;
    if (from.options.camera) po.camera = PngView{*from.options.camera, from.options.look_at};
    po.view = from.options.view;
    po.skeleton = &from.skeleton;
    po.lines = from.options.lines;
    po.min_line_px = from.options.min_line_px;
    po.width_scale = width_scale_of(from.options, from.derivation);
    return png_bytes(from.scene, from.options.width, from.options.height, target, po);
}
std::string skeleton_svg_bytes(const OutputSources& from, const std::string&) {
    SvgOptions so;
    if (from.options.size_given) {
        so.width = from.options.width;
        so.height = from.options.height;
    }
    return skeleton_svg(from.skeleton, so);
}
std::string skeleton_json_bytes(const OutputSources& from, const std::string&) {
    return skeleton_json(from.skeleton, &from.scene); // the scene lists instances' prototypes
}
std::string string_text_bytes(const OutputSources& from, const std::string&) {
    return format_string(from.program, from.derivation.string()) + "\n";
}
std::string mesh_summary_bytes(const OutputSources& from, const std::string&) {
    return mesh_summary(from.scene);
}

// Adding a format: one row here and its writer above (docs: README.md lists the extensions).
constexpr OutputFormat kFormats[] = {
    {".glb", OutputNeeds::Scene, glb_bytes,
     "glTF 2.0, binary; each organ or instance is one mesh, placed by EXT_mesh_gpu_instancing", nullptr,
     nullptr, glb_stream},
    {".gltf", OutputNeeds::Scene, gltf_json_bytes, "glTF 2.0 as JSON, the buffer embedded as a data URI"},
    {".obj", OutputNeeds::Scene, obj_bytes,
     "Wavefront OBJ, one object per organ kind, with its colours in a .mtl file beside it", ".mtl",
     mtl_sidecar_bytes},
    {".ply", OutputNeeds::Scene, ply_bytes, "PLY, everything in one triangle mesh, with vertex colours"},
    {".off", OutputNeeds::Scene, off_bytes, "OFF, everything in one triangle mesh"},
    {".png", OutputNeeds::Scene, scene_png_bytes,
     "a shaded preview (--view, --camera, --lines), --size pixels"},
    {".svg", OutputNeeds::Skeleton, skeleton_svg_bytes,
     "a line drawing of the XY plane, for 2D grammars (--size fits it in WxH)"},
    {".txt", OutputNeeds::String, string_text_bytes, "the derived string, as plant derive prints it"},
    {".skel.json", OutputNeeds::Skeleton, skeleton_json_bytes,
     "the skeleton, what the turtle drew before meshing (docs/skeleton.md)"},
    {".mesh.txt", OutputNeeds::Scene, mesh_summary_bytes,
     "counts and bounds of the meshed scene, for golden files"},
};

} // namespace

std::span<const OutputFormat> output_formats() {
    return kFormats;
}

const OutputFormat* format_of(const std::string& given) {
    std::string path = given;
    std::transform(path.begin(), path.end(), path.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    const OutputFormat* best = nullptr;
    for (const auto& f : kFormats) {
        const std::string_view e = f.extension;
        if (path.size() > e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0 &&
            (!best || e.size() > std::string_view(best->extension).size()))
            best = &f;
    }
    return best;
}

std::string known_extensions() {
    std::string out;
    for (std::size_t k = 0; k < std::size(kFormats); ++k)
        out += (k == 0                         ? ""
                : k + 1 == std::size(kFormats) ? " or "
                                               : " ") +
               std::string(kFormats[k].extension);
    return out;
}

std::string sidecar_path(const std::string& target, const std::string& extension) {
    return fs::path(target).replace_extension(extension).string();
}

std::optional<PngViewKind> parse_view(const std::string& text) {
    static constexpr std::pair<const char*, PngViewKind> kViews[] = {{"auto", PngViewKind::Auto},
                                                                     {"front", PngViewKind::Front},
                                                                     {"top", PngViewKind::Top},
                                                                     {"side", PngViewKind::Side},
                                                                     {"iso", PngViewKind::Iso}};
    for (const auto& [name, kind] : kViews)
        if (text == name) return kind;
    return std::nullopt;
}

std::uint64_t default_max_memory() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
    if (pages <= 0 || page <= 0) return std::uint64_t(4) << 30;
    return std::uint64_t(pages) * std::uint64_t(page) / 2;
}

std::optional<glm::dvec3> parse_point(const std::string& text) {
    glm::dvec3 p(0.0);
    const char* s = text.c_str();
    for (int k = 0; k < 3; ++k) {
        char* end = nullptr;
        p[k] = std::strtod(s, &end);
        if (end == s || !std::isfinite(p[k])) return std::nullopt;
        while (*end == ' ') ++end;
        if (k < 2 && *end++ != ',') return std::nullopt;
        s = end;
    }
    if (*s != '\0') return std::nullopt;
    return p;
}

std::uint64_t parse_memory(const std::string& text) {
    // digits, an optional fraction and an optional unit: no sign, exponent, hexadecimal, "inf"
    std::size_t k = 0;
    while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
    if (k == 0) return 0;
    if (k < text.size() && text[k] == '.') {
        const std::size_t f = ++k;
        while (k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]))) ++k;
        if (k == f) return 0;
    }
    if (k > 30) return 0;
    const double v = std::strtod(text.substr(0, k).c_str(), nullptr);
    const std::string unit = text.substr(k);
    double scale = 1;
    if (unit == "K" || unit == "k")
        scale = 1024.0;
    else if (unit == "M" || unit == "m")
        scale = 1024.0 * 1024;
    else if (unit == "G" || unit == "g")
        scale = 1024.0 * 1024 * 1024;
    else if (!unit.empty())
        return 0;
    const double bytes = v * scale;
    return bytes >= double(kMinMaxMemory) && bytes < 1.8e19 ? static_cast<std::uint64_t>(bytes) : 0;
}

std::string memory_usage_error(const std::string& text) {
    return fmt::format("--max-memory expects a size such as 512M or 4G, found '{}': digits and the unit "
                       "K, M or G, at least 1M",
                       escape_controls(text));
}

// Before meshing: every skeleton point becomes a ring of sides + 1 vertices (position, normal,
// texture coordinate: 32 bytes) and 2 * sides triangles (12 bytes each); the scene, its export
// copy and the exporter's own buffers hold it about three times over. The scene's two copies are
// charged against --max-memory for as long as the scene lives (`scene_memory`), the third by each
// file as it is written (the bytes returned). Stops with a Memory error naming --max-memory when
// the budget does not have room for all three beside what the run holds already.
static double reserve_mesh_memory(const Skeleton& skeleton, const OutputOptions& options,
                                  memory::Reservation& scene_memory) {
    std::uint64_t points = 0;
    for (const auto& a : skeleton.axes) points += a.points.size();
    const std::uint64_t sides = static_cast<std::uint64_t>(std::max(options.sides, 3));
    const double copy =
        double(points) * double((sides + 1) * 32 + 2 * sides * 12) + 256.0 * double(skeleton.organs.size());
    const double budget = double(memory::limit()      ? memory::limit()
                                 : options.max_memory ? options.max_memory
                                                      : default_max_memory());
    const double held = memory::limit() ? double(memory::charged()) : 0.0;
    if (3 * copy > budget - held)
        throw RuntimeError(RuntimeErrorKind::Memory, Span{},
                           fmt::format("meshing would take about {:.1f} GB ({} skeleton points, {} sides a "
                                       "ring) but --max-memory allows {:.1f} GB, {:.1f} GB of it held by "
                                       "the string and skeleton: lower --sides or the derivation length, "
                                       "or raise --max-memory",
                                       3 * copy / 1e9, points, sides, budget / 1e9, held / 1e9));
    scene_memory.resize(static_cast<std::size_t>(2 * copy));
    return copy;
}

// What writing one file may hold in memory besides the scene: a third copy of the mesh for
// formats made from it; the text for the others, from what plant run wrote for a 1-million-point
// skeleton (.skel.json about 410 bytes a point, SVG about 180, rounded up for the text growing),
// and for the string about 4 bytes a module and 24 a parameter.
static std::size_t writing_bytes(const OutputFormat& f, const Derivation& d, double mesh_copy,
                                 std::uint64_t skeleton_points) {
    if (f.needs == OutputNeeds::Scene) return static_cast<std::size_t>(mesh_copy);
    if (f.needs == OutputNeeds::Skeleton)
        return static_cast<std::size_t>(skeleton_points * (f.bytes == skeleton_json_bytes ? 480 : 224));
    return d.string().size() * 4 + d.string().params.size() * 24;
}

// Before meshing: the triangles the tubes will have (2 * sides per segment, a fifth more for the
// rounded sharp bends) and the organs (kOrganTriangles each, a leaf's or a petal's order), and the
// bytes they take in memory (about 40 a triangle, three copies: scene, export, file). Stops with a
// Memory error naming --max-triangles past it; tells the progress line otherwise.
static void check_triangles(const Skeleton& skeleton, const OutputOptions& options) {
    constexpr double kOrganTriangles = 32, kBendShare = 1.2, kBytesPerTriangle = 3 * 40.0;
    double segments = 0, organs = 0;
    for (const auto& a : skeleton.axes)
        if (a.points.size() > 1) segments += double(a.points.size() - 1);
    for (const auto& o : skeleton.organs) // instances are counted when they are drawn out
        if (o.shape.kind != OrganKind::Instance) organs += 1;
    const double triangles =
        segments * 2.0 * std::max(options.sides, 3) * kBendShare + organs * kOrganTriangles;
    if (triangles > options.max_triangles)
        throw RuntimeError(
            RuntimeErrorKind::Memory, Span{},
            fmt::format("meshing would make about {} triangles ({:.0f} segments of {} sides, "
                        "{:.0f} organs), more than --max-triangles {} allows: lower the number "
                        "of steps (-n) or --sides, or raise --max-triangles",
                        human_count(triangles), segments, options.sides, organs,
                        human_count(options.max_triangles)));
    if (options.progress)
        options.progress(fmt::format("meshing about {} triangles ({})", human_count(triangles),
                                     human_bytes(triangles * kBytesPerTriangle)));
}

// Before drawing every placement out (.obj, .ply and .off always, .glb and .gltf with --flatten):
// what that takes per drawn vertex, measured on 131,071 placements of an 18-vertex tube (2.4
// million vertices): OBJ and PLY peaked at 250 bytes a vertex, the --flatten GLB at 180; the
// figures below leave room for the text buffer doubling as it grows (up to three times the file
// while it is copied). Each drawn placement is one more transform in the flattened scene. Only for
// scenes with placed instances: a plain scene's cost is what reserve_mesh_memory counted.
static void check_drawn_out_memory(const Scene& scene, const std::vector<std::string>& paths,
                                   const std::vector<const OutputFormat*>& formats,
                                   const OutputOptions& options) {
    if (!scene.nested()) return;
    constexpr double kMeshFileBytesPerVertex = 500, kBakedGltfBytesPerVertex = 300, kBytesPerPlacement = 200;
    double per_vertex = 0;
    std::string what;
    for (std::size_t k = 0; k < formats.size(); ++k) {
        const std::string_view e = formats[k]->extension;
        const double cost = e == ".obj" || e == ".ply" || e == ".off" ? kMeshFileBytesPerVertex
                            : (e == ".glb" || e == ".gltf") && options.gltf_layout == GltfLayout::Baked
                                ? kBakedGltfBytesPerVertex
                                : 0;
        if (cost > per_vertex) {
            per_vertex = cost;
            what = escape_controls(paths[k]);
        }
    }
    if (per_vertex == 0) return;
    const DrawnSize n = drawn_size(scene);
    const double bytes = n.vertices * per_vertex + n.placements * kBytesPerPlacement;
    const std::uint64_t budget = options.max_memory ? options.max_memory : default_max_memory();
    if (bytes > double(budget))
        throw RuntimeError(
            RuntimeErrorKind::Memory, Span{},
            fmt::format("meshing '{}' would take about {:.1f} GB (every instance drawn out: {:.0f} "
                        "vertices in {:.0f} placements) but --max-memory allows {:.1f} GB: lower "
                        "the derivation length or the instances placed, write .glb without "
                        "--flatten (which keeps instances shared), or raise --max-memory",
                        what, bytes / 1e9, n.vertices, n.placements, double(budget) / 1e9));
}

// The environments' obstacles as one more prototype, placed once where it is: flat-shaded
// triangles in a stone grey.
static void add_environments(const RunState& environments, Scene& scene) {
    std::vector<glm::dvec3> tris;
    const glm::dvec3 lo(scene.bounds_min), hi(scene.bounds_max);
    for (std::size_t e = 0; e < environments.size(); ++e)
        if (const Environment* env = environments.environment(e)) env->geometry(tris, lo, hi);
    if (tris.size() < 3) return;
    MeshPart part;
    for (std::size_t k = 0; k + 2 < tris.size(); k += 3) {
        const glm::vec3 a(tris[k]), b(tris[k + 1]), c(tris[k + 2]);
        glm::vec3 n = glm::cross(b - a, c - a);
        if (!(glm::length(n) > 0)) continue;
        n = glm::normalize(n);
        const auto base = static_cast<std::uint32_t>(part.positions.size());
        for (const glm::vec3& p : {a, b, c}) {
            part.positions.push_back(p);
            part.normals.push_back(n);
            part.uvs.emplace_back(0.0f);
        }
        part.indices.insert(part.indices.end(), {base, base + 1, base + 2});
    }
    if (part.empty()) return;
    const auto material = static_cast<std::uint32_t>(scene.materials.size());
    scene.materials.push_back(Material{glm::vec3(0.62f, 0.6f, 0.56f)});
    part.primitives.push_back(Primitive{0, static_cast<std::uint32_t>(part.indices.size()), material});
    scene.prototypes.push_back(std::move(part));
    scene.prototype_names.push_back("obstacles");
    scene.instances.push_back(
        Instance{static_cast<std::uint32_t>(scene.prototypes.size() - 1), glm::mat4(1.0f)});
    scene.update_bounds();
}

OutputSummary write_outputs(const Program& program, const Derivation& d,
                            const std::vector<std::string>& paths, const OutputOptions& options) {
    std::vector<const OutputFormat*> formats;
    for (const auto& p : paths) {
        const OutputFormat* f = format_of(p);
        if (!f)
            throw ExportError(fmt::format("cannot tell the format of '{}': use {}", escape_controls(p),
                                          known_extensions()));
        formats.push_back(f);
    }
    bool need_skeleton = false, need_scene = false;
    for (const OutputFormat* f : formats) {
        need_skeleton = need_skeleton || f->needs != OutputNeeds::String;
        need_scene = need_scene || f->needs == OutputNeeds::Scene;
    }
    memory::Reservation scene_memory; // declared before the scene: released after it is freed
    double mesh_copy = 0;
    Skeleton skeleton;
    Scene scene;
    if (need_skeleton && options.progress) options.progress("interpreting the string");
    if (need_skeleton) {
        memory::Stage stage("interpreting the string");
        // without interpretation rules the turtle reads the string itself, not a copy of it
        if (program.interpret.empty())
            skeleton = build_skeleton(program, d.string(), turtle_options(d));
        else
            skeleton = build_skeleton(program, d.interpreted(d.string()), turtle_options(d));
    }
    // .skel.json lists the prototypes of instances: they are made with the scene
    if (need_skeleton && !need_scene && program.instances)
        for (const auto& p : paths) need_scene = need_scene || format_of(p)->bytes == skeleton_json_bytes;
    if (need_scene) {
        memory::Stage stage("meshing");
        mesh_copy = reserve_mesh_memory(skeleton, options, scene_memory);
        check_triangles(skeleton, options);
        MeshOptions mo;
        mo.sides = options.sides;
        mo.width_scale = width_scale_of(options, d);
        mo.camera = options.camera; // per-placement level of detail
        mo.derivation = &d;         // instances: the seed and limits
        mo.max_memory = options.max_memory ? options.max_memory : default_max_memory(); // instances
        scene = build_scene(program, skeleton, mo);
        if (options.obstacles) add_environments(d.run_state(), scene);
        check_drawn_out_memory(scene, paths, formats, options);
        memory::check_resident();
    }
    // All or nothing across the run: every file is written under a temporary name beside its
    // target, and only when all are written are they renamed (PendingFiles removes them on an
    // error and on SIGINT or SIGTERM).
    // Sidecars (an OBJ's .mtl) are written and renamed with the outputs.
    std::vector<std::string> targets = paths;
    std::vector<std::size_t> sidecar_of; // per sidecar, its output
    for (std::size_t k = 0; k < formats.size(); ++k)
        if (formats[k]->sidecar_extension) {
            targets.push_back(sidecar_path(paths[k], formats[k]->sidecar_extension));
            sidecar_of.push_back(k);
        }
    PendingFiles pending(targets);
    const OutputSources from{program, d, skeleton, scene, options};
    std::uint64_t skeleton_points = 0;
    for (const auto& a : skeleton.axes) skeleton_points += a.points.size();
    for (std::size_t k = 0; k < formats.size(); ++k) {
        if (options.progress)
            options.progress(
                fmt::format("writing {} ({} of {})", escape_controls(paths[k]), k + 1, formats.size()));
        memory::Stage stage(fmt::format("writing '{}'", escape_controls(paths[k])));
        memory::Reservation buffer(writing_bytes(*formats[k], d, mesh_copy, skeleton_points));
        if (const auto stream = formats[k]->stream)
            pending.write_with(k, [&](const ByteSink& sink) { stream(from, paths[k], sink); });
        else
            pending.write(k, formats[k]->bytes(from, paths[k]));
        memory::check_resident();
    }
    for (std::size_t j = 0; j < sidecar_of.size(); ++j)
        pending.write(paths.size() + j, formats[sidecar_of[j]]->sidecar_bytes(from, paths[sidecar_of[j]]));
    pending.commit();
    return OutputSummary{scene.tubes.triangle_count(), scene.instances.size()};
}

} // namespace plant::cli
