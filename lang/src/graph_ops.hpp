// The virtual machine's side of decomposition graphs (vm.cpp): the graph built-ins (root, child,
// depth, position, index) and parameter reads through a node. Each returns an error message,
// empty on success; the VM turns it into a runtime error at the instruction.
#pragma once

#include "plant/builtins.hpp"
#include "plant/vm.hpp"

#include <span>
#include <string>

namespace plant {

std::string graph_builtin(BuiltinId id, const double* a, double* r, const EvalEnv& env);
// Parameter `param` of the node a[0]: a number, or a curve at t = a[1] when `curve`.
std::string graph_read(int param, bool curve, const double* a, double* r, const EvalEnv& env);

// child(n, pos, index, base, dir): a[0..9) are the node, the position, the index, base and dir.
// Makes (or names again) the child and, when new, records where its silhouettes go.
std::string graph_place(const double* a, double* r, const EvalEnv& env, Span span);

// The methods of a silhouette read through a node, n.crown.METHOD(...), in world coordinates.
enum class SilhouetteMethod : std::uint8_t { Level, Contains, Reach, Axis, Heading, Base, Tip, Scale };
struct SilhouetteMethodInfo {
    const char* name;
    SilhouetteMethod id;
    std::uint8_t nargs;
    ValueType args[2];
    ValueType result;
    const char* doc;
};
std::span<const SilhouetteMethodInfo> silhouette_methods();
// Silhouette parameter `param` of the node a[0], method `method` on the arguments after it.
std::string graph_shape(int param, std::size_t method, const double* a, double* r, const EvalEnv& env);

} // namespace plant
