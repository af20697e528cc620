// The stack machine: one switch over the opcodes of opcodes.hpp, the built-ins, curves, the
// superinstruction pass (fuse) and the stack check of compiled code (check_stack).
#include "plant/vm.hpp"

#include "graph_ops.hpp"

#include "plant/builtins.hpp"
#include "plant/environment.hpp"
#include "plant/random.hpp"
#include "plant/run_state.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <numbers>

namespace plant {

namespace {

constexpr int kMaxCallDepth = 256;
constexpr std::size_t kStackSize = 1024;
// Instructions between two looks at the interrupt flag (Ctrl-C): a few milliseconds' work.
constexpr std::int64_t kStepSlice = std::int64_t{1} << 16;
constexpr double kPi = std::numbers::pi;

[[noreturn]] void fail(const Code& code, std::size_t pc, std::string msg,
                       RuntimeErrorKind kind = RuntimeErrorKind::General) {
    throw RuntimeError{kind, pc < code.spans.size() ? code.spans[pc] : Span{}, std::move(msg)};
}

double next_unit(EvalEnv& env) {
    return random_unit(random_bits(env.seed, env.phase, env.position, env.draw++));
}

// Functions of numbers alone. Each apply_* returns the width of its result, 0 when `id` is not one
// of its own.
int apply_math(BuiltinId id, const double* a, double* r) {
    switch (id) {
    case BuiltinId::Sin:
        r[0] = std::sin(a[0]);
        return 1;
    case BuiltinId::Cos:
        r[0] = std::cos(a[0]);
        return 1;
    case BuiltinId::Tan:
        r[0] = std::tan(a[0]);
        return 1;
    case BuiltinId::Asin:
        r[0] = std::asin(a[0]);
        return 1;
    case BuiltinId::Acos:
        r[0] = std::acos(a[0]);
        return 1;
    case BuiltinId::Atan:
        r[0] = std::atan(a[0]);
        return 1;
    case BuiltinId::Atan2:
        r[0] = std::atan2(a[0], a[1]);
        return 1;
    case BuiltinId::Sqrt:
        r[0] = std::sqrt(a[0]);
        return 1;
    case BuiltinId::Exp:
        r[0] = std::exp(a[0]);
        return 1;
    case BuiltinId::Log:
        r[0] = std::log(a[0]);
        return 1;
    case BuiltinId::Pow:
        r[0] = std::pow(a[0], a[1]);
        return 1;
    case BuiltinId::Abs:
        r[0] = std::fabs(a[0]);
        return 1;
    case BuiltinId::Min:
        r[0] = std::min(a[0], a[1]);
        return 1;
    case BuiltinId::Max:
        r[0] = std::max(a[0], a[1]);
        return 1;
    case BuiltinId::Clamp:
        r[0] = std::min(std::max(a[0], a[1]), a[2]);
        return 1;
    case BuiltinId::Floor:
        r[0] = std::floor(a[0]);
        return 1;
    case BuiltinId::Ceil:
        r[0] = std::ceil(a[0]);
        return 1;
    case BuiltinId::Round:
        r[0] = std::round(a[0]);
        return 1;
    case BuiltinId::Sign:
        r[0] = a[0] > 0 ? 1.0 : a[0] < 0 ? -1.0 : 0.0;
        return 1;
    case BuiltinId::Mix:
        r[0] = a[0] + (a[1] - a[0]) * a[2];
        return 1;
    case BuiltinId::Smoothstep: {
        double t =
            a[1] == a[0] ? (a[2] < a[0] ? 0.0 : 1.0) : std::clamp((a[2] - a[0]) / (a[1] - a[0]), 0.0, 1.0);
        r[0] = t * t * (3 - 2 * t);
        return 1;
    }
    case BuiltinId::Rad:
        r[0] = a[0] * kPi / 180.0;
        return 1;
    case BuiltinId::Deg:
        r[0] = a[0] * 180.0 / kPi;
        return 1;
    case BuiltinId::Pi:
        r[0] = kPi;
        return 1;
    default:
        return 0;
    }
}

// Functions that take or give vec3s.
int apply_vector(BuiltinId id, const double* a, double* r) {
    switch (id) {
    case BuiltinId::MixV:
        for (int k = 0; k < 3; ++k) r[k] = a[k] + (a[3 + k] - a[k]) * a[6];
        return 3;
    case BuiltinId::Vec3:
        r[0] = a[0];
        r[1] = a[1];
        r[2] = a[2];
        return 3;
    case BuiltinId::Vec3S:
        r[0] = r[1] = r[2] = a[0];
        return 3;
    case BuiltinId::Dot:
        r[0] = a[0] * a[3] + a[1] * a[4] + a[2] * a[5];
        return 1;
    case BuiltinId::Cross: {
        double x = a[1] * a[5] - a[2] * a[4], y = a[2] * a[3] - a[0] * a[5], z = a[0] * a[4] - a[1] * a[3];
        r[0] = x;
        r[1] = y;
        r[2] = z;
        return 3;
    }
    case BuiltinId::Length:
        r[0] = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        return 1;
    case BuiltinId::Normalize: {
        double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double inv = l > 0 ? 1.0 / l : 0.0;
        r[0] = a[0] * inv;
        r[1] = a[1] * inv;
        r[2] = a[2] * inv;
        return 3;
    }
    case BuiltinId::Distance: {
        double dx = a[0] - a[3], dy = a[1] - a[4], dz = a[2] - a[5];
        r[0] = std::sqrt(dx * dx + dy * dy + dz * dz);
        return 1;
    }
    default:
        return 0;
    }
}

// Functions of the module being rewritten: its random stream, the step, its identity.
int apply_per_module(BuiltinId id, const double* a, double* r, EvalEnv& env) {
    switch (id) {
    case BuiltinId::Uniform:
        r[0] = a[0] + (a[1] - a[0]) * next_unit(env);
        return 1;
    case BuiltinId::Normal: {
        // Box-Muller from two counter-based draws
        double u1 = next_unit(env), u2 = next_unit(env);
        r[0] = a[0] + a[1] * std::sqrt(-2.0 * std::log(1.0 - u1)) * std::cos(2 * kPi * u2);
        return 1;
    }
    case BuiltinId::Chance:
        r[0] = next_unit(env) < a[0] ? 1.0 : 0.0;
        return 1;
    case BuiltinId::Step:
        r[0] = env.step;
        return 1;
    case BuiltinId::Id:
        r[0] = static_cast<double>(env.id & ~kNewIdBit);
        return 1;
    case BuiltinId::Lod:
        // Yan & Chiba, section 3.3 (LeafNum), clamped to [0, count]; no maximum depth: count
        r[0] = a[2] <= 0 ? a[0]
                         : std::clamp(std::round(a[0] * (1 - a[1] / a[2])), std::min(0.0, a[0]),
                                      std::max(0.0, a[0]));
        return 1;
    default:
        return 0;
    }
}

// Applies builtin `id` to the arguments at `a` (already popped); writes the result to `r`.
// Returns the width of the result.
int apply_builtin(BuiltinId id, const double* a, double* r, EvalEnv& env) {
    if (int w = apply_math(id, a, r)) return w;
    if (int w = apply_vector(id, a, r)) return w;
    return apply_per_module(id, a, r, env);
}

std::string format_number(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e15) return fmt::format("{}", static_cast<long long>(v));
    return fmt::format("{}", v);
}

// A slice of the evaluation's budget is used up: looks at the interrupt, then hands out the
// next slice, or stops the evaluation at the instruction it reached.
[[gnu::noinline]] std::int64_t next_slice(const Code& code, std::size_t pc, EvalEnv& env) {
    if (env.interrupt && env.interrupt->load(std::memory_order_relaxed))
        fail(code, pc, "interrupted", RuntimeErrorKind::Interrupted);
    // (the slices handed out so far are used up: this evaluation ran max_steps - steps_left)
    if (env.work + (env.max_steps - env.steps_left) > env.work_limit) throw_work_limit(env.max_work);
    if (env.steps_left == 0) {
        std::string where = env.function >= 0
                                ? fmt::format(" (in function '{}')", env.prog->functions[env.function].name)
                                : "";
        fail(code, pc,
             fmt::format("ran out of steps: more than {} instructions in one evaluation{}; a larger "
                         "--max-steps allows more",
                         env.max_steps, where),
             RuntimeErrorKind::StepLimit);
    }
    auto n = static_cast<std::int64_t>(std::min<std::uint64_t>(env.steps_left, kStepSlice));
    env.steps_left -= static_cast<std::uint64_t>(n);
    return n;
}

struct ArenaScope {
    EvalEnv& env;
    std::size_t saved;
    ArenaScope(EvalEnv& e, std::size_t need) : env(e), saved(e.arena_top) {
        if (env.arena_top + need > env.arena.size()) env.arena.resize((env.arena_top + need) * 2);
        env.arena_top += need;
    }
    ~ArenaScope() { env.arena_top = saved; }
};

RunStatus execute(const Code& code, double* frame, EvalEnv& env, double* result);

} // namespace

