// Reading mesh files a grammar names (surfaces, climber and obstacle meshes) without trusting
// them: the file must be a regular file under the size cap (kMaxSourceBytes), its header's
// counts must fit in its size before anything is allocated, and the variants OpenMesh's readers
// mishandle (binary OFF and PLY, ASCII STL: uninitialised reads under valgrind) are refused.
// What passes is handed to OpenMesh from memory, an OBJ without its `mtllib` lines (plant uses
// no materials, and the library would be opened by name). Internal to plant_runtime.
#pragma once

#include "openmesh.hpp"

#include <string>

namespace plant {

enum class MeshRead {
    Ok,
    Failed,  // no such file, or OpenMesh could not read it: the callers' own messages
    Refused, // unsafe or malformed (`why` says how): "cannot read mesh file 'X': why", exit 66
};

// Reads `path` into `mesh`.
MeshRead read_mesh_file(const std::string& path, OpenMeshTriangles& mesh, OpenMesh::IO::Options& options,
                        std::string& why);

// Checks a mesh file's text against its format (`ext`: "obj", "off", "ply" or "stl"); returns
// an empty string when OpenMesh may read it, else what is wrong. Removes an OBJ's mtllib lines.
std::string vet_mesh_text(const std::string& ext, std::string& text);

} // namespace plant
