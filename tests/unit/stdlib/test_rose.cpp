// The shrub rose library (stdlib/rose.plant) against the rules of Umezawa & Mukai, checked on the
// skeleton the turtle draws from every grammar in grammars/rose/ and several seeds.
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
#include <filesystem>
#include <map>
#include <numbers>
#include <set>

using namespace plant;

namespace {

namespace fs = std::filesystem;

const std::string kRoseDir = std::string(PLANT_SOURCE_DIR) + "/grammars/rose";

// stem types and origins, as stdlib/rose.plant numbers them
enum Type { Trunk = 0, Inter = 1, Term = 2, BloomStem = 3 };
enum Origin { FromRoot = 0, FromTip = 1, FromSecond = 2, FromRandom = 3, FromExtra = 4 };

struct StemInfo {
    int type = 0, state = 0, origin = 0;
    int axis = -1;        // in the skeleton
    int own_segments = 0; // F modules of the stem itself
    int blooms = 0;       // Bloom modules anywhere in its branch
};

struct Rose {
    std::string string;
    Skeleton skeleton;
    std::vector<StemInfo> stems;
    std::map<std::string, double> params;
    std::map<std::string, int> counts; // modules by name in the final string
};

Rose grow(const std::string& path, std::uint64_t seed,
          std::vector<std::pair<std::string, std::string>> defines = {}, int threads = 1) {
    SourceManager sources;
    Diagnostics diags;
    CompileOptions co;
    co.defines = std::move(defines);
    co.environments = runtime_environments();
    auto program = compile_file(sources, path, co, diags);
    INFO(render_all(diags, sources));
    REQUIRE(program);
    TurtleEnvironmentPhase phase;
    DeriveOptions opt;
    opt.seed = seed;
    opt.threads = threads;
    opt.environment_phase = &phase;
    Derivation d(*program, opt);
    d.run();

    Rose rose;
    rose.string = format_string(*program, d.string(), false);
    for (const auto& g : program->globals)
        if (g.kind == GlobalKind::Param) rose.params[g.name] = d.globals()[g.slot];
    rose.skeleton = build_skeleton(*program, d.interpreted(d.string()), turtle_options(d));

    std::map<ModuleId, int> axis_of_first;
    for (std::size_t a = 0; a < rose.skeleton.axes.size(); ++a)
        if (rose.skeleton.axes[a].points.size() > 1)
            axis_of_first[rose.skeleton.axes[a].points[1].id] = static_cast<int>(a);

    const ModuleString& s = d.string();
    auto name = [&](std::size_t i) -> const std::string& { return program->symbols[s.symbol(i)].name; };
    for (std::size_t i = 0; i < s.size(); ++i) {
        ++rose.counts[name(i)];
        if (name(i) != "Stem") continue;
        StemInfo st;
        st.type = static_cast<int>(s.args(i)[0]);
        st.state = static_cast<int>(s.args(i)[1]);
        st.origin = static_cast<int>(s.args(i)[2]);
        int depth = 0;
        for (std::size_t j = i + 1; j < s.size() && depth >= 0; ++j) {
            const std::string& n = name(j);
            if (n == "[")
                ++depth;
            else if (n == "]")
                --depth;
            else if (n == "Bloom")
                ++st.blooms;
            else if (n == "F" && depth == 0) {
                if (st.own_segments++ == 0) {
                    auto it = axis_of_first.find(s.ids[j]);
                    REQUIRE(it != axis_of_first.end());
                    st.axis = it->second;
                }
            }
        }
        rose.stems.push_back(st);
    }
    return rose;
}

std::vector<glm::dvec3> points(const Rose& r, const StemInfo& s) {
    std::vector<glm::dvec3> out;
    if (s.axis < 0) return out;
    for (const auto& p : r.skeleton.axes[static_cast<std::size_t>(s.axis)].points) out.push_back(p.position);
    return out;
}

// |p / radii| for an ellipsoid centred on the bud union: 1 on the surface
double level(const glm::dvec3& p, double r, double h) {
    return glm::length(p / glm::dvec3(r, h, r));
}

std::vector<std::string> rose_grammars() {
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(kRoseDir))
        if (e.path().extension() == ".plant") files.push_back(e.path().string());
    std::sort(files.begin(), files.end());
    return files;
}

// the smallest rotation taking unit a to unit b, applied to v
glm::dvec3 transport(const glm::dvec3& v, const glm::dvec3& a, const glm::dvec3& b) {
    glm::dvec3 axis = glm::cross(a, b);
    double s = glm::length(axis);
    if (s < 1e-12) return v;
    glm::dvec3 k = axis / s;
    double c = glm::dot(a, b);
    return v * c + glm::cross(k, v) * s + k * (glm::dot(k, v) * (1 - c));
}

