// The bonsai library (stdlib/bonsai.plant, docs/bonsai.md) and its styles in grammars/bonsai/,
// checked on the skeleton the turtle draws: the branches start inside the crown's envelope
// (Boudon et al. 2003, section 3), the formal upright trunk stands straight and the cascade's
// trunk falls below the pot's rim.
#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
#include "plant/graph.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>
#include <glm/glm.hpp>

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

using namespace plant;

namespace {

const std::string kRoot = PLANT_SOURCE_DIR;

struct Bonsai {
    std::unique_ptr<Program> program;
    Skeleton skeleton;

    // asks the environment `env` its method `name` at p
    double ask(const std::string& env, const std::string& name, const glm::dvec3& p) const {
        for (const auto& e : program->environments) {
            if (e.name != env) continue;
            REQUIRE(e.initial);
            const EnvMethod* m = e.kind->method(name);
            REQUIRE(m);
            double args[3] = {p.x, p.y, p.z}, r[3] = {0, 0, 0};
            e.initial->query(m->index, args, r);
            return r[0];
        }
        FAIL("no environment " << env);
        return 0;
    }
    // the plant's silhouette: the graph root's `crown` (placed as written)
    double crown_level(const glm::dvec3& p) const {
        const int k = program->graph.find("crown");
        REQUIRE(k >= 0);
        return program->graph.params[static_cast<std::size_t>(k)].silhouette->envelope.level(p);
    }
    std::unique_ptr<Derivation> derivation;
    const SkeletonAxis& trunk() const {
        REQUIRE(!skeleton.axes.empty());
        REQUIRE(skeleton.axes[0].parent == -1);
        return skeleton.axes[0];
    }
};

Bonsai grow(const std::string& path, const std::string& edits = "") {
    SourceManager sources;
    Diagnostics diags;
    CompileOptions co;
    co.environments = runtime_environments();
    Bonsai b;
    b.program = compile_file(sources, path, co, diags);
    INFO(render_all(diags, sources));
    REQUIRE(b.program);
    TurtleEnvironmentPhase phase;
    DeriveOptions opt;
    opt.environment_phase = &phase;
    if (!edits.empty()) {
        opt.edits = parse_edits(*b.program, sources, sources.add("test.edits", edits), diags);
        INFO(render_all(diags, sources));
        REQUIRE(opt.edits);
    }
    b.derivation = std::make_unique<Derivation>(*b.program, opt);
    Derivation& d = *b.derivation;
    d.run();
    b.skeleton = build_skeleton(*b.program, d.interpreted(d.string()), turtle_options(d));
    return b;
}

// the highest vertex of the pot's mesh: the top of its rim
double pot_rim() {
    std::ifstream in(kRoot + "/stdlib/meshes/pot.obj");
    REQUIRE(in);
    double top = -std::numeric_limits<double>::infinity();
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream s(line);
        std::string tag;
        double x, y, z;
        if (s >> tag && tag == "v" && s >> x >> y >> z) top = std::max(top, y);
    }
    return top;
}

} // namespace

// Every branch (an axis with a parent) starts inside the crown: its branching point has level at
// most 1 + 1e-9 (the grammar grows a bud only where crown.contains(p), and the turtle redraws
// the same point).
TEST_CASE("bonsai: every branch point lies inside the crown's envelope", "[bonsai]") {
    for (const char* file :
         {"/stdlib/bonsai.plant", "/grammars/bonsai/chokkan.plant", "/grammars/bonsai/kengai.plant",
          "/grammars/bonsai/bunjingi.plant", "/grammars/bonsai/nejikan.plant",
          "/grammars/bonsai/fukinagashi.plant", "/grammars/bonsai/sankan.plant"}) {
        INFO(file);
        Bonsai b = grow(kRoot + file);
        int branches = 0;
        for (const auto& axis : b.skeleton.axes) {
            if (axis.parent < 0 || axis.points.size() < 2) continue;
            ++branches;
            const glm::dvec3 p = axis.points[0].position;
            INFO("branch point " << p.x << " " << p.y << " " << p.z);
            CHECK(b.crown_level(p) <= 1 + 1e-9);
        }
        // (bunjingi, the literati style, has a few branches at the top only)
        CHECK(branches >= (std::string(file).find("bunjingi") != std::string::npos ? 6 : 20));
        // the trunk stands in the pot
        CHECK(b.ask("pot", "inside", b.trunk().points.front().position) == 1);
    }
}