// An evaluation: a fresh budget of env.max_steps instructions for `code` and every function it
// calls (execute, below, runs them).
RunStatus run(const Code& code, double* frame, EvalEnv& env, double* result) {
    env.slice = static_cast<std::int64_t>(std::min<std::uint64_t>(env.max_steps, kStepSlice));
    env.steps_left = env.max_steps - static_cast<std::uint64_t>(env.slice);
    env.function = -1;
    RunStatus status = execute(code, frame, env, result);
    // every instruction took one from the slice or the steps left
    env.work += env.max_steps - env.steps_left - static_cast<std::uint64_t>(env.slice);
    if (env.work > env.work_limit) throw_work_limit(env.max_work);
    return status;
}

void throw_work_limit(std::uint64_t max_work) {
    throw RuntimeError{RuntimeErrorKind::WorkLimit, Span{},
                       fmt::format("the run did more than {} units of work (VM instructions and modules "
                                   "written, --max-work): raise --max-work",
                                   max_work)};
}

namespace {

RunStatus execute(const Code& code, double* frame, EvalEnv& env, double* result) {
    ArenaScope scope(env, kStackSize);
    // The arena may grow (and move) inside nested calls, so address the stack by offset.
    const std::size_t base = scope.saved;
    auto S = [&env, base]() { return env.arena.data() + base; };
    double* st = S();
    int sp = 0;
    const Instr* ins = code.instrs.data();
    const std::size_t n = code.instrs.size();
    std::int64_t slice = env.slice; // kept in env.slice while a function runs, and on return
    for (std::size_t pc = 0; pc < n; ++pc) {
        if (--slice < 0) [[unlikely]]
            slice = next_slice(code, pc, env) - 1;
        const Instr& I = ins[pc];
        switch (I.op) {
        case Op::Const:
            st[sp++] = code.consts[I.a];
            break;
        case Op::Const3:
            st[sp] = code.consts[I.a];
            st[sp + 1] = code.consts[I.a + 1];
            st[sp + 2] = code.consts[I.a + 2];
            sp += 3;
            break;
        case Op::LoadLocal:
            for (int k = 0; k < I.n; ++k) st[sp++] = frame[I.a + k];
            break;
        case Op::StoreLocal:
            sp -= I.n;
            for (int k = 0; k < I.n; ++k) frame[I.a + k] = st[sp + k];
            break;
        case Op::LoadGlobal:
            for (int k = 0; k < I.n; ++k) st[sp++] = env.globals[I.a + k];
            break;
        case Op::StoreGlobal:
            sp -= I.n;
            for (int k = 0; k < I.n; ++k) env.globals[I.a + k] = st[sp + k];
            break;
        case Op::Pop:
            sp -= I.n;
            break;
        case Op::Add:
            --sp;
            st[sp - 1] += st[sp];
            break;
        case Op::Sub:
            --sp;
            st[sp - 1] -= st[sp];
            break;
        case Op::Mul:
            --sp;
            st[sp - 1] *= st[sp];
            break;
        case Op::Div:
            --sp;
            if (st[sp] == 0) fail(code, pc, "division by zero", RuntimeErrorKind::Arithmetic);
            st[sp - 1] /= st[sp];
            break;
        case Op::Mod:
            --sp;
            if (st[sp] == 0) fail(code, pc, "remainder of a division by zero", RuntimeErrorKind::Arithmetic);
            st[sp - 1] = std::fmod(st[sp - 1], st[sp]);
            break;
        case Op::Neg:
            st[sp - 1] = -st[sp - 1];
            break;
        case Op::Not:
            st[sp - 1] = st[sp - 1] == 0 ? 1.0 : 0.0;
            break;
        case Op::Lt:
            --sp;
            st[sp - 1] = st[sp - 1] < st[sp];
            break;
        case Op::Le:
            --sp;
            st[sp - 1] = st[sp - 1] <= st[sp];
            break;
        case Op::Gt:
            --sp;
            st[sp - 1] = st[sp - 1] > st[sp];
            break;
        case Op::Ge:
            --sp;
            st[sp - 1] = st[sp - 1] >= st[sp];
            break;
        case Op::Eq:
            --sp;
            st[sp - 1] = st[sp - 1] == st[sp];
            break;
        case Op::Ne:
            --sp;
            st[sp - 1] = st[sp - 1] != st[sp];
            break;
        case Op::VAdd:
            sp -= 3;
            for (int k = 0; k < 3; ++k) st[sp - 3 + k] += st[sp + k];
            break;
        case Op::VSub:
            sp -= 3;
            for (int k = 0; k < 3; ++k) st[sp - 3 + k] -= st[sp + k];
            break;
        case Op::VMulS: { // vec * s
            double s = st[--sp];
            for (int k = 0; k < 3; ++k) st[sp - 3 + k] *= s;
            break;
        }
        case Op::VSMul: { // s * vec
            double s = st[sp - 4];
            for (int k = 0; k < 3; ++k) st[sp - 4 + k] = s * st[sp - 3 + k];
            --sp;
            break;
        }
        case Op::VDivS: {
            double s = st[--sp];
            if (s == 0) fail(code, pc, "division by zero", RuntimeErrorKind::Arithmetic);
            for (int k = 0; k < 3; ++k) st[sp - 3 + k] /= s;
            break;
        }
        case Op::VNeg:
            for (int k = 1; k <= 3; ++k) st[sp - k] = -st[sp - k];
            break;
        case Op::VEq:
        case Op::VNe: {
            sp -= 6;
            bool eq = st[sp] == st[sp + 3] && st[sp + 1] == st[sp + 4] && st[sp + 2] == st[sp + 5];
            st[sp++] = (I.op == Op::VEq) == eq ? 1.0 : 0.0;
            break;
        }
        case Op::Member: {
            double v = st[sp - 3 + I.a];
            sp -= 3;
            st[sp++] = v;
            break;
        }
        case Op::Jump:
            pc = static_cast<std::size_t>(I.a) - 1;
            break;
        case Op::JumpIfZero:
            if (st[--sp] == 0) pc = static_cast<std::size_t>(I.a) - 1;
            break;
        case Op::JumpIfZeroKeep:
            if (st[sp - 1] == 0)
                pc = static_cast<std::size_t>(I.a) - 1;
            else
                --sp;
            break;
        case Op::JumpIfNonZeroKeep:
            if (st[sp - 1] != 0)
                pc = static_cast<std::size_t>(I.a) - 1;
            else
                --sp;
            break;
        case Op::Builtin: {
            sp -= I.n;
            double r[3];
            int w = apply_builtin(static_cast<BuiltinId>(I.a), st + sp, r, env);
            for (int k = 0; k < w; ++k) st[sp++] = r[k];
            break;
        }
        case Op::Call: {
            const Function& fn = env.prog->functions[I.a];
            if (env.call_depth >= kMaxCallDepth)
                fail(code, pc, fmt::format("recursion deeper than {} calls in '{}'", kMaxCallDepth, fn.name));
            sp -= fn.param_width;
            std::vector<double> callee(std::max<std::size_t>(fn.frame_size, 1));
            for (int k = 0; k < fn.param_width; ++k) callee[k] = st[sp + k];
            double r[3] = {0, 0, 0};
            ++env.call_depth;
            ModuleString* saved_out = env.out;
            const int saved_function = env.function;
            env.out = nullptr;
            env.function = static_cast<int>(I.a);
            env.slice = slice;
            execute(fn.code, callee.data(), env, r);
            slice = env.slice;
            env.function = saved_function;
            env.out = saved_out;
            --env.call_depth;
            st = S();
            int w = value_width(fn.result);
            for (int k = 0; k < w; ++k) st[sp++] = r[k];
            break;
        }
        case Op::Return:
            if (result)
                for (int k = 0; k < I.n; ++k) result[k] = st[sp - I.n + k];
            env.slice = slice;
            return RunStatus::Finished;
        case Op::Emit: {
            sp -= I.n;
            const double* p = st + sp;
            for (int k = 0; k < I.n; ++k) {
                if (!std::isfinite(p[k])) {
                    std::string msg =
                        fmt::format("parameter {} of '{}' is {}", k + 1, env.prog->symbols[I.a].name,
                                    std::isnan(p[k]) ? "NaN" : "infinite");
                    if (I.b > 0 && static_cast<std::size_t>(k) < code.arg_spans[I.b - 1].size())
                        throw RuntimeError{RuntimeErrorKind::Arithmetic, code.arg_spans[I.b - 1][k], msg};
                    fail(code, pc, msg, RuntimeErrorKind::Arithmetic);
                }
            }
            auto sym = static_cast<SymbolId>(I.a);
            ModuleId id = 0;
            bool kept = false;
            for (std::uint32_t k = 0; k < env.keep_count; ++k) {
                if (!(env.keep_used & (1u << k)) && env.keep_syms[k] == sym) {
                    env.keep_used |= 1u << k;
                    id = env.keep_ids[k];
                    kept = true;
                    break;
                }
            }
            if (!kept) id = env.id_base + env.new_count++;
            env.out->push(sym, p, I.n, id);
            env.produced = true;
            if (env.out->size() > env.max_output || env.out->params.size() > env.max_params)
                fail(code, pc, "the string outgrew the module limit", RuntimeErrorKind::ModuleLimit);
            break;
        }
        case Op::ProduceEnd:
            env.produced = true;
            env.slice = slice;
            return RunStatus::Produced;
        case Op::NProduceMark:
            env.produced = true;
            break;
        case Op::Use:
            if (env.effects) env.effects->use_group = I.a;
            break;
        case Op::Stop:
            if (env.effects) env.effects->stop = true;
            break;
        case Op::Print: {
            sp -= I.n;
            const std::string& fmtstr = env.prog->print_formats[I.a];
            std::string line;
            int k = 0;
            // the format is a sequence of n (number), v (vec3), b (bool) and s<text>\x1f pieces
            for (std::size_t c = 0; c < fmtstr.size(); ++c) {
                if (!line.empty()) line += ' ';
                char t = fmtstr[c];
                if (t == 'n')
                    line += format_number(st[sp + k++]);
                else if (t == 'b')
                    line += st[sp + k++] != 0 ? "true" : "false";
                else if (t == 'v') {
                    line += fmt::format("vec3({}, {}, {})", format_number(st[sp + k]),
                                        format_number(st[sp + k + 1]), format_number(st[sp + k + 2]));
                    k += 3;
                } else if (t == 's') {
                    auto e = fmtstr.find('\x1f', c + 1);
                    line += fmtstr.substr(c + 1, e - c - 1);
                    c = e;
                }
            }
            if (env.effects) {
                line += '\n';
                if (env.effects->on_print)
                    (*env.effects->on_print)(line);
                else
                    env.effects->printed += line;
            }
            break;
        }
        case Op::ForCheck:
            if (++frame[I.a] > 1e7) fail(code, pc, "loop ran more than 10 million times");
            break;
        case Op::Halt:
            if (result)
                for (int k = 0; k < I.n; ++k) result[k] = st[sp - I.n + k];
            env.slice = slice;
            return RunStatus::Finished;
        case Op::LoadMulConst:
            st[sp++] = frame[I.a] * code.consts[I.b];
            break;
        case Op::LoadAddConst:
            st[sp++] = frame[I.a] + code.consts[I.b];
            break;
        case Op::Curve:
            st[sp - 1] = env.prog->curves[static_cast<std::size_t>(I.a)](st[sp - 1]);
            break;
        case Op::EnvCall: {
            const auto e = static_cast<std::size_t>(I.a);
            const EnvironmentDecl& decl = env.prog->environments[e];
            const std::size_t m = env_call_method(I);
            const EnvMethod& method = decl.kind->methods[m];
            sp -= I.n;
            double r[3] = {0, 0, 0};
            if (method.access == EnvAccess::Edit) {
                // the compiler allows edits in hooks only, and only hooks run with hook_run set
                if (!env.hook_run) fail(code, pc, "an environment can be changed only in hooks");
                try {
                    env.hook_run->environment(e)->edit(m, st + sp);
                } catch (RuntimeError& refused) { // an edit's argument out of bounds: at the call
                    if (!refused.span.valid() && pc < code.spans.size()) refused.span = code.spans[pc];
                    throw;
                }
            } else {
                const Environment* object = env.run ? env.run->environment(e) : decl.initial.get();
                object->query(m, st + sp, r);
            }
            for (int k = 0; k < value_width(method.result); ++k) st[sp++] = r[k];
            break;
        }
        case Op::GraphCall:
        case Op::GraphRead: {
            sp -= I.n;
            double r[1] = {0};
            std::string error = I.op == Op::GraphCall
                                    ? graph_builtin(static_cast<BuiltinId>(I.a), st + sp, r, env)
                                    : graph_read(I.a, I.n == 2, st + sp, r, env);
            if (!error.empty()) fail(code, pc, std::move(error));
            st[sp++] = r[0];
            break;
        }
        case Op::GraphPlace: {
            sp -= 9;
            double r[1] = {0};
            std::string error = graph_place(st + sp, r, env, code.spans[pc]);
            if (!error.empty()) fail(code, pc, std::move(error));
            st[sp++] = r[0];
            break;
        }
        case Op::GraphShape: {
            sp -= I.n;
            double r[3] = {0, 0, 0};
            std::string error = graph_shape(I.a, env_call_method(I), st + sp, r, env);
            if (!error.empty()) fail(code, pc, std::move(error));
            for (unsigned k = 0; k < (I.b >> kEnvMethodBits); ++k) st[sp++] = r[k];
            break;
        }
        }
    }
    if (result && sp > 0)
        for (int k = 0; k < std::min(sp, 3); ++k) result[k] = st[sp - std::min(sp, 3) + k];
    env.slice = slice;
    return RunStatus::Finished;
}

} // namespace

