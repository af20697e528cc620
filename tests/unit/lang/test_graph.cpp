// Decomposition graphs (lang/include/plant/graph.hpp; docs/language.md, decomposition graphs):
// each inheritance rule of Boudon et al. 2003, sections 2.1 and 2.2, on small graphs against
// hand-computed values, and the Fig. 10 sequence with range and single-position matching.
#include "helpers.hpp"
#include "plant/graph.hpp"

#include <catch2/catch.hpp>

#include <fmt/format.h>

#include <cmath>
#include <initializer_list>

namespace plant {

namespace {

// Three levels of three branches (at 0.25, 0.5 and 0.75) below the root: 40 nodes.
const char* kTree = R"(
graph { length = 10; bend = linear(0, 1); }
module A(n: node, k), R(v, w);
derive 4;
axiom: A(root(), 0);
rules {
  A(n, k) : k < 3 -> R(n.length, n.bend(0.5)) [ A(child(n, 0.25), k + 1) ] [ A(child(n, 0.5), k + 1) ]
                     [ A(child(n, 0.75), k + 1) ];
}
)";

// Fig. 10: `density` laterals on one axis at i / (density + 1), each with its bend curve.
const char* kFig10 = R"(
param density = 3;
graph %s { bend = linear(0, 0); }
module Axis(n: node), Lat(n: node);
derive 2;
axiom: Axis(root());
rules {
  Axis(n) { for i in 1..density + 1 { nproduce F [ Lat(child(n, i / (density + 1))) ]; } produce F; }
}
)";

struct Run {
    std::unique_ptr<test::Compiled> c;
    std::unique_ptr<Derivation> d;
    const DecompositionGraph& g() const { return *d->run_state().graph(); }
    int at(const std::string& path) const {
        for (std::size_t k = 0; k < g().size(); ++k)
            if (g().path(static_cast<int>(k)) == path) return static_cast<int>(k);
        FAIL("no node " << path);
        return -1;
    }
    const NodeValue& value(const std::string& path, const char* param) const {
        return g().value(at(path), g().decl().find(param));
    }
    double number(const std::string& path) const { return value(path, "length").number; }
};

Run derive(const std::string& grammar, const std::string& edits, CompileOptions co = {},
           DeriveOptions opt = {}) {
    Run r;
    r.c = test::compile(grammar, std::move(co));
    INFO(r.c->rendered());
    REQUIRE(r.c->program);
    const std::uint32_t id = r.c->sources.add("test.edits", edits);
    opt.edits = parse_edits(*r.c->program, r.c->sources, id, r.c->diags);
    INFO(r.c->rendered());
    REQUIRE(opt.edits);
    r.d = std::make_unique<Derivation>(*r.c->program, opt);
    r.d->run();
    return r;
}

std::string fig10(const char* match) {
    char buf[1024];
    std::snprintf(buf, sizeof buf, kFig10, match);
    return buf;
}

} // namespace

TEST_CASE("graph: child() makes nodes that are committed each step with paths and handles") {
    Run r = derive(kTree, "");
    CHECK(r.g().size() == 40);
    CHECK(r.g().node(r.at("/0.5/0.25/0.75")).depth == 3);
    CHECK(r.g().node(r.at("/0.5/0.25")).position == 0.25);
    // the handle is a 52-bit hash of the path, the same in every derivation
    CHECK(r.g().node(r.at("/0.5")).handle ==
          DecompositionGraph::child_handle(DecompositionGraph::kRoot, 0.5, 0));
    CHECK(r.g().node(r.at("/0.5")).handle < (std::uint64_t{1} << 52));
    // every node reads the root's defaults when there are no edits
    CHECK(r.number("/0.75/0.75/0.75") == 10);
    CHECK(r.value("/0.75/0.75/0.75", "length").status == ValueStatus::Inherited);
    CHECK(r.value("/0.75/0.75/0.75", "length").from == 0);
}

