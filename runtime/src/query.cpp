#include "plant/query.hpp"

#include "plant/environments.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <optional>

#include <unordered_map>

namespace plant {

namespace {

class QuerySink : public TurtleSink {
public:
    QuerySink(const Program& p, const ModuleString& s) : program_(p), string_(s) {}
    void query(std::size_t module, const TurtleState& t) override {
        const std::string& name = program_.symbols[string_.sym[module]].name;
        if (name == "?E") { // communication modules: answered after the environments see the plant
            positions[string_.ids[module]] = Place{t.position, t.axis};
            return;
        }
        glm::dvec3 v = name == "?P" ? t.position : name == "?H" ? t.heading : name == "?U" ? t.up : t.left;
        found[string_.ids[module]] = v;
    }
    struct Place {
        glm::dvec3 position;
        int axis;
    };
    std::unordered_map<ModuleId, Place> positions;
    std::unordered_map<ModuleId, glm::dvec3> found;

private:
    const Program& program_;
    const ModuleString& string_;
};

} // namespace

// Feeds one turtle pass to the query sink and, when environments want the plant, a skeleton.
class BothSinks : public TurtleSink {
public:
    BothSinks(TurtleSink& a, TurtleSink* b) : a_(a), b_(b) {}
    void axis_begin(int axis, int parent, const TurtleState& t) override {
        a_.axis_begin(axis, parent, t);
        if (b_) b_->axis_begin(axis, parent, t);
    }
    void segment(const TurtleSegment& s) override {
        a_.segment(s);
        if (b_) b_->segment(s);
    }
    void organ(const TurtleOrgan& o) override {
        a_.organ(o);
        if (b_) b_->organ(o);
    }
    void query(std::size_t module, const TurtleState& t) override {
        a_.query(module, t);
        if (b_) b_->query(module, t);
    }

private:
    TurtleSink& a_;
    TurtleSink* b_;
};

void TurtleQueryPass::fill_queries(const Derivation& d, ModuleString& string) {
    const Program& p = d.program();
    ModuleString interpreted = d.interpreted(string);
    QuerySink sink(p, interpreted);
    std::optional<SkeletonBuilder> skeleton;
    if (!p.environments.empty()) skeleton.emplace(p, interpreted);
    BothSinks both(sink, skeleton ? &*skeleton : nullptr);
    interpret(p, interpreted, turtle_options(d), both);
    if (skeleton) {
        Skeleton sk = skeleton->take();
        for (const auto& env : p.environments)
            if (auto* seeing = dynamic_cast<SkeletonEnvironment*>(env.get())) seeing->update(sk);
    }
    // ?E(env, slots...): the named environment answers at the module's position (LANGUAGE.md
    // section 8, open L-systems' communication modules)
    const auto e_symbol = p.symbols.find("?E");
    for (std::size_t i = 0; e_symbol && i < string.size(); ++i) {
        if (string.sym[i] != *e_symbol || string.arity(i) < 2) continue;
        auto it = sink.positions.find(string.ids[i]);
        double* a = string.params.data() + string.poff[i];
        const auto env = static_cast<std::size_t>(a[0]);
        if (it == sink.positions.end() || a[0] < 0 || env >= p.environments.size() || !p.environments[env]) continue;
        p.environments[env]->communicate(it->second.position, string.ids[i], it->second.axis, a + 1, string.arity(i) - 1);
    }
    for (std::size_t i = 0; i < string.size(); ++i) {
        if (!p.symbols[string.sym[i]].query || string.arity(i) != 3) continue;
        auto it = sink.found.find(string.ids[i]);
        if (it == sink.found.end()) continue;
        double* a = string.params.data() + string.poff[i];
        a[0] = it->second.x;
        a[1] = it->second.y;
        a[2] = it->second.z;
    }
}

} // namespace plant
