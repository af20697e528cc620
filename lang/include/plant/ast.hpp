// The syntax tree: plain data, every node with its source span. Produced by the parser, read by
// the checker and the compiler; nothing here evaluates anything.
#pragma once

#include "plant/source.hpp"

#include <memory>
#include <string>
#include <vector>

namespace plant::ast {

struct Expr;
using ExprPtr = std::unique_ptr<Expr>;

enum class ExprKind {
    Number,  // number
    Bool,    // number != 0
    String,  // text
    Name,    // text
    Unary,   // text = op, args[0]
    Binary,  // text = op, args[0], args[1]
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
    std::vector<ExprPtr> args;
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
    std::string name; // Let/Assign/For variable, Use group
    std::string op;   // Assign: "=", "+=", ...
    ExprPtr expr;     // value, condition, range start
    ExprPtr expr2;    // range end
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

// curve / surface / env: name = kind(args)
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
    std::string key; // derive angle step width seed
    ExprPtr value;
};

struct SymbolSet {
    Span span;
    bool ignore = true; // false: consider
    ModuleList symbols;
};

struct Hook {
    Span span;
    std::string when; // start before_step after_step end
    std::vector<Stmt> body;
};

struct Import {
    Span span;
    std::string target;
    bool is_path = false;
    std::vector<std::pair<std::string, ExprPtr>> overrides;
    std::vector<Span> override_spans;
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
    std::vector<ShapeDecl> curves, surfaces, envs;
    std::vector<InstanceDecl> instances;
    std::vector<Setting> settings;
    std::vector<Axiom> axioms;
    std::vector<SymbolSet> symbol_sets;
    std::vector<RuleBlock> rule_blocks; // in file order
    std::vector<Hook> hooks;
    std::vector<Import> imports;
};

} // namespace plant::ast
