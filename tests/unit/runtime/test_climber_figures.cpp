// The climber figure grammars (grammars/climbers/) against their captions in Hädrich et al. 2017,
// "Interactive Modeling and Authoring of Climbing Plants" (issue 18, item 5). Each test measures the
// effect its figure shows with a tolerance, not exact numbers, so that the physics may change under
// it; docs/physics.md lists what each checks.
#include "helpers.hpp"
#include "plant/climber.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

using namespace plant;

namespace {

const std::filesystem::path kFigures = std::filesystem::path(PLANT_SOURCE_DIR) / "grammars" / "climbers";

using Defines = std::vector<std::pair<std::string, std::string>>;

// A figure grammar derived step by step (test_climber_physics.cpp checks every grammar's particles
// against the obstacles at every step).
struct Figure {
    SourceManager sources;
    Diagnostics diags;
    std::unique_ptr<Program> program;
    TurtleEnvironmentPhase phase;
    DeriveOptions options;
    std::unique_ptr<Derivation> d;

    const Climber& climber() const {
        REQUIRE(d->run_state().size() > 0);
        const Environment* env = d->run_state().environment(0);
        REQUIRE(env);
        REQUIRE(&env->kind() == &climber_kind());
        return static_cast<const Climber&>(*env);
    }
    const physics::World& world() const { return climber().world(); }
    Skeleton skeleton() const {
        return build_skeleton(*program, d->interpreted(d->string()), turtle_options(*d));
    }
    std::size_t count(const std::string& module) const {
        const std::string s = format_string(*program, d->string(), false);
        std::size_t n = 0;
        for (std::size_t at = s.find(module + "("); at != std::string::npos;
             at = s.find(module + "(", at + 1))
            ++n;
        return n;
    }
    std::size_t alive() const {
        const physics::World& w = world();
        std::size_t n = 0;
        for (std::uint32_t i = 0; i < w.size(); ++i) n += w.alive(w.handle(i)) ? 1 : 0;
        return n;
    }
};

// Compiles grammars/climbers/`name` with `defines` and derives it `steps` steps (all: -1), with
// the grammar's own seed or `seed`.
std::unique_ptr<Figure> grow(const std::string& name, const Defines& defines = {}, int steps = -1,
                             std::optional<std::uint64_t> seed = std::nullopt) {
    auto f = std::make_unique<Figure>();
    CompileOptions opts;
    opts.environments = runtime_environments();
    opts.defines = defines;
    f->program = compile_file(f->sources, (kFigures / name).string(), opts, f->diags);
    INFO(render_all(f->diags, f->sources));
    REQUIRE(f->program);
    f->options.environment_phase = &f->phase;
    f->options.seed = seed;
    f->d = std::make_unique<Derivation>(*f->program, f->options);
    f->d->start();
    // (step() returns false for the last step, which it has run)
    for (bool more = true; more && (steps < 0 || f->d->steps_done() < steps);) more = f->d->step();
    return f;
}

struct Segment {
    glm::dvec3 a, b;
    double length() const { return glm::distance(a, b); }
    glm::dvec3 mid() const { return 0.5 * (a + b); }
};

std::vector<Segment> segments(const Skeleton& s) {
    std::vector<Segment> out;
    for (const auto& axis : s.axes)
        for (std::size_t k = 1; k < axis.points.size(); ++k)
            out.push_back({axis.points[k - 1].position, axis.points[k].position});
    return out;
}

double distance_to(const glm::dvec3& p, const Segment& s) {
    const glm::dvec3 ab = s.b - s.a;
    const double l2 = glm::dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(glm::dot(p - s.a, ab) / l2, 0.0, 1.0) : 0.0;
    return glm::distance(p, s.a + t * ab);
}

// Secondary growth (`strand: strand`) thickens the stems of fig01_car and fig10_dome with age, and
// each segment is drawn as thick as its particle is collided. fig01_car's pruning group keeps
// its segments' radii from its particles too: with the radius it was given, a pruned plant's
// stems were drawn up to 8 mm thicker than collided, through the car's body. (Checked on the
// runs of the Fig. 1 and Fig. 10 tests, which grow these two.)
void check_thickening(const std::string& name, const Figure& f) {
    const Skeleton s = f.skeleton();
    const physics::World& w = f.world();
    double thickest = 0, worst = 0;
    std::size_t bound = 0;
    for (const auto& axis : s.axes)
        for (const auto& p : axis.points) {
            const physics::Handle h = f.climber().particle(p.id);
            if (!h.valid() || !w.alive(h)) continue;
            ++bound;
            thickest = std::max(thickest, p.radius);
            worst = std::max(worst, std::fabs(p.radius - w.radii(h).x));
        }
    INFO(name << ": thickest stem radius " << thickest << " m; drawn and physical radii differ by up to "
              << worst << " m over " << bound << " segments");
    CHECK(bound > 300);
    CHECK(thickest > 2.5 * 0.006); // the library's birth radius
    CHECK(worst < 1e-9);
}

// The points of a figure grammar's `attractor: vec3(x, y, z)` arguments, as written.
std::vector<glm::dvec3> attractors_of(const std::string& name) {
    std::ifstream in(kFigures / name);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::regex sample(R"(attractor: vec3\(([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\))");
    std::vector<glm::dvec3> points;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), sample); it != std::sregex_iterator(); ++it)
        points.emplace_back(std::stod((*it)[1]), std::stod((*it)[2]), std::stod((*it)[3]));
    return points;
}

} // namespace

