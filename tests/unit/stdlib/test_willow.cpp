// The weeping willow library (stdlib/willow.plant) against Yan & Chiba's counts and geometry,
// checked through its instances (docs/willow.md): the trees, weeping branches and leaves the
// turtle placed, each instance derived as build_scene derives it and its skeleton put in place by
// the placements' transforms; and the scene and GLB build_scene's prototypes make.
#include "helpers.hpp"
#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/export.hpp"
#include "plant/instances.hpp"
#include "plant/mesh.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"
#include "runtime/parse_glb.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <glm/glm.hpp>
#include <tiny_gltf.h>

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string>
#include <tuple>
#include <vector>

using namespace plant;
using plant::test::parse_glb;

namespace {

const std::string kLibrary = std::string(PLANT_SOURCE_DIR) + "/stdlib/willow.plant";
const std::string kFigures = std::string(PLANT_SOURCE_DIR) + "/grammars/willow";

using Defines = std::vector<std::pair<std::string, std::string>>;

// One weeping branch as the turtle drew it, in world space: the cylinders' end points (points[0]
// is where it leaves its parent) and the frames of the leaves hanging from it.
struct WeepingBranch {
    std::vector<glm::dvec3> points;
    std::vector<glm::dmat4> leaves;
    std::size_t tree = 0; // the top-level placement it belongs to
};

// A top-level placement (a tree) and the view depth build_scene gave it.
struct Tree {
    glm::dvec3 position{0.0};
    double view_depth = 0;
};

struct Grown {
    std::unique_ptr<test::Compiled> compiled;
    Scene scene;
    std::vector<Tree> trees;
    std::vector<WeepingBranch> branches;
    int leaves = 0;     // every `leaf` organ of the plant, every placement counted
    int unattached = 0; // leaves not at the tip of a weeping-branch cylinder
    int catkins = 0;
    // the first tree's Shoot modules (its instance derivation's string)
    std::map<int, int> shoots_by_generation;
    std::map<int, std::vector<double>> shoot_widths, shoot_lengths;
};

// Walks the placements: each instance the turtle placed is derived as build_scene derives it
// (instance_derivation with the outer seed, once per tuple and view depth) and its skeleton is
// put in place by the placement's transform; a placement inside an instance inherits its view
// depth. A weeping branch is an axis drawn with G (stdlib/willow.plant), a leaf belongs to the
// branch whose cylinder tip it stands on in the same skeleton.
class Walker {
  public:
    Walker(Grown& g, std::uint64_t seed) : g_(g), seed_(seed) {}

    void walk(const Program& p, const Skeleton& sk, const glm::dmat4& to_world, double level,
              std::size_t tree) {
        std::map<std::array<double, 3>, std::size_t> tip_of; // cylinder tip (own frame) -> branch
        for (const auto& ax : sk.axes) {
            if (ax.points.size() < 2 || sk.module_name(ax.points[1]) != "G") continue;
            WeepingBranch b;
            b.tree = tree;
            for (const auto& pt : ax.points)
                b.points.push_back(glm::dvec3(to_world * glm::dvec4(pt.position, 1.0)));
            for (std::size_t k = 1; k < ax.points.size(); ++k) {
                const glm::dvec3& q = ax.points[k].position;
                tip_of[{q.x, q.y, q.z}] = g_.branches.size();
            }
            g_.branches.push_back(std::move(b));
        }
        for (const auto& o : sk.organs) {
            if (o.shape.kind == OrganKind::Instance) {
                const Skeleton& inner = derived(p, o.shape, level);
                const InstanceDef& def = (*p.instances)[static_cast<std::size_t>(o.shape.instance)];
                walk(*def.program, inner, to_world * o.transform, level, tree);
                continue;
            }
            if (o.shape.kind != OrganKind::Surface) continue;
            if (o.shape.name == "catkin") ++g_.catkins;
            if (o.shape.name != "leaf") continue;
            ++g_.leaves;
            const glm::dvec3 at(o.transform[3]);
            auto it = tip_of.find({at.x, at.y, at.z});
            if (it == tip_of.end())
                ++g_.unattached;
            else
                g_.branches[it->second].leaves.push_back(to_world * o.transform);
        }
    }

