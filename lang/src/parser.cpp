// Parse tree to AST. PEGTL builds a generic tree of the selected rules; the functions below
// turn it into the plain-data AST of ast.hpp, one function per construct.
#include "plant/parser.hpp"

#include "grammar.hpp"
#include "grammar_errors.hpp"
#include "habits.hpp"
#include "parse_node.hpp"

#include <fmt/format.h>
#include <tao/pegtl/contrib/parse_tree.hpp>

#include <cctype>
#include <charconv>

namespace plant {

namespace g = grammar;
namespace pt = tao::pegtl::parse_tree;

template <typename Rule>
using selector = pt::selector<
    Rule,
    pt::store_content::on<
        g::identifier, g::number, g::string_lit, g::true_lit, g::false_lit, g::call, g::call_args,
        g::name_ref, g::paren_expr, g::member, g::unary_expr, g::unary_op, g::mul_op, g::add_op, g::rel_op,
        g::eq_op, g::and_op, g::or_op, g::module_ref, g::module_name, g::module_args, g::bracket_open,
        g::bracket_close, g::wildcard, g::successor, g::pattern, g::production, g::ctx_part, g::ctx_op,
        g::condition, g::arrow_form, g::stoch_form, g::stoch_arrow, g::weight, g::block, g::let_stmt,
        g::assign_stmt, g::assign_op, g::if_stmt, g::else_part, g::for_stmt, g::produce_stmt,
        g::nproduce_stmt, g::use_stmt, g::stop_stmt, g::return_stmt, g::expr_stmt, g::param_item,
        g::param_range, g::const_item, g::var_item, g::module_item, g::module_decl, g::param_list,
        g::param_decl, g::bound_clause, g::fn_item, g::fn_expr_body, g::curve_item, g::surface_item,
        g::texture_item, g::shape_kind, g::env_item, g::key_args, g::key_arg, g::instance_item,
        g::instance_body, g::setting_item, g::setting_key, g::axiom_item, g::symbol_set_item,
        g::symbol_set_kind, g::rules_item, g::group_name, g::rules_body, g::decompose_item, g::interpret_item,
        g::max_depth_clause, g::hook_item, g::hook_name, g::import_item, g::import_target, g::with_clause,
        g::override_block, g::override_item, g::graph_item, g::match_clause, g::graph_body, g::graph_param,
        g::silhouette_value, g::edits_item, g::edits_target>,
    // (ternary_then and ternary_else are selected only so that their nesting is counted: the tree
    // builder calls the grammar's control for selected rules alone; each has one child, which
    // fold_one puts in its place)
    pt::fold_one::on<g::postfix, g::mul, g::add, g::rel, g::eqx, g::and_x, g::or_x, g::ternary,
                     g::ternary_then, g::ternary_else>>;

namespace {

constexpr std::size_t kMaxChain = 1000;

class Lowering {
  public:
    Lowering(std::uint32_t file, Diagnostics& diags) : file_(file), diags_(diags) {}

    Span span(const Node& n) const {
        return {file_, static_cast<std::uint32_t>(n.begin().byte), static_cast<std::uint32_t>(n.end().byte)};
    }
    static std::string trimmed(const Node& n) {
        std::string s = n.string();
        while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
        return s;
    }
    // The entry of `table` that the node spells (an operator or keyword, without the spaces and
    // comments after it); the grammar admits only spellings that are in the table.
    template <typename E, std::size_t N>
    static E spelled(const std::array<ast::Spelled<E>, N>& table, const Node& n) {
        std::string_view text = n.string_view();
        std::size_t len = 0;
        while (len < text.size() && !std::isspace(static_cast<unsigned char>(text[len])) &&
               text.compare(len, 1, "#") != 0 && text.compare(len, 2, "/*") != 0)
            ++len;
        auto value = ast::lookup(table, text.substr(0, len));
        return value ? *value : table[0].value;
    }