double wrap_degrees(double a) {
    a = std::fmod(a, 360.0);
    if (a > 180) a -= 360;
    if (a <= -180) a += 360;
    return a;
}

// The stems' own rules (docs/rose.md, checks): how each kind of stem ends, how many trunks.
void check_stems(const Rose& r) {
    const double h_trunk = r.params.at("h_trunk"), r_trunk = r.params.at("r_trunk");
    const double h_crown = r.params.at("h_crown"), r_crown = r.params.at("r_crown");
    const int N_D = static_cast<int>(r.params.at("N_D")), N_T = static_cast<int>(r.params.at("N_T"));
    const int N_B = static_cast<int>(r.params.at("N_B"));
    const bool flowering = r.params.at("stage") >= 2;

    // the derivation finished: nothing is left waiting to grow or branch
    for (const char* pending : {"Root", "Node", "Grow", "Flower", "Peduncles"}) {
        INFO(pending);
        CHECK(r.counts.count(pending) == 0);
    }
    if (flowering) CHECK(r.counts.count("Dormant") == 0);
    REQUIRE(!r.stems.empty());

    int trunks = 0;
    for (const auto& st : r.stems) {
        INFO(fmt::format("stem type {} origin {}", st.type, st.origin));
        CHECK(st.state == 1); // every candidate was kept or cut
        REQUIRE(st.axis >= 0);
        auto p = points(r, st);
        REQUIRE(p.size() >= 2);
        // no stem's first segment points downward (level is allowed: around a vertical stem
        // every perpendicular child is level)
        CHECK(p[1].y - p[0].y >= -1e-9);
        const glm::dvec3& last = p.back();
        const glm::dvec3& before = p[p.size() - 2];
        const int segments = static_cast<int>(p.size()) - 1;
        CHECK(segments == st.own_segments);
        if (st.type == Trunk) {
            ++trunks;
            // trunks end just past the trunk ellipsoid, or past the crown when that is smaller
            bool past_trunk = level(last, r_trunk, h_trunk) >= 1,
                 past_crown = level(last, r_crown, h_crown) >= 1;
            CHECK((past_trunk || past_crown));
            if (segments > 1) {
                CHECK(level(before, r_trunk, h_trunk) < 1);
                CHECK(level(before, r_crown, h_crown) < 1);
            }
        } else if (st.type == Inter) {
            // intermediate stems end just past the crown, or at N_D segments inside it
            bool past_crown = level(last, r_crown, h_crown) >= 1;
            CHECK((past_crown || segments == N_D));
            CHECK(segments <= N_D);
            if (past_crown && segments > 1) CHECK(level(before, r_crown, h_crown) < 1);
            if (!past_crown)
                for (const auto& q : p) CHECK(level(q, r_crown, h_crown) < 1);
        } else if (st.type == Term) {
            CHECK(segments == N_T);
            CHECK(st.blooms <= std::min(N_B, 9));
            CHECK(st.blooms >= 1);
        }
        CHECK((flowering || (st.type != Term && st.type != BloomStem)));
    }
    CHECK(trunks == static_cast<int>(r.params.at("N_S"))); // density control never picks a trunk
}

// Eq. 3: no two stems (trunks, intermediate, terminal) have nodes closer than delta_min, except
// where one branches from the other (a stem's first point lies on its parent), and except two
// trunks: density control picks new child stems only, never a trunk (Sec. V-B: the specified
// number of trunks grow), so trunks may stand closer to each other.
void check_spacing(const Rose& r) {
    const double delta = r.params.at("delta_min");
    std::vector<std::vector<glm::dvec3>> nodes;
    std::vector<glm::dvec3> base;
    std::vector<bool> trunk;
    for (const auto& st : r.stems)
        if (st.type != BloomStem) {
            auto p = points(r, st);
            base.push_back(p[0]);
            nodes.emplace_back(p.begin() + 1, p.end());
            trunk.push_back(st.type == Trunk);
        }
    double closest = 1e300;
    for (std::size_t a = 0; a < nodes.size(); ++a)
        for (std::size_t b = a + 1; b < nodes.size(); ++b)
            for (const auto& x : nodes[a]) {
                if (trunk[a] && trunk[b]) break;                // trunks are never picked
                if (glm::distance(x, base[b]) < 1e-9) continue; // b branches from a here
                for (const auto& y : nodes[b])
                    if (glm::distance(y, base[a]) >= 1e-9) closest = std::min(closest, glm::distance(x, y));
            }
    CHECK(closest >= delta - 1e-9);
}

