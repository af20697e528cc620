// Reading files a grammar names: regular files only, under a size cap (source.hpp); which folders
// a grammar may read (file_access.hpp); mesh files vetted before OpenMesh reads them
// (mesh_file.hpp); the distance grid's tree against the loop over every triangle.
#include "file_access.hpp"
#include "mesh_file.hpp"
#include "plant/source.hpp"
#include "triangle_mesh.hpp"

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <random>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

using namespace plant;
namespace fs = std::filesystem;

namespace {

fs::path scratch() {
    char name[] = "/tmp/plant-files-XXXXXX";
    REQUIRE(mkdtemp(name));
    return name;
}

} // namespace

TEST_CASE("read_input_file: regular files only, under the cap", "[files]") {
    fs::path dir = scratch();
    std::ofstream(dir / "a.plant") << "axiom: F;\n";
    std::string text;
    CHECK(read_input_file((dir / "a.plant").string(), text) == ReadFailure::None);
    CHECK(text == "axiom: F;\n");
    CHECK(read_input_file((dir / "a.plant").string(), text, 4) == ReadFailure::TooLarge);
    CHECK(read_input_file((dir / "none.plant").string(), text) == ReadFailure::Missing);
    CHECK(read_input_file(dir.string(), text) == ReadFailure::NotRegular);
    CHECK(read_input_file("/dev/zero", text) == ReadFailure::NotRegular);
    REQUIRE(mkfifo((dir / "pipe").c_str(), 0600) == 0);
    CHECK(read_input_file((dir / "pipe").string(), text) == ReadFailure::NotRegular); // and does not block
    // the grammar named on the command line may be a pipe, read under the cap, but not a device
    // (/dev/zero never ends, a terminal waits for typing)
    CHECK(read_input_file("/dev/zero", text, 1000, false) == ReadFailure::NotRegular);
    std::thread writer([&] {
        // opens when the reader below does; one write under PIPE_BUF goes in whole, so the reader
        // stopping at its cap cannot make a later write raise SIGPIPE
        const int fd = ::open((dir / "pipe").c_str(), O_WRONLY);
        if (fd < 0) return;
        const std::string bytes(2000, 'F');
        [[maybe_unused]] const ssize_t n = ::write(fd, bytes.data(), bytes.size());
        ::close(fd);
    });
    CHECK(read_input_file((dir / "pipe").string(), text, 1000, false) == ReadFailure::TooLarge);
    writer.join();
    fs::remove_all(dir);
}

TEST_CASE("FileAccess: the grammar's folder, the library folders and --allow-read", "[files]") {
    fs::path dir = fs::canonical(scratch());
    fs::create_directories(dir / "app");
    fs::create_directories(dir / "lib");
    fs::create_directories(dir / "apple");
    std::ofstream(dir / "lib" / "k.plant") << "const k = 1;\n";
    std::ofstream(dir / "apple" / "x.plant") << "const k = 1;\n";
    fs::create_symlink(dir / "lib" / "k.plant", dir / "app" / "link.plant");
    CompileOptions co;
    FileAccess access((dir / "app" / "main.plant").string(), co);
    CHECK(!access.allowed(FileAccess::identity((dir / "lib" / "k.plant").string())));
    CHECK(!access.allowed(FileAccess::identity((dir / "app" / "link.plant").string()))); // resolved first
    CHECK(!access.allowed(FileAccess::identity((dir / "apple" / "x.plant").string())));  // not under "app"
    CHECK(FileAccess::identity((dir / "app" / "link.plant").string()) == (dir / "lib" / "k.plant").string());
    CHECK(FileAccess::identity((dir / "app" / "none.plant").string()).empty());
    co.allow_read.push_back((dir / "lib").string());
    FileAccess allowed((dir / "app" / "main.plant").string(), co);
    CHECK(allowed.allowed(FileAccess::identity((dir / "app" / "link.plant").string())));
    CHECK(FileAccess::refusal("../x.plant").find("--allow-read") != std::string::npos);
    fs::remove_all(dir);
}

