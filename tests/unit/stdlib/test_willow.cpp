// The weeping willow library (stdlib/willow.plant) against Yan & Chiba's counts and geometry,
// checked on the skeleton the turtle draws (docs/willow.md).
#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <glm/glm.hpp>

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

using namespace plant;

namespace {

const std::string kLibrary = std::string(PLANT_SOURCE_DIR) + "/stdlib/willow.plant";
const std::string kFigures = std::string(PLANT_SOURCE_DIR) + "/grammars/willow";

using Defines = std::vector<std::pair<std::string, std::string>>;

struct Grown {
    Skeleton skeleton;
    std::string string;
    std::map<int, int> shoots_by_generation; // Shoot modules in the derived string
    std::map<int, std::vector<double>> shoot_widths, shoot_lengths;
};

Grown grow(const std::string& path, const Defines& defines = {}) {
    SourceManager sources;
    Diagnostics diags;
    CompileOptions co;
    co.defines = defines;
    auto program = compile_file(sources, path, co, diags);
    INFO(render_all(diags, sources));
    REQUIRE(program);
    Derivation d(*program, DeriveOptions{});
    d.run();
    Grown g;
    g.string = format_string(*program, d.string(), false);
    g.skeleton = build_skeleton(*program, d.interpreted(d.string()), turtle_options(d));
    const ModuleString& s = d.string();
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (program->symbols[s.sym[i]].name != "Shoot") continue;
        // Shoot(g, n, len, w, d, s)
        int gen = static_cast<int>(s.args(i)[0]);
        ++g.shoots_by_generation[gen];
        g.shoot_lengths[gen].push_back(s.args(i)[1] * s.args(i)[2]);
        g.shoot_widths[gen].push_back(s.args(i)[3]);
    }
    return g;
}

// One weeping branch as the turtle drew it: the cylinders' end points (points[0] is where it
// leaves its parent) and the frames of the leaves hanging from it.
struct WeepingBranch {
    std::vector<glm::dvec3> points;
    std::vector<glm::dmat4> leaves;
};

struct Crown {
    std::vector<WeepingBranch> branches;
    int leaves = 0;     // every `leaf` organ of the tree
    int unattached = 0; // leaves not at the tip of a weeping-branch cylinder
};

// Every weeping branch of a tree and its leaves, read off the skeleton: a weeping branch is an
// axis drawn with G (stdlib/willow.plant), a leaf belongs to the branch whose cylinder tip it
// stands on. This is the one place that knows how a weeping branch is represented: when weeping
// branches become instances it walks the placements instead (each placement's transform applied
// to its prototype's skeleton) and the checks below stay as they are.
Crown weeping_branches(const Skeleton& sk) {
    Crown c;
    std::map<std::array<double, 3>, std::size_t> tip_of; // cylinder tip -> branch
    for (const auto& ax : sk.axes) {
        if (ax.points.size() < 2 || ax.points[1].module != "G") continue;
        WeepingBranch b;
        for (const auto& p : ax.points) b.points.push_back(p.position);
        for (std::size_t k = 1; k < b.points.size(); ++k)
            tip_of[{b.points[k].x, b.points[k].y, b.points[k].z}] = c.branches.size();
        c.branches.push_back(std::move(b));
    }
    for (const auto& o : sk.organs) {
        if (o.shape.kind != OrganKind::Surface || o.shape.name != "leaf") continue;
        ++c.leaves;
        glm::dvec3 at(o.transform[3]);
        auto it = tip_of.find({at.x, at.y, at.z});
        if (it == tip_of.end())
            ++c.unattached;
        else
            c.branches[it->second].leaves.push_back(o.transform);
    }
    return c;
}

double degrees_between(const glm::dvec3& a, const glm::dvec3& b) {
    double c = glm::dot(glm::normalize(a), glm::normalize(b));
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi;
}

const glm::dvec3 kDown(0, -1, 0);

// Yan & Chiba, section 3.2: every weeping branch lies in the plane of its first two cylinders
// and its last cylinder points at the ground; section 3.2: every leaf grows toward the ground.
void check_geometry(const Crown& c) {
    REQUIRE(!c.branches.empty());
    for (std::size_t i = 0; i < c.branches.size(); ++i) {
        const auto& p = c.branches[i].points;
        INFO(fmt::format("weeping branch {}", i));
        REQUIRE(p.size() >= 3);
        glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[1]);
        REQUIRE(glm::length(n) > 1e-9);
        n = glm::normalize(n);
        double off = 0;
        for (const auto& q : p) off = std::max(off, std::abs(glm::dot(q - p[0], n)));
        CHECK(off <= 1e-6);
        CHECK(degrees_between(p.back() - p[p.size() - 2], kDown) <= 5.0);
        for (const auto& leaf : c.branches[i].leaves)
            CHECK(degrees_between(glm::dvec3(leaf[1]), kDown) <= 0.01); // the leaf's axis (heading)
    }
}