// The live particles of a figure's world that hang from no fixed root (broken off or cut,
// falling), and their mean height.
std::pair<std::size_t, double> loose(const Figure& f) {
    const physics::World& w = f.world();
    std::size_t n = 0;
    double y = 0;
    for (std::uint32_t i = 0; i < w.size(); ++i) {
        const physics::Handle h = w.handle(i);
        if (!w.alive(h) || w.attached(h)) continue;
        ++n;
        y += w.position(h).y;
    }
    return {n, n > 0 ? y / static_cast<double>(n) : 0.0};
}

TEST_CASE("climber figures: Fig. 7's gust of wind bends the plant more than 5 cm", "[climber]") {
    // fig07_editing.plant blows from step 44 to 51. The segments grown before the gust (step 43,
    // where the runs with and without it are still the same) are compared at step 51, in the
    // plant blown and in the same plant grown without the gust, by module identity: growth
    // during the gust is left out, since it starts where the wind has turned its apex and would
    // count a turned heading as a bend. (Compared by particle index, this test passed on new
    // growth while the plant itself moved 3.7 cm at most.)
    auto before = grow("fig07_editing.plant", {}, 43);
    { // the gust has not begun by then: the plant is the one grown without it
        auto unblown = grow("fig07_editing.plant", {{"gust", "0"}}, 43);
        REQUIRE(unblown->world().size() == before->world().size());
        for (std::uint32_t i = 0; i < before->world().size(); ++i)
            REQUIRE(unblown->world().position(unblown->world().handle(i)) ==
                    before->world().position(before->world().handle(i)));
    }
    auto calm = grow("fig07_editing.plant", {{"gust", "0"}}, 51);
    auto blown = grow("fig07_editing.plant", {}, 51);
    std::vector<double> moves;
    for (const auto& axis : before->skeleton().axes)
        for (const auto& p : axis.points) {
            const physics::Handle a = calm->climber().particle(p.id), b = blown->climber().particle(p.id);
            if (!a.valid() || !b.valid() || !calm->world().alive(a) || !blown->world().alive(b)) continue;
            moves.push_back(glm::distance(calm->world().position(a), blown->world().position(b)));
        }
    std::sort(moves.begin(), moves.end());
    const auto bent = std::count_if(moves.begin(), moves.end(), [](double m) { return m > 0.05; });
    INFO(moves.size() << " segments grown before the gust; it moved the farthest "
                      << (moves.empty() ? 0.0 : moves.back()) << " m, " << bent << " of them over 5 cm");
    REQUIRE(moves.size() > 30);
    CHECK(moves.back() > 0.05);
    CHECK(bent >= 5); // a stretch of stem, not one tip
    // and the cut at step 52 took the seeded branch away: #85 hangs from #28, where step 10
    // seeded the branch, on a stem of its own (the main shoot's #68 is not on its path); the cut
    // part lets go and falls for the grammar's fall_time (0.6 s, six steps) while #28 and #68
    // hang on, then leaves the string (Fig. 7 (e): "separated branches fall on the ground and
    // disappear")
    auto before_cut = grow("fig07_editing.plant", {}, 51);
    auto just_cut = grow("fig07_editing.plant", {}, 53);
    auto fallen = grow("fig07_editing.plant", {}, 56);
    auto after_cut = grow("fig07_editing.plant", {}, 60);
    {
        const physics::World& w = before_cut->world();
        const physics::Handle cut = before_cut->climber().particle(85);
        const physics::Handle seeded = before_cut->climber().particle(28);
        const physics::Handle shoot = before_cut->climber().particle(68);
        REQUIRE(cut.valid());
        REQUIRE(seeded.valid());
        REQUIRE(shoot.valid());
        bool from_seeded = false, through_shoot = false;
        for (std::uint32_t at = cut.index; at != ~0u; at = w.parent(w.handle(at))) {
            from_seeded = from_seeded || at == seeded.index;
            through_shoot = through_shoot || at == shoot.index;
        }
        CHECK(from_seeded);
        CHECK(!through_shoot);
        CHECK(loose(*before_cut).first == 0);
    }
    const physics::Handle falling = just_cut->climber().particle(85);
    REQUIRE(falling.valid());
    CHECK(just_cut->world().alive(falling));
    CHECK(!just_cut->world().attached(falling));
    const auto [n53, y53] = loose(*just_cut);
    const auto [n56, y56] = loose(*fallen);
    INFO("cut part: " << n53 << " particles at mean height " << y53 << " m at step 53, " << n56 << " at "
                      << y56 << " m at step 56");
    CHECK(n53 > 10);
    CHECK(y56 < y53 - 0.05);
    const physics::Handle gone = after_cut->climber().particle(85);
    CHECK((!gone.valid() || !after_cut->world().alive(gone)));
    CHECK(loose(*after_cut).first == 0);
    for (const ModuleId kept : {ModuleId{28}, ModuleId{68}}) {
        const physics::Handle h = after_cut->climber().particle(kept);
        CHECK((h.valid() && after_cut->world().alive(h) && after_cut->world().attached(h)));
    }
    CHECK(after_cut->count("Seg") + 10 < fallen->count("Seg")); // its segments left the string
}