TEST_CASE("graph: explicit and inherited from the parent") {
    Run r = derive(kTree, "/0.5 length = 4\n");
    CHECK(r.number("/0.5") == 4);
    CHECK(r.value("/0.5", "length").status == ValueStatus::Explicit);
    CHECK(r.value("/0.5", "length").from == r.at("/0.5"));
    CHECK(r.number("/0.5/0.25") == 4); // inherited from the parent
    CHECK(r.value("/0.5/0.25", "length").from == r.at("/0.5"));
    CHECK(r.number("/0.5/0.25/0.75") == 4); // and further down
    CHECK(r.number("/0.25") == 10);         // the siblings keep the root's
    // the productions read the resolved values: R(length, bend(0.5)) of /0.5 and of /0.5/0.25
    CHECK(test::derive(kTree).find("R(10,0.5)") != std::string::npos);
}

TEST_CASE("graph: a private parent is skipped, the value comes from the public grandparent") {
    Run r = derive(kTree, "/0.5 length = 4\n/0.5/0.5 length = 2\n/0.5/0.5 length private\n");
    CHECK(r.number("/0.5/0.5") == 2); // the private node keeps its own value
    CHECK(r.value("/0.5/0.5", "length").is_private);
    CHECK(r.number("/0.5/0.5/0.25") == 4); // its children inherit past it, from /0.5
    CHECK(r.value("/0.5/0.5/0.25", "length").from == r.at("/0.5"));
    // private on /0.5 too: the nearest public ancestor is the root
    Run r2 = derive(kTree, "/0.5 length = 4\n/0.5 length private\n/0.5/0.5 length private\n");
    CHECK(r2.number("/0.5/0.5/0.25") == 10);
    CHECK(r2.value("/0.5/0.5/0.25", "length").from == 0);
    // public again: the children see it
    Run r3 = derive(kTree, "/0.5 length = 4\n/0.5 length private\n/0.5 length public\n");
    CHECK(r3.number("/0.5/0.75") == 4);
}

TEST_CASE("graph: relative values, an offset and a fraction of the inherited value") {
    Run r =
        derive(kTree, "/0.25 length += 1.5\n/0.75 length *= 0.5\n/0.5 length *= 0.5\n/0.5/0.5 length += 1\n");
    CHECK(r.number("/0.25") == 11.5);
    CHECK(r.value("/0.25", "length").status == ValueStatus::Offset);
    CHECK(r.number("/0.75") == 5);
    CHECK(r.value("/0.75", "length").status == ValueStatus::Fraction);
    CHECK(r.number("/0.5/0.5") == 6);      // (10 * 0.5) + 1: relative values resolve recursively
    CHECK(r.number("/0.5/0.5/0.25") == 6); // and are inherited as resolved
    CHECK(r.value("/0.5/0.5", "length").from == r.at("/0.5"));
}

TEST_CASE("graph: relative curves are the sum or product of the inherited and local curves") {
    // root: bend(t) = t. /0.25: t + linear(1, 1, 3)(t); /0.75: t * linear(2, 0)(t) = 2t(1 - t)
    Run r = derive(
        kTree, "/0.25 bend += linear(1, 1, 3)\n/0.75 bend *= linear(2, 0)\n/0.5 bend = bezier(0, 0, 1)\n");
    const NodeValue& sum = r.value("/0.25", "bend");
    const double ts[] = {0, 0.25, 0.5, 0.75, 1};
    const double sums[] = {1, 1.25, 1.5, 2.75, 4};
    for (int k = 0; k < 5; ++k) CHECK(sum.at(ts[k]) == Approx(sums[k]));
    const NodeValue& product = r.value("/0.75", "bend");
    const double products[] = {0, 0.375, 0.5, 0.375, 0};
    for (int k = 0; k < 5; ++k) CHECK(product.at(ts[k]) == Approx(products[k]));
    // inherited by the children as resolved
    CHECK(r.value("/0.75/0.5", "bend").at(0.25) == Approx(0.375));
    // explicit curve: Bezier with control values 0, 0, 1 is t^2
    CHECK(r.value("/0.5", "bend").at(0.5) == Approx(0.25));
    CHECK(r.value("/0.5/0.25", "bend").at(0.5) == Approx(0.25));
    // a number for a curve is the constant curve: `*= 0.5` halves it
    Run r2 = derive(kTree, "/0.25 bend *= 0.5\n");
    CHECK(r2.value("/0.25", "bend").at(0.8) == Approx(0.4));
}

