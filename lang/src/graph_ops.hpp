// The virtual machine's side of decomposition graphs (vm.cpp): the graph built-ins (root, child,
// depth, position, index) and parameter reads through a node. Each returns an error message,
// empty on success; the VM turns it into a runtime error at the instruction.
#pragma once

#include "plant/builtins.hpp"
#include "plant/vm.hpp"

#include <string>

namespace plant {

std::string graph_builtin(BuiltinId id, const double* a, double* r, const EvalEnv& env);
// Parameter `param` of the node a[0]: a number, or a curve at t = a[1] when `curve`.
std::string graph_read(int param, bool curve, const double* a, double* r, const EvalEnv& env);

} // namespace plant