    std::size_t derivations() const { return memo_.size(); }

  private:
    const Skeleton& derived(const Program& p, const OrganShape& shape, double level) {
        auto key = std::make_tuple(shape.instance, shape.args, level);
        if (auto it = memo_.find(key); it != memo_.end()) return it->second;
        const InstanceDef& def = (*p.instances)[static_cast<std::size_t>(shape.instance)];
        Derivation d = instance_derivation(def, shape.instance, shape.args, level, seed_, DeriveOptions{});
        d.run();
        if (shape.name == "Willow" && g_.shoots_by_generation.empty()) count_shoots(*def.program, d.string());
        return memo_.emplace(key, build_skeleton(*def.program, d.interpreted(d.string()), turtle_options(d)))
            .first->second;
    }

    void count_shoots(const Program& p, const ModuleString& s) {
        for (std::size_t i = 0; i < s.size(); ++i) {
            if (p.symbols[s.symbol(i)].name != "Shoot") continue;
            // Shoot(g, n, len, w, d, s)
            const int gen = static_cast<int>(s.args(i)[0]);
            ++g_.shoots_by_generation[gen];
            g_.shoot_lengths[gen].push_back(s.args(i)[1] * s.args(i)[2]);
            g_.shoot_widths[gen].push_back(s.args(i)[3]);
        }
    }

    Grown& g_;
    std::uint64_t seed_;
    std::map<std::tuple<int, std::vector<double>, double>, Skeleton> memo_;
};

// Derives a grammar (a file, or text when `path` is empty), builds its scene as `plant run` does
// (with the camera, if any) and walks its placements.
Grown grow(const std::string& path, const Defines& defines = {}, std::optional<glm::dvec3> camera = {},
           const std::string& text = {}) {
    Grown g;
    CompileOptions co;
    co.defines = defines;
    if (path.empty()) {
        g.compiled = test::compile(text, co);
    } else {
        g.compiled = std::make_unique<test::Compiled>();
        g.compiled->program = compile_file(g.compiled->sources, path, co, g.compiled->diags);
    }
    INFO(g.compiled->rendered());
    REQUIRE(g.compiled->program);
    const Program& p = *g.compiled->program;
    Derivation d(p, DeriveOptions{});
    d.run();
    const Skeleton sk = build_skeleton(p, d.interpreted(d.string()), turtle_options(d));
    MeshOptions mo;
    mo.derivation = &d;
    mo.camera = camera;
    g.scene = build_scene(p, sk, mo);
    // the top-level placements, in the order build_scene placed them, at its view depths
    Walker w(g, d.seed());
    std::size_t k = 0;
    for (const auto& o : sk.organs) {
        if (o.shape.kind != OrganKind::Instance) continue;
        REQUIRE(k < g.scene.scene_instances.size());
        const SceneSource& src = g.scene.scene_prototype_sources.at(g.scene.scene_instances[k++].prototype);
        g.trees.push_back(Tree{glm::dvec3(o.transform[3]), src.view_depth});
        Skeleton one;
        one.organs.push_back(o);
        w.walk(p, one, glm::dmat4(1.0), src.view_depth, g.trees.size() - 1);
    }
    // every distinct tuple the walk derived, build_scene derived once
    CHECK(w.derivations() == g.scene.instance_derivations);
    return g;
}

double degrees_between(const glm::dvec3& a, const glm::dvec3& b) {
    double c = glm::dot(glm::normalize(a), glm::normalize(b));
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi;
}

const glm::dvec3 kDown(0, -1, 0);

// Yan & Chiba, section 3.2: every weeping branch lies in the plane of its first two cylinders
// and its last cylinder points at the ground; section 3.2: every leaf grows toward the ground.
void check_geometry(const Grown& g) {
    REQUIRE(!g.branches.empty());
    for (std::size_t i = 0; i < g.branches.size(); ++i) {
        const auto& p = g.branches[i].points;
        INFO(fmt::format("weeping branch {}", i));
        REQUIRE(p.size() >= 3);
        glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[1]);
        REQUIRE(glm::length(n) > 1e-9);
        n = glm::normalize(n);
        double off = 0;
        for (const auto& q : p) off = std::max(off, std::abs(glm::dot(q - p[0], n)));
        CHECK(off <= 1e-6);
        CHECK(degrees_between(p.back() - p[p.size() - 2], kDown) <= 5.0);
        for (const auto& leaf : g.branches[i].leaves)
            CHECK(degrees_between(glm::dvec3(leaf[1]), kDown) <= 0.01); // the leaf's axis (heading)
    }
}

