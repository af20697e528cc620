// The checks of rose_rules.hpp: one function per rule group of Umezawa & Mukai, Sec. IV.
#include "rose_rules.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

namespace plant::test {

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kTol = 1e-6; // directions are compared component by component

struct Ctx {
    const RoseModel& r;
    std::vector<std::string>& out;
    std::map<std::string, int> per_rule;
    double p(const char* name) const { return r.params.at(name); }
    int n(const char* name) const { return static_cast<int>(std::lround(r.params.at(name))); }
    // records a violation (at most five messages per rule, so a broken rule stays readable)
    void fail(const std::string& rule, const std::string& what) {
        if (per_rule[rule]++ < 5) out.push_back(rule + ": " + what);
    }
    const RoseStem& stem(int i) const { return r.stems[static_cast<std::size_t>(i)]; }
};

bool same(const glm::dvec3& a, const glm::dvec3& b, double tol = kTol) {
    return glm::length(a - b) <= tol;
}

std::string str(const glm::dvec3& v) {
    return fmt::format("({:.6f}, {:.6f}, {:.6f})", v.x, v.y, v.z);
}

double angle(const glm::dvec3& a, const glm::dvec3& b) {
    return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0));
}

double level(const glm::dvec3& q, double r, double h) {
    return glm::length(q / glm::dvec3(r, h, r));
}

bool woody(int type) {
    return type == RoseTrunk || type == RoseInter;
}

double seg_len(const Ctx& c, int type) {
    return type == RoseTrunk ? c.p("l_trunk") : type == RoseInter ? c.p("l_inter") : c.p("l_term");
}

// Sec. IV-B: why a trunk or intermediate stem stops at node k: the crown ellipsoid (winter
// pruning), the trunk ellipsoid (pinching out) or N_D segments (deadheading)
enum class Stop { Cut, Pinched, Deadheaded, Other };
Stop stop_at(const Ctx& c, const RoseStem& s, int k) {
    const glm::dvec3& q = s.pts[static_cast<std::size_t>(k)];
    if (level(q, c.p("r_crown"), c.p("h_crown")) > 1) return Stop::Cut;
    if (s.type == RoseTrunk && level(q, c.p("r_trunk"), c.p("h_trunk")) > 1) return Stop::Pinched;
    if (s.type == RoseInter && k >= c.n("N_D")) return Stop::Deadheaded;
    return Stop::Other;
}
Stop stop_of(const Ctx& c, const RoseStem& s) {
    return stop_at(c, s, s.segments());
}

std::string name_of(const Ctx& c, int i) {
    const RoseStem& s = c.stem(i);
    return fmt::format("stem {} (type {} origin {} at node {} of stem {})", i, s.type, s.origin, s.node,
                       s.parent);
}

// Eq. 1-2: every segment direction follows from the one before with theta-hat, and kappa and
// sigma of the stem's kind (trunks share the intermediate stems'); segment lengths by kind
void check_eq2(Ctx& c) {
    for (std::size_t i = 0; i < c.r.stems.size(); ++i) {
        const RoseStem& s = c.r.stems[i];
        const bool wood = woody(s.type);
        const double kappa = wood ? c.p("kappa_inter") : c.p("kappa_term");
        const double sigma = wood ? c.p("sigma_inter") : c.p("sigma_term");
        for (int k = 1; k <= s.segments(); ++k) {
            if (std::abs(s.lens[k] - seg_len(c, s.type)) > 1e-9)
                c.fail("segment length",
                       fmt::format("{} segment {} is {}", name_of(c, int(i)), k, s.lens[k]));
            if (k == 1) continue;
            glm::dvec3 want = rose_blend(s.dirs[k - 1], k - 1, c.p("theta"), kappa, sigma);
            if (!same(want, s.dirs[k]))
                c.fail("Eq. 1-2", fmt::format("{} segment {}: {} where Eq. 2 gives {}", name_of(c, int(i)), k,
                                              str(s.dirs[k]), str(want)));
        }
        if (woody(s.type))
            for (int k = 1; k < s.segments(); ++k)
                if (stop_at(c, s, k) != Stop::Other)
                    c.fail("stop rule", fmt::format("{} grows on past node {} of {}", name_of(c, int(i)), k,
                                                    s.segments()));
        if (s.state != 1) c.fail("picking", fmt::format("{} is still a candidate", name_of(c, int(i))));
        if (s.segments() < 1)
            c.fail("stems", fmt::format("{} has no segment", name_of(c, int(i))));
        else if (s.dirs[1].y < -1e-9)
            c.fail("shoot picking", fmt::format("{} starts downward", name_of(c, int(i))));
    }
}