double CurveDef::operator()(double t) const {
    if (!(t >= 0)) t = 0; // NaN too
    if (t > 1) t = 1;
    const std::size_t n = ys.size();
    if (!bezier) {
        // piecewise linear through (xs[i], ys[i])
        if (t <= xs.front()) return ys.front();
        for (std::size_t i = 1; i < n; ++i)
            if (t <= xs[i]) {
                double w = xs[i] > xs[i - 1] ? (t - xs[i - 1]) / (xs[i] - xs[i - 1]) : 1.0;
                return ys[i - 1] + (ys[i] - ys[i - 1]) * w;
            }
        return ys.back();
    }
    // Bezier curve (x(u), y(u)) with Bernstein weights (de Casteljau); x increases with u, so
    // the u with x(u) = t is found by bisection; the ends are exact
    if (t <= xs.front()) return ys.front();
    if (t >= xs.back()) return ys.back();
    auto point = [&](double u, double& x, double& y) {
        std::vector<double> px(xs), py(ys);
        for (std::size_t r = 1; r < n; ++r)
            for (std::size_t i = 0; i + r < n; ++i) {
                px[i] = px[i] * (1 - u) + px[i + 1] * u;
                py[i] = py[i] * (1 - u) + py[i + 1] * u;
            }
        x = px[0];
        y = py[0];
    };
    double lo = 0, hi = 1, x = 0, y = 0;
    for (int k = 0; k < 50; ++k) {
        double mid = (lo + hi) / 2;
        point(mid, x, y);
        (x < t ? lo : hi) = mid;
    }
    point((lo + hi) / 2, x, y);
    return y;
}