TEST_CASE("graph: a shared value gives every node of one level one explicit value") {
    Run r = derive(kTree, "share 2 length = 7\n/0.5/0.25 length = 3\n");
    CHECK(r.number("/0.25/0.25") == 7);
    CHECK(r.number("/0.75/0.5") == 7);
    CHECK(r.value("/0.75/0.5", "length").status == ValueStatus::Shared);
    CHECK(r.number("/0.25") == 10);         // other levels are not touched
    CHECK(r.number("/0.75/0.5/0.25") == 7); // the level below inherits the share
    CHECK(r.number("/0.5/0.25") == 3);      // a node edit overrides the share on its node
    CHECK(r.value("/0.5/0.25", "length").status == ValueStatus::Explicit);
}

TEST_CASE("graph: reverting to inherited is an edit like any other") {
    Run r = derive(kTree, "/0.25 length = 3\n/0.25 length inherit\n");
    CHECK(r.number("/0.25") == 10);
    CHECK(r.value("/0.25", "length").status == ValueStatus::Inherited);
    Run r2 = derive(kTree, "share 1 length = 7\n/0.5 length inherit\n");
    CHECK(r2.number("/0.5") == 10); // out of the share, back to the root's
    CHECK(r2.number("/0.25") == 7);
}

TEST_CASE("graph: Fig. 10, range matching keeps the edit through density changes") {
    const std::string edit = "/0.25[0..0.375] bend = linear(0, 0.4, 0.8)\n";
    CompileOptions four;
    four.defines.emplace_back("density", "4");
    Run a = derive(fig10(""), edit);
    CHECK(a.value("/0.25", "bend").at(1) == Approx(0.8));
    CHECK(a.value("/0.5", "bend").at(1) == 0);
    Run b = derive(fig10(""), edit, four);
    CHECK(b.value("/0.2", "bend").at(1) == Approx(0.8)); // the branch at 0.2 carries it
    for (const char* p : {"/0.4", "/0.6", "/0.8"}) CHECK(b.value(p, "bend").at(1) == 0);
    Run c = derive(fig10(""), edit);
    CHECK(c.value("/0.25", "bend").at(1) == Approx(0.8)); // density 3 again: curved again
}

TEST_CASE("graph: Fig. 10, single-position matching loses the edit at density four") {
    const std::string edit = "/0.25[0..0.375] bend = linear(0, 0.4, 0.8)\n";
    CompileOptions four;
    four.defines.emplace_back("density", "4");
    Run a = derive(fig10("match single"), edit);
    CHECK(a.value("/0.25", "bend").at(1) == Approx(0.8));
    Run b = derive(fig10("match single"), edit, four);
    for (const char* p : {"/0.2", "/0.4", "/0.6", "/0.8"}) CHECK(b.value(p, "bend").at(1) == 0);
    CHECK(b.g().matches()[0] == -1); // dormant
}

TEST_CASE("graph: nodes of the current pass cannot be read and copies of a derivation own their graph") {
    auto c = test::compile(R"(
graph { length = 10; }
module A(n: node), R(v);
derive 1;
axiom: A(root());
rules { A(n) -> R(child(n, 0.5).length); }
)");
    REQUIRE(c->program);
    Derivation d(*c->program, {});
    try {
        d.run();
        FAIL("expected a runtime error");
    } catch (const RuntimeError& e) {
        CHECK(e.message.find("read it from the next step") != std::string::npos);
    }
    auto t = test::compile(kTree);
    REQUIRE(t->program);
    Derivation first(*t->program, {});
    first.start();
    first.step();
    Derivation copy = first;
    first.step();
    CHECK(first.run_state().graph()->size() == 13);
    CHECK(copy.run_state().graph()->size() == 4);
    copy.step();
    CHECK(copy.run_state().graph()->size() == 13);
}