// Sec. IV-A: N_S trunks from the bud union, random positive pitch; here one to each of N_S
// azimuth sectors (docs/rose.md)
void check_trunks(Ctx& c) {
    const int N_S = c.n("N_S");
    std::set<int> sectors;
    int trunks = 0;
    for (std::size_t i = 0; i < c.r.stems.size(); ++i) {
        const RoseStem& s = c.r.stems[i];
        if ((s.type == RoseTrunk) != (s.origin == RoseFromRoot) || (s.type == RoseTrunk) != (s.parent < 0))
            c.fail("trunks",
                   fmt::format("{}: trunks and only trunks grow from the bud union", name_of(c, int(i))));
        if (s.type != RoseTrunk || s.segments() < 1) continue;
        ++trunks;
        const double pitch = rose_pitch(s.dirs[1]);
        if (pitch < c.p("trunk_pitch_min") - 1e-9 || pitch > c.p("trunk_pitch_max") + 1e-9 ||
            !same(s.pts[0], {0, 0, 0}))
            c.fail("trunks",
                   fmt::format("{} starts at {} with pitch {}", name_of(c, int(i)), str(s.pts[0]), pitch));
        double az = std::atan2(s.dirs[1].z, s.dirs[1].x);
        if (az < 0) az += 2 * kPi;
        const double x = az / (2 * kPi) * N_S;
        const int sector = static_cast<int>(std::floor(x));
        const double frac = x - sector;
        if (frac < 0.15 - 1e-6 || frac > 0.85 + 1e-6 || !sectors.insert(sector).second)
            c.fail("trunks", fmt::format("{} azimuth {} is not alone in its sector", name_of(c, int(i)), az));
    }
    // N_S trunks grow at step 1 and all of them are kept: density control (Eq. 3) picks new child
    // stems only, and "the specified number of trunks grow" (Sec. V-B)
    if (c.r.trunk_candidates != N_S || trunks != N_S)
        c.fail("N_S trunks",
               fmt::format("{} trunks grown, {} kept, N_S = {}", c.r.trunk_candidates, trunks, N_S));
}

// the kind of child a branching node gets: terminal buds after winter pruning, intermediate
// stems after pinching or deadheading (Sec. IV-D)
void check_branch_kind(Ctx& c, int parent, int type, int origin, const std::string& what) {
    const Stop why = stop_of(c, c.stem(parent));
    const bool stage1 = c.p("stage") < 2;
    const int want = why == Stop::Cut ? (stage1 ? -1 : RoseTerm) : RoseInter; // -1: a dormant bud
    if (why == Stop::Other)
        c.fail("branching", fmt::format("{} branches at its tip without having stopped", name_of(c, parent)));
    else if (type != want)
        c.fail("child by stop reason",
               fmt::format("{} of {} is type {} (-1: a dormant bud), origin {}; want {}", what,
                           name_of(c, parent), type, origin, want));
}

