// The symbol kernel: the route for parameterless strings without identities under a plan whose
// rewritten symbols all have a parameterless direct template or a context table (see
// RulePlan::build_symbol_kernel).
#include "rewriter.hpp"

#include <algorithm>

namespace plant {

namespace {

// Resizes one of the output's arrays. Kept out of line: inlined, vector's growth path copied
// five times into run_symbols more than doubles the loop's code, and the first step (the one a
// fresh process runs with cold caches) pays for it.
template <typename Vector> [[gnu::noinline]] void resize(Vector& v, std::size_t size) {
    v.resize(size);
}

// A push onto a full stack of saved keys: twice the room (out of the loops' common case).
// (The stack's pointer is returned, not written through a reference: a local whose address
// escapes must be reloaded after every store of the loop that might reach it.)
[[gnu::noinline]] ContextKey* grow_stack(std::vector<ContextKey>& saved) {
    saved.resize(2 * saved.size());
    return saved.data();
}

} // namespace

// run_range for strings without parameters or identities under a plan with a symbol kernel
// (parameterless context-sensitive systems such as ABOP's Fig. 1.31). A module's successor
// comes from its symbol's block: itself, its direct template, or the context table's entry
// for its neighbours' keys; it is written as one fixed-size copy of padded symbols, and
// parameter offsets are all zero. Neighbours are carried along rather than searched for:
// - the left key: the key of the last module context sees, saved at each '[' and taken back
//   at its ']';
// - the right keys come from one right-to-left pass that does the same mirrored, so there is no
//   bracket table. The kernel runs on one thread over the whole string (Engine::rewrite): split
//   over two threads it needed the bracket table, a search for each right neighbour and a join,
//   and ran 1.4x slower on 1.31a at n = 50 (docs/rewriting.md).
void Rewriter::run_symbols(Worker& w) {
    using Plan = RulePlan;
    ModuleString& out = w.out;
    EvalEnv& env = w.env;
    const SymbolId* in_sym = in.kinds.data();
    const Plan::SymbolRow* rows = plan.sym_rows.data();
    const Plan::SymbolSucc* succs = plan.succ_flat.data();
    const std::size_t K = plan.ctx_keys;
    const std::size_t Mmax = plan.max_modules_out;
    constexpr std::size_t kPad = Plan::SymbolSucc::kMax;

    // The right-to-left pass: the key of the last module context sees, saved at each ']'
    // and taken back at its '[' (going leftwards, a branch is entered at its ']'). A bracket
    // without a partner has none.
    // The keys are bytes (RulePlan::build_context_table keeps them under 255), one a module. Both
    // passes keep their saved keys on `stack`: the first grows it when full; the second pushes
    // only at '[' and is given room for every '[' the first counted, so its loop has no check
    // (one more live value there made the loop spill and run 10 % slower). Sized for the worst
    // case instead, the stretch's length, the stack was as large as the keys again and made
    // 1.31a's largest block (docs/rewriting.md, "Stalls").
    BigVector<ContextKey>& scratch = kernel_scratch ? *kernel_scratch : w.scratch;
    size_whole(scratch, n + 1);
    ContextKey* const rkey = scratch.data();
    std::vector<ContextKey> saved(256);
    std::size_t opens = 0;
    {
        ContextKey* stack = saved.data();
        std::size_t room = saved.size();
        ContextKey right{};
        std::size_t depth = 0;
        for (std::size_t j = n; j-- > 0;) {
            const Plan::SymbolRow r = rows[in_sym[j]];
            rkey[j] = right;
            if (r.shape == 0) {
                right = ContextKey{r.key};
            } else if (r.shape == Plan::kClose) {
                if (depth == room) stack = grow_stack(saved), room = saved.size();
                stack[depth++] = right;
                right = ContextKey{};
            } else if (r.shape == Plan::kOpen) {
                right = depth ? stack[--depth] : ContextKey{};
                ++opens;
            }
        }
    }
    if (saved.size() < opens) saved.resize(opens);
    ContextKey* const stack = saved.data();

    const std::size_t p_end = out.params.size(); // every module written here has none
    std::size_t m = out.size();
    std::size_t left = 0;
    std::size_t depth = 0; // the left keys at the open '['s are on the stack
    std::uint64_t fresh = 0;
    std::size_t i = 0, next_check = 65536;
    resize(out.kinds, std::max(out.kinds.capacity(), m)); // the room reserved is written in place
    while (i < n) {
        // the modules that fit: each writes at most Mmax, and a copy writes kPad
        std::size_t room = out.kinds.size() >= m + kPad ? (out.kinds.size() - m - kPad) / Mmax : 0;
        if (room == 0) {
            resize(out.kinds, std::max(m + Mmax + kPad, 2 * out.kinds.size()));
            continue;
        }
        if (i >= next_check) {
            next_check = i + 65536;
            if (env.interrupt && env.interrupt->load())
                throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
            if (m > env.max_output) {
                resize(out.kinds, m);
                limit_error();
            }
        }
        const std::size_t stop = std::min({n, i + room, next_check});
        KindId* S = out.kinds.data();
        for (; i < stop; ++i) {
            const Plan::SymbolRow row = rows[in_sym[i]];
            const Plan::SymbolSucc& su =
                succs[row.block + (left & row.lmask) * K + (static_cast<std::size_t>(rkey[i]) & row.rmask)];
            std::memcpy(S + m, su.syms, sizeof su.syms);
            m += su.len;
            fresh += su.fresh;
            if (row.shape == 0) {
                left = row.key;
            } else if (row.shape == Plan::kOpen) {
                stack[depth++] = ContextKey{static_cast<std::uint8_t>(left)};
            } else if (row.shape == Plan::kClose) {
                left = depth == 0
                           ? 0
                           : static_cast<std::size_t>(stack[--depth]); // a ']' without its '[': no left key
            }
        }
    }
    resize(out.kinds, m);
    const std::size_t b0 = out.block_at.size();
    resize(out.block_at, (m + ModuleString::kBlock - 1) >> ModuleString::kBlockShift);
    std::fill(out.block_at.begin() + static_cast<std::ptrdiff_t>(b0), out.block_at.end(),
              static_cast<std::uint32_t>(p_end));
    if (m > env.max_output) limit_error();
    env.new_count += static_cast<ModuleId>(fresh);
}

} // namespace plant