void check_phyllotaxis(const Rose& r) {
    const bool flowering = r.params.at("stage") >= 2;
    // 3/8 phyllotaxis: the children along a stem (lateral stems and leaves; not the tip's child,
    // nor the branching children of the last two nodes of a trunk or intermediate stem) are 135
    // degrees apart per node around the stem, measured in a frame carried along the stem by
    // the smallest rotation from segment to segment
    std::map<int, const StemInfo*> stem_of_axis;
    for (const auto& st : r.stems) stem_of_axis[st.axis] = &st;
    struct Child {
        int k;
        glm::dvec3 g;
    };
    std::map<int, std::vector<Child>> children; // by parent axis
    auto attach = [&](int parent, const glm::dvec3& at, const glm::dvec3& g) {
        const auto& pts = r.skeleton.axes[static_cast<std::size_t>(parent)].points;
        for (std::size_t k = 1; k < pts.size(); ++k)
            if (glm::distance(pts[k].position, at) < 1e-9) {
                children[parent].push_back(Child{static_cast<int>(k), glm::normalize(g)});
                return true;
            }
        return false;
    };
    for (const auto& st : r.stems) {
        const auto& ax = r.skeleton.axes[static_cast<std::size_t>(st.axis)];
        if (ax.parent < 0 || !stem_of_axis.count(ax.parent)) continue;
        CHECK(attach(ax.parent, ax.points[0].position, ax.points[1].position - ax.points[0].position));
    }
    int leaves = 0;
    for (const auto& o : r.skeleton.organs) {
        if (o.shape != OrganShape{OrganKind::Surface, "petiole", -1, {}}) continue;
        ++leaves;
        glm::dvec3 at(o.transform[3]), g(o.transform[1]);
        bool found = false;
        for (const auto& [axis, st] : stem_of_axis)
            if (st->type == Term && attach(axis, at, g)) {
                found = true;
                break;
            }
        CHECK(found);
    }
    if (flowering) CHECK(leaves > 0);
    int measured = 0;
    for (auto& [axis, kids] : children) {
        const StemInfo& parent = *stem_of_axis.at(axis);
        const auto& pts = r.skeleton.axes[static_cast<std::size_t>(axis)].points;
        const int last = static_cast<int>(pts.size()) - 1;
        const int skip_from = parent.type == Term || parent.type == BloomStem ? last : last - 1;
        std::vector<glm::dvec3> dir(pts.size()), ref(pts.size());
        for (int k = 1; k <= last; ++k) dir[k] = glm::normalize(pts[k].position - pts[k - 1].position);
        glm::dvec3 seed = std::abs(dir[1].y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
        ref[1] = glm::normalize(glm::cross(seed, dir[1]));
        for (int k = 2; k <= last; ++k) ref[k] = glm::normalize(transport(ref[k - 1], dir[k - 1], dir[k]));
        std::vector<std::pair<int, double>> az;
        for (const auto& c : kids) {
            if (c.k >= skip_from) continue;
            const glm::dvec3 d = dir[c.k], rr = ref[c.k];
            az.emplace_back(c.k, std::atan2(glm::dot(c.g, glm::cross(d, rr)), glm::dot(c.g, rr)) * 180 /
                                     std::numbers::pi);
        }
        std::sort(az.begin(), az.end());
        for (std::size_t i = 1; i < az.size(); ++i) {
            double want = 135.0 * (az[i].first - az[i - 1].first);
            double got = az[i].second - az[i - 1].second;
            INFO(fmt::format("children at nodes {} and {}", az[i - 1].first, az[i].first));
            CHECK(std::abs(wrap_degrees(got - want)) <= 1.0);
            ++measured;
        }
    }
    if (flowering) CHECK(measured > 0);
}

// Every rule of docs/rose.md that can be read off one grown rose.
void check_rose(const Rose& r, const std::string& what) {
    INFO(what);
    check_stems(r);
    check_spacing(r);
    check_phyllotaxis(r);
}

} // namespace

TEST_CASE("rose: every grammar in grammars/rose follows the paper's rules on five seeds", "[rose]") {
    auto files = rose_grammars();
    REQUIRE(files.size() >= 13);
    for (const auto& f : files)
        for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
            Rose r = grow(f, seed);
            check_rose(r, fmt::format("{} seed {}", fs::path(f).filename().string(), seed));
        }
}

TEST_CASE("rose: the same seed grows the same rose on any thread count, another seed another", "[rose]") {
    const std::string f = kRoseDir + "/fig09.plant";
    Rose a = grow(f, 7), b = grow(f, 7, {}, 2), c = grow(f, 8);
    CHECK(a.string == b.string);
    CHECK(a.string != c.string);
}

