// Built-in functions (LANGUAGE.md section 5): the one table the compiler, the virtual machine
// and the documentation generator read. Overloads are separate rows; the compiler takes the first
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
};

struct BuiltinInfo {
    const char* name;
    BuiltinId id;
    std::uint8_t nargs;
    ValueType args[3];
    ValueType result;
    const char* doc;
};

std::span<const BuiltinInfo> builtin_table();

} // namespace plant