// The largest |length / rest length - 1| of any link of the world.
double worst_stretch(const physics::World& w) {
    double worst = 0;
    for (std::uint32_t i = 0; i < w.size(); ++i) {
        const physics::Handle h = w.handle(i);
        if (!w.alive(h) || w.parent(h) == ~0u) continue;
        const physics::Handle p = w.handle(w.parent(h));
        const double rest = glm::distance(w.rest_position(h), w.rest_position(p));
        if (rest > 0)
            worst = std::max(worst, std::fabs(glm::distance(w.position(h), w.position(p)) / rest - 1));
    }
    return worst;
}

TEST_CASE("climber figures: Fig. 7's grabbed branch follows the hand off the wall, links intact",
          "[climber]") {
    // fig07_editing.plant grabs segment #68 (the main shoot, 0.45 m up) in steps 16 to 19
    auto left_alone = grow("fig07_editing.plant", {{"grab", "0"}}, 20);
    auto grabbed = grow("fig07_editing.plant", {}, 20);
    const physics::Handle still = left_alone->climber().particle(68), held = grabbed->climber().particle(68);
    REQUIRE(still.valid());
    REQUIRE(held.valid());
    const glm::dvec3 a = left_alone->world().position(still), b = grabbed->world().position(held);
    INFO("segment #68 ends at z = " << a.z << " left alone, " << b.z << " grabbed, " << glm::distance(a, b)
                                    << " m apart; worst link " << worst_stretch(grabbed->world()));
    CHECK(glm::distance(a, b) > 0.05);
    CHECK(b.z > 0.05);                            // off the wall's face (z = 0)
    CHECK(left_alone->world().anchored(still));   // clinging, left alone
    CHECK(!grabbed->world().anchored(held));      // its anchor let go
    CHECK(worst_stretch(grabbed->world()) < 0.1); // the stem followed within its length
    // nothing broke off (a broken-off part leaves the string): the grabbed plant, in more light,
    // has grown as much or more
    CHECK(grabbed->count("Seg") >= left_alone->count("Seg"));
}