// one child of a trunk or intermediate stem: where it grows and which way it points
void check_woody_child(Ctx& c, int parent, int type, int origin, int node, const glm::dvec3& g,
                       const std::string& what) {
    const RoseStem& ps = c.stem(parent);
    const int N = ps.segments();
    const glm::dvec3 d = ps.dirs[static_cast<std::size_t>(std::clamp(node, 1, N))];
    if (origin == RoseFromTip) {
        glm::dvec3 want = rose_upward(rose_tip_ideal(ps.pts.back(), d, c.p("phi_stem")), d);
        if (node != N) c.fail("tip child", fmt::format("{} at node {} of {} nodes", what, node, N));
        if (!same(g, want))
            c.fail("tip child", fmt::format("{} of {} points {}, the outward phi_stem search gives {}", what,
                                            name_of(c, parent), str(g), str(want)));
        // phi_stem from the tip segment, or more where no outward direction is that close
        if (angle(g, d) < c.p("phi_stem") - 1e-6)
            c.fail("tip child", fmt::format("{} is {} rad from its parent's tip", what, angle(g, d)));
        check_branch_kind(c, parent, type, origin, what);
        return;
    }
    if (std::abs(glm::dot(g, d)) > 1e-6)
        c.fail("perpendicular children", fmt::format("{} of {}: cos {} to the parent segment", what,
                                                     name_of(c, parent), glm::dot(g, d)));
    if (g.y < -1e-9) c.fail("shoot picking", fmt::format("{} of {} points down", what, name_of(c, parent)));
    if (origin == RoseFromSecond) {
        if (node != N - 1) c.fail("second child", fmt::format("{} at node {} of {}", what, node, N));
        check_branch_kind(c, parent, type, origin, what);
    } else if (origin == RoseFromRandom) {
        if (node < 1 || node > N - 2)
            c.fail("random shoots", fmt::format("{} at node {} of {}", what, node, N));
        if (level(ps.pts[static_cast<std::size_t>(std::max(node, 0))], c.p("r_crown"), c.p("h_crown")) <=
            c.p("gamma"))
            c.fail("gamma",
                   fmt::format("{} of {} inside the crown shrunk by gamma", what, name_of(c, parent)));
        if (c.p("rho_inter") + c.p("rho_term") <= 0) c.fail("random shoots", what + " with rho = 0");
    } else {
        c.fail("origins", fmt::format("{} of {} has origin {}", what, name_of(c, parent), origin));
    }
}

// Sec. IV-C/D: the children of trunks and intermediate stems (stems, and dormant buds at stage 1)
void check_branching(Ctx& c) {
    int tips = 0, seconds = 0;
    for (std::size_t i = 0; i < c.r.stems.size(); ++i) {
        const RoseStem& s = c.r.stems[i];
        if (!woody(s.type)) continue;
        for (int ch : s.children) {
            const RoseStem& k = c.stem(ch);
            if (k.segments() < 1) continue;
            check_woody_child(c, int(i), k.type, k.origin, k.node, k.dirs[1], name_of(c, ch));
            tips += k.origin == RoseFromTip;
            seconds += k.origin == RoseFromSecond;
        }
        for (const auto& b : s.buds) {
            check_woody_child(c, int(i), -1, b.origin, b.node, glm::normalize(b.dir),
                              fmt::format("a dormant bud (origin {}) at node {}", b.origin, b.node));
            tips += b.origin == RoseFromTip;
            seconds += b.origin == RoseFromSecond;
        }
        if (!s.leaves.empty() || !s.peduncles.empty())
            c.fail("organs", fmt::format("{} carries leaves or peduncles", name_of(c, int(i))));
    }
    // two children at the last two nodes: picking removes some, never every second child
    if (tips >= 4 && seconds == 0)
        c.fail("second child", fmt::format("{} tip children and no child at a second-to-last node", tips));
}

// ---- terminal stems, leaves, extra bloom stems, peduncles (Sec. IV-C, IV-F, IV-G) -------------

double param_or(const Ctx& c, const char* name, double fallback) {
    auto it = c.r.params.find(name);
    return it == c.r.params.end() ? fallback : it->second;
}

glm::dvec3 across(const glm::dvec3& d) {
    glm::dvec3 h = glm::cross(glm::dvec3(0, 1, 0), d);
    if (glm::length(h) < 1e-9) return {1, 0, 0};
    return glm::normalize(h);
}

glm::dvec3 outward(const glm::dvec3& p, const glm::dvec3& d) {
    glm::dvec3 o(p.x, 0, p.z);
    if (glm::length(o) >= 1e-6) return glm::normalize(o);
    glm::dvec3 h(d.x, 0, d.z);
    return glm::length(h) < 1e-9 ? glm::dvec3(1, 0, 0) : glm::normalize(h);
}