    ast::ExprPtr expr(const Node& n) {
        auto e = std::make_unique<ast::Expr>();
        e->span = span(n);
        if (n.is_type<g::number>()) {
            e->kind = ast::ExprKind::Number;
            std::string s = n.string();
            auto r = std::from_chars(s.data(), s.data() + s.size(), e->number);
            if (r.ec != std::errc())
                diags_.error(e->span, fmt::format("number '{}' is out of range", excerpt(s)));
            e->text = std::move(s); // as written: "5" is a count, "5.0" a measure (param ranges)
        } else if (n.is_type<g::string_lit>()) {
            e->kind = ast::ExprKind::String;
            e->text = unescape(n.string_view());
        } else if (n.is_type<g::true_lit>() || n.is_type<g::false_lit>()) {
            e->kind = ast::ExprKind::Bool;
            e->number = n.is_type<g::true_lit>() ? 1 : 0;
        } else if (n.is_type<g::name_ref>()) {
            e->kind = ast::ExprKind::Name;
            e->text = n.children.at(0)->string();
            e->span = span(*n.children.at(0)); // the name, without the space after it
        } else if (n.is_type<g::call>()) {
            e->kind = ast::ExprKind::Call;
            e->text = n.children.at(0)->string();
            for (const auto& a : n.children.at(1)->children) e->args.push_back(expr(*a));
        } else if (n.is_type<g::silhouette_value>()) { // keyed arguments (a graph's silhouette)
            e->kind = ast::ExprKind::Call;
            e->text = "silhouette";
            for (const auto& a : n.children.at(0)->children) {
                const bool keyed = a->children.size() == 2;
                e->keys.push_back(keyed ? a->children[0]->string() : std::string());
                e->key_spans.push_back(span(*a->children[0]));
                e->args.push_back(expr(*a->children.back()));
            }
        } else if (n.is_type<g::unary_expr>()) {
            e->kind = ast::ExprKind::Unary;
            e->unary = spelled(ast::kUnaryOps, *n.children.at(0));
            e->args.push_back(expr(*n.children.at(1)));
        } else if (n.is_type<g::paren_expr>()) {
            // the value is the inner expression; its span takes in the parentheses, so that a
            // message about `x / (x - 1)` shows the whole divisor
            ast::ExprPtr inner = expr(*n.children.at(0));
            std::string_view text = n.string_view();
            auto close = text.rfind(')');
            inner->span = {
                file_, static_cast<std::uint32_t>(n.begin().byte),
                static_cast<std::uint32_t>(n.begin().byte + (close == text.npos ? text.size() : close + 1))};
            return inner;
        } else if (n.is_type<g::ternary>()) {
            e->kind = ast::ExprKind::Ternary;
            for (const auto& c : n.children) e->args.push_back(expr(*c));
        } else if (n.is_type<g::postfix>()) {
            // primary followed by members: fold left
            ast::ExprPtr cur = expr(*n.children.at(0));
            for (std::size_t i = 1; i < n.children.size(); ++i) {
                const Node& m = *n.children[i];
                auto me = std::make_unique<ast::Expr>();
                me->span = {file_, cur->span.begin, static_cast<std::uint32_t>(m.end().byte)};
                me->text = m.children.at(0)->string();
                me->args.push_back(std::move(cur));
                if (m.children.size() > 1) {
                    me->kind = ast::ExprKind::Method;
                    for (const auto& a : m.children[1]->children) me->args.push_back(expr(*a));
                } else {
                    me->kind = ast::ExprKind::Member;
                }
                cur = std::move(me);
            }
            return cur;
        } else if (n.is_type<g::mul>() || n.is_type<g::add>() || n.is_type<g::rel>() || n.is_type<g::eqx>() ||
                   n.is_type<g::and_x>() || n.is_type<g::or_x>()) {
            // operand (op operand)*, left associative; the tree is as deep as the chain is long,
            // and everything that walks it recurses, so very long chains are refused
            if (n.children.size() > 2 * kMaxChain) {
                diags_.error(e->span,
                             fmt::format("more than {} operands in a row; split the expression", kMaxChain));
                return e;
            }
            ast::ExprPtr cur = expr(*n.children.at(0));
            for (std::size_t i = 1; i + 1 < n.children.size(); i += 2) {
                auto be = std::make_unique<ast::Expr>();
                be->kind = ast::ExprKind::Binary;
                be->binary = spelled(ast::kBinaryOps, *n.children[i]);
                auto rhs = expr(*n.children[i + 1]);
                be->span = {file_, cur->span.begin, rhs->span.end};
                be->args.push_back(std::move(cur));
                be->args.push_back(std::move(rhs));
                cur = std::move(be);
            }
            return cur;
        } else {
            diags_.error(e->span, fmt::format("internal: unexpected node {} in expression", n.type));
        }
        return e;
    }

