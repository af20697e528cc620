// The turtle pass that fills query modules (LANGUAGE.md section 8).
#pragma once

#include "plant/derive.hpp"

namespace plant {

// Interprets the string (interpretation rules included) and writes into every ?P ?H ?U ?L
// module with three parameters the turtle's position, heading, up or left vector there.
// Modules are matched by identity, so query modules that interpretation rules leave alone are
// found in the original string.
class TurtleQueryPass : public QueryPass {
  public:
    void fill_queries(const Derivation& derivation, ModuleString& string) override;
};

} // namespace plant
