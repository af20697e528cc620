#include "plant/builtins.hpp"

namespace plant {

namespace {
constexpr ValueType N = ValueType::Number;
constexpr ValueType V = ValueType::Vec3;
constexpr ValueType B = ValueType::Bool;
constexpr ValueType X = ValueType::Void;
constexpr BuiltinReads A = BuiltinReads::Arguments;
constexpr BuiltinReads R = BuiltinReads::Random;
constexpr BuiltinReads I = BuiltinReads::Identity;
constexpr ValueType G = ValueType::Node;
constexpr BuiltinReads D = BuiltinReads::Graph;

constexpr BuiltinInfo table[] = {
    {"sin", BuiltinId::Sin, 1, {N, X, X}, N, A, "sine of an angle in radians"},
    {"cos", BuiltinId::Cos, 1, {N, X, X}, N, A, "cosine of an angle in radians"},
    {"tan", BuiltinId::Tan, 1, {N, X, X}, N, A, "tangent of an angle in radians"},
    {"asin", BuiltinId::Asin, 1, {N, X, X}, N, A, "arc sine, in radians"},
    {"acos", BuiltinId::Acos, 1, {N, X, X}, N, A, "arc cosine, in radians"},
    {"atan", BuiltinId::Atan, 1, {N, X, X}, N, A, "arc tangent, in radians"},
    {"atan2", BuiltinId::Atan2, 2, {N, N, X}, N, A, "angle of the point (x, y): atan2(y, x)"},
    {"sqrt", BuiltinId::Sqrt, 1, {N, X, X}, N, A, "square root"},
    {"exp", BuiltinId::Exp, 1, {N, X, X}, N, A, "e to the power x"},
    {"log", BuiltinId::Log, 1, {N, X, X}, N, A, "natural logarithm"},
    {"pow", BuiltinId::Pow, 2, {N, N, X}, N, A, "x to the power y"},
    {"abs", BuiltinId::Abs, 1, {N, X, X}, N, A, "absolute value"},
    {"min", BuiltinId::Min, 2, {N, N, X}, N, A, "smaller of two numbers"},
    {"max", BuiltinId::Max, 2, {N, N, X}, N, A, "larger of two numbers"},
    {"clamp", BuiltinId::Clamp, 3, {N, N, N}, N, A, "clamp(x, lo, hi)"},
    {"floor", BuiltinId::Floor, 1, {N, X, X}, N, A, "largest integer not above x"},
    {"ceil", BuiltinId::Ceil, 1, {N, X, X}, N, A, "smallest integer not below x"},
    {"round", BuiltinId::Round, 1, {N, X, X}, N, A, "nearest integer, halves away from zero"},
    {"sign", BuiltinId::Sign, 1, {N, X, X}, N, A, "-1, 0 or 1"},
    {"mix", BuiltinId::Mix, 3, {N, N, N}, N, A, "mix(a, b, t) = a + (b - a) t"},
    {"mix", BuiltinId::MixV, 3, {V, V, N}, V, A, "mix(a, b, t) for vectors"},
    {"smoothstep", BuiltinId::Smoothstep, 3, {N, N, N}, N, A, "smoothstep(e0, e1, x): Hermite from 0 to 1"},
    {"rad", BuiltinId::Rad, 1, {N, X, X}, N, A, "degrees to radians"},
    {"deg", BuiltinId::Deg, 1, {N, X, X}, N, A, "radians to degrees"},
    {"pi", BuiltinId::Pi, 0, {X, X, X}, N, A, "3.14159..."},
    {"vec3", BuiltinId::Vec3, 3, {N, N, N}, V, A, "vector from three numbers"},
    {"vec3", BuiltinId::Vec3S, 1, {N, X, X}, V, A, "vector with three equal components"},
    {"dot", BuiltinId::Dot, 2, {V, V, X}, N, A, "dot product"},
    {"cross", BuiltinId::Cross, 2, {V, V, X}, V, A, "cross product"},
    {"length", BuiltinId::Length, 1, {V, X, X}, N, A, "length of a vector"},
    {"normalize", BuiltinId::Normalize, 1, {V, X, X}, V, A, "unit vector in the same direction"},
    {"distance", BuiltinId::Distance, 2, {V, V, X}, N, A, "distance between two points"},
    {"uniform", BuiltinId::Uniform, 2, {N, N, X}, N, R, "uniform random number in [a, b)"},
    {"normal", BuiltinId::Normal, 2, {N, N, X}, N, R, "normally distributed random number normal(mu, sigma)"},
    {"chance", BuiltinId::Chance, 1, {N, X, X}, B, R, "true with probability p"},
    {"step", BuiltinId::Step, 0, {X, X, X}, N, A, "the current derivation step (0 before the first)"},
    {"id", BuiltinId::Id, 0, {X, X, X}, N, I, "identity of the module being rewritten"},
    {"lod",
     BuiltinId::Lod,
     1,
     {N, X, X},
     N,
     A,
     "lod(count) = round(count * (1 - view_depth / max_view_depth)) with the program's view_depth and "
     "max_view_depth, from 0 to count"},
    {"lod",
     BuiltinId::Lod,
     3,
     {N, N, N},
     N,
     A,
     "lod(count, view_depth, max_view_depth): the same with a view depth of your own"},
    {"root",
     BuiltinId::Root,
     0,
     {X, X, X},
     G,
     D,
     "the root node of the decomposition graph: the whole plant"},
    {"child",
     BuiltinId::Child,
     2,
     {G, N, X},
     G,
     D,
     "child(n, position): the node of the branch at position (0 base, 1 tip) along n's axis, made when "
     "new"},
    {"child",
     BuiltinId::ChildIndex,
     3,
     {G, N, N},
     G,
     D,
     "child(n, position, index): the same for branch `index` of several at one position"},
    {"depth",
     BuiltinId::Depth,
     1,
     {G, X, X},
     N,
     D,
     "a node's depth in the decomposition graph (0: the root)"},
    {"position", BuiltinId::Position, 1, {G, X, X}, N, D, "a node's position along its parent's axis"},
    {"index", BuiltinId::BranchIndex, 1, {G, X, X}, N, D, "a node's branch index at its position"},
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
    case ValueType::Node:
        return "node";
    }
    return "?";
}

} // namespace plant