    std::string unescape(std::string_view quoted) {
        std::string out;
        for (std::size_t i = 1; i + 1 < quoted.size(); ++i) {
            char c = quoted[i];
            if (c == '\\' && i + 2 < quoted.size()) {
                char d = quoted[++i];
                out += d == 'n' ? '\n' : d == 't' ? '\t' : d;
            } else {
                out += c;
            }
        }
        return out;
    }

    ast::ModuleRef module_ref(const Node& n) {
        ast::ModuleRef m;
        m.span = span(n);
        if (n.is_type<g::bracket_open>() || n.is_type<g::bracket_close>() || n.is_type<g::wildcard>()) {
            m.name = n.is_type<g::bracket_open>() ? "[" : n.is_type<g::bracket_close>() ? "]" : "*";
            m.name_span = {file_, m.span.begin, m.span.begin + 1};
            m.span = m.name_span;
            return m;
        }
        const Node& nm = *n.children.at(0);
        m.name = nm.string();
        m.name_span = span(nm);
        m.raw = !m.name.empty() && (std::isalpha(static_cast<unsigned char>(m.name[0])) || m.name[0] == '_');
        if (n.children.size() > 1) {
            m.has_args = true;
            for (const auto& a : n.children[1]->children) m.args.push_back(expr(*a));
            // the argument node includes the whitespace after ')'; end the span at the ')'
            std::string_view a = n.children[1]->string_view();
            auto close = a.rfind(')');
            m.span.end = static_cast<std::uint32_t>(n.children[1]->begin().byte +
                                                    (close == a.npos ? a.size() : close + 1));
        } else {
            m.span = m.name_span;
        }
        return m;
    }

    ast::ModuleList module_list(const Node& n) {
        ast::ModuleList out;
        for (const auto& c : n.children) out.push_back(module_ref(*c));
        return out;
    }

    // A '[' without its ']' (or a ']' with no '[') in an axiom or an arrow-form successor is
    // almost always a typo; the branch would run to the end of the string (docs/language.md).
    void check_brackets(const ast::ModuleList& list, const char* what) {
        std::vector<const ast::ModuleRef*> open;
        for (const auto& m : list) {
            if (m.name == "[") {
                open.push_back(&m);
            } else if (m.name == "]") {
                if (open.empty()) {
                    diags_.warning(m.span,
                                   fmt::format("this ']' closes no '[' of the {}; remove it or add the "
                                               "'[' that opens its branch",
                                               what));
                    return;
                }
                open.pop_back();
            }
        }
        if (!open.empty())
            diags_.warning(
                open.back()->span,
                fmt::format("this '[' is never closed in the {}; add the ']' that ends its branch", what));
    }

    ast::ModuleList checked_list(const Node& n, const char* what) {
        ast::ModuleList list = module_list(n);
        check_brackets(list, what);
        return list;
    }

    std::vector<ast::Stmt> block(const Node& n) {
        std::vector<ast::Stmt> out;
        for (const auto& c : n.children) out.push_back(stmt(*c));
        return out;
    }

    ast::Stmt stmt(const Node& n) {
        ast::Stmt s;
        s.span = span(n);
        if (n.is_type<g::let_stmt>()) {
            s.kind = ast::StmtKind::Let;
            s.name = n.children.at(0)->string();
            s.expr = expr(*n.children.at(1));
        } else if (n.is_type<g::assign_stmt>()) {
            s.kind = ast::StmtKind::Assign;
            s.name = n.children.at(0)->string();
            s.op = spelled(ast::kAssignOps, *n.children.at(1));
            s.expr = expr(*n.children.at(2));
        } else if (n.is_type<g::if_stmt>()) {
            s.kind = ast::StmtKind::If;
            s.expr = expr(*n.children.at(0));
            s.body = block(*n.children.at(1));
            if (n.children.size() > 2) {
                const Node& e = *n.children[2]->children.at(0);
                if (e.is_type<g::if_stmt>())
                    s.else_body.push_back(stmt(e));
                else
                    s.else_body = block(e);
            }
        } else if (n.is_type<g::for_stmt>()) {
            s.kind = ast::StmtKind::For;
            s.name = n.children.at(0)->string();
            s.expr = expr(*n.children.at(1));
            s.expr2 = expr(*n.children.at(2));
            s.body = block(*n.children.at(3));
        } else if (n.is_type<g::produce_stmt>() || n.is_type<g::nproduce_stmt>()) {
            s.kind = n.is_type<g::produce_stmt>() ? ast::StmtKind::Produce : ast::StmtKind::NProduce;
            s.successor = module_list(*n.children.at(0));
        } else if (n.is_type<g::use_stmt>()) {
            s.kind = ast::StmtKind::Use;
            s.name = n.children.at(0)->string();
        } else if (n.is_type<g::stop_stmt>()) {
            s.kind = ast::StmtKind::Stop;
        } else if (n.is_type<g::return_stmt>()) {
            s.kind = ast::StmtKind::Return;
            if (!n.children.empty()) s.expr = expr(*n.children[0]);
        } else {
            s.kind = ast::StmtKind::Expr;
            s.expr = expr(*n.children.at(0));
        }
        return s;
    }

