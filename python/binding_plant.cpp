// plant._plant.Plant: a compiled grammar's derivation, advanced and read from Python with the GIL
// released (docs/api.md, Python).
#include "binding.hpp"

#include "outputs.hpp" // cli/: the formats `plant run -o` writes

#include "plant/export.hpp"
#include "plant/mesh.hpp"
#include "plant/turtle.hpp"

#include <fmt/format.h>

namespace plant::python {

PyPlant::PyPlant(std::unique_ptr<SourceManager> sources, std::unique_ptr<Program> program,
                 DeriveOptions options)
    : sources_(std::move(sources)), program_(std::move(program)) {
    options.environment_phase = &phase_;
    options.on_print = [this](const std::string& text) { printed_ += text; };
    derivation_ = std::make_unique<Derivation>(*program_, std::move(options));
    locked([&] { start_if_needed(); }); // settings are read now: `derive -1;` fails here
}

template <class F> auto PyPlant::locked(F&& f) -> decltype(f()) {
    std::optional<RuntimeError> runtime;
    std::optional<std::string> export_error;
    {
        py::gil_scoped_release nogil;
        std::lock_guard<std::mutex> lock(mutex_);
        try {
            return f();
        } catch (const RuntimeError& e) {
            runtime = e;
        } catch (const ExportError& e) {
            export_error = e.what();
        }
    }
    if (runtime) raise_runtime(*runtime, *sources_);
    raise_error("ExportError", escape_controls(*export_error, true), py::list());
}

void PyPlant::start_if_needed() {
    if (started_) return;
    started_ = true;
    derivation_->start();
}

int PyPlant::derive(std::optional<int> n) {
    if (n && *n < 0) throw py::value_error("derive(n): n must be 0 or more");
    return locked([&] {
        int done = 0;
        while ((!n || done < *n) && !finished_) {
            const int before = derivation_->steps_done();
            const bool more = derivation_->step();
            if (derivation_->steps_done() != before) {
                ++done;
                skeleton_.reset();
                scene_.reset();
            }
            if (!more || derivation_->stopped() || derivation_->steps_done() >= derivation_->target_steps()) {
                finished_ = true;
                derivation_->finish(); // `on end`, once
            }
        }
        return done;
    });
}

int PyPlant::steps_done() {
    return locked([&] { return derivation_->steps_done(); });
}
int PyPlant::target_steps() {
    return locked([&] { return derivation_->target_steps(); });
}
bool PyPlant::done() {
    return locked([&] { return finished_; });
}
std::uint64_t PyPlant::seed() {
    return locked([&] { return derivation_->seed(); });
}
std::size_t PyPlant::size() {
    return locked([&] { return derivation_->string().size(); });
}

py::list PyPlant::symbol_names() {
    py::list names;
    for (const auto& info : program_->symbols.all()) names.append(py::str(info.name));
    return names;
}

py::list PyPlant::modules() {
    // copied under the lock, turned into Python objects with the GIL held
    ModuleString s = locked([&] { return derivation_->string(); });
    py::object module_class = py::module_::import("plant._types").attr("Module");
    std::vector<py::object> names;
    for (const auto& info : program_->symbols.all()) names.push_back(py::str(info.name));
    py::list out(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        py::tuple params(s.arity(i));
        const ModuleArgs a = s.args(i);
        for (std::uint32_t k = 0; k < s.arity(i); ++k) params[k] = py::float_(a[k]);
        out[i] = module_class(names.at(s.symbol(i)), params);
    }
    return out;
}

std::string PyPlant::text(bool with_ids) {
    return locked([&] { return format_string(*program_, derivation_->string(), with_ids); });
}

std::string PyPlant::printed() {
    return locked([&] { return std::exchange(printed_, std::string()); });
}

const Skeleton& PyPlant::skeleton_now() {
    if (!skeleton_)
        skeleton_ = build_skeleton(*program_, derivation_->interpreted(derivation_->string()),
                                   turtle_options(*derivation_));
    return *skeleton_;
}

const Scene& PyPlant::scene_now(int sides) {
    if (!scene_ || scene_sides_ != sides) {
        MeshOptions mo;
        mo.sides = sides;
        mo.derivation = derivation_.get(); // instances: the seed and limits
        mo.max_memory = cli::default_max_memory();
        scene_ = build_scene(*program_, skeleton_now(), mo);
        scene_sides_ = sides;
    }
    return *scene_;
}

py::dict PyPlant::skeleton() {
    SkeletonData data = locked([&] { return skeleton_data(skeleton_now()); });
    return skeleton_arrays(std::move(data));
}

py::dict PyPlant::mesh(int sides) {
    if (sides < 3 || sides > 64) throw py::value_error("mesh(sides): sides must be from 3 to 64");
    MeshData data = locked([&] { return mesh_data(scene_now(sides)); });
    return mesh_arrays(std::move(data));
}

void PyPlant::save(const std::vector<std::string>& paths, int sides, int width, int height,
                   const std::string& layout, bool obstacles) {
    if (paths.empty()) throw py::value_error("save: name at least one file");
    if (sides < 3 || sides > 64) throw py::value_error("save(sides): sides must be from 3 to 64");
    if (width < 16 || height < 16 || width > 16384 || height > 16384)
        throw py::value_error("save(size): width and height must be from 16 to 16384");
    cli::OutputOptions oo;
    oo.sides = sides;
    oo.width = width;
    oo.height = height;
    oo.obstacles = obstacles;
    if (layout == "instanced")
        oo.gltf_layout = GltfLayout::GpuInstancing;
    else if (layout == "nodes")
        oo.gltf_layout = GltfLayout::Nodes;
    else if (layout == "flatten")
        oo.gltf_layout = GltfLayout::Baked;
    else
        throw py::value_error("save(layout): use 'instanced', 'nodes' or 'flatten'");
    for (const auto& p : paths)
        if (!cli::format_of(p))
            raise_error("ExportError",
                        fmt::format("cannot tell the format of '{}': use {}", escape_controls(p),
                                    cli::known_extensions()),
                        py::list());
    locked([&] { cli::write_outputs(*program_, *derivation_, paths, oo); });
}

py::bytes PyPlant::png(int width, int height, int sides) {
    if (width < 16 || height < 16 || width > 16384 || height > 16384)
        throw py::value_error("show(size): width and height must be from 16 to 16384");
    if (sides < 3 || sides > 64) throw py::value_error("show(sides): sides must be from 3 to 64");
    std::string bytes = locked([&] { return png_bytes(scene_now(sides), width, height, "preview"); });
    return py::bytes(bytes);
}

} // namespace plant::python