// Yan & Chiba, section 3.3: l leaves on each of m weeping branches on each lignified branch of
// the two youngest generations.
long paper_count(long l, long m, int t) {
    return l * m * ((1L << (t - 1)) + (1L << (t - 2)));
}

// Leaf placements in the scene drawn out (flatten), as an exporter that bakes everything sees them.
long flat_leaves(const Scene& scene) {
    const Scene flat = flatten(scene);
    long n = 0;
    for (const Instance& i : flat.instances) {
        const std::string& name = flat.prototype_names.at(i.prototype);
        n += name == "leaf" || (name.size() > 5 && name.compare(name.size() - 5, 5, "/leaf") == 0);
    }
    return n;
}

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

} // namespace

TEST_CASE("willow: l m (2^(t-1) + 2^(t-2)) leaves at view depth 0 for t = 3 to 8", "[willow]") {
    for (int t = 3; t <= 8; ++t) {
        INFO(fmt::format("t = {}", t));
        Grown g = grow(kLibrary, {{"t", std::to_string(t)}, {"l", "12"}, {"m", "5"}});
        CHECK(static_cast<long>(g.branches.size()) == paper_count(1, 5, t));
        CHECK(g.leaves == paper_count(12, 5, t));
        CHECK(flat_leaves(g.scene) == paper_count(12, 5, t));
        CHECK(g.unattached == 0);
        for (const auto& b : g.branches) CHECK(b.leaves.size() == 12);
        check_geometry(g);
        if (t == 8) CHECK(g.leaves == 11520);
        // one tree and one weeping branch, each derived once
        CHECK(g.scene.instance_derivations == 2);
    }
}

TEST_CASE("willow: round(l (1 - D/20)) leaves on every weeping branch at view depth D", "[willow]") {
    const int expected[] = {12, 9, 6, 3, 0};
    for (int i = 0; i < 5; ++i) {
        const int depth = 5 * i;
        INFO(fmt::format("view depth {}", depth));
        Grown g = grow(kLibrary, {{"t", "6"}, {"view_depth", std::to_string(depth)}});
        CHECK(static_cast<long>(g.branches.size()) == paper_count(1, 5, 6));
        for (const auto& b : g.branches) {
            CHECK(b.points.size() == 13); // the branch keeps its 12 cylinders; only leaves go
            CHECK(static_cast<int>(b.leaves.size()) == expected[i]);
        }
        CHECK(g.unattached == 0);
        // LeafNum = MaxLeafNum (1 - Depth / MaxDepth), an integer at these depths
        CHECK(g.leaves == paper_count(expected[i], 5, 6));
        CHECK(g.leaves == std::lround(paper_count(12, 5, 6) * (1 - depth / 20.0)));
        CHECK(flat_leaves(g.scene) == g.leaves);
        check_geometry(g);
    }
}

TEST_CASE("willow: the growth model branches dichotomously and the hormone sets shoot lengths", "[willow]") {
    Grown g = grow(kLibrary, {{"t", "8"}});
    for (int gen = 1; gen <= 8; ++gen) CHECK(g.shoots_by_generation[gen] == (1 << (gen - 1)));
    CHECK(g.shoots_by_generation.size() == 8);
    // apical dominance: in the youngest generation some buds broke late and grew short shoots
    const auto& len = g.shoot_lengths[8];
    REQUIRE(!len.empty());
    CHECK(*std::min_element(len.begin(), len.end()) < 0.5 * *std::max_element(len.begin(), len.end()));
    // pipe model: the trunk's cross-section is the sum of the youngest shoots'
    double tips = 0;
    for (double w : g.shoot_widths[8]) tips += w * w;
    CHECK(g.shoot_widths[1][0] == Approx(std::sqrt(tips)).epsilon(1e-9));
}

