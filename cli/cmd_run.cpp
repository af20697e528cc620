// plant run: derive, interpret with the turtle, mesh and write every requested file.
#include "batch.hpp"
#include "commands.hpp"
#include "outputs.hpp"
#include "pending_files.hpp"
#include "run_progress.hpp"

#include "plant/environment_phase.hpp"
#include "plant/export.hpp"
#include "plant/export_text.hpp"
#include "plant/mesh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <optional>
#include <tuple>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

struct RunCmd {
    GrammarOptions g;
    std::vector<std::string> outputs;
    int sides = 8;
    bool no_obstacles = false;
    std::string size = "800x800";
    bool no_gpu_instancing = false, flatten = false;
    std::optional<std::string> camera, look_at; // as given, even empty
    std::string view = "auto";
    bool lines = false, tubes = false;
    double min_line_width = 1.0;
    std::optional<double> width_scale;
    double max_triangles = kDefaultMaxTriangles;
    bool sides_given = false, size_given = false;
    BatchOptions batch; // --seeds, --grid, --shard, --manifest, --jobs
};

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// --camera and --look-at: each three finite numbers, --look-at only with --camera, and not the
// same point. Prints a usage error and returns false otherwise.
bool read_view(const RunCmd& c, std::optional<glm::dvec3>& camera, std::optional<glm::dvec3>& look_at) {
    for (auto [name, text, point] :
         {std::tuple{"--camera", &c.camera, &camera}, {"--look-at", &c.look_at, &look_at}}) {
        if (!*text) continue;
        *point = parse_point(**text);
        if (!*point) {
            std::cerr << fmt::format(
                "plant: {} expects three finite numbers x,y,z (as 0,2.5,-10), found '{}'\n", name,
                escape_controls(**text));
            return false;
        }
    }
    if (look_at && !camera) {
        std::cerr << "plant: --look-at needs --camera x,y,z, the point the preview is seen from\n";
        return false;
    }
    if (camera && look_at && *camera == *look_at) {
        std::cerr << fmt::format("plant: --camera and --look-at are the same point ({}): the camera must "
                                 "look at a point away from itself\n",
                                 escape_controls(*c.camera));
        return false;
    }
    return true;
}

// Whether an output is meshed (it needs the scene).
bool meshes(const std::vector<std::string>& outputs) {
    return std::any_of(outputs.begin(), outputs.end(), [](const std::string& o) {
        const OutputFormat* f = format_of(o);
        return f && f->needs == OutputNeeds::Scene;
    });
}

// Options no requested output reads are said to be ignored, rather than silently dropped.
void warn_unused_options(const RunCmd& c) {
    bool svg = false, png = false;
    for (const auto& o : c.outputs)
        if (const OutputFormat* f = format_of(o)) {
            svg = svg || std::string_view(f->extension) == ".svg";
            png = png || std::string_view(f->extension) == ".png";
        }
    if (c.sides_given && svg && !meshes(c.outputs))
        std::cerr << "plant: warning: --sides shapes meshed tubes; an .svg is a line drawing of the "
                     "skeleton and does not use it\n";
    if (c.size_given && !svg && !png)
        std::cerr << "plant: warning: --size sets the size of .png and .svg outputs, and none is written\n";
}

// The same file named twice by -o would be written twice, the second over the first.
bool outputs_distinct(const RunCmd& c) {
    std::vector<fs::path> seen;
    for (const auto& o : c.outputs) {
        std::error_code ec;
        fs::path p = fs::weakly_canonical(fs::absolute(o, ec), ec);
        if (ec) p = fs::path(o).lexically_normal();
        if (std::find(seen.begin(), seen.end(), p) != seen.end()) {
            std::cerr << fmt::format("plant: '{}' is given twice as an output: name each file once\n",
                                     escape_controls(o));
            return false;
        }
        seen.push_back(std::move(p));
    }
    return true;
}

