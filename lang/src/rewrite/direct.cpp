// The direct path: when every module is copied or rewritten by a direct template, the size of
// any stretch's output is known before it is written (count_direct), so the derivation allocates
// the output once and each thread writes its stretch in place (write_direct).
#include "rewriter.hpp"

#include "plant/streams.hpp"

#include <algorithm>
#include <type_traits>

namespace plant {

namespace {

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

// Whether a module of table kind k, of symbol s, can be copied with a run and then have its
// numbers rewritten in place (KindRow::kPatch): s is guarded, and whichever of its productions
// applies writes one module of kind k, every stored number of which is computed from the
// module's own (RulePlan::outcome_args), so that its kind and identity stay as copied. So a
// rule such as `F(l) : l > 0 -> F(l * 1.1)` does not cut the runs of copied modules around each
// F. (kind_rows asks it only of kinds that store all their numbers.)
bool patchable(const RulePlan& plan, SymbolId s, KindId k) {
    if (plan.guarded_at[s] < 0) return false;
    const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(plan.guarded_at[s])];
    if (!g.uniform || g.picks < 0) return false;
    for (std::uint32_t j = 0; j < g.count; ++j) {
        const SuccessorTemplate& t = plan.guards[g.first + j].pr->tmpl;
        if (t.kinds.size() != 1 || t.kinds[0] != k || t.holes.size() != t.stored.size() ||
            plan.outcome_args[plan.outcome_at[s] + 1 + j] < 0)
            return false;
    }
    return true;
}

// The writer's table of kinds (KindRow), in `rows`. A run of copied modules is read with one
// table load a module (the kind's) instead of three for its symbol (the symbol, whether it has
// productions, its copy's outcome).
const KindRow* kind_rows(const RulePlan& plan, const KindTable& kt, std::vector<KindRow>& rows,
                         std::vector<PatchOne>& ones) {
    // (a symbol past the plan's cannot be in the string: the kinds of a string made without a
    // program, 0x8000 plain ones, are left at kNoCopy past the plan's symbols)
    const std::size_t symbols = plan.has_prod.size(), kinds = kt.stored.size();
    rows.assign(kinds, KindRow{});
    ones.clear();
    ones.reserve(kinds); // (so the rows' pointers into it stay valid)
    for (std::size_t k = 0; k < kinds; ++k) {
        const bool plain = k < kt.plain;
        const SymbolId s = plain ? static_cast<SymbolId>(k) : kt.symbol[k - kt.plain];
        KindRow& r = rows[k];
        r.stored = kt.stored[k];
        r.arity = plain ? 0 : kt.arity[k - kt.plain];
        r.dense = plain || kt.layout_at[k - kt.plain] == KindTable::kAllStored;
        if (s >= symbols) continue;
        r.at = plan.outcome_at[s];
        if (!plan.has_prod[s]) {
            r.copy = plan.outcome_at[s];
            continue;
        }
        r.direct = plan.direct[s];
        if (!r.direct) r.guarded = plan.guarded_at[s];
        if (plain || !r.dense || !patchable(plan, s, static_cast<KindId>(k))) continue;
        r.copy = KindRow::kPatch;
        // one guard, and no draw: its pick table holds no guard for none and it for all
        const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(r.guarded)];
        const RulePlan::Pick* pk = plan.picks.data() + g.picks;
        if (g.count == 1 && g.tests_n == 1 && g.width == r.arity && pk[0].count == 0 &&
            pk[0].only == RulePlan::kNone && pk[1].count == 0 && pk[1].only == 0) {
            const RulePlan::Emit& em = plan.emits[r.at + 1];
            r.one = &ones.emplace_back(
                PatchOne{plan.guards[g.first], plan.moved.data() + em.moved_at, em.moved_n, r.at});
        }
    }
    return rows.data();
}

} // namespace

// The first production whose condition holds applies; when it is weighted, every weighted
// production from it on whose condition holds is a candidate and one is drawn by weight, with
// the same arithmetic as Rewriter::choose (general.cpp), so that both routes draw alike.
// (inline: only the writer and count_direct below call it)
template <typename Numbers>
inline std::int32_t Rewriter::pick_guarded(std::size_t i, const Numbers& x, std::uint32_t arity,
                                           const RulePlan::Guarded& g) const {
    if (arity != g.width) return -1; // no pattern matches
    if (g.picks < 0) {
        if constexpr (std::is_same_v<Numbers, ModuleArgs>)
            return pick_unlisted(i, x, g);
        else
            return pick_unlisted(i, ModuleArgs(x, arity), g);
    }
    // which of the symbol's intervals hold their parameters, then the table (RulePlan::build_picks;
    // a module without parameters has no conditions, so no tests)
    const RulePlan::Test* ts = plan.tests.data() + g.tests_first;
    std::uint32_t inside = 0;
    for (std::uint32_t k = 0; k < g.tests_n; ++k) inside |= std::uint32_t{ts[k].inside(x[ts[k].param])} << k;
    const RulePlan::Pick& pk = plan.picks[static_cast<std::size_t>(g.picks) + inside];
    if (pk.count == 0) return pk.only == RulePlan::kNone ? -1 : static_cast<std::int32_t>(pk.only);
    const RulePlan::PickOption* o = plan.pick_options.data() + pk.first;
    double u = random_unit(random_bits_at(draw_phase, i, stream::kChoiceDraw)) * pk.total;
    if (pk.count <= 2) {
        // one option or two: the second when there is one and the draw is not below the first's
        // weight (the loop below, without a branch on a random draw that the processor would
        // mispredict about as often as the smaller weight's share)
        const std::uint32_t second =
            static_cast<std::uint32_t>(pk.count == 2) & static_cast<std::uint32_t>(!(u < o[0].weight));
        return static_cast<std::int32_t>(o[second].guard);
    }
    for (std::uint32_t j = 0; j + 1 < pk.count; ++j) {
        if (u < o[j].weight) return static_cast<std::int32_t>(o[j].guard);
        u -= o[j].weight;
    }
    return static_cast<std::int32_t>(o[pk.count - 1].guard);
}

