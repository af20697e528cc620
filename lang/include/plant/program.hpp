// The compiled program: what the derivation engine runs. Names are resolved to slots and symbol
// ids once, here; nothing is looked up by name while rewriting.
#pragma once

#include "plant/ast.hpp"
#include "plant/diagnostics.hpp"
#include "plant/graph.hpp"
#include "plant/module_string.hpp"
#include "plant/turtle_symbols.hpp"

#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

namespace plant {

// Node: a node of the decomposition graph, one number (its handle; graph.hpp).
enum class ValueType : std::uint8_t { Number, Bool, Vec3, String, Void, Node };
inline int value_width(ValueType t) {
    return t == ValueType::Vec3 ? 3 : (t == ValueType::Void ? 0 : 1);
}
const char* value_type_name(ValueType t);

struct SymbolInfo {
    std::string name;
    bool declared = false;               // by `module`, or a built-in turtle or query symbol
    bool turtle = false;                 // a built-in turtle symbol (plant/turtle_symbols.hpp)
    bool query = false;                  // ?P ?H ?U ?L ?E
    TurtleOp turtle_op = TurtleOp::None; // what the turtle does for it (also for "~name")
    int arity = -1;                      // declared parameter count; -1 when any count is accepted
    std::vector<ValueType> param_types;
    std::vector<std::string> param_names;
    std::string bound_to; // the environment that holds its segments (`bound ivy`), as written
    int bound_env = -1;   // its index in Program::environments, resolved by the compiler
    int instance = -1;    // the instance it places: an index in *Program::instances (-1: none)
    Span decl_span;
};

class SymbolTable {
  public:
    // Thrown by intern when every symbol id is taken (kNoSymbol - 1 names).
    struct Full {};
    SymbolTable();
    SymbolId intern(std::string_view name);
    std::optional<SymbolId> find(std::string_view name) const;
    const SymbolInfo& operator[](SymbolId id) const { return infos_[id]; }
    SymbolInfo& operator[](SymbolId id) { return infos_[id]; }
    std::size_t size() const { return infos_.size(); }
    const std::vector<SymbolInfo>& all() const { return infos_; }

    SymbolId open_bracket = 0, close_bracket = 0, cut = 0;

