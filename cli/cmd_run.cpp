// plant run: derive, interpret with the turtle, mesh and write every requested file.
#include "commands.hpp"

#include "plant/export.hpp"
#include "plant/export_text.hpp"
#include "plant/mesh.hpp"
#include "plant/query.hpp"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <unistd.h>

namespace plant::cli {

namespace fs = std::filesystem;

namespace {

struct RunCmd {
    GrammarOptions g;
    std::vector<std::string> outputs;
    int sides = 8;
    std::string size = "800x800";
};

enum class Format { Glb, Gltf, Obj, Ply, Off, Png, Svg, Txt, Skeleton, MeshSummary };

// Counts and bounds of the meshed scene in a fixed format, for golden files.
std::string mesh_summary(const Scene& s) {
    std::size_t vertices = s.tubes.positions.size(), triangles = s.tubes.triangle_count();
    for (const auto& p : s.prototypes) {
        vertices += p.positions.size();
        triangles += p.triangle_count();
    }
    return fmt::format("vertices {}\ntriangles {}\nprototypes {}\ninstances {}\nbounds {:.4f} {:.4f} {:.4f} {:.4f} "
                       "{:.4f} {:.4f}\n",
                       vertices, triangles, s.prototypes.size(), s.instances.size(), s.bounds_min.x, s.bounds_min.y,
                       s.bounds_min.z, s.bounds_max.x, s.bounds_max.y, s.bounds_max.z);
}

std::optional<Format> format_of(const std::string& path) {
    auto ends = [&](const char* ext) {
        std::string e = ext;
        return path.size() > e.size() && path.compare(path.size() - e.size(), e.size(), e) == 0;
    };
    if (ends(".skel.json")) return Format::Skeleton;
    if (ends(".mesh.txt")) return Format::MeshSummary;
    if (ends(".glb")) return Format::Glb;
    if (ends(".gltf")) return Format::Gltf;
    if (ends(".obj")) return Format::Obj;
    if (ends(".ply")) return Format::Ply;
    if (ends(".off")) return Format::Off;
    if (ends(".png")) return Format::Png;
    if (ends(".svg")) return Format::Svg;
    if (ends(".txt")) return Format::Txt;
    return std::nullopt;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int run_main(RunCmd& c) {
    // check the outputs before doing any work
    int width = 0, height = 0;
    if (std::sscanf(c.size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16 || width > 16384 ||
        height > 16384) {
        std::cerr << fmt::format("plant: --size expects WIDTHxHEIGHT between 16 and 16384, found '{}'\n", c.size);
        return kUsage;
    }
    if (c.outputs.empty()) {
        std::string stem = fs::path(c.g.file).stem().string();
        c.outputs = {"out/" + stem + ".glb", "out/" + stem + ".png"};
    }
    std::vector<Format> formats;
    for (const auto& o : c.outputs) {
        auto f = format_of(o);
        if (!f) {
            std::cerr << fmt::format("plant: cannot tell the format of '{}': use .glb .gltf .obj .ply .off .png .svg "
                                     ".txt .skel.json or .mesh.txt\n",
                                     o);
            return kUsage;
        }
        formats.push_back(*f);
    }
    int exit_code = kOk;
    SourceManager sources;
    auto program = load_program(c.g, sources, exit_code);
    if (!program) return exit_code;
    const bool progress = isatty(2) != 0;
    auto t0 = std::chrono::steady_clock::now();
    DeriveOptions opt = derive_options(c.g);
    TurtleQueryPass queries;
    opt.queries = &queries;
    opt.on_print = [](const std::string& text) { std::cerr << text; };
    opt.on_step = [&](const StepStats& s) {
        if (progress) std::cerr << fmt::format("\rstep {}: {} modules   ", s.step, s.modules) << std::flush;
    };
    Derivation d(*program, opt);
    if (!run_derivation(d, sources, c.g.color)) return kRuntime;
    if (progress) std::cerr << "\r\x1b[K" << std::flush;
    try {
        bool need_skeleton = false, need_scene = false;
        for (Format f : formats) {
            need_skeleton = need_skeleton || f != Format::Txt;
            need_scene = need_scene || (f != Format::Txt && f != Format::Svg && f != Format::Skeleton);
        }
        Skeleton skeleton;
        Scene scene;
        if (need_skeleton) {
            ModuleString interpreted = d.interpreted(d.string());
            skeleton = build_skeleton(*program, interpreted, TurtleOptions{d.default_angle(), d.default_step(),
                                                                           d.default_width()});
        }
        if (need_scene) {
            MeshOptions mo;
            mo.sides = c.sides;
            scene = build_scene(*program, skeleton, mo);
        }
        for (std::size_t k = 0; k < formats.size(); ++k) {
            const std::string& path = c.outputs[k];
            fs::path parent = fs::path(path).parent_path();
            std::error_code ec;
            if (!parent.empty()) fs::create_directories(parent, ec);
            switch (formats[k]) {
            case Format::Glb:
            case Format::Gltf: write_gltf(scene, path); break;
            case Format::Obj:
            case Format::Ply:
            case Format::Off: write_mesh_file(scene, path); break;
            case Format::Png: write_png(scene, path, width, height); break;
            case Format::Svg: write_svg(skeleton, path); break;
            case Format::Skeleton: write_skeleton_json(skeleton, path); break;
            case Format::Txt: write_file_atomically(path, format_string(*program, d.string()) + "\n"); break;
            case Format::MeshSummary: write_file_atomically(path, mesh_summary(scene)); break;
            }
            if (progress) std::cerr << fmt::format("wrote {}\n", path);
        }
        if (progress)
            std::cerr << fmt::format("{} modules, {} triangles, {} organs in {:.0f} ms\n", d.string().size(),
                                     scene.tubes.triangle_count(), scene.instances.size(), ms_since(t0));
    } catch (const RuntimeError& e) {
        std::cerr << render(Diagnostic{Severity::Error, e.span, e.message, {}}, sources, c.g.color);
        return kRuntime;
    } catch (const ExportError& e) {
        std::cerr << "plant: " << e.what() << "\n";
        return kCantCreate;
    }
    return kOk;
}

} // namespace

void setup_run(CLI::App& app, int& exit_code) {
    auto c = std::make_shared<RunCmd>();
    CLI::App* cmd = app.add_subcommand("run", "Grow a grammar and write meshes, images, skeletons or strings");
    add_grammar_options(*cmd, c->g, true);
    cmd->add_option("-o,--output", c->outputs,
                    "Output file, chosen by extension: .glb .gltf .obj .ply .off .png .svg .txt .skel.json "
                    ".mesh.txt (counts and bounds); "
                    "repeat for several (default: out/NAME.glb and out/NAME.png)")
        ->type_name("FILE");
    cmd->add_option("--sides", c->sides, "Vertices around each ring of a branch")->check(CLI::Range(3, 64));
    cmd->add_option("--size", c->size, "Size of PNG previews")->type_name("WxH");
    cmd->callback([c, &exit_code] { exit_code = run_main(*c); });
}

} // namespace plant::cli
