// Every rule of Umezawa & Mukai's shrub rose (docs/rose.md), checked on the module string that
// stdlib/rose.plant derives: the string is walked as the turtle walks it (SetHead, F, brackets),
// giving each stem's nodes and segment directions, its leaves, peduncles and dormant buds. The
// checks return what they found wrong instead of asserting, so the mutation test can run them on
// a deliberately broken copy of the library and require that they notice.
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace plant::test {

// stem types and origins, as stdlib/rose.plant numbers them
enum RoseType { RoseTrunk = 0, RoseInter = 1, RoseTerm = 2, RoseBloomStem = 3 };
enum RoseOrigin {
    RoseFromRoot = 0,
    RoseFromTip = 1,
    RoseFromSecond = 2,
    RoseFromRandom = 3,
    RoseFromExtra = 4
};

struct RoseLeaf {
    int node = 0;
    glm::dvec3 dir{0};
};

struct RosePeduncle {
    int node = 0;
    std::vector<glm::dvec3> dirs; // one per segment
    std::vector<double> lens;
    int blooms = 0;
};

struct RoseBud { // a Dormant terminal bud (stage 1)
    int node = 0, origin = 0;
    glm::dvec3 dir{0};
};

struct RoseStem {
    int type = 0, state = 0, origin = 0;
    int parent = -1, node = -1;   // the stem it grows from and that stem's node it starts at
    std::vector<glm::dvec3> pts;  // pts[0] the base, pts[k] node k
    std::vector<glm::dvec3> dirs; // dirs[k] the direction of segment k (dirs[0] unused)
    std::vector<double> lens;     // lens[k] its length (lens[0] unused)
    std::vector<RoseLeaf> leaves;
    std::vector<RosePeduncle> peduncles;
    std::vector<RoseBud> buds;
    std::vector<int> children;
    int segments() const { return static_cast<int>(pts.size()) - 1; }
};

struct RoseModel {
    std::map<std::string, double> params;
    std::map<std::string, int> counts; // modules by name in the final string
    std::vector<RoseStem> stems;
    int trunk_candidates = -1; // trunk stems in the string after step 1, before picking
    std::string string;        // the final string, formatted
};

using RoseDefines = std::vector<std::pair<std::string, std::string>>;

// Compiles `path` and derives it with `seed`; an empty model with the diagnostics in `error` when
// it does not compile.
RoseModel grow_rose_model(const std::string& path, std::uint64_t seed, const RoseDefines& defines,
                          std::string& error);

// Every rule violated, each message naming its rule; empty when the rose follows them all.
std::vector<std::string> rose_rule_failures(const RoseModel& r);

// the rose's own geometry, from the paper (Sec. IV-A, IV-C, IV-D), for tests that re-derive it
double rose_pitch(const glm::dvec3& d);
glm::dvec3 rose_blend(const glm::dvec3& d, double n, double th, double kappa, double sigma);
glm::dvec3 rose_tip_ideal(const glm::dvec3& p, const glm::dvec3& d, double phi);
glm::dvec3 rose_upward(const glm::dvec3& g, const glm::dvec3& d);

} // namespace plant::test