void fuse(Code& code) {
    for (const Instr& I : code.instrs)
        if (is_jump(I.op)) return;
    if (code.consts.size() > 65535) return;
    std::vector<Instr> out;
    std::vector<Span> spans;
    for (std::size_t i = 0; i < code.instrs.size(); ++i) {
        const Instr& I = code.instrs[i];
        if (i + 2 < code.instrs.size() && I.op == Op::LoadLocal && I.n == 1 &&
            code.instrs[i + 1].op == Op::Const &&
            (code.instrs[i + 2].op == Op::Mul || code.instrs[i + 2].op == Op::Add)) {
            Op fused = code.instrs[i + 2].op == Op::Mul ? Op::LoadMulConst : Op::LoadAddConst;
            out.push_back(Instr{fused, 0, static_cast<std::uint16_t>(code.instrs[i + 1].a), I.a});
            spans.push_back(code.spans[i + 2]);
            i += 2;
            continue;
        }
        out.push_back(I);
        spans.push_back(code.spans[i]);
    }
    code.instrs = std::move(out);
    code.spans = std::move(spans);
}

double eval_number(const Code& code, double* frame, EvalEnv& env) {
    double r[3] = {0, 0, 0};
    run(code, frame, env, r);
    return r[0];
}

StackCheck check_stack(const Code& code) {
    // the range of depths each instruction can start at, widened until nothing changes; an
    // upper bound past the VM's stack stops the walk (a loop that keeps pushing)
    const std::size_t size = code.instrs.size();
    std::vector<int> lo(size + 1, INT_MAX), hi(size + 1, -1);
    std::vector<std::size_t> work;
    StackCheck out;
    auto fail_at = [&](std::size_t pc, std::string why) {
        out.ok = false;
        out.pc = pc;
        out.error = std::move(why);
    };
    auto reach = [&](std::size_t from, std::int64_t target, int l, int h) {
        if (target < 0 || static_cast<std::size_t>(target) > size) {
            fail_at(from, fmt::format("jumps to {}, outside the code", target));
            return;
        }
        auto t = static_cast<std::size_t>(target);
        if (l >= lo[t] && h <= hi[t]) return;
        lo[t] = std::min(lo[t], l);
        hi[t] = std::max(hi[t], h);
        work.push_back(t);
    };
    if (size == 0) return out;
    reach(0, 0, 0, 0);
    while (!work.empty() && out.ok) {
        const std::size_t pc = work.back();
        work.pop_back();
        out.max_depth = std::max(out.max_depth, hi[pc]);
        if (pc == size) continue; // fell off the end
        const Instr& I = code.instrs[pc];
        const StackEffect e = stack_effect(I);
        if (lo[pc] < e.pops) {
            fail_at(pc, fmt::format("{} pops {} with {} on the stack", op_info(I.op).name, e.pops, lo[pc]));
            break;
        }
        const int l = lo[pc] - e.pops + e.pushes, h = hi[pc] - e.pops + e.pushes;
        if (h > static_cast<int>(kStackSize)) {
            fail_at(pc, fmt::format("the stack can grow past {} numbers", kStackSize));
            break;
        }
        out.max_depth = std::max(out.max_depth, h);
        switch (op_info(I.op).flow) {
        case OpFlow::Next:
            reach(pc, static_cast<std::int64_t>(pc) + 1, l, h);
            break;
        case OpFlow::Jump:
            reach(pc, I.a, l, h);
            break;
        case OpFlow::Branch:
            reach(pc, static_cast<std::int64_t>(pc) + 1, l, h);
            reach(pc, I.a, l, h);
            break;
        case OpFlow::BranchKeep: // the jump keeps what the fall-through pops
            reach(pc, static_cast<std::int64_t>(pc) + 1, l, h);
            reach(pc, I.a, lo[pc], hi[pc]);
            break;
        case OpFlow::End:
            break;
        }
    }
    return out;
}

std::string disassemble(const Code& code) {
    std::string out;
    for (std::size_t pc = 0; pc < code.instrs.size(); ++pc) {
        const Instr& I = code.instrs[pc];
        out += fmt::format("{:4} {:<18} a={} n={} b={}\n", pc, op_info(I.op).name, I.a, I.n, I.b);
    }
    return out;
}

} // namespace plant
