// The stack machine's instructions, one entry each: OPCODE(name, pops, pushes, flow, doc).
//
// `pops` and `pushes` are the instruction's stack effect, written in its operands `n` and `b`
// (see Instr in program.hpp); `flow` says where control goes next (OpFlow). The table is the
// only list of opcodes: program.hpp makes `enum class Op`, the names and stack_effect() from it,
// the compiler tracks the depth of the operand stack with it and vm.cpp checks compiled code
// against it (check_stack) and names instructions with it (disassemble).
//
// No include guard: it is included several times, each time with its own OPCODE.

// ---- values ----
OPCODE(Const, 0, 1, Next, "push consts[a]")
OPCODE(Const3, 0, 3, Next, "push consts[a .. a+3)")
OPCODE(LoadLocal, 0, n, Next, "push frame[a .. a+n)")
OPCODE(StoreLocal, n, 0, Next, "pop n numbers into frame[a ..)")
OPCODE(LoadGlobal, 0, n, Next, "push globals[a .. a+n)")
OPCODE(StoreGlobal, n, 0, Next, "pop n numbers into globals[a ..)")
OPCODE(Pop, n, 0, Next, "drop n numbers")
// ---- arithmetic and comparison on numbers ----
OPCODE(Add, 2, 1, Next, "x + y")
OPCODE(Sub, 2, 1, Next, "x - y")
OPCODE(Mul, 2, 1, Next, "x * y")
OPCODE(Div, 2, 1, Next, "x / y; dividing by zero is a runtime error")
OPCODE(Mod, 2, 1, Next, "fmod(x, y); by zero is a runtime error")
OPCODE(Neg, 1, 1, Next, "-x")
OPCODE(Not, 1, 1, Next, "1 if x is 0, else 0")
OPCODE(Lt, 2, 1, Next, "x < y as 1 or 0")
OPCODE(Le, 2, 1, Next, "x <= y")
OPCODE(Gt, 2, 1, Next, "x > y")
OPCODE(Ge, 2, 1, Next, "x >= y")
OPCODE(Eq, 2, 1, Next, "x == y")
OPCODE(Ne, 2, 1, Next, "x != y")
// ---- vec3 arithmetic (S: the scalar operand) ----
OPCODE(VAdd, 6, 3, Next, "u + v")
OPCODE(VSub, 6, 3, Next, "u - v")
OPCODE(VMulS, 4, 3, Next, "v * s")
OPCODE(VSMul, 4, 3, Next, "s * v")
OPCODE(VDivS, 4, 3, Next, "v / s; dividing by zero is a runtime error")
OPCODE(VNeg, 3, 3, Next, "-v")
OPCODE(VEq, 6, 1, Next, "u == v, component by component")
OPCODE(VNe, 6, 1, Next, "u != v")
OPCODE(Member, 3, 1, Next, "component a (0 x, 1 y, 2 z) of a vec3")
// ---- control ----
OPCODE(Jump, 0, 0, Jump, "pc = a")
OPCODE(JumpIfZero, 1, 0, Branch, "pop; if it was 0, pc = a")
OPCODE(JumpIfZeroKeep, 1, 0, BranchKeep, "&&: if the top is 0 jump to a keeping it, else pop it")
OPCODE(JumpIfNonZeroKeep, 1, 0, BranchKeep, "||: if the top is not 0 jump to a keeping it, else pop it")
// ---- calls ----
OPCODE(Builtin, n, b, Next, "built-in a on n numbers of arguments, giving b numbers")
OPCODE(Call, b, n, Next, "user function a on b numbers of arguments, giving n numbers")
OPCODE(Return, n, 0, End, "end a function; its value is the n numbers on top")
// ---- production bodies and hooks ----
OPCODE(Emit, n, 0, Next, "pop the n parameters of module a and append it to the output")
OPCODE(ProduceEnd, 0, 0, End, "produce: the body has applied and ends")
OPCODE(NProduceMark, 0, 0, Next, "nproduce: marks that something was produced")
OPCODE(Use, 0, 0, Next, "select rule group a (-1: none)")
OPCODE(Stop, 0, 0, Next, "stop the derivation after the current hook")
OPCODE(Print, n, 0, Next, "pop n numbers described by print_formats[a] and print them")
OPCODE(ForCheck, 0, 0, Next, "loop guard: counts turns in frame[a], stops a runaway loop")
OPCODE(Halt, n, 0, End, "end; the code's value is the n numbers on top")
// ---- superinstructions made by fuse() in straight-line code ----
OPCODE(LoadMulConst, 0, 1, Next, "push frame[a] * consts[b]")
OPCODE(LoadAddConst, 0, 1, Next, "push frame[a] + consts[b]")
// ---- shapes and environments ----
OPCODE(Curve, 1, 1, Next, "replace t on top by curves[a](t)")
OPCODE(
    EnvCall, n, b >> 12, Next,
    "method (b & 0xfff) of environment a (the run state's), on n numbers; pushes its result, b >> 12 numbers")
// ---- decomposition graphs (graph_ops.hpp) ----
OPCODE(GraphCall, n, b, Next, "graph built-in a (root, child, depth, ...) on n numbers, giving b numbers")
OPCODE(
    GraphRead, n, 1, Next,
    "parameter a of a node: pops the node (n = 1), or the node and t for a curve (n = 2); pushes its value")
OPCODE(GraphPlace, 9, 1, Next, "child(n, pos, index, base, dir): pops those 9 numbers, pushes the child node")
OPCODE(GraphShape, n, b >> 12, Next,
       "method (b & 0xfff) of silhouette parameter a of a node: pops the node and its arguments (n numbers), "
       "pushes b >> 12")