    ast::Production production(const Node& n) {
        ast::Production p;
        p.span = span(n);
        // pattern, then (ctx_op pattern)*: place each part by the operator before and after it
        struct Part {
            std::string op_before;
            const Node* pat;
        };
        std::vector<Part> parts;
        std::size_t i = 0;
        parts.push_back({"", n.children.at(i++).get()});
        if (const auto& first = parts[0].pat->children;
            first.size() > 1 && first.front()->begin().line != first.back()->begin().line)
            // `A -> F ; G` then a new line: L-Py's colour ';' ended the production and G began the next
            diags_.warning(
                span(*first.front()),
                fmt::format("this predecessor runs from line {} to line {}; if the ';' before it was "
                            "meant as L-Py's colour step, write ;(c) with the colour index",
                            first.front()->begin().line, first.back()->begin().line));
        while (i < n.children.size() && n.children[i]->is_type<g::ctx_part>()) {
            const Node& cp = *n.children[i++];
            parts.push_back({trimmed(*cp.children.at(0)), cp.children.at(1).get()});
        }
        // The strict predecessor is the part after the last '<' or '<<' and before the first '>'.
        std::size_t strict = 0;
        for (std::size_t k = 1; k < parts.size(); ++k)
            if (parts[k].op_before == "<" || parts[k].op_before == "<<") strict = k;
        int seen_order = 0; // <, <<, strict, >, >>
        for (std::size_t k = 0; k < parts.size(); ++k) {
            const Node& pat = *parts[k].pat;
            ast::ModuleList list = module_list(pat);
            bool wildcard = list.size() == 1 && list[0].name == "*";
            if (!wildcard)
                for (const auto& m : list)
                    if (m.name == "*")
                        diags_.error(m.span, "'*' stands for a whole context, not for one module in it");
            std::string role;
            if (k < strict) {
                role = parts[k + 1].op_before; // the operator after this part says what it is
            } else if (k == strict) {
                role = "strict";
            } else {
                role = parts[k].op_before;
            }
            int order = role == "<" ? 0 : role == "<<" ? 1 : role == "strict" ? 2 : role == ">" ? 3 : 4;
            if (order < seen_order || (order == seen_order && k > 0 && role != "strict")) {
                diags_.error(span(pat),
                             fmt::format("context '{}' is out of place: the order is left < left_new << "
                                         "predecessor > right >> right_new",
                                         role));
            }
            seen_order = order;
            if (role == "strict") {
                if (wildcard) diags_.error(span(pat), "the strict predecessor cannot be '*'");
                p.strict = std::move(list);
            } else if (wildcard) {
                continue; // '*' means "any context", as in ABOP's tables
            } else if (role == "<") {
                p.left = std::move(list);
                p.has_left = true;
            } else if (role == "<<") {
                p.left_new = std::move(list);
                p.has_left_new = true;
            } else if (role == ">") {
                p.right = std::move(list);
                p.has_right = true;
            } else {
                p.right_new = std::move(list);
                p.has_right_new = true;
            }
        }
        for (; i < n.children.size(); ++i) {
            const Node& c = *n.children[i];
            if (c.is_type<g::condition>()) {
                if (!c.children.empty()) p.condition = expr(*c.children.at(0)); // none for cpfg's ': *'
            } else if (c.is_type<g::arrow_form>()) {
                // '->' is two bytes; '-->' and U+2192 three
                const std::size_t len = c.string_view().substr(0, 2) == "->" ? 2 : 3;
                p.arrow_span = {file_, static_cast<std::uint32_t>(c.begin().byte),
                                static_cast<std::uint32_t>(c.begin().byte + len)};
                p.successor = module_list(*c.children.at(0));
                check_brackets(p.successor, "successor");
                if (c.children.size() > 1) p.weight = expr(*c.children[1]->children.at(0));
            } else if (c.is_type<g::stoch_form>()) {
                // ABOP's -(p)-> : the probability is the production's weight
                const Node& a = *c.children.at(0);
                p.arrow_span = span(a);
                p.arrow_span.end =
                    p.arrow_span.begin + static_cast<std::uint32_t>(a.string_view().find('>') + 1);
                p.weight = expr(*a.children.at(0));
                p.successor = module_list(*c.children.at(1));
                check_brackets(p.successor, "successor");
            } else if (c.is_type<g::block>()) {
                p.body_form = true;
                p.body = block(c);
            }
        }
        return p;
    }