TEST_CASE("climber figures: Fig. 14 right's plants favour the building's lit side", "[climber]") {
    // stem length with its segment's midpoint on one side of x = at (side +1: x > at, -1: x < -at)
    auto stem_length = [](const Figure& f, double side, double at = 0) {
        double l = 0;
        for (const Segment& s : segments(f.skeleton()))
            if (s.mid().x * side > at) l += s.length();
        return l;
    };
    auto lit = grow("fig14_right.plant");
    const double right = stem_length(*lit, 1), left = stem_length(*lit, -1);
    // the side walls' faces are x = -2.5 (dark: the building is between it and the light) and 2.5
    const double lit_wall = stem_length(*lit, 1, 2.5), dark_wall = stem_length(*lit, -1, 2.5);
    auto unshaded = grow("fig14_right.plant", {{"shade", "0"}});
    const double unshaded_dark = stem_length(*unshaded, -1, 2.5);
    auto above = grow("fig14_right.plant", {{"light_x", "0"}});
    const double even_right = stem_length(*above, 1), even_left = stem_length(*above, -1);
    INFO("lit from the right: " << right << " m right, " << left << " m left; side walls: " << lit_wall
                                << " m lit, " << dark_wall << " m dark (" << unshaded_dark
                                << " m without the building's shade); from above: " << even_right << " m, "
                                << even_left << " m");
    CHECK(right > 1.5 * left);
    CHECK(even_right < 1.3 * even_left); // the light does it, not the seeding
    // the building's shade: its dark side wall's plants grow on the sky's light alone (the
    // grammar's diffuse: 0.3), past their seeds (four 5 cm segments) but a small part of what the
    // lit wall's do, and far less than without the shade (docs/climber-growth.md, "Diffuse light")
    CHECK(lit_wall > 20);
    CHECK(dark_wall > 0.5);
    CHECK(dark_wall * 10 < lit_wall);
    CHECK(dark_wall * 5 < unshaded_dark);
    CHECK(unshaded_dark > 20);
}

TEST_CASE("climber figures: Fig. 14 left's shoots past the water tank bend down under gravity", "[climber]") {
    // stems pointing more than 30 degrees below horizontal, over 4 cm from every obstacle
    auto hanging = [](const Figure& f) {
        const physics::World& w = f.world();
        double l = 0;
        for (const Segment& s : segments(f.skeleton())) {
            if (s.b.y - s.a.y > -0.5 * s.length()) continue;
            bool free = true;
            for (const auto& o : w.obstacles()) free = free && o.distance(s.b) > 0.04;
            if (free) l += s.length();
        }
        return l;
    };
    // Three seeds, the grammar's own (14) and two more, together: how much stem one seed hangs
    // past the tank varies from next to nothing (when no shoot has got past it in 100 steps) to
    // several metres, and a change of the solver that moves positions by under a nanometre moved
    // seed 14 alone from 2.0 to 0.35 m and seed 15 from 8.4 to 0.1 m (docs/climber-figures.md).
    // The three together hang over four times as much under gravity as weightless.
    double down = 0, floating = 0;
    std::string each;
    for (const std::uint64_t seed : {14, 15, 16}) {
        auto heavy = grow("fig14_left.plant", {}, -1, seed);
        auto weightless = grow("fig14_left.plant", {{"gravity_y", "0"}}, -1, seed);
        const double d = hanging(*heavy), f = hanging(*weightless);
        each += fmt::format(" seed {}: {:.2f} and {:.2f} m;", seed, d, f);
        down += d, floating += f;
    }
    INFO("hanging stem under gravity and weightless:" << each);
    INFO("three seeds, hanging stem: " << down << " m under gravity, " << floating << " m weightless");
    CHECK(down > 1.5);
    CHECK(floating < 0.25 * down);
}

