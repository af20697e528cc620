// The mutation test of the rose checks (issue 18, item 6): each entry breaks one rule of
// Umezawa & Mukai in a copy of stdlib/rose.plant by a text substitution, grows the copy on a few
// parameter sets and requires that rose_rule_failures notices. It fails when a mutation passes
// every check, and when a substitution no longer finds its text in the library (so the list
// cannot rot silently as rose.plant changes).
#include "rose_rules.hpp"

#include <catch2/catch.hpp>
#include <fmt/format.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

using namespace plant;
using namespace plant::test;

namespace {

namespace fs = std::filesystem;

struct Mutation {
    const char* rule;                                       // the rule the mutation breaks
    std::vector<std::pair<const char*, const char*>> edits; // each `from` must occur in rose.plant
};

// clang-format off
const std::vector<Mutation> kMutations = {
    {"Eq. 2: sigma ignored", {{"let w = pow(n, sigma);", "let w = n;"}}},
    {"Eq. 2: kappa_inter and kappa_term swapped",
     {{"fn kappa_of(t) = t <= INTER ? kappa_inter : kappa_term;", "fn kappa_of(t) = t <= INTER ? kappa_term : kappa_inter;"}}},
    {"Eq. 2: sigma_term for trunks and intermediate stems",
     {{"fn sigma_of(t) = t <= INTER ? sigma_inter : sigma_term;", "fn sigma_of(t) = sigma_term;"}}},
    {"Eq. 1-2: target pitch 0.7 theta",
     {{"blend(d, n - 1, theta, kap, sig)", "blend(d, n - 1, 0.7 * theta, kap, sig)"}}},
    {"Eq. 1: divided by |d| instead of |d_perp|",
     {{"fn ideal(d: vec3, th) = flat(d) * cos(th)", "fn ideal(d: vec3, th) = vec3(d.x, 0, d.z) * cos(th)"}}},
    {"Sec. IV-C: tip child inward",
     {{"let g = upward(tip_ideal(p, d, phi_stem), d);", "let g = upward(tip_ideal(p * -1, d, phi_stem), d);"}}},
    {"Sec. IV-C: tip child at phi_leaf",
     {{"let g = upward(tip_ideal(p, d, phi_stem), d);", "let g = upward(tip_ideal(p, d, phi_leaf), d);"}}},
    {"Sec. IV-C: tip leaf at phi_stem", {{"g = tip_ideal(p, d, phi_leaf); }", "g = tip_ideal(p, d, phi_stem); }"}}},
    {"Sec. IV-C: 3/8 phyllotaxis at 126 degrees", {{"const PHYLLO = 3 * pi / 4;", "const PHYLLO = 0.7 * pi;"}}},
    {"Sec. IV-C: leaves not perpendicular to their segment",
     {{"let g = turn(r, d, k * PHYLLO + ph);", "let g = normalize(turn(r, d, k * PHYLLO + ph) + d * 0.2);"}}},
    {"Sec. IV-D: no second branching child",
     {{"if why == CUT { produce [ Dormant(FROM_SECOND, p, g) ]; }\n      produce [ Grow(INTER, FROM_SECOND, p, g) ];",
       "produce;"}}},
    {"Sec. IV-D: pinched trunks grow terminal stems",
     {{"if why == CUT { produce [ Dormant(FROM_TIP, p, g) ]; }", "if why != DEADHEADED { produce [ Dormant(FROM_TIP, p, g) ]; }"}}},
    {"Sec. IV-D: stems cut by the crown grow intermediate second children",
     {{"if why == CUT { produce [ Dormant(FROM_SECOND, p, g) ]; }", "if why == PINCHED { produce [ Dormant(FROM_SECOND, p, g) ]; }"}}},
    {"Sec. IV-D: gamma ignored", {{"crown.contains_scaled(p, gamma)", "crown.contains_scaled(p, 0)"}}},
    {"Sec. IV-B: deadheading one segment late",
     {{"if t == INTER && n >= N_D { return DEADHEADED; }", "if t == INTER && n >= N_D + 1 { return DEADHEADED; }"}}},
    {"Sec. IV-A: one trunk whatever N_S", {{"for i in 0..N_S {", "for i in 0..1 {"}}},
    {"Sec. IV-A: trunks at any azimuth",
     {{"let az = 2 * pi * (i + uniform(0.15, 0.85)) / N_S;", "let az = 2 * pi * uniform(0, 1);"}}},
    {"Sec. V-B: density control picks trunks",
     {{"s == 0 && t != TRUNK && c < delta_min -> %;", "s == 0 && c < delta_min -> %;"}}},
    {"Sec. IV-A: trunk pitch below its range",
     {{"let pt = uniform(trunk_pitch_min, trunk_pitch_max);", "let pt = uniform(0.02, trunk_pitch_max);"}}},
    {"Sec. IV-F: a leaf dropped",
     {{"nproduce [ SetHead(g.x, g.y, g.z) $ Leaf(leaf_size) ];",
       "if k != 2 { nproduce [ SetHead(g.x, g.y, g.z) $ Leaf(leaf_size) ]; }"}}},
    {"Sec. IV-F: N_T - 1 segments", {{"Flower(TERM, o, N_T, min(N_B, 9), p, d)", "Flower(TERM, o, N_T - 1, min(N_B, 9), p, d)"}}},
    {"Sec. IV-G: peduncles 1.0 l_term instead of 1.5", {{"let l = 0.5 * l_term;", "let l = l_term / 3;"}}},
    {"Sec. IV-G: side peduncles at 22 degrees instead of 45",
     {{"normalize(d + side) : normalize(d - side)", "normalize(d + side * 0.4) : normalize(d - side * 0.4)"}}},
    {"Sec. IV-G: side peduncles not across the outward direction",
     {{"let side = cross(d, outward(p, d));", "let side = across(d);"}}},
    {"Sec. IV-G: theta_droop ignored", {{"let target = min(theta, theta_droop);", "let target = theta;"}}},
    {"Sec. IV-G: peduncles bent down",
     {{"blend(g1, 1, target, ", "blend(g1, 1, -target, "}, {"blend(g2, 2, target, ", "blend(g2, 2, -target, "}}},
    {"Sec. IV-G: extra bloom stems with one segment",
     {{"Flower(BLOOM, FROM_EXTRA, n - k, extra, p, gb)", "Flower(BLOOM, FROM_EXTRA, 1, extra, p, gb)"}}},
    {"Sec. IV-G: extra bloom stems off the leaf axil", {{"let gb = normalize(g + d);", "let gb = normalize(g + d * 2);"}}},
    {"Sec. IV-G: at most three blooms whatever N_B", {{"min(N_B, 9)", "min(N_B, 3)"}}},
    {"droop_reading 1: half the sag", {{"g3 = ideal(g3, pitch(g3) - sag);", "g3 = ideal(g3, pitch(g3) - 0.5 * sag);"}}},
    {"tip_leaf_reading 1: no search", {{"if k == n && tip_leaf_reading >= 1 { g = upward(g, d); }", ""}}},
    {"tip_leaf_reading 0: the search made anyway",
     {{"if k == n && tip_leaf_reading >= 1 { g = upward(g, d); }", "if k == n { g = upward(g, d); }"}}},
    {"tip_leaf_reading 1: the spiral not counted back from the tip leaf",
     {{"if t == TERM && tip_leaf_reading >= 1 { ph = tip_phase(p0, d0, n); }", ""}}},
};
// clang-format on

struct Run {
    const char* figure;
    std::uint64_t seed;
    RoseDefines defines;
};

// small: the first run that fails stops a mutation, so most cost one derivation
const std::vector<Run> kRuns = {
    {"fig09", 1, {}},
    {"fig09", 2, {{"N_B", "9"}, {"theta_droop", "0.4"}}},
    {"fig12a", 1, {{"gamma", "0.5"}, {"rho_inter", "0.3"}, {"rho_term", "0.5"}}},
    {"fig09", 3, {{"stage", "1"}}},
    {"fig12d", 1, {{"droop_reading", "1"}}},
    {"fig09", 4, {{"tip_leaf_reading", "0"}, {"N_B", "5"}}},
    {"fig12c", 2, {}},
    {"fig09", 1, {{"N_S", "12"}, {"delta_min", "3"}}}, // crowded trunks: picking them loses 4 of 12
};

std::string read_text(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void write_text(const fs::path& p, const std::string& s) {
    std::ofstream out(p, std::ios::binary);
    out << s;
}

// A folder holding a copy of the library and of the figure grammars, importing the copy.
struct Sandbox {
    fs::path dir;
    Sandbox() {
        dir = fs::temp_directory_path() / fmt::format("plant-rose-mutations-{}", ::getpid());
        fs::remove_all(dir);
        fs::create_directories(dir);
        const std::string root = PLANT_SOURCE_DIR;
        for (const auto& run : kRuns) {
            std::string g = read_text(root + "/grammars/rose/" + run.figure + ".plant");
            const std::string from = "import rose with";
            auto at = g.find(from);
            REQUIRE(at != std::string::npos);
            g.replace(at, from.size(), "import \"rose.plant\" with");
            write_text(dir / (std::string(run.figure) + ".plant"), g);
        }
    }
    ~Sandbox() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    // the first failure of the checks over kRuns, or "" when the library passes them all
    std::string first_failure(const std::string& library) const {
        write_text(dir / "rose.plant", library);
        for (const auto& run : kRuns) {
            std::string error;
            RoseModel r = grow_rose_model((dir / (std::string(run.figure) + ".plant")).string(), run.seed,
                                          run.defines, error);
            const std::string what = fmt::format("{} seed {}", run.figure, run.seed);
            if (!error.empty()) return what + ": does not compile: " + error;
            auto f = rose_rule_failures(r);
            if (!f.empty()) return what + ": " + f.front();
        }
        return "";
    }
};

} // namespace

TEST_CASE("rose mutations: every deliberate breaking of stdlib/rose.plant fails the rose checks", "[rose]") {
    const std::string library = read_text(std::string(PLANT_SOURCE_DIR) + "/stdlib/rose.plant");
    REQUIRE(!library.empty());
    Sandbox box;
    {
        INFO("the unbroken copy must pass, or the mutations prove nothing");
        CHECK(box.first_failure(library).empty());
    }
    for (const auto& m : kMutations) {
        INFO(m.rule);
        std::string broken = library;
        bool applies = true;
        for (const auto& [from, to] : m.edits) {
            INFO(fmt::format("substitution of \"{}\"", from));
            std::size_t at = broken.find(from), n = 0;
            CHECK(at != std::string::npos); // the list must follow rose.plant as it changes
            applies = applies && at != std::string::npos;
            for (; at != std::string::npos; at = broken.find(from, at + std::strlen(to)), ++n)
                broken.replace(at, std::strlen(from), to);
        }
        if (!applies) continue;
        const std::string caught = box.first_failure(broken);
        INFO("caught by: " + caught);
        CHECK(!caught.empty());
        UNSCOPED_INFO(m.rule << " -> " << caught);
    }
}
