// The bonsai library (stdlib/bonsai.plant, docs/bonsai.md) and its styles in grammars/bonsai/,
// checked on the skeleton the turtle draws: the branches start inside the crown's envelope
// (Boudon et al. 2003, section 3), the formal upright trunk stands straight and the cascade's
// trunk falls below the pot's rim.
#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
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
    const SkeletonAxis& trunk() const {
        REQUIRE(!skeleton.axes.empty());
        REQUIRE(skeleton.axes[0].parent == -1);
        return skeleton.axes[0];
    }
};

Bonsai grow(const std::string& path) {
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
    Derivation d(*b.program, opt);
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
         {"/stdlib/bonsai.plant", "/grammars/bonsai/chokkan.plant", "/grammars/bonsai/kengai.plant"}) {
        INFO(file);
        Bonsai b = grow(kRoot + file);
        int branches = 0;
        for (const auto& axis : b.skeleton.axes) {
            if (axis.parent < 0 || axis.points.size() < 2) continue;
            ++branches;
            const glm::dvec3 p = axis.points[0].position;
            INFO("branch point " << p.x << " " << p.y << " " << p.z);
            CHECK(b.ask("crown", "level", p) <= 1 + 1e-9);
        }
        CHECK(branches >= 20);
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
