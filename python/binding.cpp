// plant._plant: compiling a grammar from Python, and the module's definition (docs/api.md,
// Python). The friendlier signature, the choice between a path and source text, and the
// exception classes are in python/plant/*.py.
#include "binding.hpp"

#include "plant/diagnostics.hpp"
#include "plant/environments.hpp"

#include <fmt/format.h>
#include <pybind11/stl.h>

#include <filesystem>

namespace plant::python {

namespace {

py::object errors_module() {
    return py::module_::import("plant._errors");
}

// Compiles `text`, named `name` in diagnostics; raises CompileError with the rendered diagnostics
// when there are errors, and passes warnings to Python's warnings module.
std::unique_ptr<PyPlant> compile(const std::string& name, std::optional<std::string> text,
                                 const std::vector<std::pair<std::string, std::string>>& defines,
                                 const std::vector<std::string>& include_dirs,
                                 const std::vector<std::string>& allow_read,
                                 std::optional<std::uint64_t> seed, std::optional<int> steps, int threads,
                                 std::uint64_t max_modules) {
    auto sources = std::make_unique<SourceManager>();
    std::string source_text;
    if (text) {
        source_text = std::move(*text);
    } else if (ReadFailure f = read_input_file(name, source_text, kMaxSourceBytes, false);
               f != ReadFailure::None) {
        std::error_code ec;
        const std::string why = std::filesystem::is_directory(name, ec) ? "it is a directory" : describe(f);
        raise_error("CompileError", fmt::format("cannot read '{}': {}", escape_controls(name), why),
                    py::list());
    }
    if (source_text.size() > kMaxSourceBytes)
        raise_error("CompileError",
                    fmt::format("'{}' is larger than {} bytes", escape_controls(name), kMaxSourceBytes),
                    py::list());
    CompileOptions co;
    co.defines = defines;
    co.include_dirs = include_dirs;
    co.confine_reads = true; // as the plant command: a grammar reads its own folder (docs/install.md)
    co.allow_read = allow_read;
    co.environments = runtime_environments();
    Diagnostics diags;
    std::unique_ptr<Program> program;
    {
        py::gil_scoped_release nogil;
        const std::uint32_t id = sources->add(name, std::move(source_text));
        program = compile_source(*sources, id, co, diags);
    }
    std::string rendered = render_all(diags, *sources);
    if (diags.error_count() > diags.all().size())
        rendered += fmt::format("{} more errors not shown\n", diags.error_count() - diags.all().size());
    py::list list;
    for (const auto& d : diags.all()) list.append(diagnostic_object(d, *sources));
    if (!program) raise_error("CompileError", rendered, list);
    if (!diags.all().empty())
        py::module_::import("warnings").attr("warn")(rendered, py::arg("stacklevel") = 3);

    DeriveOptions opt;
    opt.steps = steps;
    opt.seed = seed;
    opt.threads = std::max(1, threads);
    opt.max_modules = max_modules;
    return std::make_unique<PyPlant>(std::move(sources), std::move(program), std::move(opt));
}

} // namespace

py::object diagnostic_object(const Diagnostic& d, const SourceManager& sources) {
    py::object file = py::none();
    std::uint32_t line = 0, column = 0;
    if (d.span.valid() && d.span.file < sources.size()) {
        const SourceFile& f = sources.file(d.span.file);
        const LineCol lc = f.line_col(d.span.begin);
        file = py::str(f.name());
        line = lc.line;
        column = lc.col;
    }
    return errors_module().attr("Diagnostic")(severity_name(d.severity), file, line, column, d.message,
                                              render(d, sources));
}

void raise_error(const char* kind, const std::string& text, py::list diagnostics) {
    py::object cls = errors_module().attr(kind);
    py::object error = cls(text, diagnostics);
    PyErr_SetObject(cls.ptr(), error.ptr());
    throw py::error_already_set();
}

void raise_runtime(const RuntimeError& e, const SourceManager& sources) {
    const Diagnostic d{Severity::Error, e.span, e.message, {}};
    py::list list;
    list.append(diagnostic_object(d, sources));
    raise_error("DeriveError", render(d, sources), list);
}

} // namespace plant::python

PYBIND11_MODULE(_plant, m) {
    using namespace plant::python;
    using plant::python::PyPlant;
    m.doc() = "plant's engine: compile a .plant grammar, derive it, mesh it and write it (docs/api.md)";
    m.def("compile", &compile, py::arg("name"), py::arg("text"), py::arg("defines"), py::arg("include_dirs"),
          py::arg("allow_read"), py::arg("seed"), py::arg("steps"), py::arg("threads"),
          py::arg("max_modules"));
    py::class_<PyPlant>(m, "Plant")
        .def("derive", &PyPlant::derive, py::arg("n") = py::none())
        .def_property_readonly("steps", &PyPlant::steps_done)
        .def_property_readonly("target_steps", &PyPlant::target_steps)
        .def_property_readonly("done", &PyPlant::done)
        .def_property_readonly("seed", &PyPlant::seed)
        .def("__len__", &PyPlant::size)
        .def("modules", &PyPlant::modules)
        .def("symbol_names", &PyPlant::symbol_names)
        .def("text", &PyPlant::text, py::arg("ids") = false)
        .def("skeleton", &PyPlant::skeleton)
        .def("mesh", &PyPlant::mesh, py::arg("sides"))
        .def("save", &PyPlant::save, py::arg("paths"), py::arg("sides"), py::arg("width"), py::arg("height"),
             py::arg("layout"), py::arg("obstacles"))
        .def("png", &PyPlant::png, py::arg("width"), py::arg("height"), py::arg("sides"))
        .def("printed", &PyPlant::printed);
}
