// Growing a rose and reading its stems back from the module string (see rose_rules.hpp), and the
// paper's direction rules the checks re-derive.
#include "plant/compiler.hpp"
#include "plant/derive.hpp"
#include "plant/environment_phase.hpp"
#include "plant/environments.hpp"
#include "rose_rules.hpp"

#include <cmath>
#include <numbers>

namespace plant::test {

// ---- geometry: Umezawa & Mukai, Sec. IV-A (Eq. 1-2), IV-C and IV-D ----------------------------

double rose_pitch(const glm::dvec3& d) {
    return std::atan2(d.y, std::sqrt(d.x * d.x + d.z * d.z));
}

namespace {

glm::dvec3 flat(const glm::dvec3& d) {
    glm::dvec3 h(d.x, 0, d.z);
    if (glm::length(h) < 1e-9) return {1, 0, 0};
    return glm::normalize(h);
}

// Eq. 1 (unit length: the horizontal part divided by its own length)
glm::dvec3 ideal(const glm::dvec3& d, double th) {
    return flat(d) * std::cos(th) + glm::dvec3(0, std::sin(th), 0);
}

glm::dvec3 turn(const glm::dvec3& v, const glm::dvec3& k, double a) {
    return v * std::cos(a) + glm::cross(k, v) * std::sin(a) + k * (glm::dot(k, v) * (1 - std::cos(a)));
}

} // namespace

// Eq. 2, and once the pitch has reached the target the stem grows straight
glm::dvec3 rose_blend(const glm::dvec3& d, double n, double th, double kappa, double sigma) {
    if (std::abs(rose_pitch(d) - th) < 1e-3) return ideal(d, th);
    double w = std::pow(n, sigma);
    return glm::normalize((d * kappa + ideal(d, th) * w) / (kappa + w));
}

// Sec. IV-C: at the tip, the child's horizontal part points away from the plant's vertical axis
// and the child makes the angle phi with the tip segment (the steeper such pitch, unless its
// horizontal part would then point inward)
glm::dvec3 rose_tip_ideal(const glm::dvec3& p, const glm::dvec3& d, double phi) {
    glm::dvec3 o(p.x, 0, p.z);
    o = glm::length(o) < 1e-6 ? flat(d) : glm::normalize(o);
    double a = glm::dot(d, o), b = d.y;
    double rr = std::max(std::sqrt(a * a + b * b), 1e-9);
    double b0 = std::atan2(b, a);
    double spread = std::acos(std::clamp(std::cos(phi) / rr, -1.0, 1.0));
    double beta = b0 + spread;
    if (std::cos(beta) < -1e-9) beta = b0 - spread;
    return o * std::cos(beta) + glm::dvec3(0, std::sin(beta), 0);
}

// Sec. IV-D: a downward ideal direction turns about the segment by 60 degrees until it points up
glm::dvec3 rose_upward(const glm::dvec3& g, const glm::dvec3& d) {
    glm::dvec3 v = g, best = g;
    for (int i = 0; i < 6; ++i) {
        if (v.y > 1e-9) return v;
        if (v.y > best.y) best = v;
        v = turn(v, d, std::numbers::pi / 3);
    }
    return best;
}

// ---- reading the string ------------------------------------------------------------------------

namespace {

// what the innermost bracket holds
enum class Holds { Nothing, Stem, Leaf, Peduncle, Bud };

struct Frame {
    glm::dvec3 pos{0}, head{0, 1, 0};
    int stem = -1; // the stem this bracket's modules belong to
    Holds holds = Holds::Nothing;
    int item = -1; // the leaf or peduncle index in stems[stem]
};

class Walker {
  public:
    Walker(const Program& p, const ModuleString& s, RoseModel& r) : program_(p), s_(s), r_(r) {}

    void run() {
        for (std::size_t i = 0; i < s_.size(); ++i) {
            const std::string& n = program_.symbols[s_.symbol(i)].name;
            ++r_.counts[n];
            step(n, s_.args(i));
        }
    }

  private:
    int node_of(int stem) const {
        return stem < 0 ? -1 : r_.stems[static_cast<std::size_t>(stem)].segments();
    }
    RoseStem& stem() { return r_.stems[static_cast<std::size_t>(f_.stem)]; }

