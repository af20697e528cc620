// The climber environment end to end: grammars whose bound modules are particles.
#include "helpers.hpp"
#include "plant/climber.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <string>

using namespace plant;

namespace {

struct Grown {
    std::unique_ptr<test::Compiled> compiled;
    std::string string;
    Skeleton skeleton;
    std::size_t particles = 0;
};

// The derivation's climber: its first environment, in these grammars.
const Climber& climber_of(const Derivation& d) {
    REQUIRE(d.run_state().size() > 0);
    const Environment* env = d.run_state().environment(0);
    REQUIRE(env);
    REQUIRE(&env->kind() == &climber_kind());
    return static_cast<const Climber&>(*env);
}

Grown grow(const std::string& text, int threads = 1) {
    Grown g;
    CompileOptions opts;
    opts.environments = runtime_environments();
    g.compiled = test::compile(text, opts);
    INFO(g.compiled->rendered());
    REQUIRE(g.compiled->program);
    TurtleEnvironmentPhase phase;
    DeriveOptions o;
    o.environment_phase = &phase;
    o.threads = threads;
    Derivation d(*g.compiled->program, o);
    d.run();
    g.string = format_string(*g.compiled->program, d.string(), false);
    g.skeleton = build_skeleton(*g.compiled->program, d.interpreted(d.string()), turtle_options(d));
    g.particles = climber_of(d).world().size();
    return g;
}

std::size_t count(const std::string& s, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
    return n;
}

// A horizontal cantilever of four bound segments, 0.1 long, growing along +x from the origin.
std::string cantilever(const std::string& climber_args, const std::string& extra = "") {
    return "env ivy = climber(" + climber_args +
           ");\n"
           "module Seg(len, r) bound ivy;\n" +
           extra +
           "derive 6;\n"
           "axiom: -(90) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) ?P(0, 0, 0);\n";
}

} // namespace

TEST_CASE("climber: bound segments sag under gravity and the turtle draws them where the particles are",
          "[climber]") {
    Grown soft = grow(cantilever("stiffness: 0.3, substeps: 10"));
    Grown still = grow(cantilever("stiffness: 0.3, substeps: 10, gravity: vec3(0, 0, 0)"));
    REQUIRE(soft.skeleton.axes.size() == 1);
    const auto& tip = soft.skeleton.axes[0].points.back().position;
    const auto& straight = still.skeleton.axes[0].points.back().position;
    CHECK(tip.y < -0.02);                          // it sagged
    CHECK(straight.y == Approx(0.0).margin(1e-9)); // without gravity it keeps its shape
    CHECK(straight.x == Approx(0.4).margin(1e-9));
    // the query module after the tip reads the physical position
    CHECK(soft.string.find("?P(" + fmt::format("{}", tip.x)) != std::string::npos);
    CHECK(soft.particles == 5); // a fixed root and one particle per segment
}

TEST_CASE("climber: a pulled tip past the break threshold leaves the string, and so does a cut branch",
          "[climber]") {
    // ids in the axiom: -(90) is 1, the segments 2 to 5; fall_time: 0, so a loose part leaves
    // the string in the step it came loose (the next test lets it fall first)
    Grown pulled = grow(cantilever("stiffness: 1, substeps: 4, break_threshold: 0.3, fall_time: 0",
                                   "on before_step { if step() == 2 { ivy.pull(5, vec3(1, 1, 0)); } }\n"));
    CHECK(count(pulled.string, "Seg(") < 4);
    CHECK(count(pulled.string, "Seg(") >= 1);
    CHECK(pulled.string.find("?P") == std::string::npos); // it followed the broken tip out
    Grown whole = grow(cantilever("stiffness: 1, substeps: 4, break_threshold: 0.3, fall_time: 0"));
    CHECK(count(whole.string, "Seg(") == 4);

    Grown cut = grow(cantilever("stiffness: 1, substeps: 4, fall_time: 0",
                                "on before_step { if step() == 3 { ivy.cut(4); } }\n"));
    CHECK(cut.string == "-(90)Seg(0.1,0.01)Seg(0.1,0.01)");
    CHECK(cut.particles == 5); // the world keeps its slots; the cut ones are dead
}