// the directions of the three segments of peduncle i at a tip p with segment d: the first along
// d, the second and third pi/4 to either side across the outward direction; each bends toward
// the target pitch min(theta, theta_droop) by Eq. 2, or with droop_reading = 1 (docs/rose.md)
// hangs pi/2 - theta_droop lower by its last segment
std::vector<glm::dvec3> peduncle_dirs(const Ctx& c, const glm::dvec3& p, const glm::dvec3& d, int i) {
    glm::dvec3 side = glm::cross(d, outward(p, d));
    if (glm::length(side) < 1e-9) side = across(d);
    side = glm::normalize(side);
    const glm::dvec3 g1 = i == 0 ? d : i == 1 ? glm::normalize(d + side) : glm::normalize(d - side);
    const double th = c.p("theta"), droop = c.p("theta_droop");
    const double target = std::min(th, droop);
    glm::dvec3 g2 = rose_blend(g1, 1, target, c.p("kappa_term"), c.p("sigma_term"));
    glm::dvec3 g3 = rose_blend(g2, 2, target, c.p("kappa_term"), c.p("sigma_term"));
    if (param_or(c, "droop_reading", 0) >= 1 && droop < kPi / 2) {
        const double sag = kPi / 2 - droop;
        auto lower = [](const glm::dvec3& g, double by) {
            glm::dvec3 h(g.x, 0, g.z);
            h = glm::length(h) < 1e-9 ? glm::dvec3(1, 0, 0) : glm::normalize(h);
            const double pitch = rose_pitch(g) - by;
            return h * std::cos(pitch) + glm::dvec3(0, std::sin(pitch), 0);
        };
        g2 = lower(g2, 0.5 * sag);
        g3 = lower(g3, sag);
    }
    return {g1, g2, g3};
}

void check_peduncles(Ctx& c, int i, int want) {
    const RoseStem& s = c.stem(i);
    if (static_cast<int>(s.peduncles.size()) != want)
        c.fail("peduncles",
               fmt::format("{} has {} peduncles, want {}", name_of(c, i), s.peduncles.size(), want));
    for (std::size_t j = 0; j < s.peduncles.size(); ++j) {
        const RosePeduncle& pd = s.peduncles[j];
        const std::string what = fmt::format("peduncle {} of {}", j, name_of(c, i));
        double total = 0;
        for (double l : pd.lens) total += l;
        if (pd.node != s.segments() || pd.blooms != 1 || std::abs(total - 1.5 * c.p("l_term")) > 1e-9)
            c.fail("peduncle length", fmt::format("{}: at node {}, {} blooms, {} long for l_term {}", what,
                                                  pd.node, pd.blooms, total, c.p("l_term")));
        auto want_dirs = peduncle_dirs(c, s.pts.back(), s.dirs.back(), static_cast<int>(j));
        if (pd.dirs.size() != want_dirs.size()) {
            c.fail("peduncle length", fmt::format("{} has {} segments", what, pd.dirs.size()));
            continue;
        }
        if (std::abs(angle(pd.dirs[0], s.dirs.back()) - (j == 0 ? 0 : kPi / 4)) > 1e-6)
            c.fail("peduncle angles",
                   fmt::format("{} starts {} rad from the stem", what, angle(pd.dirs[0], s.dirs.back())));
        for (std::size_t k = 0; k < pd.dirs.size(); ++k)
            if (!same(pd.dirs[k], want_dirs[k]))
                c.fail(k == 0 ? "peduncle angles" : "peduncle droop",
                       fmt::format("{} segment {}: {}, want {}", what, k + 1, str(pd.dirs[k]),
                                   str(want_dirs[k])));
    }
}

