// The .plant grammar as PEGTL rules (docs/language.md, from lexical rules to hooks). Only rule types live
// here; the parse-tree selector and the lowering to the AST are in parser.cpp, the error messages in
// grammar_errors.hpp. Each rule carries the grammar line it implements as a comment.
//
// Commit points: after a keyword that opens an item, after '->', after '(' '{' and '/*', a
// failure is an error (must<>), never a backtrack, so messages point where the problem is.
#pragma once

#include <tao/pegtl.hpp>

namespace plant::grammar {

using namespace tao::pegtl;

// comment <- '#' (!eol .)* | '/*' (!'*/' .)* '*/'
struct line_comment : seq<one<'#'>, until<eolf>> {};
struct block_comment_end : string<'*', '/'> {};
struct block_comment_body : until<block_comment_end> {};
struct block_comment : if_must<string<'/', '*'>, block_comment_body> {};
struct comment : sor<line_comment, block_comment> {};
struct ws : star<sor<plus<space>, comment>> {};
template <typename R> struct pad : seq<R, ws> {};

// identifier <- [A-Za-z_] [A-Za-z0-9_]*
struct identifier : seq<ranges<'a', 'z', 'A', 'Z', '_'>, star<ranges<'a', 'z', 'A', 'Z', '0', '9', '_'>>> {};
#define PLANT_KW(name, text)                                                                                 \
    struct kw_##name : seq<TAO_PEGTL_KEYWORD(text), ws> {}
PLANT_KW(param, "param");
PLANT_KW(const, "const");
PLANT_KW(var, "var");
PLANT_KW(module, "module");
PLANT_KW(bound, "bound");
PLANT_KW(fn, "fn");
PLANT_KW(curve, "curve");
PLANT_KW(surface, "surface");
PLANT_KW(env, "env");
PLANT_KW(texture, "texture");
PLANT_KW(instance, "instance");
PLANT_KW(derive, "derive");
PLANT_KW(angle, "angle");
PLANT_KW(step, "step");
PLANT_KW(width, "width");
PLANT_KW(seed, "seed");
PLANT_KW(width_scale, "width_scale");
PLANT_KW(axiom, "axiom");
PLANT_KW(ignore, "ignore");
PLANT_KW(consider, "consider");
PLANT_KW(rules, "rules");
PLANT_KW(decompose, "decompose");
PLANT_KW(interpret, "interpret");
PLANT_KW(max_depth, "max_depth");
PLANT_KW(on, "on");
PLANT_KW(import, "import");
PLANT_KW(with, "with");
PLANT_KW(let, "let");
PLANT_KW(if, "if");
PLANT_KW(else, "else");
PLANT_KW(for, "for");
PLANT_KW(in, "in");
PLANT_KW(produce, "produce");
PLANT_KW(nproduce, "nproduce");
PLANT_KW(use, "use");
PLANT_KW(stop, "stop");
PLANT_KW(return, "return");
PLANT_KW(true, "true");
PLANT_KW(false, "false");
PLANT_KW(graph, "graph");
PLANT_KW(match, "match");
PLANT_KW(edits, "edits");
#undef PLANT_KW

struct semi : pad<one<';'>> {};
struct comma : pad<one<','>> {};
struct colon : pad<one<':'>> {};
struct equals : pad<seq<one<'='>, not_at<one<'='>>>> {};
struct open_paren : pad<one<'('>> {};
struct close_paren : pad<one<')'>> {};
struct open_brace : pad<one<'{'>> {};
struct close_brace : pad<one<'}'>> {};
struct name : pad<identifier> {};

// ---- expressions (docs/language.md, values and expressions) -------------------------------

struct expr;
// number <- [0-9]+ ('.' [0-9]+)? exponent? | '.' [0-9]+ exponent?
struct exponent : seq<one<'e', 'E'>, opt<one<'+', '-'>>, plus<digit>> {};
struct number
    : seq<sor<seq<plus<digit>, opt<one<'.'>, plus<digit>>>, seq<one<'.'>, plus<digit>>>, opt<exponent>> {};
// string <- '"' ('\' . | [^"\n])* '"'
struct string_char : sor<seq<one<'\\'>, not_one<'\n'>>, not_one<'"', '\n'>> {};
struct string_body : until<one<'"'>, string_char> {};
struct string_lit : if_must<one<'"'>, string_body> {};
struct true_lit : kw_true {};
struct false_lit : kw_false {};
// args <- '(' (expr (',' expr)*)? ')'
struct arg_list : opt<list<expr, comma>> {};
struct call_args : if_must<open_paren, arg_list, close_paren> {};
struct paren_expr : if_must<open_paren, expr, close_paren> {};
struct call : seq<name, call_args> {};
struct name_ref : name {};
struct primary : sor<seq<number, ws>, seq<string_lit, ws>, true_lit, false_lit, paren_expr, call, name_ref> {
};
// postfix <- primary ('.' identifier args?)*
struct member : seq<one<'.'>, not_at<one<'.'>>, name, opt<call_args>> {};
struct postfix : seq<primary, star<member>> {};
struct unary_op : sor<one<'-'>, seq<one<'!'>, not_at<one<'='>>>> {};
struct unary;
struct operand;
struct unary_expr : seq<pad<unary_op>, must<operand>> {};
struct unary : sor<unary_expr, postfix> {};
struct operand : seq<unary> {};
struct mul_op : sor<one<'*'>, seq<one<'/'>, not_at<one<'*'>>>, one<'%'>> {};
struct mul : seq<unary, star<pad<mul_op>, must<operand>>> {};
// ABOP's stochastic arrow -(0.33)-> : a '-' with a number in parentheses right before '->' or
// '-->' is the arrow, never a '-' operator or module (docs/language.md, ABOP, cpfg and L-Py)
struct long_arrow : string<'-', '-', '>'> {};
struct stoch_prob : seq<ws, number, ws> {};
struct stoch_arrow : seq<one<'-'>, one<'('>, stoch_prob, one<')'>, sor<long_arrow, string<'-', '>'>>, ws> {};
// '-' is subtraction unless it starts an arrow: '->', '-->' (L-Py) or -(p)->
struct minus_sign : seq<not_at<stoch_arrow>, not_at<long_arrow>, one<'-'>, not_at<one<'>'>>> {};
struct add_op : sor<one<'+'>, minus_sign> {};
struct add : seq<mul, star<pad<add_op>, must<mul>>> {};
struct rel_op : sor<string<'<', '='>, string<'>', '='>, seq<one<'<'>, not_at<one<'<'>>>,
                    seq<one<'>'>, not_at<one<'>'>>>> {};
struct rel : seq<add, opt<pad<rel_op>, must<add>>> {};
struct eq_op : sor<string<'=', '='>, string<'!', '='>> {};
struct eqx : seq<rel, opt<pad<eq_op>, must<rel>>> {};
struct and_op : string<'&', '&'> {};
struct and_operand : seq<eqx> {};
struct and_x : seq<eqx, star<pad<and_op>, must<and_operand>>> {};
struct or_op : string<'|', '|'> {};
struct or_operand : seq<and_x> {};
struct or_x : seq<and_x, star<pad<or_op>, must<or_operand>>> {};
struct ternary_then;
struct ternary_else;
struct ternary : seq<or_x, opt<if_must<pad<one<'?'>>, ternary_then, colon, ternary_else>>> {};
// (expr wraps ternary in seq<> so that ternary is matched as a rule of its own and can be a
// parse-tree node; `struct expr : ternary {}` would only reuse ternary's implementation)
struct expr : seq<ternary> {};
struct ternary_then : seq<expr> {};
struct ternary_else : seq<expr> {};

// ---- modules, successors and patterns (docs/language.md, productions) -----------------------

// A module name: an @-name, a ?-query name, a ~surface name, a turtle symbol or a letter run.
struct at_name : seq<one<'@'>, identifier> {};
struct query_name : seq<one<'?'>, identifier> {};
struct tilde_name : seq<one<'~'>, opt<identifier>> {};
struct semi_sym : seq<one<';'>, at<one<'('>>> {}; // ';' is a module only with arguments
struct punct_sym : sor<one<'+'>, minus_sign, one<'&'>, one<'^'>, one<'\\'>, seq<one<'/'>, not_at<one<'*'>>>,
                       one<'|'>, one<'$'>, one<'!'>, one<'%'>> {};
struct word : identifier {};
struct module_name : sor<at_name, query_name, tilde_name, semi_sym, punct_sym, word> {};
struct module_args : if_must<open_paren, arg_list, close_paren> {};
struct module_ref : seq<module_name, ws, opt<module_args>> {};
struct bracket_open : pad<one<'['>> {};
struct bracket_close : pad<one<']'>> {};
struct wildcard : pad<one<'*'>> {};
// successor <- ('[' | ']' | module)*
struct successor : star<sor<bracket_open, bracket_close, module_ref>> {};
// pattern <- ('[' | ']' | '*' | module)+
struct pattern_elem : seq<not_at<stoch_arrow>, sor<bracket_open, bracket_close, wildcard, module_ref>> {};
struct pattern : plus<pattern_elem> {};

// production <- pattern (ctx_op pattern)* (':' expr)? ('->' successor (':' expr)? ';' | block)
struct ctx_op : sor<string<'<', '<'>, one<'<'>, string<'>', '>'>, seq<one<'>'>, not_at<one<'='>>>> {};
struct ctx_part : seq<pad<ctx_op>, must<pattern>> {};
// '->', L-Py's '-->' and the arrow character U+2192 (as ABOP prints it) are one arrow
struct utf8_arrow : string<'\xe2', '\x86', '\x92'> {};
struct arrow : pad<sor<long_arrow, string<'-', '>'>, utf8_arrow>> {};
// cpfg's ': *' (no condition) before the arrow
struct any_condition : seq<pad<one<'*'>>, at<sor<arrow, stoch_arrow, one<'{'>>>> {};
struct condition : sor<seq<colon, any_condition>, if_must<colon, expr>> {};
struct weight : if_must<colon, expr> {};
struct production_end : semi {};
struct arrow_form : if_must<arrow, successor, opt<weight>, production_end> {};
struct stoch_form : if_must<stoch_arrow, successor, production_end> {};
struct block;
struct production_tail : sor<arrow_form, stoch_form, block> {};
struct production : seq<pattern, star<ctx_part>, opt<condition>, must<production_tail>> {};
struct rules_body : if_must<open_brace, star<production>, close_brace> {};

// ---- statements (docs/language.md, productions: body form; hooks and groups) --------------

struct statement;
struct block : if_must<open_brace, star<statement>, close_brace> {};
struct let_stmt : if_must<kw_let, name, equals, expr, semi> {};
struct assign_op : pad<sor<string<'+', '='>, string<'-', '='>, string<'*', '='>, string<'/', '='>,
                           seq<one<'='>, not_at<one<'='>>>>> {};
struct assign_stmt : seq<name, assign_op, must<expr>, must<semi>> {};
struct if_stmt;
struct else_part : if_must<kw_else, sor<if_stmt, block>> {};
struct if_stmt : if_must<kw_if, expr, block, opt<else_part>> {};
// "0...2" would read as 0 .. .2 (a number may start with '.'): a third dot is an error
struct no_third_dot : not_at<one<'.'>> {};
struct range_dots : pad<seq<string<'.', '.'>, must<no_third_dot>>> {};
struct for_stmt : if_must<kw_for, name, kw_in, expr, range_dots, expr, block> {};
struct produce_stmt : if_must<kw_produce, successor, semi> {};
struct nproduce_stmt : if_must<kw_nproduce, successor, semi> {};
struct use_stmt : if_must<kw_use, name, semi> {};
struct stop_stmt : if_must<kw_stop, semi> {};
struct return_stmt : if_must<kw_return, opt<expr>, semi> {};
struct expr_stmt : seq<expr, must<semi>> {};
struct statement : sor<let_stmt, if_stmt, for_stmt, produce_stmt, nproduce_stmt, use_stmt, stop_stmt,
                       return_stmt, assign_stmt, expr_stmt> {};

// ---- top-level items (docs/language.md, top-level items) ------------------------------------

// param r = 0.9 in 0.5 .. 1.0;  (the range: values given at compile time are checked against it,
// and `plant view` draws a slider over it)
struct param_range : if_must<kw_in, expr, range_dots, expr> {};
struct param_item : if_must<kw_param, name, equals, expr, opt<param_range>, semi> {};
struct const_item : if_must<kw_const, name, equals, expr, semi> {};
struct var_item : if_must<kw_var, name, equals, expr, semi> {};
// module Name(a, b: vec3) [bound env];
struct param_decl : seq<name, opt<colon, name>> {};
struct param_list : if_must<open_paren, opt<list<param_decl, comma>>, close_paren> {};
struct bound_clause : if_must<kw_bound, name> {};
struct module_decl : seq<name, opt<param_list>, opt<bound_clause>> {};
struct module_item : if_must<kw_module, list_must<module_decl, comma>, semi> {};
struct fn_expr_body : if_must<equals, expr, semi> {};
struct fn_item : if_must<kw_fn, name, param_list, sor<fn_expr_body, block>> {};
struct shape_kind : name {};
struct curve_item : if_must<kw_curve, name, equals, shape_kind, call_args, semi> {};
struct surface_item : if_must<kw_surface, name, equals, shape_kind, call_args, semi> {};
// texture name = image("file.png");
struct texture_item : if_must<kw_texture, name, equals, shape_kind, call_args, semi> {};
// env name = kind(key: value, ...);
struct key_arg : seq<opt<name, colon>, expr> {};
struct key_args : if_must<open_paren, opt<list<key_arg, comma>>, close_paren> {};
struct env_item : if_must<kw_env, name, equals, shape_kind, key_args, semi> {};
struct item;
struct instance_body : if_must<open_brace, star<item>, close_brace> {};
struct instance_item : if_must<kw_instance, name, opt<param_list>, instance_body> {};
struct setting_key : sor<kw_derive, kw_angle, kw_step, kw_width, kw_seed, kw_width_scale> {};
struct setting_item : if_must<setting_key, expr, semi> {};
// 'axiom:' or ABOP's 'ω:'
struct omega : seq<string<'\xcf', '\x89'>, ws> {};
struct axiom_item : if_must<sor<kw_axiom, omega>, colon, successor, semi> {};
struct symbol_set_kind : sor<kw_ignore, kw_consider> {};
struct symbol_set_item : if_must<symbol_set_kind, colon, opt<pattern>, semi> {};
struct group_name : name {};
struct rules_item : if_must<kw_rules, opt<group_name>, rules_body> {};
struct max_depth_clause : if_must<kw_max_depth, expr> {};
struct decompose_item : if_must<kw_decompose, opt<max_depth_clause>, rules_body> {};
struct interpret_item : if_must<kw_interpret, opt<max_depth_clause>, rules_body> {};
struct hook_name : name {};
struct hook_item : if_must<kw_on, hook_name, block> {};
struct override_item : seq<name, equals, expr> {};
struct override_block : if_must<open_brace, opt<list<override_item, comma>>, opt<comma>, close_brace> {};
struct import_target : sor<seq<string_lit, ws>, name> {};
struct with_clause : if_must<kw_with, override_block> {};
struct import_item : if_must<kw_import, import_target, opt<with_clause>, semi> {};
// graph [match range|single] { name = value; ... }   (docs/language.md, decomposition graphs)
struct match_clause : if_must<kw_match, name> {};
// silhouette(axis: polyline(...), top: ..., ...): a silhouette value, keyed like an env's arguments
struct silhouette_value : seq<TAO_PEGTL_KEYWORD("silhouette"), ws, key_args> {};
struct graph_param : seq<name, must<equals, sor<silhouette_value, expr>, semi>> {};
struct graph_body : if_must<open_brace, star<graph_param>, close_brace> {};
struct graph_item : if_must<kw_graph, opt<match_clause>, graph_body> {};
// edits "file.edits";
struct edits_target : seq<string_lit, ws> {};
struct edits_item : if_must<kw_edits, edits_target, semi> {};
struct item
    : sor<param_item, const_item, var_item, module_item, fn_item, curve_item, surface_item, texture_item,
          env_item, instance_item, setting_item, axiom_item, symbol_set_item, rules_item, decompose_item,
          interpret_item, hook_item, import_item, graph_item, edits_item> {};

// The file is parsed one item at a time (parser.cpp) so that an error in one item does not hide
// errors in later ones.
struct item_or_end : seq<ws, sor<eof, must<item>>> {};

// A whole file in one rule, for pegtl::analyze in the tests.
struct file : seq<opt<utf8::bom>, ws, star<item>, must<eof>> {}; // (parse_file skips a BOM itself)

} // namespace plant::grammar