TEST_CASE("bonsai: chokkan's trunk tip is within 10 degrees of vertical above its base", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/chokkan.plant");
    const auto& pts = b.trunk().points;
    const glm::dvec3 rise = pts.back().position - pts.front().position;
    CHECK(rise.y > 0.5); // the whole trunk, not a piece of it
    const double angle = std::acos(glm::normalize(rise).y) * 180 / std::numbers::pi;
    CHECK(angle < 10);
}

TEST_CASE("bonsai: kengai's trunk tip falls below the pot's rim", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/kengai.plant");
    const double rim = pot_rim();
    CHECK(rim == Approx(0.012));
    const auto& pts = b.trunk().points;
    CHECK(pts.front().position.y < rim); // it starts in the soil
    CHECK(pts.back().position.y < rim - 0.1);
    // and rises over the rim before it falls
    double top = -1;
    for (const auto& p : pts) top = std::max(top, p.position.y);
    CHECK(top > 0.15);
}

// Fig. 8 in the library: each first-order branch's silhouette is placed with its T on the
// plant's envelope (|level - 1| < 1e-9), and a branch's length comes from it.
TEST_CASE("bonsai: each first-order branch's silhouette T lies on the plant's envelope", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/chokkan.plant");
    const DecompositionGraph& g = *b.derivation->run_state().graph();
    const int crown = g.decl().find("crown");
    int first = 0;
    for (std::size_t k = 1; k < g.size(); ++k) {
        if (g.node(static_cast<int>(k)).depth != 1) continue;
        ++first;
        const PlacedSilhouette s = g.value(static_cast<int>(k), crown).placed();
        INFO(g.path(static_cast<int>(k)));
        CHECK(std::fabs(b.crown_level(s.tip()) - 1) < 1e-9);
        CHECK(b.crown_level(s.base()) <= 1 + 1e-9);
    }
    CHECK(first >= 8);
}

// Per-branch quantities are read through the branch's node: an edit on one branch changes it
// and no other.
TEST_CASE("bonsai: an edit changes one branch", "[bonsai]") {
    Bonsai plain = grow(kRoot + "/grammars/bonsai/chokkan.plant");
    const DecompositionGraph& g = *plain.derivation->run_state().graph();
    int target = -1;
    for (std::size_t k = 1; k < g.size() && target < 0; ++k)
        if (g.node(static_cast<int>(k)).depth == 1) target = static_cast<int>(k);
    REQUIRE(target > 0);
    const std::string path = g.path(target, true);
    Bonsai edited = grow(kRoot + "/grammars/bonsai/chokkan.plant", path + " fill *= 0.5\n");
    const DecompositionGraph& h = *edited.derivation->run_state().graph();
    const int fill = h.decl().find("fill");
    int changed = 0;
    for (std::size_t k = 1; k < h.size(); ++k)
        if (h.node(static_cast<int>(k)).depth == 1 && h.value(static_cast<int>(k), fill).number != 0.85)
            ++changed;
    CHECK(changed == 1);
    CHECK(edited.skeleton.axes.size() <= plain.skeleton.axes.size());
    double before = 0, after = 0;
    for (const auto& a : plain.skeleton.axes)
        for (std::size_t i = 1; i < a.points.size(); ++i)
            before += glm::length(a.points[i].position - a.points[i - 1].position);
    for (const auto& a : edited.skeleton.axes)
        for (std::size_t i = 1; i < a.points.size(); ++i)
            after += glm::length(a.points[i].position - a.points[i - 1].position);
    CHECK(after < before);
}

namespace {
// the length of an axis's horizontal mean direction from its first point to its last
glm::dvec3 horizontal(const SkeletonAxis& a) {
    glm::dvec3 d = a.points.back().position - a.points.front().position;
    d.y = 0;
    return d;
}
} // namespace

