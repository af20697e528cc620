// The copy kernel: the route for strings without numbers or identities under a plan whose
// rewritten kinds all have a direct template that stores no numbers (RulePlan::copy_kernel;
// ABOP's Fig. 1.24 and other bracketed OL-systems). A step is then one copy of each module's
// successor kinds from a table: no matching, no parameters, no per-module outcome to tally.
// The output's size comes from how many modules of each kind the input holds, counted once for
// a string this route did not write and carried from step to step otherwise (a module of kind
// k becomes the kinds of k's successor, so the next string's counts follow from the last's).
#include "engine.hpp"
#include "plant/derive.hpp"

#include <algorithm>
#include <atomic>
#include <cstring>
#include <stdexcept>

namespace plant {

bool Engine::copies_apply(const RulePlan& plan, const ModuleString& in) {
    return plan.copy_kernel && in.params.empty() && !in.keep_ids && in.kind_table == &plan.P.kinds &&
           !in.empty();
}

namespace {

// How many modules of each kind `s` holds.
void count_kinds(const ModuleString& s, std::vector<std::uint64_t>& counts) {
    const KindId* k = s.kinds.data();
    const std::size_t n = s.size();
    // four tallies, summed at the end: a run of one kind (FFFF...) would otherwise wait on
    // its own last increment
    const std::size_t K = counts.size();
    std::vector<std::uint64_t> part(4 * K, 0);
    std::size_t i = 0;
    for (; i + 4 <= n; i += 4) {
        ++part[k[i]];
        ++part[K + k[i + 1]];
        ++part[2 * K + k[i + 2]];
        ++part[3 * K + k[i + 3]];
    }
    for (; i < n; ++i) ++part[k[i]];
    for (std::size_t j = 0; j < K; ++j) counts[j] = part[j] + part[K + j] + part[2 * K + j] + part[3 * K + j];
}

// Writes the successors of in[0, n) at out[0, ...), which holds exactly `modules`; returns how
// many it wrote (== modules unless the counts were wrong).
std::size_t write_copies(const RulePlan& plan, const KindId* in, std::size_t n, KindId* out,
                         std::size_t modules, const std::atomic<bool>* interrupt) {
    using Succ = RulePlan::KindSucc;
    constexpr std::size_t kPad = Succ::kMax;
    const Succ* succ = plan.copy_succ.data();
    const std::uint8_t* len = plan.copy_len.data();
    const std::size_t longest = plan.copy_longest;
    std::size_t m = 0, i = 0, next_check = 65536;
    while (i < n) {
        // the modules whose padded copy surely fits: each moves the end at most `longest` on
        const std::size_t room = modules >= m + kPad ? (modules - m - kPad) / longest + 1 : 0;
        if (room == 0) break;
        const std::size_t stop = std::min({n, i + room, next_check});
        for (; i < stop; ++i) {
            const KindId k = in[i];
            std::memcpy(out + m, succ[k].kinds, sizeof succ[k].kinds);
            m += len[k];
        }
        if (i >= next_check) { // a long step can be interrupted (Ctrl-C in the REPL)
            next_check = i + 65536;
            if (interrupt && interrupt->load())
                throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
        }
    }
    for (; i < n; ++i) { // the last few, exactly
        const KindId k = in[i];
        if (m + len[k] > modules) return modules + 1;
        std::memcpy(out + m, succ[k].kinds, len[k] * sizeof(KindId));
        m += len[k];
    }
    return m;
}

} // namespace

void Engine::rewrite_copies(const Derivation& d, const ModuleString& in, ModuleString& out,
                            const RulePlan& plan, bool counted) {
    const std::size_t K = plan.copy_succ.size();
    std::vector<std::uint64_t> have;
    bool carried = counted && counts.kinds.size() == K;
    if (carried) {
        have = std::move(counts.kinds);
    } else {
        have.assign(K, 0);
        count_kinds(in, have);
    }
    std::vector<std::uint64_t> next(K, 0);
    std::uint64_t modules = 0, fresh = 0;
    auto tally = [&] {
        modules = fresh = 0;
        std::fill(next.begin(), next.end(), 0);
        for (std::size_t k = 0; k < K; ++k) {
            const std::uint64_t c = have[k];
            if (c == 0) continue;
            modules += c * plan.copy_len[k];
            fresh += c * plan.copy_fresh[k];
            for (std::size_t j = 0; j < plan.copy_len[k]; ++j) next[plan.copy_succ[k].kinds[j]] += c;
        }
        check_limits(d, modules, 0); // before allocating anything
        // (on 1.24d, n = 10, steps 8 to 10 each mapped and cleared a fresh 2 MiB page before
        // the kept string took whole blocks, see size_whole)
        out.kinds.clear();
        size_whole(out.kinds, modules);
        return write_copies(plan, in.kinds.data(), in.size(), out.kinds.data(), modules, d.opt_.interrupt);
    };
    if (tally() != modules) {
        // carried counts that no longer describe the string (it cannot happen while every edit
        // of a string forgets them, but a wrong size must never be written): count, write again
        if (!carried) throw std::logic_error("the copy kernel miscounted its input");
        count_kinds(in, have);
        carried = false;
        if (tally() != modules) throw std::logic_error("the copy kernel miscounted its input");
    }
    out.block_at.assign((modules + ModuleString::kBlock - 1) >> ModuleString::kBlockShift, 0);
    next_id += fresh;
    if (!interpreting) {
        counts.kinds = std::move(next);
        counts.modules.clear(); // (the direct path's per-symbol counts are not kept here)
        counts.arity.clear();
        counts.stored.clear();
        counts.of = out.kinds.data();
        counts.size = out.size();
    }
}

} // namespace plant
