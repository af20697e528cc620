// The Python module plant._plant (docs/api.md, Python): a compiled grammar with its derivation,
// read as modules, numpy arrays and files. The Python side (python/plant/__init__.py) wraps it.
#pragma once

#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/environment_phase.hpp"
#include "plant/scene.hpp"
#include "plant/skeleton.hpp"
#include "plant/source.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace plant::python {

namespace py = pybind11;

// Raises one of the exception classes of plant/_errors.py: `kind` names it ("CompileError",
// "DeriveError", "ExportError"); `text` is the rendered diagnostics (file:line:col, the line and
// a caret) and `diagnostics` their data.
[[noreturn]] void raise_error(const char* kind, const std::string& text, py::list diagnostics);
// A diagnostic as a plant.Diagnostic (severity, file, line, column, message).
py::object diagnostic_object(const Diagnostic& d, const SourceManager& sources);
// A runtime error (deriving, meshing) as plant.DeriveError, pointing into the grammar.
[[noreturn]] void raise_runtime(const RuntimeError& e, const SourceManager& sources);

// What the turtle drew, as flat arrays (docs/skeleton.md): per point, per axis, per organ.
struct SkeletonData {
    std::vector<double> positions, headings, lefts, ups, radii; // per point (3 each, radius 1)
    std::vector<float> colors;                                  // per point, linear RGB
    std::vector<std::uint64_t> ids;                             // per point: the module that drew it
    std::vector<std::int32_t> axis;                             // per point: its axis
    std::vector<std::int32_t> axis_parent;                      // per axis; -1: the trunk
    std::vector<std::int64_t> axis_start;                       // axes + 1: each axis's first point
    std::vector<double> organ_transforms;                       // per organ, a 4x4 matrix (row-major)
    std::vector<float> organ_colors;
    std::vector<std::uint64_t> organ_ids;
    std::vector<std::string> organ_names;
};
SkeletonData skeleton_data(const Skeleton& s);

// The meshed plant as one world-space triangle mesh, every placement drawn out (as .obj), with
// each triangle's material and group: -1 for the tubes, k for the k-th placed organ.
struct MeshData {
    std::vector<float> vertices, normals, uvs;
    std::vector<std::uint32_t> indices, material;
    std::vector<std::int32_t> group;
    std::vector<std::string> group_names; // per placed organ: its prototype's name
    std::vector<float> colors;            // per material, linear RGB
    std::vector<std::string> textures;    // per material: its texture's name, or empty
    float bounds[6] = {0, 0, 0, 0, 0, 0}; // min x y z, max x y z
};
MeshData mesh_data(const Scene& scene);

// A compiled grammar and its derivation. Every method that reads or advances the derivation
// runs with the GIL released and this object's lock held, so Python threads may use other
// objects at the same time while one object is never read and written at once.
class PyPlant {
  public:
    PyPlant(std::unique_ptr<SourceManager> sources, std::unique_ptr<Program> program, DeriveOptions options);

    // Runs up to `n` more steps (all the remaining ones when none); the `on end` hook runs once
    // the derivation is over. Returns the steps run.
    int derive(std::optional<int> n);
    int steps_done();
    int target_steps();
    bool done();
    std::uint64_t seed();
    std::size_t size();
    py::list modules();
    py::list symbol_names();
    std::string text(bool with_ids);
    py::dict skeleton();
    py::dict mesh(int sides);
    // Writes every path in the format its extension names, as `plant run -o` does.
    void save(const std::vector<std::string>& paths, int sides, int width, int height,
              const std::string& layout, bool obstacles);
    py::bytes png(int width, int height, int sides);
    std::string printed(); // what print(...) in hooks wrote since the last call

  private:
    // Runs `f` with the GIL released and the lock held; converts the runtime's errors.
    template <class F> auto locked(F&& f) -> decltype(f());
    void start_if_needed();
    const Skeleton& skeleton_now();
    const Scene& scene_now(int sides);

    std::mutex mutex_;
    std::unique_ptr<SourceManager> sources_;
    std::unique_ptr<Program> program_;
    TurtleEnvironmentPhase phase_;
    std::unique_ptr<Derivation> derivation_;
    bool started_ = false, finished_ = false;
    std::string printed_;
    // the skeleton and scene of the current step, made on first use
    std::optional<Skeleton> skeleton_;
    std::optional<Scene> scene_;
    int scene_sides_ = 0;
};

// The arrays (binding_arrays.cpp): gathered without the GIL into vectors, then handed to numpy
// without a copy.
py::dict skeleton_arrays(SkeletonData&& data);
py::dict mesh_arrays(MeshData&& data);

} // namespace plant::python