TEST_CASE("graph: compile errors name the parameter and suggest one") {
    auto c = test::compile(R"(
graph { length = 10; bend = linear(0, 1); }
module A(n: node);
axiom: A(root());
rules { A(n) -> F(n.lenght) F(n.bend) F(n.length(1)); }
)");
    CHECK(!c->program);
    const std::string msg = c->rendered();
    CHECK(msg.find("5:19: error: the graph has no parameter 'lenght'; did you mean 'length'?") !=
          std::string::npos);
    CHECK(msg.find("'bend' is a curve: read it at a t from 0 to 1") != std::string::npos);
    CHECK(msg.find("'length' is a number: read it as n.length") != std::string::npos);
    auto s = test::compile("graph { crown = silhouette(); }\naxiom: F;\n");
    CHECK(s->rendered().find("a silhouette needs 'axis:'") != std::string::npos);
    auto n = test::compile("module A(n: node);\naxiom: A(3);\n");
    CHECK(n->rendered().find("parameter 'n' of 'A' is a node, found a number") != std::string::npos);
    auto g = test::compile("axiom: F(depth(root()));\n");
    CHECK(g->rendered().find("'root' needs a decomposition graph") != std::string::npos);
}

// ---- silhouettes (Boudon et al. 2003, sections 2.4 and 3, Fig. 8) ---------------------------

namespace {

// A small bonsai-like graph: the root's crown, a trunk along its axis bearing six branches
// (phyllotaxis 137.5 degrees, rising with height), each bearing three twigs along its own placed
// axis, all placed by child(n, pos, index, base, dir).
const char* kCrowns = R"(
graph {
  crown = silhouette(axis: bezier(vec3(0, 0, 0), vec3(0.1, 4, 0), vec3(-0.1, 7, 0), vec3(0, 10, 0)),
                     top: vec3(0, 10, 0), bottom: vec3(0, 1, 0), px: vec3(4, 4, 0), pz: vec3(0, 5, 3.5),
                     nx: vec3(-3, 4.5, 0), nz: vec3(0, 3.5, -3), top_shape: 1.5, bottom_shape: 2.5,
                     tip: vec3(0, 10, 0));
  rise = 70;
}
module Axis(n: node, o);
derive 3;
axiom: Axis(root(), 0);
fn dir(h: vec3, i, a) {
  let side = normalize(cross(h, vec3(cos(rad(137.5 * i)), 0, sin(rad(137.5 * i)))));
  return normalize(h * cos(rad(a)) + side * sin(rad(a)));
}
rules {
  Axis(n, o) : o < 2 {
    let kids = o == 0 ? 6 : 3;
    for i in 1..kids + 1 {
      let t = (o == 0 ? 0.2 : 0.1) + 0.7 * i / (kids + 1);
      let p = n.crown.axis(t);
      nproduce [ Axis(child(n, t, 0, p, dir(n.crown.heading(t), i, n.rise)), o + 1) ];
    }
    produce F(n.crown.scale());
  }
}
)";

} // namespace

TEST_CASE("graph: every placed child's T lies on its parent's envelope, every branch point inside it") {
    Run r = derive(kCrowns, "");
    const int crown = r.g().decl().find("crown");
    REQUIRE(r.g().size() == 1 + 6 + 18);
    int checked = 0;
    for (std::size_t k = 1; k < r.g().size(); ++k) {
        const GraphNode& n = r.g().node(static_cast<int>(k));
        const PlacedSilhouette child = r.g().value(static_cast<int>(k), crown).placed();
        const PlacedSilhouette parent = r.g().value(n.parent, crown).placed();
        INFO(r.g().path(static_cast<int>(k)));
        REQUIRE(n.placed);
        // T on the parent's envelope (Fig. 8): the placement solves for it, so only rounding
        CHECK(std::fabs(parent.level(child.tip()) - 1) < 1e-9);
        // the branch point inside the parent's envelope: it lies on the parent's placed axis,
        // which the envelope holds; 1e-9 absorbs rounding only
        CHECK(parent.level(child.base()) <= 1 + 1e-9);
        CHECK(glm::length(child.base() - n.base) < 1e-9);
        // BT along the branch direction
        CHECK(glm::dot(glm::normalize(child.tip() - child.base()), glm::normalize(n.dir)) > 1 - 1e-9);
        ++checked;
    }
    CHECK(checked == 24);
    // a twig is smaller than its branch, a branch than the plant
    CHECK(r.value("/0.3", "crown").placement.scale < 1);
    CHECK(r.value("/0.3/0.275", "crown").placement.scale < r.value("/0.3", "crown").placement.scale);
}