  private:
    std::vector<SymbolInfo> infos_;
    std::unordered_map<std::string, SymbolId> index_;
};

// ---- compiled expressions and statements: a small stack machine over doubles -----------------

// The opcodes, their stack effects and docs: one table, opcodes.hpp.
enum class Op : std::uint8_t {
#define OPCODE(name, pops, pushes, flow, doc) name,
#include "plant/opcodes.hpp"
#undef OPCODE
};

// Where control goes after an instruction.
enum class OpFlow : std::uint8_t {
    Next,       // the next instruction
    Jump,       // instruction a
    Branch,     // the next instruction or a
    BranchKeep, // the next instruction (having popped the top) or a (keeping it)
    End,        // nowhere: the code ends
};

struct OpInfo {
    const char* name;
    OpFlow flow;
    const char* doc;
};

inline constexpr OpInfo kOps[] = {
#define OPCODE(name, pops, pushes, flow, doc) {#name, OpFlow::flow, doc},
#include "plant/opcodes.hpp"
#undef OPCODE
};

inline constexpr const OpInfo& op_info(Op op) {
    return kOps[static_cast<std::size_t>(op)];
}
inline constexpr bool is_jump(Op op) {
    const OpFlow f = op_info(op).flow;
    return f == OpFlow::Jump || f == OpFlow::Branch || f == OpFlow::BranchKeep;
}

struct Instr {
    Op op;
    std::uint8_t n = 0;  // widths, argument counts
    std::uint16_t b = 0; // secondary operand
    std::int32_t a = 0;  // primary operand
};

// EnvCall's b holds the method's index in its low 12 bits and the width of its result (0, 1 or
// 3 numbers) above them, so that the opcode table's stack effect is exact for every method.
inline constexpr unsigned kEnvMethodBits = 12;
inline constexpr std::uint16_t env_call_operand(std::size_t method, int result_width) {
    return static_cast<std::uint16_t>(method | (static_cast<unsigned>(result_width) << kEnvMethodBits));
}
inline constexpr std::size_t env_call_method(const Instr& I) {
    return I.b & ((1u << kEnvMethodBits) - 1);
}

// How many numbers an instruction pops, then pushes (opcodes.hpp).
struct StackEffect {
    int pops = 0, pushes = 0;
};

inline StackEffect stack_effect(const Instr& I) {
    const int n = I.n, b = I.b;
    switch (I.op) {
#define OPCODE(name, pops, pushes, flow, doc)                                                                \
    case Op::name:                                                                                           \
        return {pops, pushes};
#include "plant/opcodes.hpp"
#undef OPCODE
    }
    return {};
}

struct Code {
    std::vector<Instr> instrs;
    std::vector<Span> spans; // one per instruction, for runtime errors
    std::vector<double> consts;
    std::vector<std::vector<Span>> arg_spans; // Emit with b > 0: spans of its numbers, arg_spans[b - 1]
    bool empty() const { return instrs.empty(); }
};

// One argument of a predecessor or context module: bind it to frame slots or require a value.
struct PatternArg {
    bool bind = true;
    std::uint16_t slot = 0; // frame slot of the first double when binding
    std::uint8_t width = 1; // 1 or 3
    double value = 0;       // required value when !bind
};

struct PatternModule {
    SymbolId sym = 0;
    std::uint32_t width = 0; // total doubles the module must carry
    std::vector<PatternArg> args;
    Span span;
};

// The successor of an arrow-form production as a fixed sequence of modules: constant parameters
// are filled in, the others ("holes") are computed by `values`, which leaves them on the stack
// in order. Applying it copies the modules and writes the computed numbers, without running one
// Emit instruction per module.
struct SuccessorTemplate {
    bool valid = false;
    std::vector<SymbolId> syms;
    std::vector<std::uint32_t> param_end; // parameters of module j end at param_end[j] (relative)
    std::vector<double> params;           // constants; holes are overwritten
    std::vector<std::uint32_t> holes;     // parameter index of each computed number
    std::vector<Span> hole_spans;
    int keep = -1; // module that keeps the predecessor's identity
    // how many of its modules get new identities (all but the one that keeps the predecessor's)
    std::size_t fresh() const { return syms.size() - (keep >= 0 ? 1 : 0); }
    // What the string stores of it (see KindTable; Compiler::assign_kinds): each module's kind,
    // the numbers stored (constants of plain kinds and the holes), where each hole goes among
    // them, and each module's count of them.
    std::vector<KindId> kinds;
    std::vector<double> stored;
    std::vector<std::uint32_t> stored_holes;
    std::vector<std::uint8_t> stored_nargs;
    Code values;
    // When every computed number is a bound name, optionally times or plus a constant (the
    // common `A(l * r1, w)`), the numbers are computed without the stack machine.
    struct Affine {
        enum Kind : std::uint8_t { Copy, Mul, Add } kind;
        std::uint16_t slot;
        double constant;
    };
    std::vector<Affine> affine; // empty: run `values`
};

struct Production {
    Span span;
    std::vector<PatternModule> strict, left, left_new, right, right_new;
    Code condition; // empty: always true
    Code weight;    // empty: not stochastic
    Code body;      // emits the successor; for the arrow form ends with ProduceEnd
    SuccessorTemplate tmpl;
    std::uint16_t frame_size = 0;
    bool body_form = false;
    bool has_context() const { return !left.empty() || !right.empty(); }
    bool has_new_context() const { return !left_new.empty() || !right_new.empty(); }
};

struct RuleSet {
    std::string name;
    Span span;
    std::vector<Production> productions;
    std::vector<std::vector<std::uint32_t>> by_symbol; // strict predecessor's first symbol -> productions
    int max_depth = 1;
    bool needs_brackets = false;
    bool uses_left_new = false, uses_right_new = false;
    void index(std::size_t symbols);
    bool empty() const { return productions.empty(); }
};

enum class GlobalKind { Param, Var };

struct Global {
    std::string name;
    GlobalKind kind = GlobalKind::Param;
    ValueType type = ValueType::Number;
    std::uint32_t slot = 0;
    Span span;
    // A param's declared range (`param r = 0.9 in 0.5 .. 1.0;`, docs/language.md), checked
    // against its value at compile time; has_range is false without one.
    bool has_range = false;
    double low = 0, high = 0;
    // The default and both bounds are written as whole numbers (`param N_S = 5 in 1 .. 12;`):
    // a count, which `plant view`'s slider moves by whole steps.
    bool whole = false;
};

struct Function {
    std::string name;
    Span span;
    std::vector<ValueType> param_types;
    ValueType result = ValueType::Number;
    std::uint16_t frame_size = 0;
    std::uint16_t param_width = 0;
    Code code;
};

using HookKind = ast::HookKind;

// Where a rule block was written, for listings such as the REPL's :rules (the text itself stays
// in the SourceManager).
struct RuleBlockSource {
    ast::RuleKind kind = ast::RuleKind::Rules;
    std::string group;
    std::vector<Span> productions;
};

// A file the program was read from: its source id and its rule blocks, in file order.
struct ProgramFile {
    std::uint32_t source = 0;
    std::vector<RuleBlockSource> rule_blocks;
};

// `curve name = linear(...)` or `bezier(...)`: a function of t in [0, 1], as cpfg's function
// files. Control values are numbers (equally spaced in t) or vec3 points whose x is t and y the
// value (x increasing).
struct CurveDef {
    std::string name;
    bool bezier = false;
    std::vector<double> xs, ys;
    Span span;
    double operator()(double t) const;
};

// `surface name = polygon(p0, p1, ...)` or `= load("file.obj")`, evaluated at compile time.
enum class SurfaceKind : std::uint8_t { Polygon, Load };
struct SurfaceDef {
    std::string name;
    SurfaceKind kind = SurfaceKind::Polygon;
    std::vector<std::array<double, 3>> points; // polygon corners
    std::string path;                          // load: resolved against the grammar's directory
    Span span;
};

// `texture name = image("file.png");` (docs/language.md, textures): an image read whole at compile
// time, PNG or JPEG as its first bytes say. The name is also a const holding the texture's index
// in Program::textures, which SetTexture(name) passes to the turtle.
struct TextureDef {
    std::string name;
    std::string path;                         // resolved against the declaring file
    std::string mime_type;                    // "image/png" or "image/jpeg"
    std::shared_ptr<const std::string> bytes; // the file's bytes, shared by the programs that see it
    Span span;
};

class Environment;
struct EnvironmentKind;

// One evaluated constructor argument: `key: value` (key empty when positional).
struct EnvArg {
    std::string key;
    ValueType type = ValueType::Number; // String for a quoted file name, in `text`
    double v[3] = {0, 0, 0};
    std::string text; // a string argument; a file path resolved against the grammar
    Span span;
};

// `env name = kind(key: value, ...);` as compiled: the declaration, and the object as declared,
// made and checked once by the compiler (a mesh file is read once). Neither changes after
// compilation: every derivation works on its own clone (RunState, run_state.hpp).
struct EnvironmentDecl {
    std::string name;
    std::string kind_name;
    std::vector<EnvArg> args; // evaluated
    Span span;
    const EnvironmentKind* kind = nullptr;      // its methods; null without a runtime or on error
    std::shared_ptr<const Environment> initial; // null without a runtime or on error
};

struct Program;

// `instance Name(params) { items }` compiled (docs/language.md, instances): a sub-L-system with
// its own axiom, rules, settings, interpretation rules and surfaces, compiled once. The turtle
// places it wherever it meets the module `Name(args)`; it is derived and meshed once per distinct
// argument tuple (and view depth).
struct InstanceDef {
    std::string name;
    Span span; // the declaration
    std::vector<ValueType> param_types;
    std::vector<std::string> param_names;
    std::vector<std::uint32_t> param_slots; // the global slot of each parameter in `program`
    std::shared_ptr<const Program> program; // the body; its `instances` is the root's table
    int depth = 1;                          // 1 + the deepest instance it places (1: none)
};

struct Program {
    SymbolTable symbols;
    std::vector<Global> globals;
    std::vector<double> global_values; // current values, param defaults (after overrides) at start
    std::unordered_map<std::string, std::uint32_t> global_index;
    std::vector<Function> functions;
    std::vector<std::string> print_formats;