TEST_CASE("rose: with rho = 0 there are no random shoots, otherwise there are", "[rose]") {
    int random_shoots = 0;
    for (std::uint64_t seed : {1, 2, 3, 4, 5}) {
        Rose none = grow(kRoseDir + "/fig09.plant", seed, {{"rho_inter", "0"}, {"rho_term", "0"}});
        check_rose(none, fmt::format("fig09 without random shoots, seed {}", seed));
        for (const auto& st : none.stems) CHECK(st.origin != FromRandom);
        Rose some = grow(kRoseDir + "/fig09.plant", seed);
        for (const auto& st : some.stems) random_shoots += st.origin == FromRandom;
    }
    CHECK(random_shoots > 0);
    for (const char* fig : {"fig11a", "fig11b", "fig11c"}) {
        Rose r = grow(kRoseDir + "/" + fig + ".plant", 3);
        for (const auto& st : r.stems) CHECK(st.origin != FromRandom);
    }
}

TEST_CASE("rose: density control removes stems, and removes more as delta_min grows", "[rose]") {
    auto stems = [](const Rose& r) {
        int n = 0;
        for (const auto& st : r.stems) n += st.type != BloomStem;
        return n;
    };
    int free_total = 0, tight_total = 0;
    for (std::uint64_t seed : {1, 2, 3}) {
        Rose free = grow(kRoseDir + "/fig12c.plant", seed, {{"delta_min", "0.001"}});
        Rose tight = grow(kRoseDir + "/fig12c.plant", seed, {{"delta_min", "6"}});
        check_rose(tight, fmt::format("fig12c with delta_min 6, seed {}", seed));
        free_total += stems(free);
        tight_total += stems(tight);
    }
    CHECK(tight_total < free_total);
}

TEST_CASE("rose: N_B blooms per terminal stem, up to nine on three tips", "[rose]") {
    for (int nb : {1, 3, 5, 9}) {
        Rose r = grow(kRoseDir + "/fig12c.plant", 2, {{"N_B", std::to_string(nb)}});
        check_rose(r, fmt::format("fig12c with N_B {}", nb));
        int full = 0;
        for (const auto& st : r.stems)
            if (st.type == Term) full += st.blooms == nb;
        CHECK(full > 0); // extra bloom stems that would point down are dropped, so not every stem
    }
}

TEST_CASE("rose: stage 1 is the winter-pruned shape, dormant buds where terminal stems will grow", "[rose]") {
    Rose winter = grow(kRoseDir + "/fig12c.plant", 4, {{"stage", "1"}});
    Rose summer = grow(kRoseDir + "/fig12c.plant", 4);
    check_rose(winter, "fig12c stage 1");
    int dormant = winter.counts.count("Dormant") ? winter.counts.at("Dormant") : 0;
    CHECK(dormant > 0);
    int terminal = 0, woody_winter = 0, woody_summer = 0;
    for (const auto& st : summer.stems) {
        terminal += st.type == Term;
        woody_summer += st.type <= Inter;
    }
    for (const auto& st : winter.stems) woody_winter += st.type <= Inter;
    CHECK(woody_winter == woody_summer); // flowering adds to the frame, never changes it
    CHECK(terminal > 0);
    CHECK(terminal <= dormant); // some buds are picked by density control
}

// stdlib/rose.plant gives every param a range (plant view's sliders): each figure's values lie in
// it, and a value outside does not compile, naming the range
TEST_CASE("rose: every param has a range holding each figure's value, and outside it fails", "[rose]") {
    for (const auto& f : rose_grammars()) {
        SourceManager sources;
        Diagnostics diags;
        CompileOptions co;
        co.environments = runtime_environments();
        auto program = compile_file(sources, f, co, diags);
        INFO(f << "\n" << render_all(diags, sources));
        REQUIRE(program);
        int params = 0;
        for (const auto& g : program->globals) {
            if (g.kind != GlobalKind::Param) continue;
            ++params;
            INFO(g.name);
            CHECK(g.has_range);
            const double v = program->global_values[g.slot];
            CHECK(g.low <= v);
            CHECK(v <= g.high);
        }
        CHECK(params >= 31);
    }
    for (const auto& [name, value] :
         std::vector<std::pair<std::string, std::string>>{{"N_S", "13"},
                                                          {"N_S", "0"},
                                                          {"theta", "pi / 2 + 0.01"},
                                                          {"droop_reading", "2"},
                                                          {"N_B", "10"}}) {
        SourceManager sources;
        Diagnostics diags;
        CompileOptions co;
        co.defines = {{name, value}};
        co.environments = runtime_environments();
        auto program = compile_file(sources, kRoseDir + "/fig09.plant", co, diags);
        const std::string text = render_all(diags, sources);
        INFO(name << " = " << value << "\n" << text);
        CHECK(!program);
        CHECK(text.find("is outside its range") != std::string::npos);
        CHECK(text.find("rose.plant") != std::string::npos); // the note at the declared range
    }
}