TEST_CASE("climber: a cut part falls for fall_time, drawn as a tube of its own, then leaves the string",
          "[climber]") {
    // Hädrich et al., section 6.1 and Fig. 7 (e): "separated branches fall on the ground and
    // disappear". Cut at segment 4 in step 3 of 6 (0.4 s a step); the default fall_time, 1 s,
    // keeps it falling to the end
    const std::string cut_at_3 = "on before_step { if step() == 3 { ivy.cut(4); } }\n";
    Grown falling = grow(cantilever("stiffness: 1, substeps: 4", cut_at_3));
    CHECK(count(falling.string, "Seg(") == 4);
    REQUIRE(falling.skeleton.axes.size() == 2); // the part that hangs on, and the falling one
    const auto& kept = falling.skeleton.axes[0].points;
    const auto& loose = falling.skeleton.axes[1].points;
    REQUIRE(loose.size() == 3); // its own start, then segments 4 and 5
    INFO("kept tip at y = " << kept.back().position.y << ", falling part's lowest at y = "
                            << std::min(loose[1].position.y, loose[2].position.y));
    CHECK(kept.back().position.y > -0.02);                            // stiff: it holds its shape
    CHECK(std::max(loose[1].position.y, loose[2].position.y) < -0.1); // fallen over 10 cm in 1.2 s
    // its own start: the first segment is as long as the others, not stretched back to the plant
    CHECK(glm::distance(loose[0].position, loose[1].position) == Approx(0.1).margin(1e-9));
    // with a fall time of two steps it has left by the end
    Grown gone = grow(cantilever("stiffness: 1, substeps: 4, fall_time: 0.2", cut_at_3));
    CHECK(gone.string == "-(90)Seg(0.1,0.01)Seg(0.1,0.01)");
}

TEST_CASE("climber: a plant beside a wall climbs it without entering, parallel to its face", "[climber]") {
    const std::string g = R"(
env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, adaption_range: 0.2,
                  anchor: 0.5, anchor_range: 0.03, light: vec3(0, 1, 0.3), phototropism: 0.2);
module Seg(len, r) bound ivy;
module Apex(k);
derive 30;
axiom: @M(0, 0, 0.1) SetHead(0, 0.8, -0.6) Seg(0.05, 0.006) Apex(0) ?P(0, 0, 0) ?H(0, 1, 0);
rules {
  Apex(k) > ?P(p) ?H(h) : k < 30 { let g = ivy.grow_dir(p, h); produce SetHead(g.x, g.y, g.z) Seg(0.05, 0.006) Apex(k + 1); }
}
)";
    Grown r = grow(g);
    const auto& pts = r.skeleton.axes.at(0).points;
    REQUIRE(pts.size() > 25);
    double lowest_z = 1e9;
    for (const auto& p : pts) lowest_z = std::min(lowest_z, p.position.z);
    CHECK(lowest_z >= 0.0);                       // never inside the wall (z < 0)
    CHECK(pts.back().position.y > 0.8);           // it climbed
    CHECK(std::abs(pts.back().heading.z) < 0.15); // along the face, not away from it
}

TEST_CASE("climber: grow_dir turns a free shoot toward the light, and not when there is none to follow",
          "[climber]") {
    auto shoot = [](double eta) {
        return grow(fmt::format(R"(
env ivy = climber(gravity: vec3(0, 0, 0), light: vec3(1, 1, 0), phototropism: {});
module Seg(len, r) bound ivy;
module Apex(k);
derive 12;
axiom: Seg(0.05, 0.006) Apex(0) ?P(0, 0, 0) ?H(0, 1, 0);
rules {{
  Apex(k) > ?P(p) ?H(h) {{ let g = ivy.grow_dir(p, h); produce SetHead(g.x, g.y, g.z) Seg(0.05, 0.006) Apex(k + 1); }}
}}
)",
                                eta));
    };
    Grown lit = shoot(0.3), blind = shoot(0);
    CHECK(lit.skeleton.axes[0].points.back().heading.x > 0.3);
    CHECK(blind.skeleton.axes[0].points.back().heading.x == Approx(0.0).margin(1e-9));
}