// Yan & Chiba, section 3.3: l leaves on each of m weeping branches on each lignified branch of
// the two youngest generations.
long paper_count(long l, long m, int t) {
    return l * m * ((1L << (t - 1)) + (1L << (t - 2)));
}

} // namespace

TEST_CASE("willow: l m (2^(t-1) + 2^(t-2)) leaves at view depth 0 for t = 3 to 8", "[willow]") {
    for (int t = 3; t <= 8; ++t) {
        INFO(fmt::format("t = {}", t));
        Grown g = grow(kLibrary, {{"t", std::to_string(t)}, {"l", "12"}, {"m", "5"}});
        Crown c = weeping_branches(g.skeleton);
        CHECK(static_cast<long>(c.branches.size()) == paper_count(1, 5, t));
        CHECK(c.leaves == paper_count(12, 5, t));
        CHECK(c.unattached == 0);
        for (const auto& b : c.branches) CHECK(b.leaves.size() == 12);
        check_geometry(c);
        if (t == 8) CHECK(c.leaves == 11520);
    }
}

TEST_CASE("willow: round(l (1 - D/20)) leaves on every weeping branch at view depth D", "[willow]") {
    const int expected[] = {12, 9, 6, 3, 0};
    for (int i = 0; i < 5; ++i) {
        const int depth = 5 * i;
        INFO(fmt::format("view depth {}", depth));
        Grown g = grow(kLibrary, {{"t", "6"}, {"view_depth", std::to_string(depth)}});
        Crown c = weeping_branches(g.skeleton);
        CHECK(static_cast<long>(c.branches.size()) == paper_count(1, 5, 6));
        for (const auto& b : c.branches) {
            CHECK(b.points.size() == 13); // the branch keeps its 12 cylinders; only leaves go
            CHECK(static_cast<int>(b.leaves.size()) == expected[i]);
        }
        CHECK(c.unattached == 0);
        // LeafNum = MaxLeafNum (1 - Depth / MaxDepth), an integer at these depths
        CHECK(c.leaves == paper_count(expected[i], 5, 6));
        CHECK(c.leaves == std::lround(paper_count(12, 5, 6) * (1 - depth / 20.0)));
        check_geometry(c);
    }
}

TEST_CASE("willow: the growth model branches dichotomously and the hormone sets shoot lengths", "[willow]") {
    Grown g = grow(kLibrary, {{"t", "8"}});
    for (int gen = 1; gen <= 8; ++gen) CHECK(g.shoots_by_generation[gen] == (1 << (gen - 1)));
    CHECK(g.shoots_by_generation.size() == 8);
    // apical dominance: in the youngest generation some buds broke late and grew short shoots
    const auto& len = g.shoot_lengths[8];
    CHECK(*std::min_element(len.begin(), len.end()) < 0.5 * *std::max_element(len.begin(), len.end()));
    // pipe model: the trunk's cross-section is the sum of the youngest shoots'
    double tips = 0;
    for (double w : g.shoot_widths[8]) tips += w * w;
    CHECK(g.shoot_widths[1][0] == Approx(std::sqrt(tips)).epsilon(1e-9));
}

TEST_CASE("willow: every figure grammar keeps the paper's geometry", "[willow]") {
    for (const char* fig : {"fig05_near", "fig06a", "fig06b", "fig07a", "fig07d", "row"}) {
        INFO(fig);
        Grown g = grow(kFigures + "/" + fig + ".plant");
        Crown c = weeping_branches(g.skeleton);
        check_geometry(c);
        CHECK(c.unattached == 0);
        if (std::string(fig) == "fig07d") CHECK(c.leaves == 0);
        if (std::string(fig) == "fig05_near") CHECK(c.leaves == paper_count(9, 5, 8));
        if (std::string(fig) == "row") CHECK(c.leaves == 5 * paper_count(9, 5, 7));
    }
}

TEST_CASE("willow: the pussy willow carries a catkin on every weeping-branch cylinder", "[willow]") {
    Grown g = grow(kFigures + "/fig06b.plant");
    Crown c = weeping_branches(g.skeleton);
    int catkins = 0;
    for (const auto& o : g.skeleton.organs)
        catkins += o.shape.kind == OrganKind::Surface && o.shape.name == "catkin";
    std::size_t cylinders = 0;
    for (const auto& b : c.branches) cylinders += b.points.size() - 1;
    CHECK(catkins == static_cast<int>(cylinders));
    CHECK(catkins > 0);
}
