// Built-in functions (docs/language.md, values and expressions): the one table the compiler, the
// virtual machine and `plant help builtins` read. Overloads are separate rows; the compiler takes the first
// row whose name and argument types fit (a bool is accepted where a number is expected).
#pragma once

#include "plant/program.hpp"

#include <span>

namespace plant {

enum class BuiltinId : std::uint16_t {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sqrt,
    Exp,
    Log,
    Pow,
    Abs,
    Min,
    Max,
    Clamp,
    Floor,
    Ceil,
    Round,
    Sign,
    Mix,
    MixV,
    Smoothstep,
    Rad,
    Deg,
    Pi,
    Vec3,
    Vec3S,
    Dot,
    Cross,
    Length,
    Normalize,
    Distance,
    Uniform,
    Normal,
    Chance,
    Step,
    Id,
    Lod,
    Root,
    Child,
    ChildIndex,
    Depth,
    Position,
    BranchIndex,
};

// What a built-in reads besides its arguments that belongs to the module being rewritten. Such a
// call has no value before the derivation starts (in a param or const), and a function that makes
// one is module-dependent too.
enum class BuiltinReads : std::uint8_t {
    Arguments, // nothing else: a pure function (or the step number, known to every module)
    Random,    // draws random numbers from the module's counter-based stream
    Identity,  // the module's identity
    Graph,     // the derivation's decomposition graph (compiled to Op::GraphCall, graph_ops.hpp)
};

struct BuiltinInfo {
    const char* name;
    BuiltinId id;
    std::uint8_t nargs;
    ValueType args[3];
    ValueType result;
    BuiltinReads reads;
    const char* doc;

    constexpr bool draws_random() const { return reads == BuiltinReads::Random; }
    constexpr bool per_module() const { return reads != BuiltinReads::Arguments; }
};

std::span<const BuiltinInfo> builtin_table();

} // namespace plant