TEST_CASE("vet_mesh_text: counts against the file's size, refused variants", "[files]") {
    std::string off = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    CHECK(vet_mesh_text("off", off).empty());
    std::string lying = "OFF\n1000000000 1 0\n0 0 0\n";
    CHECK(vet_mesh_text("off", lying).find("more than its") != std::string::npos);
    std::string long_face = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n4000000 0 1 2\n";
    CHECK(!vet_mesh_text("off", long_face).empty());
    std::string binary_off = "OFF BINARY\n";
    CHECK(vet_mesh_text("off", binary_off).find("binary OFF") != std::string::npos);
    std::string ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    CHECK(vet_mesh_text("ply", ply).empty());
    std::string no_end = "ply\nformat ascii 1.0\nelement vertex 3\nproperty";
    CHECK(vet_mesh_text("ply", no_end).find("end_header") != std::string::npos);
    std::string binary_ply = "ply\nformat binary_little_endian 1.0\nend_header\n";
    CHECK(vet_mesh_text("ply", binary_ply).find("binary PLY") != std::string::npos);
    std::string ascii_stl = "solid x\nendsolid x\n";
    CHECK(!vet_mesh_text("stl", ascii_stl).empty());
    std::string binary_stl(84 + 50, '\0');
    binary_stl[80] = 1;
    CHECK(vet_mesh_text("stl", binary_stl).empty());
    std::string obj = "mtllib a.mtl\n  mtllib b.mtl\nv 0 0 0\n";
    CHECK(vet_mesh_text("obj", obj).empty());
    CHECK(obj.find("mtllib") == std::string::npos);
    std::string om = "x";
    CHECK(!vet_mesh_text("om", om).empty());
}

TEST_CASE("TriangleTree: the same signed distances, bit for bit, as the loop over every triangle",
          "[files]") {
    std::vector<Triangle> mesh;
    std::string error;
    REQUIRE(load_triangles(std::string(PLANT_TEST_DATA) + "/cube.obj", mesh, "test", error));
    // a soup of random triangles, some sharing corners with the cube (ties at edges and corners)
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.5, 2.5);
    for (int i = 0; i < 300; ++i) {
        glm::dvec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
        if (i % 3 == 0) a = mesh[static_cast<std::size_t>(i) % 12].a;
        glm::dvec3 n = glm::cross(b - a, c - a);
        if (!(glm::length(n) > 0)) continue;
        mesh.push_back({a, b, c, glm::normalize(n)});
    }
    for (const auto& m : {std::vector<Triangle>(mesh.begin(), mesh.begin() + 12), mesh}) {
        TriangleTree tree(m);
        std::size_t checked = 0;
        // grid points on the cube's faces, edges and corners (exact ties), and random points
        for (int z = -4; z <= 8; ++z)
            for (int y = -4; y <= 8; ++y)
                for (int x = -4; x <= 8; ++x) {
                    glm::dvec3 p = glm::dvec3(x, y, z) * 0.25;
                    REQUIRE(tree.signed_distance(p) == signed_distance(m, p));
                    ++checked;
                }
        for (int i = 0; i < 3000; ++i) {
            glm::dvec3 p(u(rng), u(rng), u(rng));
            REQUIRE(tree.signed_distance(p) == signed_distance(m, p));
        }
        CHECK(checked == 13 * 13 * 13);
    }
}

TEST_CASE("distance_grid: refuses a box that is not finite", "[files]") {
    std::vector<Triangle> mesh;
    std::string error;
    REQUIRE(load_triangles(std::string(PLANT_TEST_DATA) + "/cube.obj", mesh, "test", error));
    CHECK(distance_grid(mesh, 0.05, 1e308) == nullptr);
    CHECK(distance_grid(mesh, 1e308, 1.0) != nullptr);
    CHECK(distance_grid(mesh, std::nan(""), 1.0) == nullptr);
    auto g = distance_grid(mesh, 0.25, 0.5);
    REQUIRE(g);
    CHECK(g->n == glm::ivec3(9, 9, 9));
}