TEST_CASE("climber figures: Fig. 10's stems cover the dome's upper half, thickening with age", "[climber]") {
    auto f = grow("fig10_dome.plant");
    check_thickening("fig10_dome", *f);
    const std::vector<Segment> segs = segments(f->skeleton());
    // a Fibonacci lattice of 600 points on the dome (radius 0.8 about the origin), those at
    // y >= 0.4 kept: the upper half of the 0.8 m it stands above the ground
    const double golden = 3.14159265358979 * (3 - std::sqrt(5.0));
    std::size_t points = 0, covered = 0;
    for (int i = 0; i < 600; ++i) {
        const double y = 1 - (i + 0.5) / 600.0;
        const double r = std::sqrt(1 - y * y);
        const glm::dvec3 p = 0.8 * glm::dvec3(r * std::cos(golden * i), y, r * std::sin(golden * i));
        if (p.y < 0.4) continue;
        ++points;
        for (const Segment& s : segs)
            if (distance_to(p, s) < 0.05) {
                ++covered;
                break;
            }
    }
    INFO(covered << " of " << points << " points of the upper half within 5 cm of a stem");
    REQUIRE(points > 100);
    CHECK(covered > 0.7 * points);
}

TEST_CASE("climber figures: Fig. 5's branching probability and variance show", "[climber]") {
    struct Shoots {
        std::size_t count = 0;
        double lean = 0; // mean angle of the laterals from the vertical, degrees
    };
    auto shoots = [](const std::string& variant) {
        auto f = grow("fig05_branching.plant", {{"variant", variant}});
        Shoots s;
        std::size_t laterals = 0;
        for (const auto& axis : f->skeleton().axes) {
            ++s.count;
            if (axis.parent < 0 || axis.points.size() < 3) continue;
            const glm::dvec3 d = axis.points.back().position - axis.points.front().position;
            if (glm::length(d) <= 0) continue;
            s.lean += std::acos(std::clamp(d.y / glm::length(d), -1.0, 1.0)) * 180 / 3.14159265358979;
            ++laterals;
        }
        if (laterals > 0) s.lean /= static_cast<double>(laterals);
        return s;
    };
    const Shoots a = shoots("1"), b = shoots("2"), c = shoots("3"), d = shoots("4");
    INFO("(a) " << a.count << " shoots leaning " << a.lean << " deg; (b) " << b.count << " leaning " << b.lean
                << " deg; (c) " << c.count << " leaning " << c.lean << " deg; (d) " << d.count << " leaning "
                << d.lean << " deg");
    CHECK(b.count > 2.5 * static_cast<double>(a.count)); // branching probability
    CHECK(b.lean > c.lean + 10);                         // branching variance
    // (d), low probability and medium variance: far fewer shoots than (b), and laterals leaning
    // further than (a)'s (low variance) but less than (b)'s (high)
    CHECK(2 * d.count < b.count);
    CHECK(d.lean > 2 * a.lean);
    CHECK(d.lean < b.lean);
}

