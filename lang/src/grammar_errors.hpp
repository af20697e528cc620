// Error messages for the .plant grammar and the control class that raises them. A message may
// contain {at}: it is replaced by the line:column where the innermost open construct (a
// production, a '(' or '{', an item) began, so messages name both ends of a problem; {hooks}
// is replaced by the hook names of ast::kHooks.
#pragma once

#include "grammar.hpp"
#include "plant/diagnostics.hpp"
#include "plant/source.hpp"

#include <string>
#include <vector>

namespace plant::grammar {

template <typename Rule> inline constexpr const char* error_message = nullptr;

#define PLANT_ERR(rule, text) template <> inline constexpr const char* error_message<rule> = text
PLANT_ERR(block_comment_body, "unterminated comment: expected '*/' to close '/*' at {at}");
PLANT_ERR(string_body, "unterminated string: expected '\"' to close '\"' at {at}");
PLANT_ERR(close_paren, "expected ')' to close '(' at {at}");
PLANT_ERR(close_brace, "expected '}' to close '{' at {at}");
PLANT_ERR(open_paren, "expected '('");
PLANT_ERR(open_brace, "expected '{'");
PLANT_ERR(arg_list, "expected arguments");
PLANT_ERR(expr, "expected an expression");
PLANT_ERR(operand, "expected an expression after the operator");
PLANT_ERR(mul, "expected an expression after the operator");
PLANT_ERR(add, "expected an expression after the operator");
PLANT_ERR(rel, "expected an expression after the operator");
PLANT_ERR(eqx, "expected an expression after the operator");
PLANT_ERR(and_operand, "expected an expression after '&&'");
PLANT_ERR(or_operand, "expected an expression after '||'");
PLANT_ERR(ternary_then, "expected an expression after '?'");
PLANT_ERR(ternary_else, "expected an expression after ':' of '?' (started at {at})");
PLANT_ERR(colon, "expected ':'");
PLANT_ERR(semi, "expected ';' (statement started at {at})");
PLANT_ERR(equals, "expected '='");
PLANT_ERR(name, "expected a name");
PLANT_ERR(pattern, "expected a module pattern after the context operator");
PLANT_ERR(production_tail, "expected '->' or '{' after the predecessor of the production (started at {at})");
PLANT_ERR(production_end, "expected ';' after production (started at {at})");
PLANT_ERR(successor, "expected a successor");
PLANT_ERR(block, "expected '{'");
PLANT_ERR(statement, "expected a statement");
PLANT_ERR(if_stmt, "expected 'if' or '{' after 'else'");
PLANT_ERR(kw_in, "expected 'in' after the loop variable");
PLANT_ERR(range_dots, "expected '..' between the bounds of the range");
// habits::hint adds what "0...2" would read as
PLANT_ERR(no_third_dot, "expected the range's end after '..'");
PLANT_ERR(module_decl, "expected a module name");
PLANT_ERR(param_decl, "expected a parameter name");
PLANT_ERR(param_list, "expected '(' and the parameter list");
PLANT_ERR(shape_kind, "expected a kind name such as polygon, bezier or ellipsoid");
PLANT_ERR(call_args, "expected '(' and the arguments");
PLANT_ERR(key_args, "expected '(' and the arguments");
PLANT_ERR(key_arg, "expected an argument");
PLANT_ERR(instance_body, "expected '{' to start the instance body");
PLANT_ERR(rules_body, "expected '{' to start the rules");
PLANT_ERR(hook_name, "expected a hook name: {hooks}"); // the names from ast::kHooks
PLANT_ERR(import_target, "expected a library name or a quoted path after 'import'");
PLANT_ERR(override_block, "expected '{' and parameter overrides after 'with'");
PLANT_ERR(override_item, "expected 'name = value'");
PLANT_ERR(graph_body, "expected '{' and the graph's parameters, as in graph { length = 10; }");
PLANT_ERR(edits_target, "expected a quoted file name after 'edits', as in edits \"plant.edits\";");
using else_target = sor<if_stmt, block>;
using fn_body = sor<fn_expr_body, block>;
using module_decls = list_must<module_decl, comma>;
PLANT_ERR(else_target, "expected 'if' or '{' after 'else'");
PLANT_ERR(fn_body, "expected '=' or '{' after the parameters of the function");
PLANT_ERR(fn_expr_body, "expected '=' or '{' after the parameters of the function");
PLANT_ERR(item, "expected a top-level item (param, const, var, module, fn, axiom, rules, derive, ...)");
PLANT_ERR(eof, "expected a top-level item or the end of the file");
PLANT_ERR(max_depth_clause, "expected a depth after 'max_depth'");
PLANT_ERR(expr_stmt, "expected a statement");
PLANT_ERR(with_clause, "expected '{' after 'with'");
PLANT_ERR(bound_clause, "expected the environment name after 'bound'");
PLANT_ERR(symbol_set_item, "expected ':' and a list of modules");
PLANT_ERR(opt<pattern>, "expected a list of modules");
PLANT_ERR(module_decls, "expected a module name");
#undef PLANT_ERR

// Rules whose start is remembered so that messages can say where a construct began.
template <typename Rule> inline constexpr bool is_construct = false;
#define PLANT_CONSTRUCT(rule) template <> inline constexpr bool is_construct<rule> = true
PLANT_CONSTRUCT(block_comment);
PLANT_CONSTRUCT(string_lit);
PLANT_CONSTRUCT(call_args);
PLANT_CONSTRUCT(paren_expr);
PLANT_CONSTRUCT(module_args);
PLANT_CONSTRUCT(param_list);
PLANT_CONSTRUCT(key_args);
PLANT_CONSTRUCT(production);
PLANT_CONSTRUCT(rules_body);
PLANT_CONSTRUCT(block);
PLANT_CONSTRUCT(instance_body);
PLANT_CONSTRUCT(override_block);
PLANT_CONSTRUCT(ternary);
PLANT_CONSTRUCT(param_item);
PLANT_CONSTRUCT(const_item);
PLANT_CONSTRUCT(var_item);
PLANT_CONSTRUCT(module_item);
PLANT_CONSTRUCT(fn_item);
PLANT_CONSTRUCT(curve_item);
PLANT_CONSTRUCT(surface_item);
PLANT_CONSTRUCT(texture_item);
PLANT_CONSTRUCT(env_item);
PLANT_CONSTRUCT(setting_item);
PLANT_CONSTRUCT(axiom_item);
PLANT_CONSTRUCT(symbol_set_item);
PLANT_CONSTRUCT(import_item);
PLANT_CONSTRUCT(graph_item);
PLANT_CONSTRUCT(edits_item);
PLANT_CONSTRUCT(let_stmt);
PLANT_CONSTRUCT(assign_stmt);
PLANT_CONSTRUCT(produce_stmt);
PLANT_CONSTRUCT(nproduce_stmt);
PLANT_CONSTRUCT(use_stmt);
PLANT_CONSTRUCT(stop_stmt);
PLANT_CONSTRUCT(return_stmt);
PLANT_CONSTRUCT(expr_stmt);
#undef PLANT_CONSTRUCT

// Rules that nest; their depth is bounded so that a pathological input (ten thousand '(')
// is an error rather than a stack overflow. Each must also be selected in parser.cpp's
// selector: the parse-tree builder calls this control's start() for selected rules only.
template <typename Rule> inline constexpr bool is_nesting = false;
template <> inline constexpr bool is_nesting<paren_expr> = true;
template <> inline constexpr bool is_nesting<unary_expr> = true;
template <> inline constexpr bool is_nesting<call_args> = true;
template <> inline constexpr bool is_nesting<module_args> = true;
template <> inline constexpr bool is_nesting<block> = true;
template <> inline constexpr bool is_nesting<instance_body> = true;
template <> inline constexpr bool is_nesting<ternary_then> = true;
template <> inline constexpr bool is_nesting<ternary_else> = true;
template <> inline constexpr bool is_nesting<else_part> = true;
inline constexpr std::size_t max_nesting = 200;

// Byte offsets of the constructs open at the current point of the parse.
struct ParseState {
    std::vector<std::size_t> open;
    std::size_t depth = 0; // nesting of expressions, blocks and brackets, bounded
};

// The position of a raised error and its message, with {at} still unresolved: the parser
// resolves it against the source file.
struct GrammarError {
    std::size_t byte;
    std::string message;
    std::size_t at; // byte offset of the innermost open construct, or npos
};

// (parse_errors.cpp) What is at `byte`, for a message: "'rules'", "'}'", "end of line", ...
std::string describe_found(const std::string& text, std::size_t byte);
// Adds `e` to `diags`: {at} replaced by where the construct began, what was found named, and
// a ';' left off at the end of a line shown there.
void report(const GrammarError& e, const SourceFile& src, std::uint32_t file_id, Diagnostics& diags);
// Where to parse on after an error at `from` in an item begun at `item_start`: the first line
// at or after the error that starts with a top-level keyword, always after `item_start`.
std::size_t resync(const std::string& text, std::size_t from, std::size_t item_start);

template <typename Rule> struct control : normal<Rule> {
    template <typename Input> static void start(const Input& in, ParseState& st) {
        if constexpr (is_construct<Rule>) st.open.push_back(in.byte());
        if constexpr (is_nesting<Rule>) {
            if (++st.depth > max_nesting) {
                --st.depth;
                if constexpr (is_construct<Rule>) st.open.pop_back();
                throw GrammarError{in.byte(), "nesting deeper than 200 levels", std::string::npos};
            }
        }
    }
    template <typename Input> static void leave(ParseState& st) {
        if constexpr (is_construct<Rule>) st.open.pop_back();
        if constexpr (is_nesting<Rule>) --st.depth;
    }
    template <typename Input> static void success(const Input&, ParseState& st) { leave<Input>(st); }
    template <typename Input> static void failure(const Input&, ParseState& st) { leave<Input>(st); }
    template <typename Input> static void unwind(const Input&, ParseState& st) { leave<Input>(st); }
    template <typename Input> [[noreturn]] static void raise(const Input& in, ParseState& st) {
        const char* msg = error_message<Rule>;
        std::string text = msg ? msg : "syntax error";
        if (!msg) text += " (in " + std::string(demangle<Rule>()) + ")";
        throw GrammarError{in.byte(), std::move(text), st.open.empty() ? std::string::npos : st.open.back()};
    }
};

} // namespace plant::grammar
