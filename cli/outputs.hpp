// Writing a derivation's results to files by extension; shared by `plant run` and the REPL.
#pragma once

#include "plant/derive.hpp"

#include <optional>
#include <string>
#include <vector>

namespace plant::cli {

enum class Format { Glb, Gltf, Obj, Ply, Off, Png, Svg, Txt, Skeleton, MeshSummary };

// The format named by a file's extension, if any.
std::optional<Format> format_of(const std::string& path);
const char* known_extensions();

struct OutputOptions {
    int sides = 8;
    int width = 800, height = 800;
    bool obstacles = true; // the environments' geometry (walls, boxes) goes into meshes and images
};

// Interprets, meshes (when some output needs it) and writes every path. Throws RuntimeError or
// ExportError. Returns the number of triangles and organs meshed, for a summary.
struct OutputSummary {
    std::size_t triangles = 0, organs = 0;
};
OutputSummary write_outputs(const Program& program, const Derivation& d,
                            const std::vector<std::string>& paths, const OutputOptions& options);

} // namespace plant::cli