TEST_CASE("graph: silhouettes are explicit or inherited in edits, never relative") {
    const std::string sil =
        "silhouette(axis: polyline(vec3(0, 0, 0), vec3(0, 2, 0)), top: vec3(0, 2, 0), "
        "bottom: vec3(0, 0, 0), px: vec3(1, 1, 0), pz: vec3(0, 1, 1), nx: vec3(-1, 1, 0), "
        "nz: vec3(0, 1, -1), tip: vec3(0, 2, 0))";
    Run r = derive(kCrowns, "/0.3[0.2..0.4] crown = " + sil + "\n/0.4 rise = 20\n");
    const NodeValue& own = r.value("/0.3", "crown");
    CHECK(own.status == ValueStatus::Explicit);
    CHECK(own.silhouette->envelope.top.y == 2);
    // its twigs inherit the edited silhouette, placed inside it
    const NodeValue& twig = r.value("/0.3/0.275", "crown");
    CHECK(twig.status == ValueStatus::Inherited);
    CHECK(twig.silhouette == own.silhouette);
    CHECK(std::fabs(own.placed().level(twig.placed().tip()) - 1) < 1e-9);
    // a sibling keeps the root's
    CHECK(r.value("/0.6", "crown").silhouette == r.value("/", "crown").silhouette);
    auto c = test::compile(kCrowns);
    REQUIRE(c->program);
    const std::uint32_t id =
        c->sources.add("bad.edits", "/0.3 crown *= 2\n/0.5 crown = 3\n/0.6 rise = " + sil + "\n");
    CHECK(!parse_edits(*c->program, c->sources, id, c->diags));
    const std::string msg = c->rendered();
    CHECK(msg.find("bad.edits:1:12: error: a silhouette can be explicit or inherited, not relative") !=
          std::string::npos);
    CHECK(msg.find("bad.edits:2:14: error: 'crown' is a silhouette: give silhouette(") != std::string::npos);
    CHECK(msg.find("bad.edits:3:13: error: 'rise' is a number, found a silhouette") != std::string::npos);
}

TEST_CASE("graph: silhouette errors, at compile time and at the child() call") {
    auto c = test::compile(R"(
graph { crown = silhouette(axis: polyline(vec3(0, 0, 0), vec3(0, 1, 0)), top: vec3(0, 1, 0), bottom: vec3(0, 0, 0),
                           px: vec3(1, 0.5, 0), pz: vec3(0, 0.5, 1), nx: vec3(-1, 0.5, 0), nz: vec3(0, 0.5, -1)); }
module A(n: node);
axiom: A(root());
rules { A(n) -> F(n.crown.levle(vec3(0, 0, 0))) F(n.crown) F(n.crown.reach(vec3(0, 0, 0))); }
)");
    CHECK(!c->program);
    const std::string msg = c->rendered();
    CHECK(msg.find("6:19: error: a silhouette has no method 'levle'; did you mean 'level'?") !=
          std::string::npos);
    CHECK(msg.find("'crown' is a silhouette: call one of its methods") != std::string::npos);
    CHECK(msg.find("'crown.reach' takes 2 arguments, given 1") != std::string::npos);
    auto k =
        test::compile("graph { crown = silhouette(axis: polyline(vec3(0, 0, 0), vec3(0, 1, 0)), topp: 1); }\n"
                      "axiom: F;\n");
    CHECK(k->rendered().find("a silhouette has no argument 'topp'; did you mean 'top'?") !=
          std::string::npos);
    // a branch point outside the parent's envelope: a runtime error at the call
    auto out = test::compile(R"(
graph { crown = silhouette(axis: polyline(vec3(0, 0, 0), vec3(0, 1, 0)), top: vec3(0, 1, 0), bottom: vec3(0, 0, 0),
                           px: vec3(1, 0.5, 0), pz: vec3(0, 0.5, 1), nx: vec3(-1, 0.5, 0), nz: vec3(0, 0.5, -1)); }
module A(n: node);
derive 1;
axiom: A(root());
rules { A(n) -> A(child(n, 0.5, 0, vec3(5, 0.5, 0), vec3(1, 0, 0))); }
)");
    REQUIRE(out->program);
    Derivation d(*out->program, {});
    try {
        d.run();
        FAIL("expected a runtime error");
    } catch (const RuntimeError& e) {
        CHECK(e.message.find("the branching point lies outside the parent's envelope") != std::string::npos);
        CHECK(e.span.begin > 0);
    }
}