// Reads --size, --max-memory, the view and the layout into `oo`, and checks the outputs' formats
// (the default outputs when none are given). Returns kOk, or kUsage having said why.
int read_output_options(RunCmd& c, OutputOptions& oo) {
    int width = 0, height = 0;
    if (std::sscanf(c.size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16 ||
        width > 16384 || height > 16384 || static_cast<long long>(width) * height > 64LL * 1000 * 1000) {
        std::cerr << fmt::format(
            "plant: --size expects WIDTHxHEIGHT, each from 16 to 16384 and at most 64 million "
            "pixels, found '{}'\n",
            escape_controls(c.size));
        return kUsage;
    }
    if (c.outputs.empty() && reads_standard_input(c.g) &&
        !isatty(STDIN_FILENO)) { // (a terminal: refused later)
        std::cerr << "plant: a grammar from standard input has no name to call its outputs by: give "
                     "them with -o (-o out/plant.glb)\n";
        return kUsage;
    }
    if (c.outputs.empty()) {
        std::string stem = fs::path(c.g.file).stem().string();
        c.outputs = c.batch.any() ? std::vector<std::string>{"out/" + stem + "-{n}.glb"}
                                  : std::vector<std::string>{"out/" + stem + ".glb", "out/" + stem + ".png"};
    }
    for (const auto& o : c.outputs) {
        const OutputFormat* f = format_of(o);
        if (!f) {
            std::cerr << fmt::format("plant: cannot tell the format of '{}': use {}\n", escape_controls(o),
                                     known_extensions());
            return kUsage;
        }
        // a placeholder is filled in by a batch only: a single run would write '{seed}' as it is
        if (!c.batch.any())
            for (std::size_t at = o.find('{'); at != std::string::npos; at = o.find('{', at + 1)) {
                const std::size_t close = o.find('}', at);
                if (close == std::string::npos || close == at + 1 ||
                    !std::all_of(o.begin() + static_cast<std::ptrdiff_t>(at) + 1,
                                 o.begin() + static_cast<std::ptrdiff_t>(close), [](char ch) {
                                     return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_';
                                 }))
                    continue;
                std::cerr << fmt::format(
                    "plant: the output '{}' holds the placeholder {}, which only a batch "
                    "fills in: give --seeds S..S for one variant, or write the name out\n",
                    escape_controls(o), escape_controls(o.substr(at, close - at + 1)));
                return kUsage;
            }
        // a folder it cannot go into stops the run now, not after deriving and meshing
        if (o.find('{') == std::string::npos)
            if (const std::string problem = output_problem(o); !problem.empty()) {
                std::cerr << "plant: " << escape_controls(problem) << "\n";
                return kCantCreate;
            }
        // an output (or its sidecar) that is the grammar itself would replace it
        for (const std::string& written :
             {o, f->sidecar_extension ? sidecar_path(o, f->sidecar_extension) : std::string{}}) {
            std::error_code ec;
            if (!written.empty() && fs::equivalent(written, c.g.file, ec)) {
                std::cerr << fmt::format("plant: '{}' is the grammar being run: writing it would replace "
                                         "the grammar; give another output name\n",
                                         escape_controls(written));
                return kUsage;
            }
        }
    }
    std::optional<glm::dvec3> camera, look_at;
    if (!read_view(c, camera, look_at)) return kUsage;
    oo.sides = c.sides;
    oo.obstacles = !c.no_obstacles;
    oo.width = width;
    oo.height = height;
    oo.max_memory = c.g.max_memory;
    oo.gltf_layout = c.flatten             ? GltfLayout::Baked
                     : c.no_gpu_instancing ? GltfLayout::Nodes
                                           : GltfLayout::GpuInstancing;
    oo.camera = camera;
    oo.look_at = look_at;
    const auto view = parse_view(c.view);
    if (!view) {
        std::cerr << fmt::format("plant: --view expects front, top, side, iso or auto, found '{}'\n",
                                 escape_controls(c.view));
        return kUsage;
    }
    if (camera && *view != PngViewKind::Auto) {
        std::cerr << "plant: --view and --camera both say where the preview is seen from: keep one of them\n";
        return kUsage;
    }
    oo.view = *view;
    oo.lines = c.lines ? PngLines::Lines : c.tubes ? PngLines::Tubes : PngLines::Auto;
    oo.min_line_px = c.min_line_width;
    oo.width_scale = c.width_scale;
    oo.max_triangles = c.max_triangles;
    oo.size_given = c.size_given;
    if (!outputs_distinct(c)) return kUsage;
    warn_unused_options(c);
    return kOk;
}

// Many variants: --seeds, --grid, --shard (docs/batch.md).
int run_many(RunCmd& c, const OutputOptions& oo) {
    if (c.g.seed && !c.batch.seeds.empty()) {
        std::cerr << "plant: --seed and --seeds both set the seed: keep one of them\n";
        return kUsage;
    }
    BatchJob job{c.g, c.outputs, oo, c.batch, {}};
    std::string error;
    auto plan = make_plan(c.batch, c.g.defines, error);
    if (!plan) {
        std::cerr << "plant: " << error << "\n";
        return kUsage;
    }
    job.plan = std::move(*plan);
    return run_batch(job);
}

int run_main(RunCmd& c) {
    // check the outputs before doing any work
    OutputOptions oo;
    if (int code = read_output_options(c, oo); code != kOk) return code;
    set_memory_budget(c.g.max_memory);
    if (c.batch.jobs > 0 && !c.batch.any()) {
        std::cerr << "plant: --jobs runs several variants at once: give --seeds or --grid too\n";
        return kUsage;
    }
    if (c.batch.any()) return run_many(c, oo);
    int exit_code = kOk;
    SourceManager sources;
    auto program = load_program(c.g, sources, exit_code);
    if (!program) return exit_code;
    RunProgress progress(isatty(2) != 0);
    auto t0 = std::chrono::steady_clock::now();
    DeriveOptions opt = derive_options(c.g); // (it gives the strings their share of --max-memory)
    TurtleEnvironmentPhase phase;
    opt.environment_phase = &phase;
    opt.on_print = [](const std::string& text) { std::cerr << escape_controls(text, true); };
    const Derivation* running = nullptr; // the target step is known once it has started
    opt.on_step = [&](const StepStats& s) { progress.step(s, running ? running->target_steps() : s.step); };
    Derivation d(*program, opt);
    running = &d;
    if (progress.enabled()) oo.progress = [&progress](const std::string& what) { progress.stage(what); };
    const bool derived = run_derivation(d, sources, c.g.color);
    progress.clear();
    if (!derived) return kRuntime;
    try {
        OutputSummary summary = write_outputs(*program, d, c.outputs, oo);
        progress.clear();
        if (meshes(c.outputs) && summary.triangles == 0 && summary.organs == 0)
            std::cerr << fmt::format(
                "plant: warning: the plant draws nothing: no tube, organ or instance came "
                "of its string ({} module{} after {} step{}), so the files show an "
                "empty scene\n",
                d.string().size(), d.string().size() == 1 ? "" : "s", d.steps_done(),
                d.steps_done() == 1 ? "" : "s");
        if (progress.enabled())
            std::cerr << fmt::format("{} modules, {} triangles, {} organs in {:.0f} ms\n", d.string().size(),
                                     summary.triangles, summary.organs, ms_since(t0));
    } catch (const RuntimeError& e) {
        progress.clear();
        std::cerr << render(Diagnostic{Severity::Error, e.span, e.message, {}}, sources, c.g.color);
        return e.kind == RuntimeErrorKind::Input ? kNoInput : kRuntime; // a mesh file it cannot read
    } catch (const ExportError& e) {
        progress.clear();
        std::cerr << "plant: " << escape_controls(e.what(), true) << "\n";
        return kCantCreate;
    }
    return kOk;
}

void add_batch_options(CLI::App& cmd, BatchOptions& b) {
    const char* group = "Many variants (docs/batch.md)";
    cmd.add_option("--seeds", b.seeds,
                   "Grow one variant per seed from A to B; outputs then need a placeholder: {seed}, {n} "
                   "(the variant's number from 0) or {NAME} of a --grid parameter")
        ->type_name("A..B")
        ->group(group);
    cmd.add_option("--grid", b.grid,
                   "Sweep a param over FROM, FROM+STEP, ... up to TO (or the values V1,V2,...); repeat "
                   "for several: every combination with every seed is a variant")
        ->type_name("NAME=FROM:TO:STEP")
        ->group(group);
    cmd.add_option("--jobs", b.jobs, "Variants grown at once (default: one per core)")
        ->transform(number_in(1, 256, Bound::Whole))
        ->group(group);
    cmd.add_option("--shard", b.shard,
                   "Grow only the K-th of N slices of the variants (those whose number n has n mod N = "
                   "K - 1), for job arrays")
        ->type_name("K/N")
        ->group(group);
    cmd.add_option("--manifest", b.manifest,
                   "Write a row per variant (seed, params, outputs, modules, triangles, ms, status, "
                   "message) as JSON lines (.jsonl) or CSV (.csv)")
        ->type_name("FILE")
        ->group(group);
}

} // namespace

