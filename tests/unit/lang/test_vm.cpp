// The opcode table's stack effects against compiled code: every grammar in the repository
// compiles to code that never pops more than its operand stack holds and fits the VM's stack.
#include "helpers.hpp"
#include "plant/environments.hpp"
#include "plant/vm.hpp"

#include <catch2/catch.hpp>

#include <filesystem>

using namespace plant;
namespace fs = std::filesystem;

namespace {

// Every piece of code in a program, with a name for messages.
std::vector<std::pair<std::string, const Code*>> all_code(const Program& p) {
    std::vector<std::pair<std::string, const Code*>> out;
    out.emplace_back("axiom", &p.axiom);
    for (const Code& s : p.settings) out.emplace_back("setting", &s);
    for (const auto& f : p.functions) out.emplace_back("fn " + f.name, &f.code);
    for (std::size_t k = 0; k < p.hooks.size(); ++k)
        out.emplace_back(std::string("on ") + ast::spelling(static_cast<HookKind>(k)), &p.hooks[k]);
    auto rules = [&](const RuleSet& rs) {
        for (std::size_t i = 0; i < rs.productions.size(); ++i) {
            const Production& q = rs.productions[i];
            const std::string name = "rules " + rs.name + " #" + std::to_string(i);
            out.emplace_back(name + " condition", &q.condition);
            out.emplace_back(name + " weight", &q.weight);
            out.emplace_back(name + " body", &q.body);
            if (q.tmpl.valid) out.emplace_back(name + " template", &q.tmpl.values);
        }
    };
    rules(p.rules);
    for (const auto& g : p.groups) rules(g);
    rules(p.decompose);
    rules(p.interpret);
    return out;
}

} // namespace

TEST_CASE("the opcode table names every opcode once and knows which ones jump", "[vm]") {
    CHECK(std::string(op_info(Op::Const).name) == "Const");
    CHECK(std::string(op_info(Op::EnvCall).name) == "EnvCall");
    CHECK(is_jump(Op::Jump));
    CHECK(is_jump(Op::JumpIfNonZeroKeep));
    CHECK(!is_jump(Op::Halt));
    CHECK(op_info(Op::Halt).flow == OpFlow::End);
    CHECK(stack_effect(Instr{Op::VEq, 0, 0, 0}).pops == 6);
    CHECK(stack_effect(Instr{Op::Builtin, 2, 3, 0}).pushes == 3);
}

TEST_CASE("an environment call pushes exactly its method's result width", "[vm]") {
    // b holds the method and the result's width (program.hpp)
    const Instr number{Op::EnvCall, 3, env_call_operand(5, 1), 0};
    CHECK(env_call_method(number) == 5);
    CHECK(stack_effect(number).pops == 3);
    CHECK(stack_effect(number).pushes == 1);
    CHECK(stack_effect(Instr{Op::EnvCall, 3, env_call_operand(2, 3), 0}).pushes == 3);
    CHECK(stack_effect(Instr{Op::EnvCall, 3, env_call_operand(2, 0), 0}).pushes == 0);
    // a number-returning method called in a loop: counted as a vec3, the loop's depth would
    // seem to grow on every turn and the check would fail
    CompileOptions opts;
    opts.environments = runtime_environments();
    auto c = test::compile(
        "env box = ellipsoid(center: vec3(0, 0, 0), radii: vec3(1, 1, 1));\n"
        "fn total(n) {\n  let s = 0;\n"
        "  for k in 0..n { s += box.level(vec3(k, 0, 0)); if box.contains(vec3(0, k, 0)) { s += 1; } }\n"
        "  return s;\n}\naxiom: F(total(3));\n",
        opts);
    INFO(c->rendered());
    REQUIRE(c->program);
    for (const auto& [name, code] : all_code(*c->program)) {
        const StackCheck r = check_stack(*code);
        INFO(name << ": " << r.error << "\n" << disassemble(*code));
        CHECK(r.ok);
    }
}

TEST_CASE("check_stack finds code that pops more than the stack holds", "[vm]") {
    Code bad;
    bad.instrs = {Instr{Op::Const, 0, 0, 0}, Instr{Op::Add, 0, 0, 0}, Instr{Op::Halt, 1, 0, 0}};
    bad.consts = {1};
    StackCheck r = check_stack(bad);
    CHECK(!r.ok);
    CHECK(r.pc == 1);
    Code good = bad;
    good.instrs.insert(good.instrs.begin(), Instr{Op::Const, 0, 0, 0});
    r = check_stack(good);
    CHECK(r.ok);
    CHECK(r.max_depth == 2);
}

TEST_CASE("compiled code of every grammar keeps to the opcode table's stack effects", "[vm]") {
    std::size_t programs = 0, codes = 0;
    for (const char* dir : {"grammars", "stdlib", "tests/scripts"}) {
        for (const auto& entry : fs::recursive_directory_iterator(fs::path(PLANT_SOURCE_DIR) / dir)) {
            if (entry.path().extension() != ".plant") continue;
            SourceManager sources;
            Diagnostics diags;
            CompileOptions opts;
            opts.environments = runtime_environments();
            auto program = compile_file(sources, entry.path().string(), opts, diags);
            if (!program) continue; // grammars that test errors
            ++programs;
            for (const auto& [name, code] : all_code(*program)) {
                if (code->empty()) continue;
                ++codes;
                const StackCheck r = check_stack(*code);
                INFO(entry.path().string() << ": " << name << ": " << r.error << "\n" << disassemble(*code));
                CHECK(r.ok);
            }
        }
    }
    CHECK(programs > 100);
    CHECK(codes > 1000);
}
