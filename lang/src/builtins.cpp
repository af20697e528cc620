#include "plant/builtins.hpp"

namespace plant {

namespace {
constexpr ValueType N = ValueType::Number;
constexpr ValueType V = ValueType::Vec3;
constexpr ValueType B = ValueType::Bool;
constexpr ValueType X = ValueType::Void;

constexpr BuiltinInfo table[] = {
    {"sin", BuiltinId::Sin, 1, {N, X, X}, N, "sine of an angle in radians"},
    {"cos", BuiltinId::Cos, 1, {N, X, X}, N, "cosine of an angle in radians"},
    {"tan", BuiltinId::Tan, 1, {N, X, X}, N, "tangent of an angle in radians"},
    {"asin", BuiltinId::Asin, 1, {N, X, X}, N, "arc sine, in radians"},
    {"acos", BuiltinId::Acos, 1, {N, X, X}, N, "arc cosine, in radians"},
    {"atan", BuiltinId::Atan, 1, {N, X, X}, N, "arc tangent, in radians"},
    {"atan2", BuiltinId::Atan2, 2, {N, N, X}, N, "angle of the point (x, y): atan2(y, x)"},
    {"sqrt", BuiltinId::Sqrt, 1, {N, X, X}, N, "square root"},
    {"exp", BuiltinId::Exp, 1, {N, X, X}, N, "e to the power x"},
    {"log", BuiltinId::Log, 1, {N, X, X}, N, "natural logarithm"},
    {"pow", BuiltinId::Pow, 2, {N, N, X}, N, "x to the power y"},
    {"abs", BuiltinId::Abs, 1, {N, X, X}, N, "absolute value"},
    {"min", BuiltinId::Min, 2, {N, N, X}, N, "smaller of two numbers"},
    {"max", BuiltinId::Max, 2, {N, N, X}, N, "larger of two numbers"},
    {"clamp", BuiltinId::Clamp, 3, {N, N, N}, N, "clamp(x, lo, hi)"},
    {"floor", BuiltinId::Floor, 1, {N, X, X}, N, "largest integer not above x"},
    {"ceil", BuiltinId::Ceil, 1, {N, X, X}, N, "smallest integer not below x"},
    {"round", BuiltinId::Round, 1, {N, X, X}, N, "nearest integer, halves away from zero"},
    {"sign", BuiltinId::Sign, 1, {N, X, X}, N, "-1, 0 or 1"},
    {"mix", BuiltinId::Mix, 3, {N, N, N}, N, "mix(a, b, t) = a + (b - a) t"},
    {"mix", BuiltinId::MixV, 3, {V, V, N}, V, "mix(a, b, t) for vectors"},
    {"smoothstep", BuiltinId::Smoothstep, 3, {N, N, N}, N, "smoothstep(e0, e1, x), Hermite between 0 and 1"},
    {"rad", BuiltinId::Rad, 1, {N, X, X}, N, "degrees to radians"},
    {"deg", BuiltinId::Deg, 1, {N, X, X}, N, "radians to degrees"},
    {"pi", BuiltinId::Pi, 0, {X, X, X}, N, "3.14159..."},
    {"vec3", BuiltinId::Vec3, 3, {N, N, N}, V, "vector from three numbers"},
    {"vec3", BuiltinId::Vec3S, 1, {N, X, X}, V, "vector with three equal components"},
    {"dot", BuiltinId::Dot, 2, {V, V, X}, N, "dot product"},
    {"cross", BuiltinId::Cross, 2, {V, V, X}, V, "cross product"},
    {"length", BuiltinId::Length, 1, {V, X, X}, N, "length of a vector"},
    {"normalize", BuiltinId::Normalize, 1, {V, X, X}, V, "unit vector in the same direction"},
    {"distance", BuiltinId::Distance, 2, {V, V, X}, N, "distance between two points"},
    {"uniform", BuiltinId::Uniform, 2, {N, N, X}, N, "uniform random number in [a, b)"},
    {"normal", BuiltinId::Normal, 2, {N, N, X}, N, "normally distributed random number normal(mu, sigma)"},
    {"chance", BuiltinId::Chance, 1, {N, X, X}, B, "true with probability p"},
    {"step", BuiltinId::Step, 0, {X, X, X}, N, "the current derivation step (0 before the first)"},
    {"id", BuiltinId::Id, 0, {X, X, X}, N, "identity of the module being rewritten"},
    {"lod", BuiltinId::Lod, 3, {N, N, N}, N, "round(count * (1 - view_depth / max_view_depth))"},
};
} // namespace

std::span<const BuiltinInfo> builtin_table() {
    return table;
}

const char* value_type_name(ValueType t) {
    switch (t) {
    case ValueType::Number:
        return "number";
    case ValueType::Bool:
        return "bool";
    case ValueType::Vec3:
        return "vec3";
    case ValueType::String:
        return "string";
    case ValueType::Void:
        return "nothing";
    }
    return "?";
}

} // namespace plant