    std::vector<ast::ParamName> params(const Node& n) {
        std::vector<ast::ParamName> out;
        for (const auto& pd : n.children) {
            ast::ParamName pn;
            pn.name = pd->children.at(0)->string();
            pn.span = span(*pd->children.at(0));
            if (pd->children.size() > 1) pn.type = pd->children[1]->string();
            out.push_back(std::move(pn));
        }
        return out;
    }

    ast::ShapeDecl shape(const Node& n) {
        ast::ShapeDecl s;
        s.span = span(n);
        s.name = n.children.at(0)->string();
        s.kind = n.children.at(1)->children.at(0)->string();
        s.kind_span = span(*n.children.at(1)->children.at(0));
        for (const auto& a : n.children.at(2)->children) {
            if (a->is_type<g::key_arg>()) {
                if (a->children.size() == 2) {
                    s.keys.push_back(a->children[0]->string());
                    s.args.push_back(expr(*a->children[1]));
                } else {
                    s.keys.emplace_back();
                    s.args.push_back(expr(*a->children.at(0)));
                }
            } else {
                s.keys.emplace_back();
                s.args.push_back(expr(*a));
            }
        }
        return s;
    }

    void graph_block(const Node& n, ast::File& f) {
        ast::GraphBlock gb;
        gb.span = span(n);
        for (const auto& c : n.children) {
            if (c->is_type<g::match_clause>()) {
                gb.match = c->children.at(0)->string();
                gb.match_span = span(*c->children.at(0));
                continue;
            }
            for (const auto& p : c->children) {
                ast::GraphParam gp;
                gp.span = span(*p);
                gp.name = p->children.at(0)->string();
                gp.name_span = span(*p->children.at(0));
                gp.value = expr(*p->children.at(1));
                gb.params.push_back(std::move(gp));
            }
        }
        f.graphs.push_back(std::move(gb));
    }

    void rule_block(const Node& n, ast::File& f, ast::RuleKind kind) {
        ast::RuleBlock rb;
        rb.kind = kind;
        rb.span = span(n);
        for (const auto& c : n.children) {
            if (c->is_type<g::group_name>()) {
                rb.group = c->children.at(0)->string();
                rb.group_span = span(*c->children.at(0));
            } else if (c->is_type<g::max_depth_clause>()) {
                rb.max_depth = expr(*c->children.at(0));
            } else if (c->is_type<g::rules_body>()) {
                for (const auto& p : c->children) rb.productions.push_back(production(*p));
            }
        }
        f.rule_blocks.push_back(std::move(rb));
    }

    // param / const / var NAME = EXPR [in LOW .. HIGH];
    ast::ValueDecl value_decl(const Node& n) {
        ast::ValueDecl v;
        v.kind = n.is_type<g::param_item>()   ? ast::DeclKind::Param
                 : n.is_type<g::const_item>() ? ast::DeclKind::Const
                                              : ast::DeclKind::Var;
        v.span = span(n);
        v.name = n.children.at(0)->string();
        v.name_span = span(*n.children.at(0));
        v.value = expr(*n.children.at(1));
        if (n.children.size() > 2 && n.children[2]->is_type<g::param_range>()) {
            const Node& r = *n.children[2];
            v.range_span = span(r);
            v.range_low = expr(*r.children.at(0));
            v.range_high = expr(*r.children.at(1));
        }
        return v;
    }

