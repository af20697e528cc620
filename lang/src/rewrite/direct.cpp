// The direct path: when every module is copied or rewritten by a direct template, the size of
// any stretch's output is known before it is written (count_direct), so the derivation allocates
// the output once and each thread writes its stretch in place (write_direct).
#include "rewriter.hpp"

#include "plant/streams.hpp"

#include <algorithm>

namespace plant {

namespace {

bool holds(Op op, double x, double y) {
    switch (op) {
    case Op::Lt:
        return x < y;
    case Op::Le:
        return x <= y;
    case Op::Gt:
        return x > y;
    case Op::Ge:
        return x >= y;
    case Op::Eq:
        return x == y;
    default:
        return x != y; // Ne
    }
}

// Records a snapshot of a writer (Worker::snaps). Out of line: the writer's loop stays as tight
// as without it.
[[gnu::noinline]] void snapshot(std::vector<std::uint64_t>& snaps, std::size_t written,
                                const std::uint64_t* tally, std::size_t outcomes) {
    snaps.push_back(written);
    snaps.insert(snaps.end(), tally, tally + outcomes);
}

// Fills the block offsets (ModuleString::block_at) of the kBlock-th modules among the n just
// written at `from`, module index `at` of `out`, whose parameters start at p; returns the
// index of the next such module after them. Out of line: the writer calls it once in kBlock
// modules, while the kinds it sums are still in cache (instead of a pass over the whole output
// after writing it, ModuleString::index_range).
[[gnu::noinline]] std::size_t mark_blocks(ModuleString& out, const KindId* from, std::size_t n,
                                          std::size_t at, std::size_t p, std::size_t next,
                                          const std::uint8_t* stored_of) {
    constexpr std::size_t B = ModuleString::kBlock;
    for (std::size_t j = 0; next < at + n; next += B) {
        for (; j < next - at; ++j) p += stored_of[from[j]];
        out.block_at[next >> ModuleString::kBlockShift] = static_cast<std::uint32_t>(p);
    }
    return next;
}

// Per kind, the outcome of copying a module of it when its symbol has no productions, else
// kNoCopy: write_direct reads a run of copied modules with one table load a module (the kind's)
// instead of three for its symbol (the symbol, whether it has productions, its copy's outcome).
constexpr std::uint32_t kNoCopy = ~std::uint32_t{0};
const std::uint32_t* copy_outcomes(const RulePlan& plan, const SymbolReader& reader, std::size_t kinds,
                                   std::vector<std::uint32_t>& out) {
    // (a symbol past the plan's cannot be in the string: the kinds of a string made without a
    // program, 0x8000 plain ones, are left at kNoCopy past the plan's symbols)
    const std::size_t symbols = plan.has_prod.size();
    out.assign(kinds, kNoCopy);
    for (std::size_t k = 0; k < std::min<std::size_t>(reader.plain, symbols); ++k)
        out[k] = plan.has_prod[k] ? kNoCopy : plan.outcome_at[k];
    for (std::size_t k = reader.plain; k < kinds; ++k)
        if (const SymbolId s = reader.table[k - reader.plain]; s < symbols)
            out[k] = plan.has_prod[s] ? kNoCopy : plan.outcome_at[s];
    return out.data();
}

} // namespace

// The first production whose condition holds applies; when it is weighted, every weighted
// production from it on whose condition holds is a candidate and one is drawn by weight, with
// the same arithmetic as Rewriter::choose (general.cpp), so that both routes draw alike.
const RulePlan::Guard* Rewriter::pick_guarded(std::size_t i, const ModuleArgs& a,
                                              const RulePlan::Guarded& g) const {
    if (in.arity(i) != g.width) return nullptr; // no pattern matches
    const RulePlan::Guard* gs = plan.guards.data() + g.first;
    auto ok = [&](const RulePlan::Guard& q) {
        if (q.op == Op::Halt) return true;
        return q.swapped ? holds(q.op, q.constant, a[q.param]) : holds(q.op, a[q.param], q.constant);
    };
    std::uint32_t k = 0;
    while (k < g.count && !ok(gs[k])) ++k;
    if (k == g.count) return nullptr;
    if (gs[k].weight < 0) return &gs[k];
    const RulePlan::Guard* options[64];
    std::size_t count = 0;
    double total = 0;
    for (std::uint32_t j = k; j < g.count; ++j) {
        if (gs[j].weight < 0 || !ok(gs[j]) || gs[j].weight == 0 || count == 64) continue;
        options[count++] = &gs[j];
        total += gs[j].weight;
    }
    if (count == 0) return nullptr;
    double scale = 1;
    if (!std::isfinite(total)) {
        double largest = 0;
        for (std::size_t j = 0; j < count; ++j) largest = std::max(largest, options[j]->weight);
        scale = 1 / largest;
        total = 0;
        for (std::size_t j = 0; j < count; ++j) total += options[j]->weight * scale;
    }
    double u = random_unit(random_bits_at(draw_phase, i, stream::kChoiceDraw)) * total;
    std::size_t pick = count - 1;
    for (std::size_t j = 0; j < count; ++j) {
        const double weight = options[j]->weight * scale;
        if (u < weight) {
            pick = j;
            break;
        }
        u -= weight;
    }
    return options[pick];
}

Rewriter::Counts Rewriter::count_direct(std::size_t b, std::size_t e) const {
    Counts c;
    const SymbolReader sym_of = in.symbols();
    const double* a = in.params.data() + in.offset(b); // module i's stored parameters
    for (std::size_t i = b; i < e; a += in.stored(i), ++i) {
        const SymbolId s = sym_of(i);
        if (!plan.has_prod[s]) {
            ++c.modules;
            c.params += in.stored(i);
            continue;
        }
        const Production* pr = plan.direct[s];
        if (!pr) {
            const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(plan.guarded_at[s])];
            if (!g.uniform)
                if (const RulePlan::Guard* q = pick_guarded(i, in.args_at(i, a), g)) pr = q->pr;
            if (!pr) { // copied, or as large as a copy
                ++c.modules;
                c.params += in.stored(i);
                continue;
            }
        } else if (in.arity(i) != pr->strict[0].width) {
            c.ok = false;
            return c;
        }
        c.modules += pr->tmpl.syms.size();
        c.params += pr->tmpl.stored.size();
        c.new_ids += pr->tmpl.fresh();
    }
    return c;
}