TEST_CASE("climber figures: Fig. 6's dragged branch breaks off, falls and leaves the plant", "[climber]") {
    // fig06_break.plant drags segment #67 from step 28 on; the part above the break lets go of the
    // wall and falls (section 6.1: "the pieces fall down due to gravity") for the climber's
    // fall_time (1 s, ten steps), then leaves the string
    auto before = grow("fig06_break.plant", {}, 28);
    auto broken = grow("fig06_break.plant", {}, 31);
    auto falling = grow("fig06_break.plant", {}, 38);
    auto gone = grow("fig06_break.plant", {}, 40);
    auto undisturbed = grow("fig06_break.plant", {{"drag", "0"}}, 40);
    const auto [n31, y31] = loose(*broken);
    const auto [n38, y38] = loose(*falling);
    INFO("segments: " << before->count("Seg") << " before the drag, " << broken->count("Seg")
                      << " at step 31, " << gone->count("Seg") << " at step 40, " << undisturbed->count("Seg")
                      << " undisturbed; loose particles " << n31 << " at mean height " << y31
                      << " m at step 31, " << n38 << " at " << y38 << " m at step 38, " << loose(*gone).first
                      << " at step 40");
    CHECK(n31 > 20);                                        // most of the plant broke off
    CHECK(broken->count("Seg") + 5 > before->count("Seg")); // still drawn while it falls
    CHECK(n38 == n31);
    CHECK(y38 < y31 - 0.3);                               // fallen
    CHECK(y38 < 0.1);                                     // to the foot of the wall
    CHECK(loose(*gone).first == 0);                       // then gone, from the world
    CHECK(gone->count("Seg") + 5 < before->count("Seg")); // and the string
    CHECK(gone->alive() + 5 < undisturbed->alive());
    CHECK(undisturbed->count("Seg") > before->count("Seg"));
}

TEST_CASE("climber figures: Fig. 1's plants are cut away from the car's windows and lights, and thicken "
          "with age",
          "[climber]") {
    // the boxes of fig01_car.plant's over_glass()
    const std::vector<std::pair<glm::dvec3, glm::dvec3>> glass = {
        {{-0.5, 0.76, 0.43}, {0.4, 1.1, 0.6}},    {{-0.5, 0.76, -0.6}, {0.4, 1.1, -0.43}},
        {{0.43, 0.76, -0.38}, {0.6, 1.1, 0.38}},  {{-0.7, 0.76, -0.38}, {-0.53, 1.1, 0.38}},
        {{0.98, 0.4, 0.18}, {1.15, 0.62, 0.4}},   {{0.98, 0.4, -0.4}, {1.15, 0.62, -0.18}},
        {{-1.15, 0.4, 0.18}, {-0.98, 0.62, 0.4}}, {{-1.15, 0.4, -0.4}, {-0.98, 0.62, -0.18}}};
    auto over_glass = [&](const Figure& f) {
        std::size_t n = 0;
        // a segment is over glass where its end, its start or any point between (sampled every
        // tenth of it) is in one of the boxes
        for (const Segment& s : segments(f.skeleton())) {
            bool over = false;
            for (int k = 0; k <= 10 && !over; ++k) {
                const glm::dvec3 p = s.a + (s.b - s.a) * (k / 10.0);
                for (const auto& [lo, hi] : glass)
                    over = over ||
                           (glm::all(glm::greaterThanEqual(p, lo)) && glm::all(glm::lessThanEqual(p, hi)));
            }
            n += over ? 1 : 0;
        }
        return n;
    };
    auto pruned = grow("fig01_car.plant");
    check_thickening("fig01_car", *pruned);
    auto wild = grow("fig01_car.plant", {{"prune_from", "1000"}});
    INFO(over_glass(*pruned) << " segments over glass pruned, " << over_glass(*wild) << " unpruned");
    CHECK(over_glass(*wild) > 20); // the plants do grow over the glass
    CHECK(over_glass(*pruned) == 0);
    CHECK(pruned->count("Seg") > 300); // and cover the rest of the car
    // the sketched attractors draw stems to them: stem length with its midpoint within 25 cm of a
    // sketched point, against the same plants grown without them (-D sketch=0)
    const std::vector<glm::dvec3> sketched = attractors_of("fig01_car.plant");
    REQUIRE(sketched.size() >= 5);
    auto near_sketch = [&](const Figure& f) {
        double l = 0;
        for (const Segment& s : segments(f.skeleton()))
            for (const glm::dvec3& p : sketched)
                if (glm::distance(s.mid(), p) < 0.25) l += s.length();
        return l;
    };
    auto unsketched = grow("fig01_car.plant", {{"sketch", "0"}});
    const double with = near_sketch(*pruned), without = near_sketch(*unsketched);
    INFO(with << " m of stem within 25 cm of the sketched points, " << without << " m without them");
    CHECK(with > 1.5 * without);
}

