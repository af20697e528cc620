// Growth by the paper's rules (issue 18 item 4; docs/climber-growth.md, "Growth rate and secondary
// growth"): an apex grows by the light it receives, and stems thicken with age by the pipe model.
#include "helpers.hpp"
#include "plant/climber.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"

#include <catch2/catch.hpp>

#include <regex>
#include <string>
#include <vector>

using namespace plant;

namespace {

struct Grown {
    std::unique_ptr<test::Compiled> compiled;
    TurtleEnvironmentPhase phase;
    DeriveOptions options;
    std::unique_ptr<Derivation> d;
};

std::unique_ptr<Grown> start(const std::string& text) {
    auto g = std::make_unique<Grown>();
    CompileOptions opts;
    opts.environments = runtime_environments();
    g->compiled = test::compile(text, opts);
    INFO(g->compiled->rendered());
    REQUIRE(g->compiled->program);
    g->options.environment_phase = &g->phase;
    g->d = std::make_unique<Derivation>(*g->compiled->program, g->options);
    g->d->start();
    return g;
}

const Climber& climber_of(const Derivation& d) {
    const Environment* env = d.run_state().environment(0);
    REQUIRE(env);
    REQUIRE(&env->kind() == &climber_kind());
    return static_cast<const Climber&>(*env);
}

// The radii of each plant's main shoot, base first: the Seg modules directly inside each plant's
// outermost brackets, in the derived string.
std::vector<std::vector<double>> main_shoots(const Grown& g) {
    const std::string s = format_string(*g.compiled->program, g.d->string(), false);
    std::vector<std::vector<double>> plants;
    int depth = 0;
    static const std::regex token(R"(\[|\]|Seg\(([^,]*),([^)]*)\))");
    for (auto it = std::sregex_iterator(s.begin(), s.end(), token); it != std::sregex_iterator(); ++it) {
        const std::string t = (*it)[0];
        if (t == "[") {
            if (++depth == 1) plants.emplace_back();
        } else if (t == "]") {
            --depth;
        } else if (depth == 1) {
            plants.back().push_back(std::stod((*it)[2]));
        }
    }
    return plants;
}

} // namespace

TEST_CASE("climber growth: a lit shoot grows faster than a shaded one of the same age", "[climber]") {
    // two unbranched shoots 0.4 m apart, weightless, not turning; the light comes from the left,
    // nearly level, so the right shoot's light passes through the left shoot
    auto g = start(R"(
import climber with { N = 2, BP = 0, Ph = 0, spacing = 0.4, steps = 30, leaf_size = 0 };
env ivy = climber(gravity: vec3(0, 0, 0), light: vec3(-1, 0.1, 0), phototropism: Ph, adaption: 0,
                  stiffness: 1, strand: strand);
seed 1;
)");
    while (g->d->step()) {
    }
    const auto plants = main_shoots(*g);
    REQUIRE(plants.size() == 2);
    const std::size_t lit = plants[0].size(), shaded = plants[1].size();
    INFO("segments: lit " << lit << ", shaded " << shaded);
    CHECK(lit == 30); // fully lit: a segment a step after the step that seeds it
    CHECK(shaded + 5 < lit);
    CHECK(shaded > 5); // shaded, not dark: it still grows
}

TEST_CASE("climber growth: an obstacle between an apex and the light shades it", "[climber]") {
    // two unbranched weightless shoots 0.6 m apart, a wall between them, the light level from the
    // right: the left shoot is behind the wall from the light, the right one in the open. The
    // plants' own shade is off (opacity 0), so only the wall can shade.
    const std::string scene = R"(
import climber with { N = 2, BP = 0, Ph = 0, spacing = 0.6, steps = 20, leaf_size = 0 };
env ivy = climber(gravity: vec3(0, 0, 0), light: vec3(1, 0.05, 0), phototropism: Ph, adaption: 0,
                  stiffness: 1, opacity: 0, obstacle_shade: SHADE,
                  box_min: vec3(-0.1, 0, -0.3), box_max: vec3(0.1, 3, 0.3));
seed 1;
)";
    auto grown = [&](const char* shade) {
        std::string text = scene;
        text.replace(text.find("SHADE"), 5, shade);
        auto g = start(text);
        while (g->d->step()) {
        }
        return g;
    };
    auto g = grown("1");
    const auto plants = main_shoots(*g);
    REQUIRE(plants.size() == 2);
    INFO("segments: behind the wall " << plants[0].size() << ", in the open " << plants[1].size());
    CHECK(plants[1].size() == 20); // lit: a segment a step
    CHECK(plants[0].size() == 1);  // O = 1 behind the wall: it does not grow past its seed
    // Eq. 7's occlusion as the grammar reads it
    const Climber& c = climber_of(*g->d);
    auto occlusion = [&](glm::dvec3 p) {
        double r = -1;
        c.query(static_cast<std::size_t>(ClimberMethod::Occlusion), &p.x, &r);
        return r;
    };
    CHECK(occlusion({-0.3, 0.5, 0.015}) == 1.0); // behind the wall
    CHECK(occlusion({0.3, 0.5, 0.015}) == 0.0);  // in the open
    CHECK(occlusion({-0.3, 0.5, 0.5}) == 0.0);   // beside the wall
    // obstacle_shade: 0, as before: the wall casts no shade and both grow alike
    const auto unshaded = main_shoots(*grown("0"));
    REQUIRE(unshaded.size() == 2);
    CHECK(unshaded[0].size() == 20);
    CHECK(unshaded[1].size() == 20);
    // diffuse: 0.3, a share of the light from the open sky: the shoot behind the wall grows on
    // the sky it sees, slowly; the one in the open a little slower than in full sun, since the
    // wall hides part of its sky too (docs/climber-growth.md, "Diffuse light")
    const auto sky = main_shoots(*grown("1, diffuse: 0.3"));
    REQUIRE(sky.size() == 2);
    INFO("with diffuse light, segments: behind the wall " << sky[0].size() << ", in the open "
                                                          << sky[1].size());
    CHECK(sky[0].size() > 1);
    CHECK(sky[0].size() * 3 < sky[1].size());
    CHECK(sky[1].size() < 20);
    CHECK(sky[1].size() >= 15);
}