// Sankan: three trunks from one point. In the graph they are the root's children at position 0
// with indices 0, 1 and 2, placed at the plant's base; in the skeleton, three axes start there
// and each rises more than 0.3.
TEST_CASE("bonsai: sankan has three trunks from one point", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/sankan.plant");
    const DecompositionGraph& g = *b.derivation->run_state().graph();
    const int crown = g.decl().find("crown");
    const glm::dvec3 base = g.value(0, crown).placed().base();
    int trunks = 0;
    for (int c : g.node(0).children) {
        CHECK(g.node(c).position == 0);
        CHECK(g.node(c).index == trunks);
        CHECK(glm::length(g.value(c, crown).placed().base() - base) < 1e-12);
        ++trunks;
    }
    CHECK(trunks == 3);
    int drawn = 0;
    for (const auto& a : b.skeleton.axes) {
        if (a.points.size() < 2) continue;
        double top = -1;
        for (const auto& p : a.points) top = std::max(top, p.position.y);
        bool from_base = false; // an axis that starts at the base, or a trunk whose first chord does
        for (std::size_t i = 0; i < std::min<std::size_t>(a.points.size(), 2); ++i)
            from_base = from_base || glm::length(a.points[i].position - base) < 1e-6;
        if (from_base && top - base.y > 0.3) ++drawn;
    }
    CHECK(drawn == 3);
}

// Fukinagashi: every first-order branch (an axis whose parent is the trunk) streams to the
// leeward: its horizontal direction, first point to last, within 60 degrees of the wind (+x).
TEST_CASE("bonsai: fukinagashi's branches all lie to the leeward", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/fukinagashi.plant");
    const glm::dvec3 wind{1, 0, 0};
    int branches = 0;
    for (const auto& a : b.skeleton.axes) {
        if (a.parent != 0 || a.points.size() < 2) continue;
        const glm::dvec3 h = horizontal(a);
        if (glm::length(h) < 1e-9) continue;
        ++branches;
        const double angle = std::acos(glm::dot(glm::normalize(h), wind)) * 180 / std::numbers::pi;
        INFO("branch from " << a.points[0].position.x << " " << a.points[0].position.y);
        CHECK(angle < 60);
    }
    CHECK(branches >= 6);
}

// Nejikan: the trunk's frame turns more than 180 degrees about its axis from base to tip. The
// roll is summed point to point: the previous up vector carried onto the new heading by the
// smallest rotation, then the signed angle to the new up about the new heading.
TEST_CASE("bonsai: nejikan's trunk twists more than half a turn", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/nejikan.plant");
    const auto& pts = b.trunk().points;
    REQUIRE(pts.size() > 10);
    double roll = 0;
    for (std::size_t i = 2; i < pts.size(); ++i) {
        const glm::dvec3 h0 = glm::normalize(pts[i - 1].heading), h1 = glm::normalize(pts[i].heading);
        glm::dvec3 u = pts[i - 1].up;
        const glm::dvec3 k = glm::cross(h0, h1);
        const double s = glm::length(k), c = glm::dot(h0, h1);
        if (s > 1e-12) { // Rodrigues: turn u by the angle between h0 and h1 about k
            const glm::dvec3 n = k / s;
            u = u * c + glm::cross(n, u) * s + n * (glm::dot(n, u) * (1 - c));
        }
        roll += std::atan2(glm::dot(glm::cross(u, pts[i].up), h1), glm::dot(u, pts[i].up));
    }
    INFO("roll " << roll * 180 / std::numbers::pi);
    CHECK(std::fabs(roll) * 180 / std::numbers::pi > 180);
}

// Bunjingi: a bare trunk, foliage only at the top. Rule: no foliage pad (an organ) has its centre
// in the lower half of the trunk's height (between its base and its highest point).
TEST_CASE("bonsai: bunjingi has no foliage on the lower half of its trunk", "[bonsai]") {
    Bonsai b = grow(kRoot + "/grammars/bonsai/bunjingi.plant");
    const auto& pts = b.trunk().points;
    double top = -1;
    for (const auto& p : pts) top = std::max(top, p.position.y);
    const double half = pts.front().position.y + 0.5 * (top - pts.front().position.y);
    int pads = 0;
    for (const auto& o : b.skeleton.organs) {
        ++pads;
        INFO("pad at height " << o.transform[3].y);
        CHECK(o.transform[3].y > half);
    }
    CHECK(pads >= 6);
    CHECK(top > 0.75); // and the trunk is tall
}
