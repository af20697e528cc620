// The environment phase of a step: climbers, the environments that see the plant, ?E and the
// turtle's query modules, in the order environment_phase.hpp gives.
#include "plant/environment_phase.hpp"

#include "plant/environment.hpp"
#include "plant/program.hpp"
#include "plant/run_state.hpp"
#include "plant/skeleton.hpp"
#include "plant/turtle.hpp"

#include <fmt/format.h>

#include <optional>
#include <set>

#include <unordered_map>
#include <unordered_set>

namespace plant {

namespace {

class QuerySink : public TurtleSink {
  public:
    QuerySink(const Program& p, const ModuleString& s) : program_(p), string_(s) {}
    void query(std::size_t module, const TurtleState& t) override {
        const TurtleOp op = program_.symbols[string_.symbol(module)].turtle_op;
        if (op == TurtleOp::Communicate) { // answered after the environments see the plant
            positions[string_.id(module)] = Place{t.position, t.axis};
            return;
        }
        glm::dvec3 v = op == TurtleOp::QueryPosition  ? t.position
                       : op == TurtleOp::QueryHeading ? t.heading
                       : op == TurtleOp::QueryUp      ? t.up
                                                      : t.left;
        found[string_.id(module)] = v;
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

// Shows each environment that holds segments the segments of the modules bound to it, in
// string order.
class BoundSink : public TurtleSink {
  public:
    BoundSink(const ModuleString& s, const std::vector<Environment*>& by_symbol,
              const std::unordered_set<ModuleId>& own)
        : string_(s), by_symbol_(by_symbol), own_(own) {}
    void segment(const TurtleSegment& seg) override {
        const SymbolId sym = string_.symbol(seg.module);
        Environment* holder = sym < by_symbol_.size() ? by_symbol_[sym] : nullptr;
        if (!holder || !own_.count(seg.id)) return;
        const TurtleState& t = *seg.state;
        const double len = string_.arity(seg.module) > 0 ? string_.args(seg.module)[0] : t.step;
        holder->segment(BoundSegment{seg.id, t.bound_parent, seg.from, seg.to,
                                     glm::dmat3(-t.left, t.heading, t.up), t.width / 2, len});
    }

  private:
    const ModuleString& string_;
    const std::vector<Environment*>& by_symbol_;
    const std::unordered_set<ModuleId>& own_;
};

// Part 1 (climber.hpp): place new bound modules' particles, run the physics, and cut what broke
// off out of the string.
void advance_bound(const Derivation& d, RunState& state, ModuleString& string) {
    const Program& p = d.program();
    std::vector<Environment*> by_symbol(p.symbols.size(), nullptr);
    std::vector<Environment*> holders;
    for (std::size_t k = 0; k < p.symbols.size(); ++k) {
        const int e = p.symbols.all()[k].bound_env;
        if (e < 0 || static_cast<std::size_t>(e) >= state.size()) continue;
        Environment* env = state.environment(static_cast<std::size_t>(e));
        if (env && env->kind().holds_segments) by_symbol[k] = env;
    }
    std::vector<std::size_t> holder_envs; // each holder's index in p.environments
    for (std::size_t e = 0; e < state.size(); ++e)
        if (state.environment(e) && state.environment(e)->kind().holds_segments) {
            holders.push_back(state.environment(e));
            holder_envs.push_back(e);
        }
    if (holders.empty()) return;
    ModuleString interpreted = d.interpreted(string);
    for (Environment* h : holders) h->begin_segments();
    // only modules of the string itself hold particles: one an interpretation rule made has an
    // identity that the next step may give to another module
    std::unordered_set<ModuleId> own;
    for (std::size_t i = 0; i < string.size(); ++i)
        if (string.symbol(i) < by_symbol.size() && by_symbol[string.symbol(i)]) own.insert(string.id(i));
    BoundSink sink(interpreted, by_symbol, own);
    interpret(p, interpreted, turtle_options(d), sink);
    std::set<ModuleId> gone;
    for (std::size_t k = 0; k < holders.size(); ++k) {
        try {
            holders[k]->advance(gone);
        } catch (RuntimeError& e) {
            if (e.kind != RuntimeErrorKind::Physics || e.span.valid()) throw;
            // name the environment and point at its declaration
            const EnvironmentDecl& decl = p.environments[holder_envs[k]];
            e.span = decl.span;
            e.message = fmt::format("{} '{}': {}", decl.kind_name, decl.name, e.message);
            throw;
        }
    }
    if (!gone.empty())
        cut_branches(string, p.symbols.open_bracket, p.symbols.close_bracket,
                     [&](std::size_t i) { return gone.count(string.id(i)) > 0; });
}

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

void TurtleEnvironmentPhase::run(const Derivation& d, RunState& state, ModuleString& string) {
    const Program& p = d.program();
    advance_bound(d, state, string);
    ModuleString interpreted = d.interpreted(string);
    QuerySink sink(p, interpreted);
    std::optional<SkeletonBuilder> skeleton;
    bool seen = false;
    for (std::size_t e = 0; e < state.size() && !seen; ++e)
        if (const Environment* env = state.environment(e)) seen = env->sees_plant();
    if (seen) skeleton.emplace(p, interpreted);
    BothSinks both(sink, skeleton ? &*skeleton : nullptr);
    interpret(p, interpreted, turtle_options(d), both);
    if (skeleton) {
        Skeleton sk = skeleton->take();
        for (std::size_t e = 0; e < state.size(); ++e)
            if (Environment* env = state.environment(e)) env->see(sk);
    }
    // ?E(env, slots...): the named environment answers at the module's position (docs/language.md,
    // environment objects: open L-systems' communication modules)
    // module i's parameters (the string is read in order); query and communication modules are
    // always of plain kinds, every number stored, so `a` may be written
    double* a = string.params.data();
    for (std::size_t i = 0; !sink.positions.empty() && i < string.size(); a += string.stored(i), ++i) {
        if (p.symbols[string.symbol(i)].turtle_op != TurtleOp::Communicate || string.arity(i) < 2) continue;
        auto it = sink.positions.find(string.id(i));
        const auto env = static_cast<std::size_t>(a[0]);
        if (it == sink.positions.end() || a[0] < 0 || env >= state.size() || !state.environment(env))
            continue;
        state.environment(env)->communicate(it->second.position, string.id(i), it->second.axis, a + 1,
                                            string.arity(i) - 1);
    }
    a = string.params.data();
    for (std::size_t i = 0; i < string.size(); a += string.stored(i), ++i) {
        if (!p.symbols[string.symbol(i)].query || string.arity(i) != 3) continue;
        auto it = sink.found.find(string.id(i));
        if (it == sink.found.end()) continue;
        a[0] = it->second.x;
        a[1] = it->second.y;
        a[2] = it->second.z;
    }
}

} // namespace plant