TEST_CASE("climber: a grammar grows the same plant for a seed, on any thread count and when derived again",
          "[climber]") {
    // the library with a wall scene, through the stdlib search path
    const std::string text =
        "import climber with { N = 3, BP = 0.3, steps = 20, shoot_length = 20 };\n"
        "env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, "
        "anchor: 0.5, phototropism: 0.3);\nseed 5;\n";
    Grown a = grow(text, 1), b = grow(text, 2);
    CHECK(a.string == b.string);
    CHECK(count(a.string, "Seg(") > 60);
    // one compiled program derived twice: each derivation starts from the climber as declared
    CompileOptions opts;
    opts.environments = runtime_environments();
    auto c = test::compile(text, opts);
    REQUIRE(c->program);
    TurtleEnvironmentPhase phase;
    DeriveOptions o;
    o.environment_phase = &phase;
    std::string first, second;
    for (std::string* out : {&first, &second}) {
        Derivation d(*c->program, o);
        d.run();
        *out = format_string(*c->program, d.string(), false);
    }
    CHECK(first == second);
    CHECK(first == a.string);
}

namespace {

struct Compiled {
    std::unique_ptr<test::Compiled> compiled;
    TurtleEnvironmentPhase phase;
    DeriveOptions options;
};

std::unique_ptr<Compiled> compile_climber(const std::string& text) {
    auto c = std::make_unique<Compiled>();
    CompileOptions opts;
    opts.environments = runtime_environments();
    c->compiled = test::compile(text, opts);
    INFO(c->compiled->rendered());
    REQUIRE(c->compiled->program);
    c->options.environment_phase = &c->phase;
    return c;
}

std::string text_of(const Derivation& d) {
    return format_string(d.program(), d.string(), true);
}

} // namespace

TEST_CASE("climber: a derivation copied mid-way goes on like the original, particles and all", "[climber]") {
    // the wall scene of the library, with SPH air around it and a hook that switches the wind
    // after the copy: the particles, the air and the edits are all part of what is copied
    for (const char* air :
         {"", ", air_min: vec3(-0.4, 0, -0.4), air_max: vec3(0.4, 0.6, 0.2), air_spacing: 0.1"}) {
        auto c = compile_climber(fmt::format(
            "import climber with {{ N = 2, BP = 0.3, steps = 16, shoot_length = 16 }};\n"
            "env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, "
            "anchor: 0.5, phototropism: 0.3{});\nseed 3;\n"
            "on before_step {{ if step() == 10 {{ ivy.wind(vec3(2, 0, 1)); }} }}\n",
            air));
        Derivation original(*c->compiled->program, c->options);
        original.start();
        for (int k = 0; k < 8; ++k) original.step();
        Derivation copy(original);
        const std::uint64_t at_copy = climber_of(copy).world().state_hash();
        CHECK(climber_of(original).world().state_hash() == at_copy);
        // the original's steps leave the copy where it was
        original.step();
        CHECK(climber_of(copy).world().state_hash() == at_copy);
        CHECK(climber_of(original).world().state_hash() != at_copy);
        copy.step();
        for (int k = 0; k < 7; ++k) {
            original.step();
            copy.step();
        }
        CHECK(original.steps_done() == 16);
        CHECK(copy.steps_done() == 16);
        CHECK(text_of(copy) == text_of(original));
        CHECK(climber_of(copy).world().size() == climber_of(original).world().size());
        CHECK(climber_of(copy).world().state_hash() == climber_of(original).world().state_hash());
        CHECK(climber_of(original).world().size() > 10);
    }
}