    void step(const std::string& n, const ModuleArgs& a) {
        if (n == "[") {
            stack_.push_back(f_);
            f_.holds = Holds::Nothing;
        } else if (n == "]") {
            if (stack_.empty()) return;
            f_ = stack_.back();
            stack_.pop_back();
        } else if (n == "Stem") {
            RoseStem st;
            st.type = static_cast<int>(a[0]);
            st.state = static_cast<int>(a[1]);
            st.origin = static_cast<int>(a[2]);
            st.parent = f_.stem;
            st.node = node_of(f_.stem);
            st.pts.push_back(f_.pos);
            st.dirs.emplace_back(0);
            st.lens.push_back(0);
            r_.stems.push_back(st);
            const int me = static_cast<int>(r_.stems.size()) - 1;
            if (f_.stem >= 0) stem().children.push_back(me);
            f_.stem = me;
            f_.holds = Holds::Stem;
        } else if (n == "SetHead") {
            f_.head = glm::normalize(glm::dvec3(a[0], a[1], a[2]));
        } else if (n == "F") {
            segment(a[0]);
        } else if (n == "Leaf" && f_.stem >= 0) {
            stem().leaves.push_back(RoseLeaf{node_of(f_.stem), f_.head});
        } else if (n == "Bloom" && f_.holds == Holds::Peduncle) {
            ++stem().peduncles[static_cast<std::size_t>(f_.item)].blooms;
        } else if (n == "Dormant" && f_.stem >= 0) {
            stem().buds.push_back(
                RoseBud{node_of(f_.stem), static_cast<int>(a[0]), glm::dvec3(a[4], a[5], a[6])});
        }
    }

    void segment(double l) {
        if (f_.stem < 0) return;
        if (f_.holds == Holds::Nothing && !stack_.empty()) { // a bracket of F's without a Stem
            f_.holds = Holds::Peduncle;
            stem().peduncles.push_back(RosePeduncle{node_of(f_.stem), {}, {}, 0});
            f_.item = static_cast<int>(stem().peduncles.size()) - 1;
        }
        f_.pos += f_.head * l;
        if (f_.holds == Holds::Stem) {
            stem().pts.push_back(f_.pos);
            stem().dirs.push_back(f_.head);
            stem().lens.push_back(l);
        } else if (f_.holds == Holds::Peduncle) {
            auto& pd = stem().peduncles[static_cast<std::size_t>(f_.item)];
            pd.dirs.push_back(f_.head);
            pd.lens.push_back(l);
        }
    }

    const Program& program_;
    const ModuleString& s_;
    RoseModel& r_;
    Frame f_;
    std::vector<Frame> stack_;
};

} // namespace

RoseModel grow_rose_model(const std::string& path, std::uint64_t seed, const RoseDefines& defines,
                          std::string& error) {
    SourceManager sources;
    Diagnostics diags;
    CompileOptions co;
    co.defines = defines;
    co.environments = runtime_environments();
    auto program = compile_file(sources, path, co, diags);
    RoseModel rose;
    if (!program) {
        error = render_all(diags, sources);
        return rose;
    }
    TurtleEnvironmentPhase phase;
    DeriveOptions opt;
    opt.seed = seed;
    opt.environment_phase = &phase;
    Derivation d(*program, opt);
    d.start();
    for (bool more = true; more;) {
        more = d.step();
        if (d.steps_done() != 1 || rose.trunk_candidates >= 0) continue;
        rose.trunk_candidates = 0;
        const ModuleString& s = d.string();
        for (std::size_t i = 0; i < s.size(); ++i)
            if (program->symbols[s.symbol(i)].name == "Stem" && static_cast<int>(s.args(i)[0]) == RoseTrunk)
                ++rose.trunk_candidates;
    }
    d.finish();
    for (const auto& g : program->globals)
        if (g.kind == GlobalKind::Param) rose.params[g.name] = d.globals()[g.slot];
    rose.string = format_string(*program, d.string(), false);
    Walker(*program, d.string(), rose).run();
    return rose;
}

} // namespace plant::test
