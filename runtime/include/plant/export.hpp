// Writing a scene to files. Every writer writes to a temporary file beside the target and
// renames it, so a failed run never leaves a partial file. Errors throw ExportError.
#pragma once

#include "plant/scene.hpp"

#include <cstddef>
#include <functional>
#include <iosfwd>
#include <optional>
#include <stdexcept>
#include <string>

namespace plant {

struct ExportError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Throws ExportError, naming `what` ("glTF export: tubes"), when the part's arrays disagree:
// normals or uvs present but not one per position, a partial triangle, an index out of range.
void check_mesh_part(const MeshPart& part, const std::string& what);

// What a writer draws: `scene` itself, or its flattened copy (flatten_keeping_bounds in
// plant/scene.hpp: the bounds are scene's), kept in `storage`, when it places whole scenes. Throws
// ExportError, naming `what` ("glTF export"), when an instance places a prototype the scene does not have.
const Scene& exported_scene(const Scene& scene, Scene& storage, const std::string& what);

// Writes `bytes` to `path` through a temporary file and a rename.
void write_file_atomically(const std::string& path, const std::string& bytes);

// Puts the finished file `temp` in the place of `target` (same folder) in one step, as rename(2)
// does: a reader finds the old file or the new one, never neither. Returns 0 or the errno.
// When `target` is a regular file it is swapped with `temp` (renameat2 RENAME_EXCHANGE) and the
// old contents, now under `temp`, are removed; a plain rename over an existing file makes ext4
// write the new file's data out first (its auto_da_alloc heuristic), which took 9 ms for a
// 10 MB glTF. Elsewhere, or where the swap is not supported, a plain rename.
int replace_file(const char* temp, const char* target);

// glTF's two containers: binary (.glb), or JSON with the buffer embedded as a data URI (.gltf).
enum class GltfContainer : std::uint8_t { Binary, Json };
// How placements are written (prototype scenes are always flattened first, plant/scene.hpp):
//   GpuInstancing: one mesh per distinct prototype and one node per prototype carrying
//     EXT_mesh_gpu_instancing (TRANSLATION, ROTATION, SCALE accessors); a placement whose matrix
//     is not a rotation times a positive scale gets a plain node of its own instead.
//   Nodes: one plain node per placement, referencing the shared meshes (--no-gpu-instancing).
//   Baked: everything transformed into one world-space mesh, nothing shared (--flatten).
enum class GltfLayout : std::uint8_t { GpuInstancing, Nodes, Baked };
// One buffer, the tubes as one mesh and node, prototypes with the same triangles, attributes and
// materials as one mesh, placements as `layout` says, one material per color. The caller names
// the container; the path's extension is not read.
void write_gltf(const Scene& scene, const std::string& path, GltfContainer container,
                GltfLayout layout = GltfLayout::GpuInstancing);
// The bytes write_gltf writes; `path` names the file in messages only.
std::string gltf_bytes(const Scene& scene, GltfContainer container, const std::string& path,
                       GltfLayout layout = GltfLayout::GpuInstancing);
// Receives a file's bytes in order, piece by piece; a piece is only valid during the call.
using ByteSink = std::function<void(const void* data, std::size_t size)>;
// The same bytes handed to `sink` as they are made: a .glb's header, JSON and binary chunk go
// straight from the scene's arrays to the sink, never gathered into one block of memory. Throws
// ExportError before the first byte when the scene cannot be written.
void gltf_to(const Scene& scene, GltfContainer container, const std::string& path, GltfLayout layout,
             const ByteSink& sink);

// Where a PNG preview is seen from (plant run --camera, --look-at): a perspective camera at `eye`
// looking at `target` (default: the centre of the scene's bounds), y up.
struct PngView {
    glm::dvec3 eye{0.0};
    std::optional<glm::dvec3> target;
};

// The orthographic views of a PNG preview (plant run --view), each framed on the scene's bounds:
//   Front: from +z looking along -z, y up, x to the right: a figure in the xy plane face-on.
//   Top: from +y looking down, -z at the top of the image.  Side: from +x, y up.
//   Iso: from the front right and above (azimuth 40, elevation 24 degrees).
//   Auto: Front, Side or Top when the skeleton is flat (its extent along z, x or y at most a
//   thousandth of its largest extent: a 2-D figure is drawn face-on), Iso otherwise.
enum class PngViewKind : std::uint8_t { Auto, Front, Top, Side, Iso };

// How branches are drawn (plant run --lines, --tubes):
//   Tubes: the meshed tubes only.
//   Lines: every skeleton segment as a flat band, its drawn width (Skeleton radius times
//     width_scale, projected) but at least min_line_px pixels; no tubes. For skeletal figures.
//   Auto: Lines when the widest tube would be under kAutoLinePx pixels across (every branch a
//     hairline); otherwise tubes, with every segment also drawn min_line_px wide underneath so
//     that branches thinner than a pixel stay visible (a tube wider than that hides its line).
enum class PngLines : std::uint8_t { Auto, Tubes, Lines };
inline constexpr double kAutoLinePx = 1.5;

struct Skeleton;

// Everything a preview may be asked for. Without a skeleton, the view Auto is chosen from the
// scene's bounds and no lines are drawn.
struct PngOptions {
    PngViewKind view = PngViewKind::Iso;
    std::optional<PngView> camera; // a perspective camera, instead of `view`
    const Skeleton* skeleton = nullptr;
    PngLines lines = PngLines::Tubes;
    double min_line_px = 1.0; // in output pixels
    double width_scale = 1.0; // what the tubes were meshed with (MeshOptions::width_scale)
};

// A PNG preview: software rasterizer with a z-buffer and Lambert shading, white background;
// without a view, an orthographic 3/4 view framed on the scene's bounding box.
void write_png(const Scene& scene, const std::string& path, int width, int height,
               const std::optional<PngView>& view = std::nullopt);
// The bytes write_png writes; `path` names the file in messages only.
std::string png_bytes(const Scene& scene, int width, int height, const std::string& path,
                      const std::optional<PngView>& view = std::nullopt);
std::string png_bytes(const Scene& scene, int width, int height, const std::string& path,
                      const PngOptions& options);

// Wavefront OBJ with its colours: `mtllib MTL_NAME`, then one object (`o` and `g` of one name) per
// organ kind: `branches` for the tubes, then each prototype by its name (`leaf`, `petal`, ...)
// with every placement of it, and `usemtl m<i>` before the triangles of material i. Positions,
// texture coordinates and normals per vertex, in world space (placed scenes drawn out).
std::string obj_file_bytes(const Scene& scene, const std::string& path, const std::string& mtl_name);
// The .mtl file the OBJ names: `newmtl m<i>` with `Kd` the colour the PNG preview draws material i
// in (a texture's average colour), linear RGB.
std::string mtl_file_bytes(const Scene& scene);

// The mesh files OpenMesh writes for us: plain, without materials (plant run writes .obj with
// obj_file_bytes and mtl_file_bytes instead).
enum class MeshFileFormat : std::uint8_t { Obj, Ply, Off };
// Everything flattened into one triangle mesh with vertex normals (and texture coordinates, but
// for OFF; vertex colours for PLY), written through OpenMesh in `format`; the path's extension
// is not read.
void write_mesh_file(const Scene& scene, const std::string& path, MeshFileFormat format);
// The bytes write_mesh_file writes; `path` names the file in messages only.
std::string mesh_file_bytes(const Scene& scene, MeshFileFormat format, const std::string& path);
// The same written to `out`; throws ExportError when the stream fails to take all of it.
void write_mesh_stream(const Scene& scene, MeshFileFormat format, const std::string& path, std::ostream& out);

} // namespace plant