TEST_CASE("climber: a derivation leaves the compiled program as it was, so it derives again the same",
          "[climber]") {
    auto c = compile_climber(
        "import climber with { N = 2, BP = 0.3, steps = 12, shoot_length = 12 };\n"
        "env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, anchor: 0.5);\n"
        "seed 4;\n");
    const Program& program = *c->compiled->program;
    REQUIRE(program.environments.size() == 1);
    const EnvironmentDecl& decl = program.environments[0];
    REQUIRE(decl.kind == &climber_kind());
    const auto& declared = static_cast<const Climber&>(*decl.initial);
    const std::uint64_t declared_hash = declared.world().state_hash();
    CHECK(declared.world().size() == 0);
    std::string first, second;
    std::uint64_t first_hash = 0, second_hash = 0;
    for (auto [text, hash] : {std::pair{&first, &first_hash}, std::pair{&second, &second_hash}}) {
        Derivation d(program, c->options);
        d.run();
        *text = text_of(d);
        *hash = climber_of(d).world().state_hash();
        // the declared climber is not the one that grew
        CHECK(declared.world().size() == 0);
        CHECK(declared.world().state_hash() == declared_hash);
    }
    CHECK(first == second);
    CHECK(first_hash == second_hash);
    CHECK(first_hash != declared_hash);
}

TEST_CASE("climber: SPH air blowing past a stem pushes it downwind", "[climber]") {
    auto stem = [](double coupling) {
        return grow(fmt::format(R"(
env ivy = climber(stiffness: 0.3, gravity: vec3(0, 0, 0), substeps: 4, wind: vec3(3, 0, 0),
                  air_min: vec3(-0.3, 0, -0.3), air_max: vec3(0.5, 0.6, 0.3), air_spacing: 0.05,
                  air_coupling: {});
module Seg(len, r) bound ivy;
derive 6;
axiom: Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) ?P(0, 0, 0);
)",
                                coupling));
    };
    Grown calm = stem(0), blown = stem(1);
    const auto& still = calm.skeleton.axes.at(0).points.back().position;
    const auto& bent = blown.skeleton.axes.at(0).points.back().position;
    CHECK(still.x == Approx(0.0).margin(1e-9)); // uncoupled, the air passes through
    CHECK(bent.x > 0.005);                      // coupled, it bends the stem downwind
}

TEST_CASE("climber: a mesh obstacle (a distance grid of a loaded cube) is climbed and never entered",
          "[climber]") {
    // the unit cube [0, 1]^3 from tests/data/cube.obj, scaled by nothing: a plant starts in front
    // of its +z face and leans into it
    const std::string cube = std::string(PLANT_TEST_DATA) + "/cube.obj";
    Grown r = grow(fmt::format(R"(
env ivy = climber(mesh: "{}", mesh_cell: 0.05, adaption: 0.8, adaption_range: 0.2, anchor: 0.5, anchor_range: 0.03);
module Seg(len, r) bound ivy;
module Apex(k);
derive 24;
axiom: @M(0.5, 0, 1.08) SetHead(0, 0.8, -0.6) Seg(0.05, 0.006) Apex(0) ?P(0, 0, 0) ?H(0, 1, 0);
rules {{
  Apex(k) > ?P(p) ?H(h) {{ let g = ivy.grow_dir(p, h); produce SetHead(g.x, g.y, g.z) Seg(0.05, 0.006) Apex(k + 1); }}
}}
)",
                               cube));
    const auto& pts = r.skeleton.axes.at(0).points;
    REQUIRE(pts.size() > 20);
    for (const auto& p : pts) {
        const glm::dvec3& x = p.position;
        const bool inside = x.x > 0.01 && x.x < 0.99 && x.y > 0.01 && x.y < 0.99 && x.z > 0.01 && x.z < 0.99;
        CHECK(!inside);
    }
    CHECK(pts.back().position.y > 0.7); // it went up the face
    CHECK(pts.back().position.z < 1.1); // staying on it
}