// pick_guarded for a symbol with more guards than the table takes.
std::int32_t Rewriter::pick_unlisted(std::size_t i, const ModuleArgs& a, const RulePlan::Guarded& g) const {
    const RulePlan::Guard* gs = plan.guards.data() + g.first;
    auto ok = [&](const RulePlan::Guard& q) { return g.width == 0 || q.holds(a[q.param]); };
    std::uint32_t k = 0;
    while (k < g.count && !ok(gs[k])) ++k;
    if (k == g.count) return -1;
    if (gs[k].weight < 0) return static_cast<std::int32_t>(k);
    const RulePlan::Guard* options[64];
    std::size_t count = 0;
    double total = 0;
    for (std::uint32_t j = k; j < g.count; ++j) {
        if (gs[j].weight < 0 || !ok(gs[j]) || gs[j].weight == 0 || count == 64) continue;
        options[count++] = &gs[j];
        total += gs[j].weight;
    }
    if (count == 0) return -1;
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
    return static_cast<std::int32_t>(options[pick] - gs);
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
                if (const std::int32_t k = pick_guarded(i, in.args_at(i, a), in.arity(i), g); k >= 0)
                    pr = plan.guards[g.first + static_cast<std::uint32_t>(k)].pr;
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

// write_direct's copy of the run of modules from i on (before e) that are copied or patched
// (KindRow::kPatch), module i included, whatever its row; their parameters start at q. Writes
// them at S, PA and ID, tallies them (module i's outcome excepted) and returns the end of the
// run, its parameters' count in np.
template <bool Ids>
std::size_t Rewriter::copy_run(const KindRow* rows, std::size_t i, std::size_t e, std::size_t q, KindId* S,
                               double* PA, ModuleId* ID, std::uint64_t* tally, std::uint32_t& np) const {
    const KindId* in_kinds = in.kinds.data();
    const double* in_params = in.params.data();
    const ModuleId* in_ids = Ids ? in.ids.data() : nullptr;
    np = rows[in_kinds[i]].stored;
    std::size_t j = i + 1;
    // the patchable modules of the run: where they are in it, and their numbers
    constexpr std::uint32_t kMaxPatches = 8;
    std::uint32_t patches = 0, patch_m[kMaxPatches], patch_p[kMaxPatches];
    const KindRow* patch_r[kMaxPatches];
    for (; j < e; ++j) {
        const KindRow& rj = rows[in_kinds[j]];
        if (rj.copy >= KindRow::kPatch) {
            if (rj.copy == KindRow::kNoCopy || patches == kMaxPatches) break;
            patch_r[patches] = &rj;
            patch_m[patches] = static_cast<std::uint32_t>(j - i);
            patch_p[patches++] = np;
        } else {
            ++tally[rj.copy];
        }
        np += rj.stored;
    }
    const std::size_t n = j - i;
    if (n <= 8 && np <= 8) {
        // the usual run between two rewritten modules is a few turtle symbols: plain loops beat
        // three library calls
        for (std::size_t k = 0; k < n; ++k) {
            S[k] = in_kinds[i + k];
            if constexpr (Ids) ID[k] = in_ids[i + k];
        }
        for (std::uint32_t k = 0; k < np; ++k) PA[k] = in_params[q + k];
    } else {
        std::memcpy(S, in_kinds + i, n * sizeof(KindId));
        if constexpr (Ids) std::memcpy(ID, in_ids + i, n * sizeof(ModuleId));
        if (np) std::memcpy(PA, in_params + q, np * sizeof(double));
    }
    const RulePlan::Emit* emits = plan.emits.data();
    for (std::uint32_t k = 0; k < patches; ++k) { // as the top of write_direct's loop would
        const KindRow& rm = *patch_r[k];
        const double* at = in_params + q + patch_p[k]; // all its numbers (the row is dense)
        if (const PatchOne* one = rm.one) {
            const bool holds = one->guard.holds(at[one->guard.param]);
            ++tally[one->at + holds];
            if (holds) put_moved(*one, at, PA + patch_p[k]);
            continue;
        }
        const std::size_t m = i + patch_m[k];
        const RulePlan::Guarded& g = plan.guarded[static_cast<std::size_t>(rm.guarded)];
        const std::int32_t gd = pick_guarded(m, at, rm.arity, g);
        const std::uint32_t o = gd < 0 ? rm.at : rm.at + 1 + static_cast<std::uint32_t>(gd);
        ++tally[o];
        if (gd >= 0) put_numbers(o, emits[o], at, PA + patch_p[k]);
    }
    return j;
}

// Writes the output of modules [b, e) at module m_at and parameter p_at of `out`, whose
// arrays are already sized; new identities are numbered from id_at.
// Identities are written only when `out` keeps them (Ids, a template argument so that the
// loop has no test for it).
Rewriter::Counts Rewriter::write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out,
                                        std::size_t m_at, std::size_t p_at, ModuleId id_at,
                                        std::uint64_t* tally) {
    if (out.keep_ids) return write_direct<true>(w, b, e, out, m_at, p_at, id_at, tally);
    return write_direct<false>(w, b, e, out, m_at, p_at, id_at, tally);
}
template <bool Ids>
Rewriter::Counts Rewriter::write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out,
                                        std::size_t m_at, std::size_t p_at, ModuleId id_at,
                                        std::uint64_t* tally) {
    w.frame.assign(plan.frame_size, 0.0);
    // the tables, read through local copies (members read through `in` or `plan` would be
    // reloaded after every store)
    const KindRow* rows = kind_rows(plan, *in.kind_table, w.kind_rows, w.patch_ones);
    const KindId* in_kinds = in.kinds.data();
    const double* in_params = in.params.data();
    const ModuleId* in_ids = Ids ? in.ids.data() : nullptr;
    const RulePlan::Guarded* guarded = plan.guarded.data();
    const RulePlan::Guard* guards = plan.guards.data();
    const RulePlan::Emit* emits = plan.emits.data();
    KindId* S = out.kinds.data() + m_at;
    ModuleId* ID = Ids ? out.ids.data() + m_at : nullptr;
    const std::uint8_t* stored_of = in.kind_table->stored.data();
    double* PA = out.params.data() + p_at;
    std::size_t q = in.offset(b); // where module i's parameters start
    const ModuleId id0 = id_at;
    std::size_t p = p_at;
    double values[256];
    std::size_t i = b;
    std::size_t next_check = b + kSnapEvery;
    const std::size_t outcomes = plan.outcome_tmpl.size();
    w.snaps.clear();
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
        const KindRow& r = rows[in_kinds[i]];
        const Production* prp = r.direct;
        std::uint32_t outcome = r.at + 1;
        if (r.guarded >= 0) { // the guard that applies (see pick_guarded), if one does
            const RulePlan::Guarded& g = guarded[static_cast<std::size_t>(r.guarded)];
            const std::int32_t k = r.dense ? pick_guarded(i, in_params + q, r.arity, g)
                                           : pick_guarded(i, in.args_at(i, in_params + q), r.arity, g);
            if (k >= 0) {
                prp = guards[g.first + static_cast<std::uint32_t>(k)].pr;
                outcome += static_cast<std::uint32_t>(k);
            }
        }
        if (!prp) { // a run of modules without productions (or none that applies): copy it
            ++tally[r.at];
            std::uint32_t np = 0;
            const std::size_t j = copy_run<Ids>(rows, i, e, q, S, PA, ID, tally, np);
            const std::size_t n = j - i;
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
        const RulePlan::Emit& em = emits[outcome];
        std::uint32_t m = 0, stored = 0;
        if (em.kinds) {
            if (r.dense)
                put_affine<Ids>(outcome, em, in_params + q, Ids ? in_ids[i] : 0, id_at, S, PA, ID);
            else
                put_affine<Ids>(outcome, em, in.args_at(i, in_params + q), Ids ? in_ids[i] : 0, id_at, S, PA,
                                ID);
            m = em.m;
            stored = em.stored_n;
        } else {
            const Production& pr = *prp;
            const SuccessorTemplate& t = pr.tmpl;
            if (!t.holes.empty()) {
                bind_args(w, i, in_params + q, pr.strict[0]);
                w.env.position = i;
                w.env.draw = 0;
                w.env.id = in.id(i);
                w.env.out = nullptr;
                compute_holes(w, t, values);
                check_holes(t, values);
            }
            put_template<Ids>(t, values, Ids ? in_ids[i] : 0, id_at, S, PA, ID);
            m = static_cast<std::uint32_t>(t.syms.size());
            stored = static_cast<std::uint32_t>(t.stored.size());
        }
        marks(S, m, p);
        if constexpr (Ids) ID += m;
        S += m;
        PA += stored;
        p += stored;
        q += r.stored;
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
