// The environment phase of a step (derive.hpp's EnvironmentPhase), as the runtime runs it with
// the turtle (docs/language.md, environments and query modules).
#pragma once

#include "plant/derive.hpp"

namespace plant {

// In this order, each part a turtle pass over the string as interpretation rules show it:
//   1. environments that hold segments (climbers) are shown the segments of the modules bound
//      to them and advance; the modules that broke off or were cut leave the string, with the
//      rest of their branch;
//   2. every environment sees the plant's skeleton;
//   3. ?E(env, slots...) modules receive the answers of the environment `env` at their place;
//   4. ?P ?H ?U ?L modules with three parameters receive the turtle's position, heading, up or
//      left vector there.
// Modules are matched by identity, so query modules that interpretation rules leave alone are
// found in the original string.
class TurtleEnvironmentPhase : public EnvironmentPhase {
  public:
    void run(const Derivation& derivation, RunState& state, ModuleString& string) override;
};

} // namespace plant