// Eq. 7 turns a shoot toward the light's direction, so only the direct light weighs the turn: a
// shoot in an obstacle's shadow that grows on the open sky's light (`diffuse`) does not turn toward
// the sun behind the obstacle (docs/climber-growth.md, "Diffuse light").
TEST_CASE("climber growth: in an obstacle's shadow, diffuse light does not turn a shoot toward the sun",
          "[climber]") {
    const std::string scene = R"(
import climber with { N = 1, BP = 0, Ph = 0, steps = 1, leaf_size = 0 };
env ivy = climber(gravity: vec3(0, 0, 0), light: vec3(1, 0.05, 0), phototropism: 2, adaption: 0,
                  stiffness: 1, opacity: 0, diffuse: DIFFUSE,
                  box_min: vec3(-0.1, 0, -0.3), box_max: vec3(0.1, 3, 0.3));
seed 1;
)";
    auto turn = [&](const char* diffuse, glm::dvec3 p) {
        std::string text = scene;
        text.replace(text.find("DIFFUSE"), 7, diffuse);
        auto g = start(text);
        const Climber& c = climber_of(*g->d);
        const double args[6] = {p.x, p.y, p.z, 0, 1, 0}; // heading straight up
        double r[3] = {0, 0, 0};
        c.query(static_cast<std::size_t>(ClimberMethod::GrowDir), args, r);
        return glm::dvec3(r[0], r[1], r[2]);
    };
    const glm::dvec3 behind(-0.3, 0.5, 0.015), open(0.3, 0.5, 0.015);
    const glm::dvec3 lit = turn("0.5", open), shaded = turn("0.5", behind), dark = turn("0", behind);
    INFO("toward the light (+x): in the open " << lit.x << ", behind the wall " << shaded.x
                                               << " with the sky's light, " << dark.x << " without");
    CHECK(lit.x > 0.01);       // in the open it turns toward the light
    CHECK(dark.x == 0.0);      // behind the wall, without the sky, it does not (O = 1)
    CHECK(shaded.x == dark.x); // and with the sky's light it still does not
}

TEST_CASE("climber growth: stems thicken with age by the pipe model, base thicker than tip", "[climber]") {
    auto g = start(R"(
import climber with { N = 1, BP = 0.3, V = 0.5, Ph = 0, steps = 24, leaf_size = 0 };
env ivy = climber(gravity: vec3(0, 0, 0), phototropism: Ph, adaption: 0, stiffness: 1, strand: strand);
seed 3;
)");
    std::vector<double> base; // the first segment's drawn radius, step by step
    while (g->d->step()) {
        const auto plants = main_shoots(*g);
        REQUIRE(plants.size() == 1);
        base.push_back(plants[0].front());
    }
    const auto shoot = main_shoots(*g)[0];
    INFO("base radius " << shoot.front() << ", tip " << shoot.back() << ", after 8 steps " << base[7]);
    // a segment's radius increases over the steps, and never decreases
    for (std::size_t k = 1; k < base.size(); ++k) CHECK(base[k] >= base[k - 1]);
    CHECK(base.back() > base[7] + 0.002);
    // the base is thicker than the tip, which has its birth radius (the library's `radius`), or
    // one strand more when the apex has made a particle the string does not draw yet
    CHECK(shoot.back() >= 0.006);
    CHECK(shoot.back() <= std::sqrt(0.006 * 0.006 + 0.001 * 0.001) + 1e-12);
    CHECK(shoot.front() > 2 * shoot.back());
    // the pipe model exactly: r^2 = r0^2 + strand^2 n, n the particles beyond the first (all the
    // plant's particles but its root and itself, counted as the last physics ran)
    const physics::World& w = climber_of(*g->d).world();
    std::size_t particles = 0;
    for (std::uint32_t i = 0; i < w.size(); ++i) particles += w.alive(w.handle(i)) ? 1 : 0;
    const double n = static_cast<double>(particles) - 2;
    CHECK(shoot.front() * shoot.front() == Approx(0.006 * 0.006 + 0.001 * 0.001 * n));
    // the physics collides the stem as thick as it is drawn: the first particle (slot 1, after
    // its root) has the drawn radius
    CHECK(w.radii(w.handle(1)).x == Approx(shoot.front()));
}