TEST_CASE("graph: one child named at positions a rounding error apart is the same node in any order") {
    // whichever call comes first (string order here, thread timing in a parallel step), the node
    // keeps the lower position, so its path and the values read through it never depend on timing
    const char* grammar = R"(
graph { length = 10; }
module A(n: node, p), B(n: node);
derive 1;
axiom: %s;
rules { A(n, p) -> B(child(n, p)); }
)";
    for (const char* axiom :
         {"A(root(), 0.5 + 1e-12) A(root(), 0.5)", "A(root(), 0.5) A(root(), 0.5 + 1e-12)"}) {
        char buf[512];
        std::snprintf(buf, sizeof buf, grammar, axiom);
        Run r = derive(buf, "");
        INFO(axiom);
        CHECK(r.g().size() == 2);
        CHECK(r.g().node(1).position == 0.5);
        CHECK(r.g().path(1) == "/0.5");
    }
}

TEST_CASE("graph: a relative edit that overflows stops at the edit, not at a module parameter") {
    Run r;
    r.c = test::compile(kTree);
    REQUIRE(r.c->program);
    const std::uint32_t id =
        r.c->sources.add("big.edits", "/0.5 length *= 1e200\n/0.5/0.5 length *= 1e200\n");
    DeriveOptions opt;
    opt.edits = parse_edits(*r.c->program, r.c->sources, id, r.c->diags);
    REQUIRE(opt.edits);
    Derivation d(*r.c->program, opt);
    try {
        d.run();
        FAIL("expected an error");
    } catch (const RuntimeError& e) {
        CHECK(e.message.find("not a finite number") != std::string::npos);
        CHECK(e.span.file == id);
        CHECK(r.c->sources.file(id).line_col(e.span.begin).line == 2);
    }
}

TEST_CASE("graph: the range written for a node always holds the node's own position") {
    // two siblings 2e-10 apart: the midpoint rounds past the upper one at 9 decimals, so the
    // written range is widened instead (the REPL's :edit writes this range into the edits line)
    Run r = derive(R"(
graph { length = 10; }
module A(n: node, p), B(n: node);
derive 1;
axiom: A(root(), 0.1234567894) A(root(), 0.1234567896);
rules { A(n, p) -> B(child(n, p)); }
)",
                   "");
    REQUIRE(r.g().size() == 3);
    for (int k = 1; k <= 2; ++k) {
        const std::string path = r.g().path(k, true);
        INFO(path);
        const double lo = std::stod(path.substr(path.find('[') + 1));
        const double hi = std::stod(path.substr(path.find("..") + 2));
        CHECK(lo <= r.g().node(k).position);
        CHECK(r.g().node(k).position <= hi);
    }
}

} // namespace plant