TEST_CASE("distance grid: trilinear samples of a box's distance", "[climber]") {
    plant::physics::DistanceGrid g;
    g.lo = glm::dvec3(-1.0);
    g.cell = 0.25;
    g.n = glm::ivec3(9);
    g.d.resize(9 * 9 * 9);
    plant::physics::Obstacle box;
    box.kind = plant::physics::Obstacle::Box;
    box.a = glm::dvec3(-0.5);
    box.b = glm::dvec3(0.5);
    for (int z = 0; z < 9; ++z)
        for (int y = 0; y < 9; ++y)
            for (int x = 0; x < 9; ++x)
                g.d[(static_cast<std::size_t>(z) * 9 + y) * 9 + x] =
                    box.distance(g.lo + glm::dvec3(x, y, z) * 0.25);
    CHECK(g.sample(glm::dvec3(0.75, 0, 0)) == Approx(0.25));   // a grid point
    CHECK(g.sample(glm::dvec3(0.625, 0, 0)) == Approx(0.125)); // between two, along a linear stretch
    CHECK(g.sample(glm::dvec3(0, 0, 0)) == Approx(-0.5));      // the centre
    CHECK(g.sample(glm::dvec3(3, 0, 0)) == Approx(2.5));       // outside the grid: 2 beyond it plus 0.5
}

TEST_CASE("climber: a box moved by a hook pushes the plant along, which never ends inside it", "[climber]") {
    auto run = [](bool move) {
        return grow(fmt::format(R"(
env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, adaption_range: 0.2,
                  anchor: 0.5, anchor_range: 0.03);
module Seg(len, r) bound ivy;
module Apex(k);
derive 24;
axiom: @M(0, 0, 0.02) Seg(0.05, 0.006) Apex(0) ?P(0, 0, 0) ?H(0, 1, 0);
on before_step {{ if {} && step() >= 16 && step() < 20 {{ ivy.move(0, vec3(0, 0, 0.02)); }} }}
rules {{
  Apex(k) > ?P(p) ?H(h) {{ let g = ivy.grow_dir(p, h); produce SetHead(g.x, g.y, g.z) Seg(0.05, 0.006) Apex(k + 1); }}
}}
)",
                                move ? "true" : "false"));
    };
    Grown still = run(false), moved = run(true);
    double still_z = 1e9, moved_z = 1e9;
    for (const auto& p : still.skeleton.axes.at(0).points) still_z = std::min(still_z, p.position.z);
    for (const auto& p : moved.skeleton.axes.at(0).points)
        if (p.position.y > 0.1) moved_z = std::min(moved_z, p.position.z); // above the fixed root
    CHECK(still_z < 0.03);
    CHECK(moved_z >= 0.08 - 1e-6); // the wall's face went from z = 0 to 0.08; the plant is in front
}

TEST_CASE("climber: a hook seeds a new branch at a segment, and it grows from there", "[climber]") {
    // stdlib/climber.plant with one unbranched plant; #12 is its second segment
    auto plant = [](const std::string& hook) {
        return grow("import climber with { N = 1, BP = 0, steps = 12, leaf_size = 0 };\n"
                    "env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, "
                    "anchor: 0.5);\n" +
                    hook);
    };
    Grown plain = plant(""), seeded = plant("on before_step { if step() == 4 { ivy.seed(12); } }\n");
    CHECK(count(plain.string, "Apex(") == 1);
    CHECK(count(seeded.string, "Apex(") == 2);
    CHECK(count(seeded.string, "Seg(") > count(plain.string, "Seg(") + 4); // the new shoot grew on
    REQUIRE(seeded.skeleton.axes.size() == 2);
    // it starts where the second segment ends
    const auto& base = seeded.skeleton.axes[1].points.front().position;
    CHECK(glm::distance(base, seeded.skeleton.axes[0].points[2].position) < 1e-9);
}

TEST_CASE("climber: a painted sample a shoot reaches is used up, so the shoot moves on", "[climber]") {
    auto shoot = [](double reach) {
        return grow(fmt::format(R"(
env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 3, 0), adaption: 0.8, anchor: 0.5,
                  attractor: vec3(0.1, 0.6, 0), attractor_radius: 0.5, attractor_strength: 1.5, attractor_reach: {});
module Seg(len, r) bound ivy;
module Apex(k);
derive 40;
axiom: @M(0, 0, 0.01) Seg(0.05, 0.006) Apex(0) ?P(0, 0, 0) ?H(0, 1, 0);
rules {{
  Apex(k) > ?P(p) ?H(h) {{ let g = ivy.grow_dir(p, h); produce SetHead(g.x, g.y, g.z) Seg(0.05, 0.006) Apex(k + 1); }}
}}
)",
                                reach));
    };
    auto highest = [](const Grown& g) {
        double y = 0;
        for (const auto& p : g.skeleton.axes.at(0).points) y = std::max(y, p.position.y);
        return y;
    };
    CHECK(highest(shoot(0)) < 0.8);   // never used up: the shoot circles the sample
    CHECK(highest(shoot(0.1)) > 1.2); // used up once reached: the shoot grows on
}

