// Writing a derivation's results to files by extension; shared by `plant run`, the REPL's
// :export and `plant help formats`. Every output format is one row of `output_formats()`.
#pragma once

#include "plant/derive.hpp"
#include "plant/export.hpp"
#include "plant/scene.hpp"
#include "plant/skeleton.hpp"

#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace plant::cli {

inline constexpr double kDefaultMaxTriangles = 20e6;

struct OutputOptions {
    int sides = 8;
    int width = 800, height = 800;
    bool obstacles = true;        // the environments' geometry (walls, boxes) goes into meshes and images
    std::uint64_t max_memory = 0; // bytes meshing and export may take; 0: default_max_memory()
    // how .glb and .gltf write placements: GPU instancing, plain nodes (--no-gpu-instancing) or
    // everything baked (--flatten)
    GltfLayout gltf_layout = GltfLayout::GpuInstancing;
    // --camera: where the PNG preview is seen from, and where placements measure their view
    // depth from (MeshOptions::camera); --look-at: the point it looks at
    std::optional<glm::dvec3> camera, look_at;
    // --view, --lines/--tubes, --min-line-width: how the PNG preview looks (PngOptions)
    PngViewKind view = PngViewKind::Auto;
    PngLines lines = PngLines::Auto;
    double min_line_px = 1.0;
    // --width-scale: replaces the grammar's `width_scale` (what drawn widths are multiplied by)
    std::optional<double> width_scale;
    bool size_given = false; // --size was given: an .svg takes it too
    // --max-triangles: a run whose meshing is estimated to make more stops before meshing
    double max_triangles = kDefaultMaxTriangles;
    // Called with each stage (interpreting, meshing with its estimate, writing each file), for
    // plant run's progress line; none: quiet.
    std::function<void(const std::string&)> progress;
};

// "front", "top", "side", "iso" or "auto"; none for anything else.
std::optional<PngViewKind> parse_view(const std::string& text);

// "x,y,z": three finite numbers separated by commas; none when the text is not that.
std::optional<glm::dvec3> parse_point(const std::string& text);

// Half the machine's physical memory: the default of --max-memory.
std::uint64_t default_max_memory();
// The smallest --max-memory: 1 MB (below it no command can do anything, and "--max-memory 1" is
// more likely a forgotten unit than a budget of one byte).
constexpr std::uint64_t kMinMaxMemory = std::uint64_t(1) << 20;
// "512M", "4G", "1.5G" or a number of bytes, at least kMinMaxMemory; 0 when it cannot be read
// (empty, a sign, an exponent, hexadecimal, an unknown unit) or is smaller.
std::uint64_t parse_memory(const std::string& text);
// The usage error for a --max-memory that parse_memory refuses.
std::string memory_usage_error(const std::string& text);

// What a format is made from; each stage needs the ones before it.
enum class OutputNeeds {
    String,   // the derived module string only
    Skeleton, // what the turtle drew (interprets the string)
    Scene,    // the meshed plant (meshes the skeleton)
};

// Everything a writer may read; the skeleton and scene are empty unless some requested format
// needs them.
struct OutputSources {
    const Program& program;
    const Derivation& derivation;
    const Skeleton& skeleton;
    const Scene& scene;
    const OutputOptions& options;
};

struct OutputFormat {
    const char* extension; // with its dot; matched case-insensitively, the longest match wins
    OutputNeeds needs;
    // the file's bytes; `target` names the file in messages only
    std::string (*bytes)(const OutputSources& from, const std::string& target);
    const char* doc; // one line for `plant run --help` and `plant help formats`
    // A file written beside the output, its extension replacing the output's (an OBJ's .mtl), and
    // its bytes; written and renamed with the other outputs. Null: none.
    const char* sidecar_extension = nullptr;
    std::string (*sidecar_bytes)(const OutputSources& from, const std::string& target) = nullptr;
    // When set, what writes the file instead of `bytes`: the bytes handed to the sink as they are
    // made, so a large file is never held whole in memory (.glb). Same bytes as `bytes`.
    void (*stream)(const OutputSources& from, const std::string& target, const ByteSink& sink) = nullptr;
};

// The path of `target`'s sidecar: its extension replaced by `extension` ("a/tree.obj" ->
// "a/tree.mtl").
std::string sidecar_path(const std::string& target, const std::string& extension);

// The formats, in the order they are listed to users.
std::span<const OutputFormat> output_formats();

// The format named by a file's extension, or null.
const OutputFormat* format_of(const std::string& path);
// The extensions for messages: ".glb .gltf ... or .mesh.txt".
std::string known_extensions();

// Interprets, meshes (when some output needs it) and writes every path. Throws RuntimeError or
// ExportError. Returns the number of triangles and organs meshed, for a summary.
struct OutputSummary {
    std::size_t triangles = 0, organs = 0;
};
OutputSummary write_outputs(const Program& program, const Derivation& d,
                            const std::vector<std::string>& paths, const OutputOptions& options);

} // namespace plant::cli