// Writes the output of modules [b, e) at module m_at and parameter p_at of `out`, whose
// arrays are already sized; new identities are numbered from id_at.
// Identities are written only when `out` keeps them (Ids, a template argument so that the
// loop has no test for it).
Rewriter::Counts Rewriter::write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out,
                                        std::size_t m_at, std::size_t p_at, ModuleId id_at,
                                        std::uint64_t* tally) {
    // Kinds: whether the table has kinds past the symbols' own (plain kinds with numbers, kinds
    // of constants); otherwise every kind is its symbol, and the loop does without the test
    const bool kinds = in.kind_table && in.kind_table->size() > 0;
    if (out.keep_ids)
        return kinds ? write_direct<true, true>(w, b, e, out, m_at, p_at, id_at, tally)
                     : write_direct<true, false>(w, b, e, out, m_at, p_at, id_at, tally);
    return kinds ? write_direct<false, true>(w, b, e, out, m_at, p_at, id_at, tally)
                 : write_direct<false, false>(w, b, e, out, m_at, p_at, id_at, tally);
}
template <bool Ids, bool Kinds>
Rewriter::Counts Rewriter::write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out,
                                        std::size_t m_at, std::size_t p_at, ModuleId id_at,
                                        std::uint64_t* tally) {
    w.frame.assign(plan.frame_size, 0.0);
    const SymbolReader reader = in.symbols();
    auto sym_of = [reader](std::size_t j) -> SymbolId {
        if constexpr (Kinds)
            return reader(j);
        else
            return reader.kinds[j];
    };
    KindId* S = out.kinds.data() + m_at;
    ModuleId* ID = Ids ? out.ids.data() + m_at : nullptr;
    const std::uint8_t* stored_of = in.kind_table->stored.data();
    double* PA = out.params.data() + p_at;
    std::size_t q = in.offset(b); // where module i's parameters start
    const std::uint32_t* at = plan.outcome_at.data();
    const ModuleId id0 = id_at;
    std::size_t p = p_at;
    double values[256];
    std::size_t i = b;
    std::size_t next_check = b + kSnapEvery;
    const std::size_t outcomes = plan.outcome_tmpl.size();
    w.snaps.clear();
    const std::uint32_t* copy_of = copy_outcomes(plan, reader, in.kind_table->stored.size(), w.copy_outcome);
    // the next module that starts a block (ModuleString::block_at), as a position in `out`
    constexpr std::size_t B = ModuleString::kBlock;
    std::size_t next_block = (m_at + B - 1) & ~(B - 1);
    KindId* const S0 = out.kinds.data();
    KindId* block_mark = S0 + next_block;
    auto marks = [&](const KindId* from, std::size_t n, std::size_t p_from) {
        if (from + n > block_mark) [[unlikely]] {
            next_block =
                mark_blocks(out, from, n, static_cast<std::size_t>(from - S0), p_from, next_block, stored_of);
            block_mark = S0 + next_block;
        }
    };
    while (i < e) {
        if (i >= next_check) { // a long step can be interrupted (Ctrl-C in the REPL)
            next_check = i + kSnapEvery;
            if (w.env.interrupt && w.env.interrupt->load())
                throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
            // the snapshot from which the next step sizes its threads' stretches
            snapshot(w.snaps, static_cast<std::size_t>(S - (out.kinds.data() + m_at)), tally, outcomes);
        }
        const SymbolId s = sym_of(i);
        const Production* prp = plan.direct[s];
        std::uint32_t outcome = at[s] + 1;
        if (!prp && plan.has_prod[s]) {
            const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(plan.guarded_at[s])];
            if (const RulePlan::Guard* gd = pick_guarded(i, in.args_at(i, in.params.data() + q), g)) {
                prp = gd->pr;
                outcome += static_cast<std::uint32_t>(gd - (plan.guards.data() + g.first));
            }
        }
        if (!prp) { // a run of modules without productions (or none that applies): copy it
            ++tally[at[s]];
            std::uint32_t np = stored_of[reader.kinds[i]];
            std::size_t j = i + 1;
            for (std::uint32_t o; j < e && (o = copy_of[reader.kinds[j]]) != kNoCopy; ++j) {
                ++tally[o];
                np += stored_of[reader.kinds[j]];
            }
            const std::size_t n = j - i;
            if (n <= 8 && np <= 8) {
                // the usual run between two rewritten modules is a few turtle symbols: plain
                // loops beat three library calls
                for (std::size_t k = 0; k < n; ++k) {
                    S[k] = in.kinds[i + k];
                    if constexpr (Ids) ID[k] = in.ids[i + k];
                }
                for (std::uint32_t k = 0; k < np; ++k) PA[k] = in.params[q + k];
            } else {
                std::memcpy(S, in.kinds.data() + i, n * sizeof(KindId));
                if constexpr (Ids) std::memcpy(ID, in.ids.data() + i, n * sizeof(ModuleId));
                if (np) std::memcpy(PA, in.params.data() + q, np * sizeof(double));
            }
            marks(S, n, p);
            S += n;
            if constexpr (Ids) ID += n;
            PA += np;
            p += np;
            q += np;
            i = j;
            continue;
        }
        ++tally[outcome];
        const Production& pr = *prp;
        const SuccessorTemplate& t = pr.tmpl;
        if (const std::int32_t affine = plan.outcome_args[outcome]; affine >= 0) {
            put_affine<Ids>(t, plan.args.data() + affine, in.args_at(i, in.params.data() + q),
                            Ids ? in.ids[i] : 0, id_at, S, PA, ID);
        } else {
            if (!t.holes.empty()) {
                bind_args(w, i, in.params.data() + q, pr.strict[0]);
                w.env.position = i;
                w.env.draw = 0;
                w.env.id = in.id(i);
                w.env.out = nullptr;
                compute_holes(w, t, values);
                check_holes(t, values);
            }
            put_template<Ids>(t, values, Ids ? in.ids[i] : 0, id_at, S, PA, ID);
        }
        const std::size_t m = t.syms.size();
        marks(S, m, p);
        if constexpr (Ids) ID += m;
        S += m;
        PA += t.stored.size();
        p += t.stored.size();
        q += stored_of[reader.kinds[i]];
        ++i;
    }
    Counts c;
    c.modules = static_cast<std::size_t>(S - (out.kinds.data() + m_at));
    c.params = p - p_at;
    c.new_ids = id_at - id0;
    // (block_at, sized by the caller, was filled as the modules were written)
    return c;
}

} // namespace plant
