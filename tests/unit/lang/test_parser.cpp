#include "grammar.hpp"
#include "plant/parser.hpp"

#include <catch2/catch.hpp>
#include <tao/pegtl/contrib/analyze.hpp>

using namespace plant;

namespace {
struct Parsed {
    SourceManager sm;
    Diagnostics diags;
    std::unique_ptr<ast::File> file;
    std::string errors() const { return render_all(diags, sm); }
};
std::unique_ptr<Parsed> parse(const std::string& text) {
    auto p = std::make_unique<Parsed>();
    auto id = p->sm.add("t.plant", text);
    p->file = parse_file(p->sm, id, p->diags);
    return p;
}
std::string first_error(const std::string& text) {
    auto p = parse(text);
    if (p->diags.all().empty()) return "";
    const auto& d = p->diags.all()[0];
    auto lc = p->sm.file(d.span.file).line_col(d.span.begin);
    return std::to_string(lc.line) + ":" + std::to_string(lc.col) + ": " + d.message;
}
} // namespace

TEST_CASE("the grammar has no rules that can loop without consuming input", "[parser]") {
    CHECK(tao::pegtl::analyze<grammar::file>(1) == 0);
    CHECK(tao::pegtl::analyze<grammar::item_or_end>(1) == 0);
}

TEST_CASE("top-level items land in the syntax tree", "[parser]") {
    auto p = parse(R"(
        # comment
        param r1 = 0.9; const d = 137.5; var count = 0;
        module A(l, w), B(p: vec3) bound ivy;
        fn f(x) = x * 2;
        fn g(x) { return x + 1; }
        derive 10; angle 22.5; step 2; width 0.5; seed 7;
        axiom: A(1, 10) F b;
        ignore: + - F;
        rules { A(l, w) -> F(l) A(l * r1, w); }
        rules pinch { F -> ; }
        decompose max_depth 3 { B(p) -> F; }
        interpret { A(l, w) -> F(l); }
        on start { use pinch; }
        on end { print("done", 1); stop; }
        import "lib.plant" with { size = 2 };
        env crown = ellipsoid(center: vec3(0, 5, 0), radii: vec3(3, 2, 3));
        surface leaf = polygon(vec3(0,0,0), vec3(1,0,0), vec3(0,1,0));
        curve c = bezier(0, 1, 0.5);
        instance Twig(n) { axiom: F; }
    )");
    REQUIRE(p->errors().empty());
    const ast::File& f = *p->file;
    CHECK(f.values.size() == 3);
    CHECK(f.modules.size() == 2);
    CHECK(f.modules[1].params[0].type == "vec3");
    CHECK(f.modules[1].bound_to == "ivy");
    CHECK(f.functions.size() == 2);
    CHECK(f.settings.size() == 5);
    CHECK(f.axioms[0].successor.size() == 3);
    CHECK(f.axioms[0].successor[2].raw);
    CHECK(f.symbol_sets[0].symbols.size() == 3);
    CHECK(f.rule_blocks.size() == 4);
    CHECK(f.rule_blocks[1].group == "pinch");
    CHECK(f.rule_blocks[2].kind == ast::RuleKind::Decompose);
    CHECK(f.hooks.size() == 2);
    CHECK(f.imports[0].overrides.size() == 1);
    CHECK(f.envs[0].keys == std::vector<std::string>{"center", "radii"});
    CHECK(f.surfaces.size() == 1);
    CHECK(f.curves.size() == 1);
    CHECK(f.instances[0].body->axioms.size() == 1);
}

TEST_CASE("context parts of a production are sorted by their operators", "[parser]") {
    auto p =
        parse("axiom: A; rules { B C < A > E [ F ] >> D : x > 1 -> G : 2; X << Y -> Z; * < P > * -> Q; }");
    REQUIRE(p->errors().empty());
    const auto& prods = p->file->rule_blocks[0].productions;
    REQUIRE(prods.size() == 3);
    CHECK(prods[0].left.size() == 2);
    CHECK(prods[0].strict.size() == 1);
    CHECK(prods[0].strict[0].name == "A");
    CHECK(prods[0].right_new.size() == 1);
    CHECK(prods[0].right.size() == 4);
    CHECK(prods[0].condition != nullptr);
    CHECK(prods[0].weight != nullptr);
    CHECK(prods[1].left_new.size() == 1);
    CHECK(prods[1].strict[0].name == "Y");
    CHECK(!prods[2].has_left);
    CHECK(!prods[2].has_right);
}

TEST_CASE("turtle symbols, @-names, queries and the color symbol with arguments are modules", "[parser]") {
    auto p = parse(R"(axiom: F(1)+(30)-&^\/|$!(2);(3)~leaf(1)%@O(1)?P(0,0,0)[G]f//;)");
    REQUIRE(p->errors().empty());
    std::vector<std::string> names;
    for (const auto& m : p->file->axioms[0].successor) names.push_back(m.name);
    CHECK(names == std::vector<std::string>{"F",     "+", "-",  "&",  "^", "\\", "/", "|", "$", "!", ";",
                                            "~leaf", "%", "@O", "?P", "[", "G",  "]", "f", "/", "/"});
}

TEST_CASE("precedence and associativity of expressions", "[parser]") {
    auto p = parse("param x = 1 - 2 - 3 * 4 < 5 == !0 && 1 || 0 ? 7 : 8; axiom: F;");
    REQUIRE(p->errors().empty());
    const ast::Expr& e = *p->file->values[0].value;
    REQUIRE(e.kind == ast::ExprKind::Ternary);
    const ast::Expr& orx = *e.args[0];
    CHECK(ast::spelling(orx.binary) == std::string("||"));
    CHECK(ast::spelling(orx.args[0]->binary) == std::string("&&"));
    const ast::Expr& eq = *orx.args[0]->args[0];
    CHECK(ast::spelling(eq.binary) == std::string("=="));
    CHECK(ast::spelling(eq.args[0]->binary) == std::string("<"));
    const ast::Expr& sub = *eq.args[0]->args[0];
    CHECK(ast::spelling(sub.binary) == std::string("-"));
    CHECK(ast::spelling(sub.args[0]->binary) == std::string("-")); // (1 - 2) - ...
    CHECK(ast::spelling(sub.args[1]->binary) == std::string("*"));
}