namespace plant {

namespace {
// Laterals of the root at the given positions, made in one step.
std::string laterals(std::initializer_list<double> positions) {
    std::string axiom;
    for (double p : positions) axiom += fmt::format(" L(root(), {})", p);
    return "graph { bend = linear(0, 0); }\nmodule L(n: node, p), Lat(n: node);\nderive 1;\naxiom:" + axiom +
           ";\nrules { L(n, p) -> Lat(child(n, p)); }\n";
}
} // namespace

TEST_CASE("graph: range matching keeps an edit on its branch while that branch is still there") {
    const std::string edit = "/0.25[0..0.375] bend = linear(0, 0.4, 0.8)\n";
    // the range's centre (0.1875) is nearer 0.15, but the edited branch at 0.25 is still there
    Run a = derive(laterals({0.15, 0.25}), edit);
    CHECK(a.value("/0.25", "bend").at(1) == Approx(0.8));
    CHECK(a.value("/0.15", "bend").at(1) == 0);
    // gone: the branch in the range nearest the recorded position (0.35, not 0.1 by the centre)
    Run b = derive(laterals({0.1, 0.35}), edit);
    CHECK(b.value("/0.35", "bend").at(1) == Approx(0.8));
    CHECK(b.value("/0.1", "bend").at(1) == 0);
    // equally near: the lower
    Run c = derive(laterals({0.2, 0.3}), edit);
    CHECK(c.value("/0.2", "bend").at(1) == Approx(0.8));
    CHECK(c.value("/0.3", "bend").at(1) == 0);
    // out of the range: dormant
    Run d = derive(laterals({0.4, 0.6}), edit);
    CHECK(d.g().matches()[0] == -1);
}

TEST_CASE("graph: matching many edits to many siblings is a binary search per path component") {
    // 5000 laterals at k / 8192 (exact in binary), one edit each with its range: 5000 x 5000
    // sibling comparisons if each component scanned the siblings, about 5000 x 13 by bisection
    constexpr int kCount = 5000;
    const std::string grammar = R"(
graph { length = 0; }
module Axis(n: node), Lat(n: node);
derive 2;
axiom: Axis(root());
rules { Axis(n) { for k in 1..5001 { nproduce [ Lat(child(n, k / 8192)) ]; } } }
)";
    std::string edits;
    for (int k = 1; k <= kCount; ++k)
        edits += fmt::format("/{:.14f}[{:.14f}..{:.14f}] length = {}\n", k / 8192.0, (k - 0.5) / 8192.0,
                             (k + 0.5) / 8192.0, k);
    Run r = derive(grammar, edits);
    REQUIRE(r.g().size() == kCount + 1);
    int wrong = 0;
    for (int k = 1; k <= kCount; ++k) {
        const int m = r.g().matches()[static_cast<std::size_t>(k - 1)];
        if (m < 0 || r.g().node(m).position != k / 8192.0 || r.g().value(m, 0).number != k) ++wrong;
    }
    CHECK(wrong == 0);
    CHECK(r.g().match_comparisons() < std::size_t{kCount} * 20);
    // and the ranges `plant graph` and :edit write, from each node's neighbours
    CHECK(r.g().path(r.g().matches()[0], true) == "/0.0001220703125[0..0.000183106]");
    CHECK(r.g().path(r.g().matches()[2499], true) == "/0.30517578125[0.305114746..0.305236817]");
    CHECK(r.g().path(r.g().matches()[4999], true) == "/0.6103515625[0.610290527..1]");
}

TEST_CASE("graph: a commit resolves its new nodes and the subtrees of the nodes whose edits moved") {
    // three levels of three (kTree): 1 + 3 + 9 + 27 nodes made over three commits, two
    // parameters; each commit resolves only its new nodes, so 40 x 2 values in all
    Run tree = derive(kTree, "/0.5 length = 4\n");
    CHECK(tree.g().resolved_values() == 40 * 2);
    CHECK(tree.number("/0.5/0.25/0.75") == 4);
    // an edit that moves: /0.4 (with its child /0.4/0.5) holds it until /0.3, nearer its recorded
    // position 0.25, appears at the third step; then /0.4's subtree inherits again
    const std::string moving = R"(
graph { length = 10; }
module A(n: node), B(n: node, k), C(n: node, k);
axiom: A(root());
rules {
  A(n) -> [ B(child(n, 0.4), 0) ] C(n, 0);
  B(n, k) : k < 1 -> B(child(n, 0.5), k + 1);
  C(n, k) : k < 1 -> C(n, k + 1);
  C(n, k) : k >= 1 -> [ B(child(n, 0.3), 1) ];
}
)";
    const std::string edit = "/0.25[0..0.5] length = 3\n";
    Run two = derive("derive 2;\n" + moving, edit);
    CHECK(two.number("/0.4") == 3);
    CHECK(two.number("/0.4/0.5") == 3);
    Run three = derive("derive 3;\n" + moving, edit);
    CHECK(three.number("/0.3") == 3);
    CHECK(three.number("/0.4") == 10);
    CHECK(three.number("/0.4/0.5") == 10);
    CHECK(three.value("/0.4/0.5", "length").from == 0);
    // the root, /0.4, /0.4/0.5, then /0.3 new and /0.4 with its child again: 6 node resolutions
    CHECK(three.g().resolved_values() == 6);
}

} // namespace plant
