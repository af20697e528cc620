// grow: compile a .plant grammar, derive it, interpret it with the turtle, mesh it and write a
// GLB, through plant's C++ API (docs/api.md).
//   grow GRAMMAR OUT.glb [--stdlib DIR] [--seed N] [--steps N]
// Prints the counts of the result: modules, skeleton axes and organs, vertices, triangles.
#include <plant/compiler.hpp>
#include <plant/derive.hpp>
#include <plant/diagnostics.hpp>
#include <plant/environment_phase.hpp>
#include <plant/environments.hpp>
#include <plant/export.hpp>
#include <plant/mesh.hpp>
#include <plant/skeleton.hpp>
#include <plant/source.hpp>
#include <plant/turtle.hpp>

#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
    if (argc < 3) {
        std::cerr << "usage: grow GRAMMAR OUT.glb [--stdlib DIR] [--seed N] [--steps N]\n";
        return 64;
    }
    std::string stdlib = GROW_STDLIB_DIR;
    plant::DeriveOptions derive;
    for (int k = 3; k + 1 < argc; k += 2) {
        const std::string option = argv[k], value = argv[k + 1];
        if (option == "--stdlib")
            stdlib = value;
        else if (option == "--seed")
            derive.seed = std::strtoull(value.c_str(), nullptr, 10);
        else if (option == "--steps")
            derive.steps = std::atoi(value.c_str());
    }

    // 1. compile: diagnostics come back as data, rendered as file:line:col with a caret
    plant::SourceManager sources;
    plant::Diagnostics diags;
    plant::CompileOptions options;
    options.include_dirs = {stdlib};                      // `import rose;` (after -I-like dirs)
    options.environments = plant::runtime_environments(); // `env` declarations
    auto program = plant::compile_file(sources, argv[1], options, diags);
    std::cerr << plant::render_all(diags, sources);
    if (!program) return 65;

    try {
        // 2. derive, the environments seeing the plant between steps
        plant::TurtleEnvironmentPhase phase;
        derive.environment_phase = &phase;
        plant::Derivation d(*program, derive);
        d.run();
        // 3. interpret with the turtle, 4. mesh
        plant::Skeleton skeleton =
            plant::build_skeleton(*program, d.interpreted(d.string()), plant::turtle_options(d));
        plant::MeshOptions mesh;
        mesh.derivation = &d; // instances take the derivation's seed and limits
        plant::Scene scene = plant::build_scene(*program, skeleton, mesh);
        // 5. export
        plant::write_gltf(scene, argv[2], plant::GltfContainer::Binary);

        std::size_t vertices = scene.tubes.positions.size(), triangles = scene.tubes.triangle_count();
        for (const auto& p : scene.prototypes) {
            vertices += p.positions.size();
            triangles += p.triangle_count();
        }
        std::cout << "modules " << d.string().size() << "\n"
                  << "axes " << skeleton.axes.size() << "\n"
                  << "organs " << skeleton.organs.size() << "\n"
                  << "vertices " << vertices << "\n"
                  << "triangles " << triangles << "\n";
    } catch (const plant::RuntimeError& e) {
        std::cerr << plant::render(plant::Diagnostic{plant::Severity::Error, e.span, e.message, {}}, sources);
        return 70;
    } catch (const plant::ExportError& e) {
        std::cerr << "grow: " << e.what() << "\n";
        return 73;
    }
    return 0;
}
