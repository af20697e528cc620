// The run state of one derivation: the live objects its steps change (environments: a
// climber's particles, the proximity grid, light occupancy), made from the program's
// declarations when the derivation starts. The Program itself never changes; copying a
// derivation (the REPL keeps one per step) copies its run state, so going back to a copy goes
// back to its environments too.
#pragma once

#include "plant/environment.hpp"
#include "plant/graph.hpp"

#include <memory>
#include <vector>

namespace plant {

class RunState {
  public:
    RunState() = default;
    // A clone of each declaration's object as declared (null where the program has none: it
    // was compiled without a runtime).
    // With a `graph` block, the decomposition graph's root, with `edits` to match as it grows.
    // The graph may take `graph_bytes` of memory.
    explicit RunState(const Program& program, std::shared_ptr<const GraphEdits> edits = nullptr,
                      std::size_t graph_bytes = std::size_t{4} << 30) {
        environments_.reserve(program.environments.size());
        for (const EnvironmentDecl& d : program.environments)
            environments_.push_back(d.initial ? d.initial->clone() : nullptr);
        if (program.graph.declared)
            graph_ = std::make_unique<DecompositionGraph>(program.graph, std::move(edits), graph_bytes);
    }
    RunState(const RunState& other) { *this = other; }
    RunState& operator=(const RunState& other) {
        if (this == &other) return *this;
        std::vector<std::unique_ptr<Environment>> copy;
        copy.reserve(other.environments_.size());
        for (const auto& e : other.environments_) copy.push_back(e ? e->clone() : nullptr);
        environments_ = std::move(copy);
        graph_ = other.graph_ ? std::make_unique<DecompositionGraph>(*other.graph_) : nullptr;
        return *this;
    }
    RunState(RunState&&) noexcept = default;
    RunState& operator=(RunState&&) noexcept = default;
    ~RunState() = default;

    // One per `env` declaration, in file order (Program::environments).
    std::size_t size() const { return environments_.size(); }
    bool empty() const { return environments_.empty(); }
    // The live object of declaration k; null when the program has none for it.
    Environment* environment(std::size_t k) { return environments_[k].get(); }
    const Environment* environment(std::size_t k) const { return environments_[k].get(); }

    // The decomposition graph (graph.hpp); null when the program declares none.
    DecompositionGraph* graph() { return graph_.get(); }
    const DecompositionGraph* graph() const { return graph_.get(); }

  private:
    std::vector<std::unique_ptr<Environment>> environments_;
    std::unique_ptr<DecompositionGraph> graph_;
};

} // namespace plant
