// Meshing throughput (issue: at least 20 million triangles per second on one thread, flat
// buffers at most 40 bytes per triangle, counted as the memory the buffers hold: capacity, not size)
// on a large tree: ABOP Fig. 2.7 at n = 14, 8 sides.
//   plant_mesh_bench GRAMMAR [STEPS] [SIDES] [REPEATS]
#include "grown.hpp"
#include "plant/mesh.hpp"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

using namespace plant;

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: plant_mesh_bench GRAMMAR [STEPS] [SIDES] [REPEATS]\n");
        return 64;
    }
    int steps = argc > 2 ? std::atoi(argv[2]) : 14;
    int sides = argc > 3 ? std::atoi(argv[3]) : 8;
    int repeats = argc > 4 ? std::atoi(argv[4]) : 5;
    bench::Grown g;
    if (!bench::grow(argv[1], steps, 1, g)) return 65;
    const Skeleton& sk = g.skeleton;
    MeshOptions mo;
    mo.sides = sides;
    double best = 1e300;
    Scene scene;
    for (int r = 0; r < repeats; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        scene = build_scene(*g.program, sk, mo);
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        best = std::min(best, s);
    }
    const MeshPart& t = scene.tubes;
    double tris = static_cast<double>(t.triangle_count());
    double bytes = static_cast<double>(
        t.positions.capacity() * sizeof(glm::vec3) + t.normals.capacity() * sizeof(glm::vec3) +
        t.uvs.capacity() * sizeof(glm::vec2) + t.indices.capacity() * sizeof(std::uint32_t));
    std::printf(
        "meshing modules=%zu axes=%zu triangles=%.0f best_ms=%.3f mtri_per_s=%.2f bytes_per_triangle=%.1f\n",
        g.modules, sk.axes.size(), tris, best * 1e3, tris / best / 1e6, bytes / tris);
    return 0;
}
