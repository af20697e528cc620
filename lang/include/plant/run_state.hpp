// The run state of one derivation: the live objects its steps change (environments: a
// climber's particles, the proximity grid, light occupancy), made from the program's
// declarations when the derivation starts. The Program itself never changes; copying a
// derivation (the REPL keeps one per step) copies its run state, so going back to a copy goes
// back to its environments too.
#pragma once

#include "plant/environment.hpp"

#include <memory>
#include <vector>

namespace plant {

class RunState {
  public:
    RunState() = default;
    // A clone of each declaration's object as declared (null where the program has none: it
    // was compiled without a runtime).
    explicit RunState(const Program& program) {
        environments_.reserve(program.environments.size());
        for (const EnvironmentDecl& d : program.environments)
            environments_.push_back(d.initial ? d.initial->clone() : nullptr);
    }
    RunState(const RunState& other) { *this = other; }
    RunState& operator=(const RunState& other) {
        if (this == &other) return *this;
        std::vector<std::unique_ptr<Environment>> copy;
        copy.reserve(other.environments_.size());
        for (const auto& e : other.environments_) copy.push_back(e ? e->clone() : nullptr);
        environments_ = std::move(copy);
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

  private:
    std::vector<std::unique_ptr<Environment>> environments_;
};

} // namespace plant