TEST_CASE("climber: an emitter's wind stream bends a stem in it, and a hook switches it", "[climber]") {
    // a stem in a box of still air, an emitter 0.3 m upwind of it blowing along +x; `emit`
    // switches the emitter off before the first step, or on from off
    auto stem = [](const std::string& velocity, const std::string& hook) {
        return grow(fmt::format(R"(
env ivy = climber(stiffness: 0.3, gravity: vec3(0, 0, 0), substeps: 4,
                  air_min: vec3(-0.5, 0, -0.3), air_max: vec3(0.5, 0.6, 0.3), air_spacing: 0.05,
                  emitter: vec3(-0.3, 0.3, 0), emitter_velocity: {}, emitter_radius: 0.15);
module Seg(len, r) bound ivy;
derive 6;
axiom: Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) Seg(0.1, 0.02) ?P(0, 0, 0);
{}
)",
                                velocity, hook));
    };
    auto tip_x = [](const Grown& g) { return g.skeleton.axes.at(0).points.back().position.x; };
    const double blown = tip_x(stem("vec3(3, 0, 0)", "")), calm = tip_x(stem("vec3(0, 0, 0)", ""));
    const double off = tip_x(stem("vec3(3, 0, 0)", "on start { ivy.emit(0, vec3(0, 0, 0)); }"));
    const double on = tip_x(stem("vec3(0, 0, 0)", "on start { ivy.emit(0, vec3(3, 0, 0)); }"));
    INFO("blown " << blown << " calm " << calm << " switched off " << off << " switched on " << on);
    CHECK(blown > calm + 0.005); // downstream
    CHECK(off == calm);          // switched off before any air step: as if it had never blown
    CHECK(on == blown);          // and switched on: as if declared blowing
}

TEST_CASE("climber: ivy.remove(k) takes a support away and the plant anchored to it falls", "[climber]") {
    // a soft shoot of ten segments anchored along the face of a box (obstacle 0), 1 m up, beside a
    // second box (obstacle 1) it never touches; removing the second changes nothing, removing the
    // first from a hook lets the shoot go, and it sags (issue 18, item 3)
    const std::string shoot = R"(
env ivy = climber(box_min: vec3(-1, 0, -0.2), box_max: vec3(1, 2, 0), box_min: vec3(3, 0, 0), box_max: vec3(4, 1, 1),
                  anchor: 0.5, anchor_range: 0.03, stiffness: 0.2);
module Seg(len, r) bound ivy;
derive 10;
axiom: @M(0, 1, 0.015) SetHead(1, 0, 0, 0, 0, 1) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01)
       Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) Seg(0.1, 0.01) ?P(0, 0, 0);
)";
    auto tip = [](const Grown& g) { return g.skeleton.axes.at(0).points.back().position; };
    const Grown held = grow(shoot);
    const Grown other = grow(shoot + "on before_step { if step() == 3 { ivy.remove(1); } }\n");
    const Grown removed = grow(shoot + "on before_step { if step() == 3 { ivy.remove(0); } }\n");
    // numbered as declared: the wall is still 0 after the other box went
    const Grown both = grow(shoot + "on before_step { if step() == 3 { ivy.remove(1); } if step() == 4 { "
                                    "ivy.remove(0); } }\n");
    INFO("tip held at y = " << tip(held).y << ", with the other box removed " << tip(other).y
                            << ", with its wall removed " << tip(removed).y << ", with both " << tip(both).y);
    CHECK(tip(held).y > 0.9); // anchored, it holds its line along the wall
    CHECK(tip(other) == tip(held));
    CHECK(tip(removed).y < tip(held).y - 0.2); // let go, it sags
    CHECK(tip(both).y < tip(held).y - 0.2);
}