    void item(const Node& n, ast::File& f) {
        if (n.is_type<g::param_item>() || n.is_type<g::const_item>() || n.is_type<g::var_item>()) {
            f.values.push_back(value_decl(n));
        } else if (n.is_type<g::module_item>()) {
            for (const auto& d : n.children) {
                ast::ModuleDecl m;
                m.span = span(*d->children.at(0));
                m.name = d->children.at(0)->string();
                for (std::size_t k = 1; k < d->children.size(); ++k) {
                    if (d->children[k]->is_type<g::param_list>()) {
                        m.has_params = true;
                        m.params = params(*d->children[k]);
                    } else if (d->children[k]->is_type<g::bound_clause>()) {
                        m.bound_to = d->children[k]->children.at(0)->string();
                    }
                }
                f.modules.push_back(std::move(m));
            }
        } else if (n.is_type<g::fn_item>()) {
            ast::FnDecl fn;
            fn.span = span(*n.children.at(0));
            fn.name = n.children.at(0)->string();
            fn.params = params(*n.children.at(1));
            const Node& b = *n.children.at(2);
            if (b.is_type<g::fn_expr_body>())
                fn.expr = expr(*b.children.at(0));
            else
                fn.body = block(b);
            f.functions.push_back(std::move(fn));
        } else if (n.is_type<g::curve_item>()) {
            f.curves.push_back(shape(n));
        } else if (n.is_type<g::surface_item>()) {
            f.surfaces.push_back(shape(n));
        } else if (n.is_type<g::texture_item>()) {
            f.textures.push_back(shape(n));
        } else if (n.is_type<g::env_item>()) {
            f.envs.push_back(shape(n));
        } else if (n.is_type<g::instance_item>()) {
            ast::InstanceDecl inst;
            inst.span = span(n);
            inst.name = n.children.at(0)->string();
            inst.body = std::make_unique<ast::File>();
            inst.body->source = file_;
            for (std::size_t k = 1; k < n.children.size(); ++k) {
                if (n.children[k]->is_type<g::param_list>())
                    inst.params = params(*n.children[k]);
                else
                    for (const auto& it : n.children[k]->children) item(*it, *inst.body);
            }
            f.instances.push_back(std::move(inst));
        } else if (n.is_type<g::setting_item>()) {
            ast::Setting s;
            s.span = span(n);
            s.key = spelled(ast::kSettings, *n.children.at(0));
            s.value = expr(*n.children.at(1));
            f.settings.push_back(std::move(s));
        } else if (n.is_type<g::axiom_item>()) {
            ast::Axiom a;
            a.span = span(n);
            a.successor = checked_list(*n.children.at(0), "axiom");
            f.axioms.push_back(std::move(a));
        } else if (n.is_type<g::symbol_set_item>()) {
            ast::SymbolSet s;
            s.span = span(n);
            s.ignore = trimmed(*n.children.at(0)) == "ignore";
            if (n.children.size() > 1) s.symbols = module_list(*n.children[1]);
            f.symbol_sets.push_back(std::move(s));
        } else if (n.is_type<g::rules_item>()) {
            rule_block(n, f, ast::RuleKind::Rules);
        } else if (n.is_type<g::decompose_item>()) {
            rule_block(n, f, ast::RuleKind::Decompose);
        } else if (n.is_type<g::interpret_item>()) {
            rule_block(n, f, ast::RuleKind::Interpret);
        } else if (n.is_type<g::hook_item>()) {
            ast::Hook h;
            h.span = span(*n.children.at(0));
            const std::string when = n.children.at(0)->children.at(0)->string();
            h.body = block(*n.children.at(1));
            if (auto kind = ast::lookup(ast::kHooks, when))
                h.when = *kind;
            else
                diags_.error(h.span,
                             fmt::format("unknown hook '{}': expected {}", when, ast::hook_list("", " or ")));
            f.hooks.push_back(std::move(h));
        } else if (n.is_type<g::graph_item>()) {
            graph_block(n, f);
        } else if (n.is_type<g::edits_item>()) {
            ast::EditsDecl ed;
            ed.span = span(n);
            const Node& t = *n.children.at(0)->children.at(0);
            ed.path = unescape(t.string_view());
            ed.path_span = span(t);
            f.edits_files.push_back(std::move(ed));
        } else if (n.is_type<g::import_item>()) {
            ast::Import im;
            im.span = span(n);
            const Node& t = *n.children.at(0)->children.at(0);
            if (t.is_type<g::string_lit>()) {
                im.is_path = true;
                im.target = unescape(t.string_view());
            } else {
                im.target = t.string();
            }
            if (n.children.size() > 1) {
                for (const auto& ov : n.children[1]->children.at(0)->children) {
                    im.overrides.emplace_back(ov->children.at(0)->string(), expr(*ov->children.at(1)));
                    im.override_spans.push_back(span(*ov->children.at(0)));
                }
            }
            f.imports.push_back(std::move(im));
        }
    }