TEST_CASE("willow: every figure grammar keeps the paper's geometry", "[willow]") {
    for (const char* fig : {"fig05_near", "fig05_far", "fig06a", "fig06b", "fig07a", "fig07d", "row"}) {
        INFO(fig);
        Grown g = grow(kFigures + "/" + fig + ".plant");
        check_geometry(g);
        CHECK(g.unattached == 0);
        CHECK(flat_leaves(g.scene) == g.leaves);
        const std::string f = fig;
        if (f == "fig07d") CHECK(g.leaves == 0);
        if (f == "fig05_near") CHECK(g.leaves == paper_count(9, 5, 8)); // 8,640
        if (f == "fig05_far") CHECK(g.leaves == paper_count(6, 5, 8));  // 5,760
        if (f == "row") CHECK(g.leaves == 6 * paper_count(9, 5, 7));
    }
}

TEST_CASE("willow: the pussy willow carries a catkin on every weeping-branch cylinder", "[willow]") {
    Grown g = grow(kFigures + "/fig06b.plant");
    std::size_t cylinders = 0;
    for (const auto& b : g.branches) cylinders += b.points.size() - 1;
    CHECK(g.catkins == static_cast<int>(cylinders));
    CHECK(g.catkins > 0);
}

TEST_CASE("willow: the t = 8 GLB holds one weeping-branch mesh and one leaf mesh, 5x smaller than flattened",
          "[willow]") {
    for (int t : {6, 8}) {
        INFO(fmt::format("t = {}", t));
        Grown g = grow(kLibrary, {{"t", std::to_string(t)}});
        const std::string instanced = gltf_bytes(g.scene, GltfContainer::Binary, "x.glb");
        const tinygltf::Model model = parse_glb(instanced);
        int branch_meshes = 0, leaf_meshes = 0;
        for (const auto& mesh : model.meshes) {
            branch_meshes +=
                mesh.name.find("WeepingBranch(12)") != std::string::npos && ends_with(mesh.name, "/tubes");
            leaf_meshes += ends_with(mesh.name, "/leaf");
        }
        CHECK(branch_meshes == 1); // one level of detail used
        CHECK(leaf_meshes == 1);
        // the leaf mesh is placed once per leaf by one instanced node
        int leaf_nodes = 0;
        for (const auto& node : model.nodes) {
            if (!ends_with(node.name, "/leaf")) continue;
            ++leaf_nodes;
            REQUIRE(node.extensions.count("EXT_mesh_gpu_instancing"));
            const int acc = node.extensions.at("EXT_mesh_gpu_instancing")
                                .Get("attributes")
                                .Get("TRANSLATION")
                                .GetNumberAsInt();
            CHECK(static_cast<long>(model.accessors[std::size_t(acc)].count) == paper_count(12, 5, t));
        }
        CHECK(leaf_nodes == 1);
        if (t == 8) {
            const std::string flat = gltf_bytes(g.scene, GltfContainer::Binary, "x.glb", GltfLayout::Baked);
            INFO(fmt::format("instanced {} bytes, flattened {} bytes", instanced.size(), flat.size()));
            CHECK(instanced.size() * 5 <= flat.size());
        }
    }
}

TEST_CASE("willow: a tree is derived once per distinct tuple however often it is placed", "[willow]") {
    // five trees, two individuals: two tree derivations and the one weeping branch
    Grown g = grow({}, {}, {},
                   "import willow with { t = 5 };\n"
                   "axiom: Willow(t, 1) [ @M(20, 0, 0) /(90) Willow(t, 1) ] [ @M(40, 0, 0) Willow(t, 2) ]\n"
                   "       [ @M(60, 0, 0) /(45) Willow(t, 1) ] [ @M(80, 0, 0) Willow(t, 2) ];\n");
    CHECK(g.trees.size() == 5);
    CHECK(g.scene.instance_derivations == 3);
    CHECK(g.scene.scene_prototypes.size() == 2);
    CHECK(g.scene.scene_instances.size() == 5);
    CHECK(g.leaves == 5 * paper_count(12, 5, 5));
    CHECK(flat_leaves(g.scene) == g.leaves);
    check_geometry(g);
}