// 3/8 phyllotaxis: successive children 135 degrees apart per node around the stem, measured in a
// frame carried along it by the smallest rotation
void check_spiral(Ctx& c, int i, const std::vector<std::pair<int, glm::dvec3>>& kids) {
    const RoseStem& s = c.stem(i);
    const int N = s.segments();
    std::vector<glm::dvec3> ref(static_cast<std::size_t>(N) + 1);
    const glm::dvec3 seed = std::abs(s.dirs[1].y) < 0.9 ? glm::dvec3(0, 1, 0) : glm::dvec3(1, 0, 0);
    ref[1] = glm::normalize(glm::cross(seed, s.dirs[1]));
    for (int k = 2; k <= N; ++k) {
        const glm::dvec3 a = s.dirs[k - 1], b = s.dirs[k], axis = glm::cross(a, b);
        const double sn = glm::length(axis);
        if (sn < 1e-12) {
            ref[k] = ref[k - 1];
            continue;
        }
        const glm::dvec3 kk = axis / sn, v = ref[k - 1];
        const double cs = glm::dot(a, b);
        ref[k] = glm::normalize(v * cs + glm::cross(kk, v) * sn + kk * (glm::dot(kk, v) * (1 - cs)));
    }
    bool have = false;
    int k0 = 0;
    double a0 = 0;
    for (const auto& [k, g] : kids) {
        const glm::dvec3 d = s.dirs[static_cast<std::size_t>(k)], r = ref[static_cast<std::size_t>(k)];
        const double a = std::atan2(glm::dot(g, glm::cross(d, r)), glm::dot(g, r)) * 180 / kPi;
        if (have) {
            double off = std::fmod(a - a0 - 135.0 * (k - k0), 360.0);
            if (off > 180) off -= 360;
            if (off <= -180) off += 360;
            if (std::abs(off) > 1e-3)
                c.fail("3/8 phyllotaxis", fmt::format("{} children at nodes {} and {} off by {} degrees",
                                                      name_of(c, i), k0, k, off));
        }
        have = true;
        k0 = k;
        a0 = a;
    }
}