void setup_run(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<RunCmd>();
    CLI::App* cmd =
        app.add_subcommand("run", "Grow a grammar and write meshes, images, skeletons or strings");
    add_grammar_options(*cmd, c->g, true);
    cmd->add_option("-o,--output", c->outputs,
                    "Output file, its format chosen by extension (listed below); repeat for several "
                    "(default: out/NAME.glb and out/NAME.png; for many variants out/NAME-{n}.glb)")
        ->type_name("FILE");
    cmd->add_option("--sides", c->sides, "Vertices around each ring of a branch (meshes only; not .svg)")
        ->transform(number_in(3, 64, Bound::Whole))
        ->each([c](const std::string&) { c->sides_given = true; });
    cmd->add_option("--size", c->size, "Size of PNG previews, and of SVG drawings (the figure fitted inside)")
        ->type_name("WxH")
        ->each([c](const std::string&) { c->size_given = true; });
    cmd->add_option("--width-scale", c->width_scale,
                    "Multiply every drawn width by this (replaces the grammar's `width_scale`; ABOP's "
                    "!(w) is in pixels: try 0.02)")
        ->transform(number_in(0, 1e6, Bound::Above))
        ->type_name("X");
    cmd->add_option("--view", c->view,
                    "PNG preview from the front (looking along -z, y up), top, side (from +x) or iso (3/4 "
                    "view); default auto: a flat figure face-on, iso otherwise")
        ->type_name("VIEW");
    auto* lines = cmd->add_flag("--lines", c->lines,
                                "PNG: draw branches as lines at least --min-line-width pixels wide instead "
                                "of tubes (default: lines when every tube would be under 1.5 pixels)");
    cmd->add_flag("--tubes", c->tubes, "PNG: draw the meshed tubes only, however thin")->excludes(lines);
    cmd->add_option("--min-line-width", c->min_line_width,
                    "PNG: the narrowest branch drawn, in pixels (default 1; 0 lets thin tubes vanish)")
        ->transform(number_in(0, 100, Bound::From))
        ->type_name("PX");
    cmd->add_option("--max-triangles", c->max_triangles,
                    "Stop before meshing when the mesh is estimated to have more triangles than this "
                    "(default 20 million, about 3 GB while meshing and a 600 MB .glb)")
        ->transform(number_in(1, 1e12, Bound::Whole))
        ->type_name("N");
    auto* nodes = cmd->add_flag("--no-gpu-instancing", c->no_gpu_instancing,
                                "glTF: place each organ and instance by a plain node sharing its mesh, for "
                                "viewers without EXT_mesh_gpu_instancing");
    cmd->add_flag("--flatten", c->flatten,
                  "glTF: bake every placement into one world-space mesh (nothing shared; larger files)")
        ->excludes(nodes);
    cmd->add_option("--camera", c->camera,
                    "Perspective view of PNG previews from this point; with a grammar's `param "
                    "depth_unit`, also the point each placement's view depth is measured from")
        ->type_name("X,Y,Z");
    cmd->add_option("--look-at", c->look_at,
                    "The point the --camera looks at (default: the centre of the plant's bounds)")
        ->type_name("X,Y,Z");
    cmd->add_flag("--no-obstacles", c->no_obstacles,
                  "Leave the environments' obstacles (a climber's walls, say) out of meshes and images");
    add_batch_options(*cmd, c->batch);
    std::string formats = "Output formats:\n";
    for (const auto& f : output_formats()) formats += fmt::format("  {:<11} {}\n", f.extension, f.doc);
    cmd->footer(formats);
    cmd->callback([c, &exit_code] { exit_code = run_main(*c); });
}

} // namespace plant::cli
