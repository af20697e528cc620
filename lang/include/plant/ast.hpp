// The syntax tree: plain data, every node with its source span. Produced by the parser, read by
// the checker and the compiler; nothing here evaluates anything.
#pragma once

#include "plant/source.hpp"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace plant::ast {

// ---- the language's small vocabularies: each an enum and one table {enum, spelling, doc} ------
// The parser reads spellings through these tables, the compiler switches on the enums, and
// messages and listings print the spellings from them.

template <typename E> struct Spelled {
    E value;
    const char* spelling;
    const char* doc;
};

// Binary operators, in the order of the grammar's precedence levels (grammar.hpp).
enum class BinaryOp : std::uint8_t { Mul, Div, Mod, Add, Sub, Lt, Le, Gt, Ge, Eq, Ne, And, Or };
inline constexpr std::array<Spelled<BinaryOp>, 13> kBinaryOps = {{
    {BinaryOp::Mul, "*", "product; a vec3 times a number scales it"},
    {BinaryOp::Div, "/", "quotient; division by zero is a runtime error"},
    {BinaryOp::Mod, "%", "remainder (fmod)"},
    {BinaryOp::Add, "+", "sum; of two vec3s too"},
    {BinaryOp::Sub, "-", "difference; of two vec3s too"},
    {BinaryOp::Lt, "<", "less than"},
    {BinaryOp::Le, "<=", "less than or equal"},
    {BinaryOp::Gt, ">", "greater than"},
    {BinaryOp::Ge, ">=", "greater than or equal"},
    {BinaryOp::Eq, "==", "equal; of two vec3s too"},
    {BinaryOp::Ne, "!=", "not equal; of two vec3s too"},
    {BinaryOp::And, "&&", "both non-zero; the right side runs only when the left is"},
    {BinaryOp::Or, "||", "either non-zero; the right side runs only when the left is zero"},
}};

enum class UnaryOp : std::uint8_t { Neg, Not };
inline constexpr std::array<Spelled<UnaryOp>, 2> kUnaryOps = {{
    {UnaryOp::Neg, "-", "negation; of a vec3 too"},
    {UnaryOp::Not, "!", "1 for zero, else 0"},
}};

// `name = value` and the compound assignments of statements.
enum class AssignOp : std::uint8_t { Set, Add, Sub, Mul, Div };
inline constexpr std::array<Spelled<AssignOp>, 5> kAssignOps = {{
    {AssignOp::Set, "=", "assign"},
    {AssignOp::Add, "+=", "add to"},
    {AssignOp::Sub, "-=", "subtract from"},
    {AssignOp::Mul, "*=", "multiply by"},
    {AssignOp::Div, "/=", "divide by"},
}};

// `on NAME { ... }`: the hooks, in the order they run in a derivation.
enum class HookKind : std::uint8_t { Start, BeforeStep, AfterStep, End };
inline constexpr std::array<Spelled<HookKind>, 4> kHooks = {{
    {HookKind::Start, "start", "once, after the axiom is built"},
    {HookKind::BeforeStep, "before_step", "before each step"},
    {HookKind::AfterStep, "after_step", "after each step"},
    {HookKind::End, "end", "once, after the last step"},
}};

// The top-level settings `derive N;`, `angle A;` and so on.
enum class SettingKey : std::uint8_t { Derive, Angle, Step, Width, Seed, WidthScale };
inline constexpr std::array<Spelled<SettingKey>, 6> kSettings = {{
    {SettingKey::Derive, "derive", "the number of steps"},
    {SettingKey::Angle, "angle", "the turtle's default turning angle, in degrees"},
    {SettingKey::Step, "step", "the turtle's default step length"},
    {SettingKey::Width, "width", "the turtle's initial line width"},
    {SettingKey::Seed, "seed", "the seed of the random numbers"},
    {SettingKey::WidthScale, "width_scale", "what drawn widths are multiplied by (ABOP's !(w) in pixels)"},
}};

// The spelling of an enum value; the tables are in enum order.
template <typename E, std::size_t N>
constexpr const char* spelling_in(const std::array<Spelled<E>, N>& table, E value) {
    return table[static_cast<std::size_t>(value)].spelling;
}
inline const char* spelling(BinaryOp op) {
    return spelling_in(kBinaryOps, op);
}
inline const char* spelling(UnaryOp op) {
    return spelling_in(kUnaryOps, op);
}
inline const char* spelling(AssignOp op) {
    return spelling_in(kAssignOps, op);
}
inline const char* spelling(HookKind kind) {
    return spelling_in(kHooks, kind);
}
inline const char* spelling(SettingKey key) {
    return spelling_in(kSettings, key);
}

// The value spelled `text`, if any.
template <typename E, std::size_t N>
std::optional<E> lookup(const std::array<Spelled<E>, N>& table, std::string_view text) {
    for (const auto& entry : table)
        if (text == entry.spelling) return entry.value;
    return std::nullopt;
}

// The hook names as a list: "start, before_step, after_step or end" with prefix "" and last
// separator " or ", "on start, on before_step, ..." with prefix "on " and last separator ", ".
std::string hook_list(std::string_view prefix, std::string_view last_separator);

struct Expr;
using ExprPtr = std::unique_ptr<Expr>;