// one leaf at each node of a terminal stem; the tip's faces outward at phi_leaf (and with
// tip_leaf_reading = 1, turned up by the 60 degree search as the Japanese version says); the
// others perpendicular to their segment on the 3/8 spiral
void check_leaves(Ctx& c, int i, std::vector<glm::dvec3>& leaf_at) {
    const RoseStem& s = c.stem(i);
    const int N = s.segments();
    const bool japanese = param_or(c, "tip_leaf_reading", 0) >= 1;
    leaf_at.assign(static_cast<std::size_t>(N) + 1, glm::dvec3(0));
    std::vector<int> count(static_cast<std::size_t>(N) + 1, 0);
    std::vector<std::pair<int, glm::dvec3>> spiral;
    for (const auto& lf : s.leaves) {
        if (lf.node < 1 || lf.node > N) {
            c.fail("leaves", fmt::format("{}: a leaf at node {}", name_of(c, i), lf.node));
            continue;
        }
        ++count[static_cast<std::size_t>(lf.node)];
        leaf_at[static_cast<std::size_t>(lf.node)] = lf.dir;
        const glm::dvec3 d = s.dirs[static_cast<std::size_t>(lf.node)];
        if (lf.node == N) {
            glm::dvec3 want = rose_tip_ideal(s.pts.back(), d, c.p("phi_leaf"));
            if (japanese) want = rose_upward(want, d);
            if (!same(lf.dir, want))
                c.fail("tip leaf",
                       fmt::format("{}: tip leaf {}, want {}", name_of(c, i), str(lf.dir), str(want)));
            if (angle(lf.dir, d) < c.p("phi_leaf") - 1e-6)
                c.fail("tip leaf",
                       fmt::format("{}: tip leaf {} rad from the stem", name_of(c, i), angle(lf.dir, d)));
            if (japanese) spiral.emplace_back(lf.node, lf.dir);
        } else {
            if (std::abs(glm::dot(lf.dir, d)) > 1e-6)
                c.fail("perpendicular children",
                       fmt::format("{}: leaf at node {} not perpendicular", name_of(c, i), lf.node));
            spiral.emplace_back(lf.node, lf.dir);
        }
    }
    for (int k = 1; k <= N; ++k)
        if (count[static_cast<std::size_t>(k)] != 1)
            c.fail("leaves", fmt::format("{}: {} leaves at node {}", name_of(c, i),
                                         count[static_cast<std::size_t>(k)], k));
    std::sort(spiral.begin(), spiral.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    check_spiral(c, i, spiral);
}

// a terminal stem: N_T segments, its leaves, its extra bloom stems two and three nodes back (as
// many segments as nodes to the tip, in the leaf's axil) and up to three peduncles
void check_terminal(Ctx& c, int i) {
    const RoseStem& s = c.stem(i);
    const int N = s.segments(), N_T = c.n("N_T");
    if (N != N_T) c.fail("N_T segments", fmt::format("{} has {} segments", name_of(c, i), N));
    if (s.parent < 0 || !woody(c.stem(s.parent).type))
        c.fail("terminal stems",
               fmt::format("{} does not grow from a trunk or intermediate stem", name_of(c, i)));
    std::vector<glm::dvec3> leaf_at;
    check_leaves(c, i, leaf_at);
    const int nbl = std::min(c.n("N_B"), 9);
    int blooms = 0;
    std::map<int, int> extra_at; // node -> bloom stem
    for (int ch : s.children) {
        const RoseStem& b = c.stem(ch);
        if (b.type != RoseBloomStem || b.origin != RoseFromExtra || extra_at.count(b.node))
            c.fail("extra bloom stems", fmt::format("{} on {}", name_of(c, ch), name_of(c, i)));
        extra_at[b.node] = ch;
    }
    for (int back : {2, 3}) {
        const int k = N - back;
        const int extra = back == 2 ? std::min(nbl - 3, 3) : std::min(nbl - 6, 3);
        if (k < 1 || k > N) continue;
        const glm::dvec3 gb =
            glm::normalize(leaf_at[static_cast<std::size_t>(k)] + s.dirs[static_cast<std::size_t>(k)]);
        const bool want = extra > 0 && gb.y >= -1e-9;
        auto it = extra_at.find(k);
        if (want != (it != extra_at.end())) {
            c.fail("extra bloom stems", fmt::format("{}: node {} {} an extra bloom stem", name_of(c, i), k,
                                                    want ? "lacks" : "has"));
            continue;
        }
        if (!want) continue;
        const RoseStem& b = c.stem(it->second);
        if (b.segments() != back || !same(b.dirs[1], gb))
            c.fail("extra bloom stems",
                   fmt::format("{}: {} segments starting {}, want {} starting {}", name_of(c, it->second),
                               b.segments(), str(b.dirs[1]), back, str(gb)));
        check_peduncles(c, it->second, extra);
        blooms += static_cast<int>(b.peduncles.size());
        extra_at.erase(it);
    }
    for (const auto& [k, ch] : extra_at)
        c.fail("extra bloom stems", fmt::format("{} at node {}", name_of(c, ch), k));
    check_peduncles(c, i, std::min(nbl, 3));
    blooms += static_cast<int>(s.peduncles.size());
    if (blooms > nbl || blooms < 1)
        c.fail("blooms", fmt::format("{}: {} blooms, N_B = {}", name_of(c, i), blooms, nbl));
}

void check_flowers(Ctx& c) {
    int terminal = 0;
    for (std::size_t i = 0; i < c.r.stems.size(); ++i) {
        const int t = c.r.stems[i].type;
        if (t == RoseTerm) {
            ++terminal;
            check_terminal(c, int(i));
        } else if (t == RoseBloomStem) {
            const int p = c.r.stems[i].parent;
            if (p < 0 || c.stem(p).type != RoseTerm)
                c.fail("extra bloom stems", name_of(c, int(i)) + " off a terminal stem");
        }
    }
    if (c.p("stage") >= 2 && terminal == 0)
        c.fail("terminal stems", "a rose in flower without terminal stems");
    if (c.p("stage") < 2 && terminal > 0) c.fail("terminal stems", "terminal stems before flowering");
}

} // namespace

std::vector<std::string> rose_rule_failures(const RoseModel& r) {
    std::vector<std::string> out;
    Ctx c{r, out, {}};
    for (const char* pending : {"Root", "Node", "Grow", "Flower", "Peduncles", "%"})
        if (r.counts.count(pending))
            c.fail("pending", fmt::format("{} {} left at the end", r.counts.at(pending), pending));
    if (r.params.at("stage") >= 2 && r.counts.count("Dormant"))
        c.fail("pending", "dormant buds left in flower");
    if (r.stems.empty()) {
        c.fail("stems", "no stem at all");
        return out;
    }
    check_eq2(c);
    check_trunks(c);
    check_branching(c);
    check_flowers(c);
    return out;
}

} // namespace plant::test
