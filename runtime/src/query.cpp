#include "plant/query.hpp"

#include "plant/turtle.hpp"

#include <unordered_map>

namespace plant {

namespace {

class QuerySink : public TurtleSink {
public:
    QuerySink(const Program& p, const ModuleString& s) : program_(p), string_(s) {}
    void query(std::size_t module, const TurtleState& t) override {
        const std::string& name = program_.symbols[string_.sym[module]].name;
        glm::dvec3 v = name == "?P" ? t.position : name == "?H" ? t.heading : name == "?U" ? t.up : t.left;
        found[string_.ids[module]] = v;
    }
    std::unordered_map<ModuleId, glm::dvec3> found;

private:
    const Program& program_;
    const ModuleString& string_;
};

} // namespace

void TurtleQueryPass::fill_queries(const Derivation& d, ModuleString& string) {
    const Program& p = d.program();
    ModuleString interpreted = d.interpreted(string);
    QuerySink sink(p, interpreted);
    TurtleOptions o{d.default_angle(), d.default_step(), d.default_width()};
    interpret(p, interpreted, o, sink);
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