TEST_CASE("climber figures: Fig. 12's free shoot stands when stiff and droops when soft, keeping its length",
          "[climber]") {
    // fig12_free_shoot.plant as shipped, at three stiffnesses (-D stiff): its one shoot's highest
    // point against the length of stem it grew (test_climber_physics.cpp checks the same on a shoot
    // of its own, with a cap on its length)
    double last = HUGE_VAL;
    for (const char* stiff : {"1", "0.5", "0.2"}) {
        auto f = grow("fig12_free_shoot.plant", {{"stiff", stiff}});
        double height = 0, length = 0;
        std::size_t count = 0;
        for (const Segment& s : segments(f->skeleton())) {
            height = std::max({height, s.a.y, s.b.y});
            length += s.length();
            ++count;
        }
        const double rest = 0.05 * static_cast<double>(count); // the library's segment length
        INFO("stiffness " << stiff << ": " << count << " segments, " << length << " m of stem for " << rest
                          << " m of rest length, highest point " << height << " m");
        REQUIRE(count >= 30);
        CHECK(std::fabs(length / rest - 1) < 0.1);
        if (std::string(stiff) == "1") CHECK(height > 0.8 * rest);   // stands within 20 % of its length
        if (std::string(stiff) == "0.2") CHECK(height < 0.2 * rest); // droops to the ground
        CHECK(height < last);                                        // lower as it gets softer
        last = height;
    }
}

TEST_CASE("climber figures: Fig. 8's shoots spread over the painted band", "[climber]") {
    // fig08_painted_wall.plant paints a band of samples across the wall; -D paint=0 grows the same
    // plants on an unpainted wall. A sample is covered when a stem passes within 15 cm of it.
    const std::vector<glm::dvec3> painted = attractors_of("fig08_painted_wall.plant");
    REQUIRE(painted.size() >= 20);
    auto covered = [&](const Figure& f) {
        const std::vector<Segment> stems = segments(f.skeleton());
        return std::count_if(painted.begin(), painted.end(), [&](const glm::dvec3& p) {
            return std::any_of(stems.begin(), stems.end(),
                               [&](const Segment& s) { return distance_to(p, s) < 0.15; });
        });
    };
    auto with_paint = grow("fig08_painted_wall.plant");
    auto without = grow("fig08_painted_wall.plant", {{"paint", "0"}});
    const auto on = covered(*with_paint), off = covered(*without);
    INFO(painted.size() << " painted samples; covered " << on << " with the paint, " << off << " without");
    CHECK(on >= 0.8 * static_cast<double>(painted.size()));
    CHECK(on >= 2 * off);
}

TEST_CASE("climber figures: Fig. 11's plants grow toward the light from the upper left", "[climber]") {
    // fig11_fence.plant lights its fence from the upper left (light_x -1); -D light_x=1 mirrors the
    // light. The fence and the seeds are symmetric about x = 0: the share of stem length at x < 0.
    auto left_share = [](const Figure& f) {
        double left = 0, all = 0;
        for (const Segment& s : segments(f.skeleton())) {
            all += s.length();
            if (s.mid().x < 0) left += s.length();
        }
        return all > 0 ? left / all : 0.0;
    };
    auto from_left = grow("fig11_fence.plant");
    auto from_right = grow("fig11_fence.plant", {{"light_x", "1"}});
    const double l = left_share(*from_left), r = left_share(*from_right);
    INFO("stem length left of the middle: " << l << " lit from the upper left, " << r
                                            << " from the upper right");
    CHECK(l > 0.7);
    CHECK(r < 0.3);
}