TEST_CASE(
    "willow: in the receding row seen with a camera, leaves per weeping branch never increase with distance",
    "[willow]") {
    const glm::dvec3 camera(12, 4, 16); // grammars/willow/row.plant's command line
    Grown g = grow(kFigures + "/row.plant", {}, camera);
    REQUIRE(g.trees.size() >= 5);
    // leaves per weeping branch, per tree, and the trees by distance from the camera
    std::vector<std::set<std::size_t>> per_tree(g.trees.size());
    for (const auto& b : g.branches) per_tree[b.tree].insert(b.leaves.size());
    std::vector<std::size_t> order(g.trees.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return glm::distance(g.trees[a].position, camera) < glm::distance(g.trees[b].position, camera);
    });
    std::set<double> levels;
    for (std::size_t k = 0; k < order.size(); ++k) {
        const std::size_t i = order[k];
        INFO(fmt::format("tree {} at {:.1f} m, view depth {}", i, glm::distance(g.trees[i].position, camera),
                         g.trees[i].view_depth));
        REQUIRE(per_tree[i].size() == 1); // every weeping branch of a tree is the same one
        levels.insert(g.trees[i].view_depth);
        if (k == 0) continue;
        const std::size_t nearer = order[k - 1];
        CHECK(g.trees[i].view_depth >= g.trees[nearer].view_depth);
        CHECK(*per_tree[i].begin() <= *per_tree[nearer].begin());
    }
    // the row spans several levels, the farthest tree carries fewer leaves than the nearest
    CHECK(levels.size() >= 4);
    CHECK(*per_tree[order.back()].begin() < *per_tree[order.front()].begin());
    check_geometry(g);
    CHECK(g.unattached == 0);
    // one tree derivation and one weeping branch per (tree, level): the weeping branch is derived
    // once per level used, and the GLB still holds one weeping-branch mesh and one leaf mesh (the
    // tubes are the same at every level: only leaves go, Yan & Chiba 3.3)
    std::size_t tree_prototypes = 0;
    for (const auto& s : g.scene.scene_prototype_sources) tree_prototypes += s.instance == "Willow";
    CHECK(tree_prototypes == g.trees.size());
    CHECK(g.scene.instance_derivations == g.trees.size() + levels.size());
    const tinygltf::Model model = parse_glb(gltf_bytes(g.scene, GltfContainer::Binary, "row.glb"));
    int branch_meshes = 0, leaf_meshes = 0;
    for (const auto& mesh : model.meshes) {
        branch_meshes +=
            mesh.name.find("WeepingBranch(12)") != std::string::npos && ends_with(mesh.name, "/tubes");
        leaf_meshes += ends_with(mesh.name, "/leaf");
    }
    CHECK(branch_meshes >= 1);
    CHECK(branch_meshes <= static_cast<int>(levels.size()));
    CHECK(leaf_meshes == 1);
}

TEST_CASE("willow: an importing file's surface leaf replaces the leaf every weeping branch places",
          "[willow]") {
    auto leaf_corners = [](const Scene& scene) {
        const Scene flat = flatten(scene);
        std::set<std::size_t> corners;
        for (const Instance& i : flat.instances)
            if (ends_with(flat.prototype_names.at(i.prototype), "/leaf"))
                corners.insert(flat.prototypes[i.prototype].positions.size());
        return corners;
    };
    Grown lance = grow({}, {}, {}, "import willow with { t = 4 };\n");
    Grown mine = grow({}, {}, {},
                      "import willow with { t = 4 };\n"
                      "surface leaf = polygon(vec3(0, 0, 0), vec3(0.1, 0.5, 0), vec3(0, 1, 0));\n");
    CHECK(mine.leaves == paper_count(12, 5, 4));
    CHECK(flat_leaves(mine.scene) == mine.leaves);
    const auto a = leaf_corners(lance.scene), b = leaf_corners(mine.scene);
    REQUIRE(a.size() == 1); // one leaf mesh
    REQUIRE(b.size() == 1);
    CHECK(*b.begin() < *a.begin()); // a triangle, not the 12-corner lance
}
