// OpenMesh for the runtime's readers and writers (internal to plant_runtime): its headers, with
// the -Wmaybe-uninitialized that GCC reports inside them silenced, the mesh type they use, and
// its log streams switched off.
#pragma once

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <mutex>

namespace plant {

using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;

// OpenMesh logs to stdout and stderr (the OBJ writer's progress, add_face's complex edges, a
// file it cannot read); the runtime reports failures as its own errors instead.
inline void quiet_openmesh() {
    static std::once_flag once;
    std::call_once(once, [] {
        omlog().disable();
        omerr().disable();
    });
}

} // namespace plant