    Code axiom;                                       // emits the axiom's modules
    std::array<Code, ast::kSettings.size()> settings; // by ast::SettingKey; empty: not set
    const Code& setting(ast::SettingKey key) const { return settings[static_cast<std::size_t>(key)]; }
    double default_angle = 90, default_step = 1, default_width = 1;
    std::vector<std::uint8_t> ignored; // per symbol: skipped when matching context
    bool uses_cut = false;             // some successor or the axiom produces '%'
    bool uses_id = false;              // some code calls id()

    KindTable kinds; // the kinds of the successor templates' modules (see SuccessorTemplate)

    RuleSet rules;               // the unnamed, always-active group
    std::vector<RuleSet> groups; // named groups, selected by `use`
    RuleSet decompose;
    RuleSet interpret;
    std::array<Code, ast::kHooks.size()> hooks;
    std::array<bool, ast::kHooks.size()> has_hook{};
    std::array<std::uint16_t, ast::kHooks.size()> hook_frame{};

    std::vector<SurfaceDef> surfaces;
    std::vector<TextureDef> textures; // by index: the value of the texture's name
    std::vector<CurveDef> curves;
    std::vector<EnvironmentDecl> environments; // `env` declarations, in file order
    std::vector<ProgramFile> files;            // in the order they were read: the main file first

    // The decomposition graph's parameters (`graph { }`, graph.hpp), and, when there is one, the
    // consts by name, which edits files may use in their values.
    GraphDecl graph;
    struct NamedConst {
        std::string name;
        ValueType type = ValueType::Number;
        double v[3] = {0, 0, 0};
    };
    std::vector<NamedConst> constants;

    // Every instance declaration of the grammar (top level, imported and nested), in one table
    // owned by the root program; an instance's program reads the same table through `instances`
    // (SymbolInfo::instance indexes it). Empty when the grammar declares none.
    std::shared_ptr<std::vector<InstanceDef>> instance_table; // set in the root program only
    const std::vector<InstanceDef>* instances = nullptr;      // the root's table, in every program
    const InstanceDef* instance(SymbolId s) const {
        const int k = s < symbols.size() ? symbols[s].instance : -1;
        return k >= 0 && instances ? &(*instances)[static_cast<std::size_t>(k)] : nullptr;
    }

    int group_index(std::string_view name) const;
};

} // namespace plant