enum class ExprKind {
    Number,  // number
    Bool,    // number != 0
    String,  // text
    Name,    // text
    Unary,   // unary, args[0]
    Binary,  // binary, args[0], args[1]
    Ternary, // args[0] ? args[1] : args[2]
    Call,    // text = function name, args
    Member,  // args[0].text  (.x .y .z)
    Method,  // args[0].text(args[1..])
};

struct Expr {
    ExprKind kind = ExprKind::Number;
    Span span;
    double number = 0;
    std::string text;
    BinaryOp binary = BinaryOp::Add; // Binary
    UnaryOp unary = UnaryOp::Neg;    // Unary
    std::vector<ExprPtr> args;
    // silhouette(key: value, ...) only: each argument's key ("" when none) and its span
    std::vector<std::string> keys;
    std::vector<Span> key_spans;
};

// One module as written in a successor or pattern. `raw` is a letter run not yet split into
// modules (that needs the declared names, so the compiler does it). In patterns, the args are
// names to bind or value constraints.
struct ModuleRef {
    std::string name;
    Span span;
    Span name_span;
    bool has_args = false;
    bool raw = false; // a plain identifier run such as FbFb
    std::vector<ExprPtr> args;
};
using ModuleList = std::vector<ModuleRef>;

enum class StmtKind { Let, Assign, If, For, Produce, NProduce, Use, Stop, Return, Expr };

struct Stmt {
    StmtKind kind = StmtKind::Expr;
    Span span;
    std::string name;            // Let/Assign/For variable, Use group
    AssignOp op = AssignOp::Set; // Assign
    ExprPtr expr;                // value, condition, range start
    ExprPtr expr2;               // range end
    std::vector<Stmt> body;
    std::vector<Stmt> else_body;
    ModuleList successor;
};

struct Production {
    Span span;
    Span arrow_span;
    ModuleList left, left_new, strict, right, right_new;
    bool has_left = false, has_left_new = false, has_right = false, has_right_new = false;
    ExprPtr condition;
    bool body_form = false;
    ModuleList successor;
    ExprPtr weight;
    std::vector<Stmt> body;
};

enum class RuleKind { Rules, Decompose, Interpret };

struct RuleBlock {
    RuleKind kind = RuleKind::Rules;
    Span span;
    std::string group; // empty: the always-active group
    Span group_span;
    ExprPtr max_depth;
    std::vector<Production> productions;
};

enum class DeclKind { Param, Const, Var };

struct ValueDecl {
    DeclKind kind = DeclKind::Param;
    Span span;
    Span name_span;
    std::string name;
    ExprPtr value;
    // `param r = 0.9 in 0.5 .. 1.0;`: the range's bounds (both null without one)
    ExprPtr range_low, range_high;
    Span range_span;
};

struct ParamName {
    std::string name;
    std::string type; // empty or a type name such as vec3
    Span span;
};

struct ModuleDecl {
    Span span;
    std::string name;
    std::vector<ParamName> params;
    bool has_params = false;
    std::string bound_to; // environment name for physics-bound segments
};

struct FnDecl {
    Span span;
    std::string name;
    std::vector<ParamName> params;
    ExprPtr expr; // expression form
    std::vector<Stmt> body;
};

// curve / surface / texture / env: name = kind(args)
struct ShapeDecl {
    Span span;
    std::string name;
    std::string kind;
    Span kind_span;
    std::vector<std::string> keys; // same length as args; empty key for positional arguments
    std::vector<ExprPtr> args;
};

struct Setting {
    Span span;
    SettingKey key = SettingKey::Derive;
    ExprPtr value;
};

struct SymbolSet {
    Span span;
    bool ignore = true; // false: consider
    ModuleList symbols;
};

struct Hook {
    Span span;
    HookKind when = HookKind::Start;
    std::vector<Stmt> body;
};

struct Import {
    Span span;
    std::string target;
    bool is_path = false;
    std::vector<std::pair<std::string, ExprPtr>> overrides;
    std::vector<Span> override_spans;
};

// graph [match range|single] { name = value; ... } (docs/language.md, decomposition graphs)
struct GraphParam {
    Span span;
    Span name_span;
    std::string name;
    ExprPtr value; // a number expression, linear(...), bezier(...) or silhouette(...)
};

struct GraphBlock {
    Span span;
    std::string match; // empty: the default, range
    Span match_span;
    std::vector<GraphParam> params;
};

// edits "file.edits";
struct EditsDecl {
    Span span;
    std::string path;
    Span path_span;
};

struct File;

struct InstanceDecl {
    Span span;
    std::string name;
    std::vector<ParamName> params;
    std::unique_ptr<File> body;
};

struct Axiom {
    Span span;
    ModuleList successor;
};

struct File {
    std::uint32_t source = 0;
    std::vector<ValueDecl> values; // params, consts and vars in file order
    std::vector<ModuleDecl> modules;
    std::vector<FnDecl> functions;
    std::vector<ShapeDecl> curves, surfaces, envs, textures;
    std::vector<InstanceDecl> instances;
    std::vector<Setting> settings;
    std::vector<Axiom> axioms;
    std::vector<SymbolSet> symbol_sets;
    std::vector<RuleBlock> rule_blocks; // in file order
    std::vector<Hook> hooks;
    std::vector<Import> imports;
    std::vector<GraphBlock> graphs;
    std::vector<EditsDecl> edits_files;
};

} // namespace plant::ast