TEST_CASE("parse errors name what was expected, where the construct began and what was found", "[parser]") {
    // a ';' left off at a line's end is shown there (after the last word, before a # comment),
    // naming what began the next line; one missing before more text on the same line is not
    CHECK(first_error("axiom: A;\nrules {\n  A -> B C\n}\n") ==
          "3:11: expected ';' after production (started at 3:3), found '}' on the next line");
    CHECK(first_error("derive 2   # steps\n\naxiom: A;\n") ==
          "1:9: expected ';' (statement started at 1:1), found 'axiom' on the next line");
    CHECK(first_error("axiom: A\nrules { A -> B; }\n") ==
          "1:9: expected ';' (statement started at 1:1), found 'rules' on the next line");
    CHECK(first_error("axiom: A;\nrules {\n  A -> F [ + A ]\n     [ - A ] ) ;\n}\n") ==
          "4:14: expected ';' after production (started at 3:3), found ')'");
    CHECK(first_error("axiom: A(1);\nrules {\n  A(x) : x < 3 -> A(x+1)\n  A(x) : x >= 3 -> B;\n}\n") ==
          "3:25: expected ';' after production (started at 3:3), found 'A' on the next line");
    CHECK(first_error("axiom: A(1)\n") == "1:12: expected ';' (statement started at 1:1), found end of file");
    CHECK(first_error("param x = (1 + 2;\n") == "1:17: expected ')' to close '(' at 1:11, found ';'");
    CHECK(first_error("param x = 1 +;\n") == "1:14: expected an expression after the operator, found ';'");
    CHECK(first_error("rules { A B }\n") ==
          "1:13: expected '->' or '{' after the predecessor of the production (started at 1:9), found '}'");
    CHECK(first_error("axiom: F; /* never closed\n") ==
          "2:1: unterminated comment: expected '*/' to close '/*' at 1:11, found end of file");
    CHECK(first_error("import \"lib.plant;\n") ==
          "1:19: unterminated string: expected '\"' to close '\"' at 1:8, found end of line");
    CHECK(first_error("banana;\n") == "1:1: expected a top-level item (param, const, var, module, fn, axiom, "
                                      "rules, derive, ...), found 'banana'");
}

TEST_CASE("the parser recovers at the next item and reports later errors too", "[parser]") {
    auto p = parse("param a = ;\nparam b = 2;\nmodule A(x;\naxiom: A(1);\nrules { A(x) -> }\n");
    REQUIRE(p->diags.all().size() == 3);
    CHECK(p->file->values.size() == 1); // b survived
    CHECK(p->file->axioms.size() == 1);
}

TEST_CASE("deep nesting is an error, not a stack overflow", "[parser]") {
    std::string deep =
        "param x = " + std::string(10000, '(') + "1" + std::string(10000, ')') + ";\naxiom: F;";
    CHECK(first_error(deep) == "1:211: nesting deeper than 200 levels, found '('");
    std::string brackets = "axiom: " + std::string(10000, '[') + std::string(10000, ']') + ";";
    auto p = parse(brackets);
    CHECK(p->diags.all().empty());
    CHECK(p->file->axioms[0].successor.size() == 20000);
}

TEST_CASE("every recursive construct counts toward the nesting limit", "[parser][limits]") {
    auto repeat = [](const std::string& s, int n) {
        std::string out;
        for (int k = 0; k < n; ++k) out += s;
        return out;
    };
    const int n = 20000; // deep enough to overflow the stack if a level went uncounted
    const std::string deep[] = {
        "x ? 1 : " + repeat("x ? 1 : ", n) + "1",       // conditional chain (else)
        repeat("x ? ", n) + "1" + repeat(" : 1", n),    // conditional chain (then)
        repeat("-", n) + "1",                           // unary minus
        repeat("!", n) + "x",                           // negation
        repeat("(", n) + "1" + repeat(")", n),          // parentheses
        repeat("f(", n) + "1" + repeat(")", n),         // calls
        repeat("x.f(", n) + "1" + repeat(")", n),       // method calls
        repeat("-(x ? ", n) + "1" + repeat(" : 1)", n), // a mixture
    };
    for (const auto& e : deep) {
        auto p = parse("param x = 1;\naxiom: F(" + e + ");");
        REQUIRE(!p->diags.all().empty());
        CHECK(p->diags.all()[0].message.rfind("nesting deeper than 200 levels", 0) == 0);
    }
    std::string hook = "on start { " + repeat("if (1) { ", n) + repeat("}", n) + " }\naxiom: F;";
    CHECK(first_error(hook).find("nesting deeper than 200 levels") != std::string::npos);
    std::string chain = "on start { if (1) {} " + repeat("else if (1) {} ", n) + "}\naxiom: F;";
    CHECK(first_error(chain).find("nesting deeper than 200 levels") != std::string::npos);
}

TEST_CASE("binary garbage gives a positioned error", "[parser]") {
    std::string junk("\x7f\x45\x4c\x46\x02\x01\x00\x00\xff\xfe", 10);
    auto p = parse(junk);
    REQUIRE(!p->diags.all().empty());
    CHECK(p->diags.all()[0].message.find("found byte 0x7f") != std::string::npos);
}