  private:
    std::uint32_t file_;
    Diagnostics& diags_;
};

} // namespace

std::unique_ptr<ast::File> parse_file(const SourceManager& sources, std::uint32_t file_id,
                                      Diagnostics& diags) {
    const SourceFile& src = sources.file(file_id);
    const std::string& text = src.text();
    auto file = std::make_unique<ast::File>();
    file->source = file_id;
    Lowering lower(file_id, diags);
    habits::check_cpfg_lines(src, file_id, diags);
    // a UTF-8 byte-order mark at the start, which some editors write, is skipped
    std::size_t offset = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    std::size_t errors = 0;
    while (offset <= text.size()) {
        LineCol lc = src.line_col(static_cast<std::uint32_t>(offset));
        tao::pegtl::memory_input<> in(text.data() + offset, text.data() + text.size(), src.name(), offset,
                                      lc.line, lc.col);
        g::ParseState state;
        try {
            auto root = pt::parse<g::item_or_end, Node, selector, tao::pegtl::nothing, g::control>(in, state);
            if (!root) break;
            if (root->children.empty()) break; // end of file
            for (const auto& c : root->children) lower.item(*c, *file);
            std::size_t next = in.byte();
            if (next <= offset) break;
            offset = next;
        } catch (const g::GrammarError& e) {
            g::report(e, src, file_id, diags);
            if (++errors >= 20) break;
            offset = g::resync(text, e.byte, offset);
            if (offset >= text.size()) break;
        }
    }
    return file;
}

namespace {
// One expression (by `Rule`, with the blanks before it) and nothing after it, lowered; `whole` is
// the place named when there is none.
template <typename Rule>
ast::ExprPtr parse_one(tao::pegtl::memory_input<>& in, const SourceFile& src, std::uint32_t file_id,
                       Span whole, Diagnostics& diags) {
    g::ParseState state;
    try {
        auto root =
            pt::parse<tao::pegtl::seq<g::ws, Rule, g::ws>, Node, selector, tao::pegtl::nothing, g::control>(
                in, state);
        if (!root || root->children.empty()) {
            diags.error(whole, "expected an expression");
            return nullptr;
        }
        if (!in.empty()) { // an expression, then more: the error is where the more starts
            const auto at = static_cast<std::uint32_t>(in.byte());
            diags.error({file_id, at, std::max(at + 1, whole.end)},
                        fmt::format("expected the end of the value after the expression, found {}",
                                    g::describe_found(src.text(), at)));
            return nullptr;
        }
        Lowering lower(file_id, diags);
        return lower.expr(*root->children.at(0));
    } catch (const g::GrammarError& e) {
        g::report(e, src, file_id, diags);
        return nullptr;
    }
}
} // namespace

ast::ExprPtr parse_expression(const SourceManager& sources, std::uint32_t file_id, Diagnostics& diags) {
    const SourceFile& src = sources.file(file_id);
    tao::pegtl::memory_input<> in(src.text(), src.name());
    return parse_one<g::expr>(in, src, file_id, {file_id, 0, 1}, diags);
}

// (the edits files' values: an expression or a silhouette(...))
ast::ExprPtr parse_expression(const SourceManager& sources, std::uint32_t file_id, std::uint32_t begin,
                              std::uint32_t end, Diagnostics& diags) {
    const SourceFile& src = sources.file(file_id);
    const std::string& text = src.text();
    end = std::min<std::uint32_t>(end, static_cast<std::uint32_t>(text.size()));
    begin = std::min(begin, end);
    LineCol lc = src.line_col(begin);
    tao::pegtl::memory_input<> in(text.data() + begin, text.data() + end, src.name(), begin, lc.line, lc.col);
    return parse_one<tao::pegtl::sor<g::silhouette_value, g::expr>>(in, src, file_id, {file_id, begin, end},
                                                                    diags);
}

std::string ast::hook_list(std::string_view prefix, std::string_view last_separator) {
    std::string out;
    for (std::size_t k = 0; k < kHooks.size(); ++k) {
        if (k > 0) out += k + 1 == kHooks.size() ? last_separator : ", ";
        out += prefix;
        out += kHooks[k].spelling;
    }
    return out;
}

} // namespace plant
