// The derivation engine. One step: hooks, then (if some production reads query modules) a
// turtle pass, then the parallel rewrite, decomposition and cut, then hooks again.
//
// Parallel rewriting splits the old string into chunks, each rewritten by one thread into its
// own buffer; the buffers are joined with prefix sums. Random draws are keyed by the module's
// position in the old string and identities of new modules are numbered after the join, so the
// result is the same for any number of threads.
#include "plant/derive.hpp"

#include "plant/random.hpp"
#include "plant/vm.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cstring>
#include <chrono>
#include <unordered_set>
#include <cmath>
#include <span>
#include <thread>

namespace plant {

void ModuleString::append_range(const ModuleString& o, std::size_t b, std::size_t e) {
    if (b >= e) return;
    if (e - b == 1) { // the common case in context-sensitive grammars: one module between rewrites
        sym.push_back(o.sym[b]);
        ids.push_back(o.ids[b]);
        for (std::uint32_t k = o.poff[b]; k < o.poff[e]; ++k) params.push_back(o.params[k]);
        poff.push_back(static_cast<std::uint32_t>(params.size()));
        return;
    }
    const std::size_t n = e - b, m0 = sym.size(), p0 = params.size();
    const std::uint32_t pb = o.poff[b], pe = o.poff[e];
    sym.resize(m0 + n);
    ids.resize(m0 + n);
    poff.resize(m0 + n + 1);
    params.resize(p0 + (pe - pb));
    std::memcpy(sym.data() + m0, o.sym.data() + b, n * sizeof(SymbolId));
    std::memcpy(ids.data() + m0, o.ids.data() + b, n * sizeof(ModuleId));
    if (pe > pb) std::memcpy(params.data() + p0, o.params.data() + pb, (pe - pb) * sizeof(double));
    const auto shift = static_cast<std::uint32_t>(p0 - pb); // unsigned wrap-around is intended
    std::uint32_t* dst = poff.data() + m0 + 1;
    const std::uint32_t* src = o.poff.data() + b + 1;
    for (std::size_t i = 0; i < n; ++i) dst[i] = src[i] + shift;
}

std::vector<std::uint32_t> bracket_table(const ModuleString& s, SymbolId open, SymbolId close) {
    const auto n = static_cast<std::uint32_t>(s.size());
    std::vector<std::uint32_t> match(s.size(), n);
    std::vector<std::uint32_t> stack;
    for (std::uint32_t i = 0; i < n; ++i) {
        if (s.sym[i] == open) {
            stack.push_back(i);
        } else if (s.sym[i] == close && !stack.empty()) {
            match[i] = stack.back();
            match[stack.back()] = i;
            stack.pop_back();
        }
    }
    return match;
}

namespace {

constexpr std::uint64_t kChoiceDraw = 0xffffffffULL; // draw index of the stochastic choice

double now_ms() {
    using namespace std::chrono;
    return duration<double, std::milli>(steady_clock::now().time_since_epoch()).count();
}

} // namespace

// Everything one thread needs to rewrite a stretch of the string.
constexpr std::int64_t kUnknown = -2;

struct Worker {
    EvalEnv env;
    std::vector<double> frame;
    ModuleString out;
    std::optional<RuntimeError> error;
    // context neighbours of the module at ctx_at, found once for all its productions
    std::size_t ctx_at = ~std::size_t{0};
    std::int64_t ctx_left = kUnknown, ctx_right = kUnknown;
};

class Rewriter {
public:
    Rewriter(const Program& p, const ModuleString& in, const std::vector<const RuleSet*>& sets)
        : P(p), in(in), sets(sets), n(in.size()) {
        bool brackets = false;
        std::size_t frame = 1;
        has_prod.assign(P.symbols.size(), 0);
        for (const RuleSet* rs : sets) {
            brackets = brackets || rs->needs_brackets || rs->uses_left_new || rs->uses_right_new;
            for (const auto& pr : rs->productions) {
                frame = std::max<std::size_t>(frame, pr.frame_size);
                has_prod[pr.strict[0].sym] = 1;
                if (pr.strict.size() > 1) multi = true;
            }
            left_new = left_new || rs->uses_left_new;
            right_new = right_new || rs->uses_right_new;
        }
        frame_size = frame;
        if (brackets) match = bracket_table(in, P.symbols.open_bracket, P.symbols.close_bracket);
        // A symbol whose first production always applies (no condition, context or weight, one
        // predecessor module whose arguments are all bound) needs no matching: with the right
        // number of parameters, its template is applied at once.
        direct.assign(P.symbols.size(), nullptr);
        for (SymbolId s = 0; s < P.symbols.size(); ++s) {
            for (const RuleSet* rs : sets) {
                if (rs->by_symbol[s].empty()) continue;
                const Production& pr = rs->productions[rs->by_symbol[s][0]];
                bool binds_all = pr.strict.size() == 1;
                for (const auto& a : pr.strict[0].args) binds_all = binds_all && a.bind;
                if (binds_all && pr.condition.empty() && pr.weight.empty() && !pr.has_context() &&
                    !pr.has_new_context() && pr.tmpl.valid)
                    direct[s] = &pr;
                break;
            }
        }
    }

    bool sequential() const { return multi || left_new || right_new; }

    // ---- the direct path: every module is copied or rewritten by a direct template ----------
    // Then the size of the output of any stretch is known before writing it, so the output is
    // allocated once, exactly, and each thread writes its stretch in place.
    struct Counts {
        std::size_t modules = 0, params = 0;
        ModuleId new_ids = 0;
        bool ok = true;
    };

    Counts count_direct(std::size_t b, std::size_t e) const {
        Counts c;
        for (std::size_t i = b; i < e; ++i) {
            const SymbolId s = in.sym[i];
            if (!has_prod[s]) {
                ++c.modules;
                c.params += in.arity(i);
                continue;
            }
            const Production* pr = direct[s];
            if (!pr || in.arity(i) != pr->strict[0].width) {
                c.ok = false;
                return c;
            }
            c.modules += pr->tmpl.syms.size();
            c.params += pr->tmpl.params.size();
            c.new_ids += pr->tmpl.syms.size() - (pr->tmpl.keep >= 0 ? 1 : 0);
        }
        return c;
    }

    // Writes the output of modules [b, e) at module m_at and parameter p_at of `out`, whose
    // arrays are already sized; new identities are numbered from id_at.
    void write_direct(Worker& w, std::size_t b, std::size_t e, ModuleString& out, std::size_t m_at, std::size_t p_at,
                      ModuleId id_at) {
        w.frame.assign(frame_size, 0.0);
        SymbolId* S = out.sym.data() + m_at;
        ModuleId* ID = out.ids.data() + m_at;
        std::uint32_t* PO = out.poff.data() + m_at + 1; // poff[m_at] is the previous stretch's end
        double* PA = out.params.data() + p_at;
        std::size_t p = p_at;
        double values[256];
        std::size_t i = b;
        while (i < e) {
            if (!has_prod[in.sym[i]]) { // a run of modules without productions: copy it
                std::size_t j = i + 1;
                while (j < e && !has_prod[in.sym[j]]) ++j;
                const std::size_t n = j - i;
                const std::uint32_t pb = in.poff[i], pe = in.poff[j];
                std::memcpy(S, in.sym.data() + i, n * sizeof(SymbolId));
                std::memcpy(ID, in.ids.data() + i, n * sizeof(ModuleId));
                if (pe > pb) std::memcpy(PA, in.params.data() + pb, (pe - pb) * sizeof(double));
                const auto shift = static_cast<std::uint32_t>(p - pb); // wraps around on purpose
                for (std::size_t k = 0; k < n; ++k) PO[k] = in.poff[i + 1 + k] + shift;
                S += n;
                ID += n;
                PO += n;
                PA += pe - pb;
                p += pe - pb;
                i = j;
                continue;
            }
            const Production& pr = *direct[in.sym[i]];
            const SuccessorTemplate& t = pr.tmpl;
            if (!t.holes.empty()) {
                const double* a = in.args(i);
                for (const auto& pa : pr.strict[0].args) {
                    for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + k] = a[k];
                    a += pa.width;
                }
                w.env.position = i;
                w.env.draw = 0;
                w.env.id = in.ids[i];
                w.env.out = nullptr;
                compute_holes(w, t, values);
                check_holes(t, values);
            }
            const std::size_t m = t.syms.size();
            std::memcpy(S, t.syms.data(), m * sizeof(SymbolId));
            std::memcpy(PA, t.params.data(), t.params.size() * sizeof(double));
            for (std::size_t h = 0; h < t.holes.size(); ++h) PA[t.holes[h]] = values[h];
            for (std::size_t j = 0; j < m; ++j) {
                PO[j] = static_cast<std::uint32_t>(p + t.param_end[j]);
                ID[j] = static_cast<int>(j) == t.keep ? in.ids[i] : id_at++;
            }
            S += m;
            ID += m;
            PO += m;
            PA += t.params.size();
            p += t.params.size();
            ++i;
        }
    }

    void compute_holes(Worker& w, const SuccessorTemplate& t, double* values) const {
        if (t.affine.empty()) {
            run(t.values, w.frame.data(), w.env, values);
            return;
        }
        const double* f = w.frame.data();
        for (std::size_t h = 0; h < t.affine.size(); ++h) {
            const auto& a = t.affine[h];
            values[h] = a.kind == a.Copy ? f[a.slot] : a.kind == a.Mul ? f[a.slot] * a.constant : f[a.slot] + a.constant;
        }
    }

    void check_holes(const SuccessorTemplate& t, const double* values) const {
        for (std::size_t h = 0; h < t.holes.size(); ++h) {
            if (std::isfinite(values[h])) continue;
            std::size_t j = 0;
            while (t.param_end[j] <= t.holes[h]) ++j;
            std::uint32_t k = t.holes[h] - (j ? t.param_end[j - 1] : 0);
            throw RuntimeError{t.hole_spans[h], fmt::format("parameter {} of '{}' is {}", k + 1,
                                                            P.symbols[t.syms[j]].name,
                                                            std::isnan(values[h]) ? "NaN" : "infinite")};
        }
    }

    // Rewrites modules [b, e) into w.out.
    void run_range(Worker& w, std::size_t b, std::size_t e) {
        w.frame.assign(frame_size, 0.0);
        std::size_t i = b;
        while (i < e) {
            if (!has_prod[in.sym[i]]) {
                std::size_t j = i + 1;
                while (j < e && !has_prod[in.sym[j]]) ++j;
                w.out.append_range(in, i, j);
                i = j;
                if (w.out.size() > w.env.max_output || w.out.params.size() > w.env.max_params) limit_error(w);
                continue;
            }
            if (const Production* pr = direct[in.sym[i]]; pr && in.arity(i) == pr->strict[0].width) {
                if (!pr->tmpl.holes.empty()) {
                    const double* a = in.args(i);
                    for (const auto& pa : pr->strict[0].args) {
                        for (int k = 0; k < pa.width; ++k) w.frame[pa.slot + k] = a[k];
                        a += pa.width;
                    }
                    w.env.position = i;
                    w.env.draw = 0;
                    w.env.id = in.ids[i];
                }
                apply_template(w, i, *pr);
                ++i;
                continue;
            }
            std::size_t used = apply(w, i);
            if (used == 0) {
                w.out.append_range(in, i, i + 1);
                used = 1;
            }
            i += used;
        }
    }

    // Backward processing for `>>`: modules right to left; each successor becomes a piece and
    // the new string to the right is the pieces made so far, newest first.
    void run_backward(Worker& w) {
        w.frame.assign(frame_size, 0.0);
        piece_starts.clear();
        // Going right to left, a predecessor is found by its last module.
        std::vector<std::vector<std::pair<std::size_t, std::size_t>>> by_last(P.symbols.size());
        for (std::size_t si = 0; si < sets.size(); ++si)
            for (std::size_t pi = 0; pi < sets[si]->productions.size(); ++pi)
                by_last[sets[si]->productions[pi].strict.back().sym].emplace_back(si, pi);
        std::size_t k = n;
        while (k-- > 0) {
            piece_starts.push_back(w.out.size());
            std::size_t used = 0;
            for (const auto& [si, pi] : by_last[in.sym[k]]) {
                const Production& pr = sets[si]->productions[pi];
                const std::size_t len = pr.strict.size();
                if (len > k + 1) continue;
                const std::size_t start = k + 1 - len;
                w.env.position = start;
                w.env.draw = 0;
                w.env.id = in.ids[start];
                if (!matches(w, start, pr)) continue;
                if (!pr.weight.empty()) {
                    const auto& cands = sets[si]->by_symbol[pr.strict[0].sym];
                    std::size_t ci = 0;
                    while (ci < cands.size() && cands[ci] != pi) ++ci;
                    used = choose(w, start, si, ci, len); // only predecessors that end at k
                } else {
                    used = run_body(w, start, pr);
                }
                if (used) break;
            }
            if (used == 0) {
                w.out.append_range(in, k, k + 1);
            } else {
                k -= used - 1; // the predecessor's other modules are consumed too
            }
        }
        piece_starts.push_back(w.out.size());
    }

    ModuleString assemble_backward(const ModuleString& pieces) const {
        ModuleString out;
        for (std::size_t p = piece_starts.size() - 1; p-- > 0;) out.append_range(pieces, piece_starts[p], piece_starts[p + 1]);
        return out;
    }

private:
    [[noreturn]] void limit_error(Worker& w) const {
        (void)w;
        throw RuntimeError{Span{}, "module limit"};
    }

    bool match_module(std::size_t j, const PatternModule& pm, double* frame) const {
        return match_in(in, j, pm, frame);
    }

    // The next module of a left context at or before j: a ']' skips its whole branch, a '['
    // is stepped over to the parent, ignored modules are stepped over. -1 when there is none.
    std::int64_t left_step(std::int64_t j) const {
        while (j >= 0) {
            SymbolId s = in.sym[static_cast<std::size_t>(j)];
            if (s == P.symbols.close_bracket) {
                std::uint32_t m = match[static_cast<std::size_t>(j)];
                if (m >= n) return -1;
                j = static_cast<std::int64_t>(m) - 1;
            } else if (s == P.symbols.open_bracket || P.ignored[s]) {
                --j;
            } else {
                return j;
            }
        }
        return -1;
    }

    // Matches the left context whose last module is at j (as found by left_step).
    bool match_left_from(std::int64_t j, const std::vector<PatternModule>& pats, double* frame) const {
        for (std::size_t k = pats.size(); k-- > 0;) {
            if (j < 0 || !match_module(static_cast<std::size_t>(j), pats[k], frame)) return false;
            if (k > 0) j = left_step(j - 1);
        }
        return true;
    }

    // The next module of a right context at or after j, for a pattern module that is not a
    // bracket: lateral branches are skipped, the end of the branch ends the context. n if none.
    std::size_t right_step(std::size_t j) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        while (j < n) {
            SymbolId s = in.sym[j];
            if (s == open) {
                if (match[j] >= n) return n;
                j = match[j] + 1;
            } else if (s == close) {
                return n;
            } else if (P.ignored[s]) {
                ++j;
            } else {
                return j;
            }
        }
        return n;
    }

    bool match_right(std::size_t e, std::span<const PatternModule> pats, double* frame) const {
        std::size_t j = e;
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        for (const auto& p : pats) {
            if (p.sym == open) {
                while (j < n && P.ignored[in.sym[j]]) ++j;
                if (j >= n || in.sym[j] != open) return false;
                ++j;
                continue;
            }
            if (p.sym == close) { // skip the rest of the current branch
                while (j < n && in.sym[j] != close) {
                    if (in.sym[j] == open) {
                        if (match[j] >= n) return false;
                        j = match[j] + 1;
                    } else {
                        ++j;
                    }
                }
                if (j >= n) return false;
                ++j;
                continue;
            }
            j = right_step(j);
            if (j >= n || !match_module(j, p, frame)) return false;
            ++j;
        }
        return true;
    }

    // Left context in the new string (forward processing): the output made so far.
    bool match_left_new(const ModuleString& out, const std::vector<PatternModule>& pats, double* frame) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        auto j = static_cast<std::int64_t>(out.size()) - 1;
        for (std::size_t k = pats.size(); k-- > 0;) {
            for (;;) {
                if (j < 0) return false;
                SymbolId s = out.sym[static_cast<std::size_t>(j)];
                if (s == close) { // skip the whole preceding branch
                    int depth = 0;
                    for (; j >= 0; --j) {
                        SymbolId t = out.sym[static_cast<std::size_t>(j)];
                        if (t == close) ++depth;
                        else if (t == open && --depth == 0) break;
                    }
                    if (j < 0) return false;
                    --j;
                } else if (s == open || P.ignored[s]) {
                    --j;
                } else {
                    break;
                }
            }
            if (!match_in(out, static_cast<std::size_t>(j), pats[k], frame)) return false;
            --j;
        }
        return true;
    }

    // Walks the new string to the right of the module being rewritten in backward processing:
    // the pieces made so far, the newest (the right neighbour's successor) first.
    struct PieceIter {
        const std::vector<std::size_t>& ps;
        std::size_t p = 0, i = 0;
        bool valid = false;
        explicit PieceIter(const std::vector<std::size_t>& starts) : ps(starts) {
            if (ps.size() >= 2) {
                p = ps.size() - 2;
                i = ps[p];
                valid = true;
                normalize();
            }
        }
        void normalize() {
            while (valid && i >= ps[p + 1]) {
                if (p == 0) {
                    valid = false;
                    break;
                }
                --p;
                i = ps[p];
            }
        }
        void next() {
            ++i;
            normalize();
        }
    };

    bool match_right_new(const ModuleString& out, const std::vector<PatternModule>& pats, double* frame) const {
        const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
        PieceIter it(piece_starts);
        for (const auto& pat : pats) {
            for (;;) {
                if (!it.valid) return false;
                SymbolId s = out.sym[it.i];
                if (s == open && pat.sym != open) { // skip the lateral branch
                    int depth = 0;
                    for (; it.valid; it.next()) {
                        SymbolId t = out.sym[it.i];
                        if (t == open) ++depth;
                        else if (t == close && --depth == 0) break;
                    }
                    if (!it.valid) return false;
                    it.next();
                } else if (s == close && pat.sym != close) {
                    return false;
                } else if (s != open && s != close && P.ignored[s]) {
                    it.next();
                } else {
                    break;
                }
            }
            if (!match_in(out, it.i, pat, frame)) return false;
            it.next();
        }
        return true;
    }

    bool match_in(const ModuleString& s, std::size_t j, const PatternModule& pm, double* frame) const {
        if (s.sym[j] != pm.sym || s.arity(j) != pm.width) return false;
        const double* a = s.args(j);
        for (const auto& pa : pm.args) {
            if (pa.bind) {
                for (int k = 0; k < pa.width; ++k) frame[pa.slot + k] = a[k];
            } else if (!std::isnan(pa.value) && a[0] != pa.value) {
                return false;
            }
            a += pa.width;
        }
        return true;
    }

    // Pattern, context and condition. Binds the frame.
    bool matches(Worker& w, std::size_t i, const Production& pr) {
        double* frame = w.frame.data();
        for (std::size_t k = 0; k < pr.strict.size(); ++k)
            if (i + k >= n || !match_module(i + k, pr.strict[k], frame)) return false;
        if (!pr.left.empty() || !pr.right.empty()) {
            // the neighbours found by scanning are the same for every production tried at i
            if (w.ctx_at != i) {
                w.ctx_at = i;
                w.ctx_left = kUnknown;
                w.ctx_right = kUnknown;
            }
            if (!pr.left.empty()) {
                if (w.ctx_left == kUnknown) w.ctx_left = left_step(static_cast<std::int64_t>(i) - 1);
                if (!match_left_from(w.ctx_left, pr.left, frame)) return false;
            }
            if (!pr.right.empty()) {
                const std::size_t e = i + pr.strict.size();
                if (pr.strict.size() == 1 && pr.right[0].sym != P.symbols.open_bracket &&
                    pr.right[0].sym != P.symbols.close_bracket) {
                    if (w.ctx_right == kUnknown) w.ctx_right = static_cast<std::int64_t>(right_step(e));
                    if (static_cast<std::size_t>(w.ctx_right) >= n ||
                        !match_module(static_cast<std::size_t>(w.ctx_right), pr.right[0], frame))
                        return false;
                    if (pr.right.size() > 1 &&
                        !match_right(static_cast<std::size_t>(w.ctx_right) + 1,
                                     std::span<const PatternModule>(pr.right).subspan(1), frame))
                        return false;
                } else if (!match_right(e, pr.right, frame)) {
                    return false;
                }
            }
        }
        if (!pr.left_new.empty() && !match_left_new(w.out, pr.left_new, frame)) return false;
        if (!pr.right_new.empty() && !match_right_new(w.out, pr.right_new, frame)) return false;
        if (!pr.condition.empty() && eval_number(pr.condition, frame, w.env) == 0) return false;
        return true;
    }

    // Tries the productions for module i; returns the number of modules consumed (0: none applied).
    std::size_t apply(Worker& w, std::size_t i) {
        EvalEnv& env = w.env;
        env.position = i;
        env.draw = 0;
        env.id = in.ids[i];
        const SymbolId sym = in.sym[i];
        for (std::size_t si = 0; si < sets.size(); ++si) {
            const RuleSet& rs = *sets[si];
            const auto& cands = rs.by_symbol[sym];
            for (std::size_t ci = 0; ci < cands.size(); ++ci) {
                const Production& pr = rs.productions[cands[ci]];
                if (!matches(w, i, pr)) continue;
                if (!pr.weight.empty()) return choose(w, i, si, ci);
                if (std::size_t used = run_body(w, i, pr)) return used;
            }
        }
        return 0;
    }

    // The fast path of run_body for arrow-form successors (see SuccessorTemplate).
    std::size_t apply_template(Worker& w, std::size_t i, const Production& pr) {
        const SuccessorTemplate& t = pr.tmpl;
        ModuleString& out = w.out;
        EvalEnv& env = w.env;
        double values[256];
        if (!t.holes.empty()) {
            env.out = nullptr;
            compute_holes(w, t, values);
            check_holes(t, values);
        }
        const std::size_t m = t.syms.size();
        if (m <= 4 && t.holes.empty()) { // short constant successors: plain appends
            for (std::size_t j = 0; j < m; ++j) {
                out.sym.push_back(t.syms[j]);
                for (std::uint32_t k = j ? t.param_end[j - 1] : 0; k < t.param_end[j]; ++k) out.params.push_back(t.params[k]);
                out.poff.push_back(static_cast<std::uint32_t>(out.params.size()));
                out.ids.push_back(static_cast<int>(j) == t.keep ? in.ids[i] : env.id_base + env.new_count++);
            }
            if (out.size() > env.max_output) throw RuntimeError{Span{}, "module limit"};
            return 1;
        }
        const std::size_t m0 = out.sym.size();
        const std::size_t p0 = out.params.size();
        out.sym.resize(m0 + m);
        out.ids.resize(m0 + m);
        out.poff.resize(m0 + m + 1);
        out.params.resize(p0 + t.params.size());
        std::copy(t.syms.begin(), t.syms.end(), out.sym.begin() + static_cast<std::ptrdiff_t>(m0));
        double* pp = out.params.data() + p0;
        std::copy(t.params.begin(), t.params.end(), pp);
        for (std::size_t h = 0; h < t.holes.size(); ++h) pp[t.holes[h]] = values[h];
        std::uint32_t* po = out.poff.data() + m0 + 1;
        ModuleId* ids = out.ids.data() + m0;
        const auto base = static_cast<std::uint32_t>(p0);
        for (std::size_t j = 0; j < m; ++j) {
            po[j] = base + t.param_end[j];
            ids[j] = static_cast<int>(j) == t.keep ? in.ids[i] : env.id_base + env.new_count++;
        }
        if (out.size() > env.max_output) throw RuntimeError{Span{}, "module limit"};
        return 1;
    }

    std::size_t run_body(Worker& w, std::size_t i, const Production& pr) {
        if (pr.tmpl.valid) return apply_template(w, i, pr);
        EvalEnv& env = w.env;
        SymbolId keep_syms[32];
        ModuleId keep_ids[32];
        const std::size_t k = std::min<std::size_t>(pr.strict.size(), 32);
        for (std::size_t m = 0; m < k; ++m) {
            keep_syms[m] = in.sym[i + m];
            keep_ids[m] = in.ids[i + m];
        }
        env.keep_syms = keep_syms;
        env.keep_ids = keep_ids;
        env.keep_count = static_cast<std::uint32_t>(k);
        env.keep_used = 0;
        env.produced = false;
        env.out = &w.out;
        const std::size_t mark = w.out.size();
        RunStatus st = run(pr.body, w.frame.data(), env);
        env.keep_count = 0;
        if (st == RunStatus::Produced || env.produced) return pr.strict.size();
        // not applied: drop anything a partial body emitted
        w.out.sym.resize(mark);
        w.out.ids.resize(mark);
        w.out.params.resize(w.out.poff[mark]);
        w.out.poff.resize(mark + 1);
        return 0;
    }

    // cpfg semantics: all applicable weighted productions of the module, one drawn by weight.
    std::size_t choose(Worker& w, std::size_t i, std::size_t set0, std::size_t cand0, std::size_t length = 0) {
        struct Option {
            const Production* pr;
            double weight;
        };
        Option options[64];
        std::size_t count = 0;
        double total = 0;
        const SymbolId sym = in.sym[i];
        for (std::size_t si = set0; si < sets.size(); ++si) {
            const auto& cands = sets[si]->by_symbol[sym];
            for (std::size_t ci = si == set0 ? cand0 : 0; ci < cands.size(); ++ci) {
                const Production& pr = sets[si]->productions[cands[ci]];
                if (pr.weight.empty() || (length && pr.strict.size() != length) || !matches(w, i, pr)) continue;
                double wt = eval_number(pr.weight, w.frame.data(), w.env);
                if (!(wt >= 0) || !std::isfinite(wt))
                    throw RuntimeError{pr.weight.spans.empty() ? pr.span : pr.weight.spans.back(),
                                       fmt::format("a production weight must be a finite number >= 0, found {}", wt)};
                if (wt == 0 || count == 64) continue;
                options[count++] = {&pr, wt};
                total += wt;
            }
        }
        if (count == 0) return 0;
        double u = random_unit(random_bits(w.env.seed, w.env.phase, i, kChoiceDraw)) * total;
        std::size_t pick = count - 1;
        for (std::size_t k = 0; k < count; ++k) {
            if (u < options[k].weight) {
                pick = k;
                break;
            }
            u -= options[k].weight;
        }
        const Production& pr = *options[pick].pr;
        w.env.draw = 0;
        matches(w, i, pr); // bind the chosen production's names again
        return run_body(w, i, pr);
    }

    const Program& P;
    const ModuleString& in;
    const std::vector<const RuleSet*>& sets;
    const std::size_t n;
    std::vector<std::uint8_t> has_prod;
    std::vector<std::uint32_t> match;
    std::vector<const Production*> direct;
    std::vector<std::size_t> piece_starts;
    std::size_t frame_size = 1;
    bool multi = false, left_new = false, right_new = false;
};


// ---- Derivation ------------------------------------------------------------------------------

Derivation::Derivation(const Program& program, DeriveOptions options) : prog_(program), opt_(std::move(options)) {
    globals_ = prog_.global_values;
}

void Derivation::check_limits(const ModuleString& s) const { check_limits(s.size(), s.params.size()); }

void Derivation::check_limits(std::size_t modules, std::size_t params) const {
    if (modules > opt_.max_modules)
        throw RuntimeError{Span{}, fmt::format("step {}: the string grew past the limit of {} modules (raise it "
                                               "with --max-modules)",
                                               step_, opt_.max_modules)};
    std::size_t estimate = modules * (sizeof(SymbolId) + sizeof(std::uint32_t) + sizeof(ModuleId)) +
                           params * sizeof(double);
    if (estimate > opt_.max_bytes)
        throw RuntimeError{Span{}, fmt::format("step {}: the string needs about {:.1f} GiB, more than the limit of "
                                               "{:.1f} GiB",
                                               step_, estimate / double(1 << 30), opt_.max_bytes / double(1 << 30))};
}

void Derivation::rewrite(const ModuleString& in, ModuleString& out, const std::vector<const RuleSet*>& sets,
                         std::uint64_t phase, int step_for_env) const {
    Rewriter rw(prog_, in, sets);
    auto setup = [&](Worker& w) {
        w.env.prog = &prog_;
        w.env.globals = const_cast<double*>(globals_.data()); // read-only during rewriting
        w.env.seed = seed_;
        w.env.phase = phase;
        w.env.step = step_for_env;
        w.env.max_output = opt_.max_modules;
        w.env.max_params = opt_.max_bytes / sizeof(double);
    };
    const std::size_t n = in.size();
    int threads = std::max(1, opt_.threads);
    if (rw.sequential() || n < 20000) threads = 1;
    out.clear();
    if (!rw.sequential() && rewrite_direct(rw, in, out, threads, setup)) {
        // done
    } else if (threads == 1) {
        Worker w;
        setup(w);
        w.env.id_base = next_id_; // one thread numbers new modules in string order directly
        w.out.sym.reserve(static_cast<std::size_t>(n * growth_ * 1.02) + 16);
        w.out.ids.reserve(w.out.sym.capacity());
        w.out.poff.reserve(w.out.sym.capacity() + 1);
        w.out.params.reserve(static_cast<std::size_t>(in.params.size() * param_growth_ * 1.02) + 16);
        try {
            bool backward = false;
            for (const RuleSet* rs : sets) backward = backward || rs->uses_right_new;
            if (backward) {
                // right to left: new modules are marked, then numbered in string order
                w.env.id_base = kNewIdBit;
                rw.run_backward(w);
                w.out = rw.assemble_backward(w.out);
                ModuleId next = next_id_;
                for (auto& id : w.out.ids)
                    if (id & kNewIdBit) id = next++;
            } else {
                rw.run_range(w, 0, n);
            }
        } catch (const RuntimeError& e) {
            if (e.message == "module limit" || e.message == "the string outgrew the module limit")
                check_limits(w.out);
            throw;
        }
        out.swap(w.out);
        next_id_ += w.env.new_count;
    } else {
        // Worker 0 writes into buffers sized for the whole output and numbers its new modules
        // directly; the others' parts are appended to it afterwards, so only (T-1)/T of the
        // string is copied a second time.
        std::vector<Worker> workers(static_cast<std::size_t>(threads));
        {
            std::vector<std::jthread> pool;
            for (int t = 0; t < threads; ++t) {
                pool.emplace_back([&, t] {
                    Worker& w = workers[static_cast<std::size_t>(t)];
                    setup(w);
                    std::size_t b = n * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads);
                    std::size_t e = n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads);
                    std::size_t modules = (t == 0 ? n : e - b), params = in.params.size() * (e - b) / std::max<std::size_t>(n, 1);
                    if (t == 0) {
                        params = in.params.size();
                        w.env.id_base = next_id_;
                    }
                    w.out.sym.reserve(static_cast<std::size_t>(modules * growth_ * 1.02) + 16);
                    w.out.ids.reserve(w.out.sym.capacity());
                    w.out.poff.reserve(w.out.sym.capacity() + 1);
                    w.out.params.reserve(static_cast<std::size_t>(params * param_growth_ * 1.02) + 16);
                    try {
                        rw.run_range(w, b, e);
                    } catch (const RuntimeError& err) {
                        w.error = err;
                    }
                });
            }
        }
        std::size_t total = 0, total_params = 0;
        for (auto& w : workers) {
            if (w.error) {
                if (w.error->message == "module limit" || w.error->message == "the string outgrew the module limit")
                    check_limits(w.out);
                throw *w.error;
            }
            total += w.out.size();
            total_params += w.out.params.size();
        }
        if (total > opt_.max_modules) {
            check_limits(total, total_params);
        }
        std::vector<std::size_t> mod_at(workers.size()), par_at(workers.size());
        std::vector<ModuleId> id_at(workers.size());
        std::size_t m = 0, p = 0;
        ModuleId ids = next_id_;
        for (std::size_t t = 0; t < workers.size(); ++t) {
            mod_at[t] = m;
            par_at[t] = p;
            id_at[t] = ids;
            m += workers[t].out.size();
            p += workers[t].out.params.size();
            ids += workers[t].env.new_count;
        }
        out.swap(workers[0].out);
        out.sym.resize(total);
        out.ids.resize(total);
        out.poff.resize(total + 1);
        out.params.resize(total_params);
        {
            std::vector<std::jthread> pool;
            for (std::size_t t = 1; t < workers.size(); ++t) {
                pool.emplace_back([&, t] {
                    ModuleString& src = workers[t].out;
                    std::copy(src.sym.begin(), src.sym.end(), out.sym.begin() + static_cast<std::ptrdiff_t>(mod_at[t]));
                    std::copy(src.params.begin(), src.params.end(),
                              out.params.begin() + static_cast<std::ptrdiff_t>(par_at[t]));
                    for (std::size_t i = 0; i < src.size(); ++i) {
                        out.poff[mod_at[t] + i] = static_cast<std::uint32_t>(par_at[t] + src.poff[i]);
                        ModuleId id = src.ids[i];
                        out.ids[mod_at[t] + i] = (id & kNewIdBit) ? id_at[t] + (id & ~kNewIdBit) : id;
                    }
                    ModuleString().swap(src);
                });
            }
        }
        out.poff[total] = static_cast<std::uint32_t>(total_params);
        next_id_ = ids;
    }
    if (n > 0) {
        growth_ = std::max(0.5, std::min(16.0, double(out.size()) / double(n)));
        param_growth_ = in.params.empty() ? growth_ : std::max(0.5, std::min(16.0, double(out.params.size()) / double(in.params.size())));
    }
    check_limits(out);
}

// Whether some module of `s` is the first module of a predecessor in `rs`: a pass over the
// symbols is much cheaper than a rewrite that copies the whole string unchanged.
static bool any_candidate(const ModuleString& s, const RuleSet& rs) {
    for (SymbolId x : s.sym)
        if (x < rs.by_symbol.size() && !rs.by_symbol[x].empty()) return true;
    return false;
}

// Tries the direct path (see Rewriter::count_direct): count the output of each thread's stretch,
// allocate the output once, write the stretches in place. Returns false, having written
// nothing, when some module needs the general path.
template <typename Setup>
bool Derivation::rewrite_direct(Rewriter& rw, const ModuleString& in, ModuleString& out, int threads,
                                const Setup& setup) const {
    const std::size_t n = in.size();
    const auto T = static_cast<std::size_t>(threads);
    std::vector<Rewriter::Counts> counts(T);
    auto bounds = [&](std::size_t t) { return std::pair{n * t / T, n * (t + 1) / T}; };
    auto parallel = [&](auto&& body) {
        if (T == 1) {
            body(std::size_t{0});
            return;
        }
        std::vector<std::jthread> pool;
        for (std::size_t t = 0; t < T; ++t) pool.emplace_back([&body, t] { body(t); });
    };
    parallel([&](std::size_t t) {
        auto [b, e] = bounds(t);
        counts[t] = rw.count_direct(b, e);
    });
    std::size_t modules = 0, params = 0;
    for (const auto& c : counts) {
        if (!c.ok) return false;
        modules += c.modules;
        params += c.params;
    }
    check_limits(modules, params); // before allocating anything
    out.sym.resize(modules);
    out.ids.resize(modules);
    out.poff.resize(modules + 1);
    out.params.resize(params);
    out.poff[0] = 0;
    std::vector<Worker> workers(T);
    std::vector<std::size_t> m_at(T), p_at(T);
    std::vector<ModuleId> id_at(T);
    ModuleId ids = next_id_;
    for (std::size_t t = 0, m = 0, p = 0; t < T; ++t) {
        m_at[t] = m;
        p_at[t] = p;
        id_at[t] = ids;
        m += counts[t].modules;
        p += counts[t].params;
        ids += counts[t].new_ids;
    }
    parallel([&](std::size_t t) {
        Worker& w = workers[t];
        setup(w);
        auto [b, e] = bounds(t);
        try {
            rw.write_direct(w, b, e, out, m_at[t], p_at[t], id_at[t]);
        } catch (const RuntimeError& err) {
            w.error = err;
        }
    });
    for (auto& w : workers)
        if (w.error) throw *w.error;
    next_id_ = ids;
    return true;
}

void Derivation::decompose(ModuleString& s, int step_for_env) {
    if (prog_.decompose.empty()) return;
    std::vector<const RuleSet*> sets{&prog_.decompose};
    for (int pass = 0; pass < prog_.decompose.max_depth; ++pass) {
        if (!any_candidate(s, prog_.decompose)) break;
        ModuleString next;
        ModuleId before = next_id_;
        rewrite(s, next, sets, (static_cast<std::uint64_t>(step_for_env) << 16) | static_cast<std::uint64_t>(pass + 1),
                step_for_env);
        bool changed = next_id_ != before || next.size() != s.size() || next.sym != s.sym || next.params != s.params;
        s.swap(next);
        if (!changed) break;
    }
}

void Derivation::apply_cut(ModuleString& s) const {
    if (!prog_.uses_cut) return;
    const SymbolId cut = prog_.symbols.cut, open = prog_.symbols.open_bracket, close = prog_.symbols.close_bracket;
    bool any = false;
    for (SymbolId x : s.sym)
        if (x == cut) {
            any = true;
            break;
        }
    if (!any) return;
    ModuleString out;
    const std::size_t n = s.size();
    std::size_t i = 0;
    while (i < n) {
        if (s.sym[i] != cut) {
            out.append_range(s, i, i + 1);
            ++i;
            continue;
        }
        // skip to the ']' closing the current branch (kept) or to the end
        int depth = 0;
        ++i;
        while (i < n) {
            if (s.sym[i] == open) ++depth;
            else if (s.sym[i] == close) {
                if (depth == 0) break;
                --depth;
            }
            ++i;
        }
    }
    s.swap(out);
}

ModuleString Derivation::interpreted(const ModuleString& s) const {
    ModuleString cur = s;
    if (prog_.interpret.empty()) return cur;
    std::vector<const RuleSet*> sets{&prog_.interpret};
    ModuleId saved = next_id_;
    for (int pass = 0; pass < prog_.interpret.max_depth; ++pass) {
        if (!any_candidate(cur, prog_.interpret)) break;
        ModuleString next;
        rewrite(cur, next, sets, (static_cast<std::uint64_t>(step_) << 16) | 0x8000u | static_cast<std::uint64_t>(pass),
                step_);
        bool changed = next.sym != cur.sym || next.params != cur.params;
        cur.swap(next);
        if (!changed) break;
    }
    next_id_ = saved; // interpretation never creates modules that live on
    return cur;
}

void Derivation::run_hook(HookKind kind) {
    const auto k = static_cast<std::size_t>(kind);
    if (!prog_.has_hook[k]) return;
    EvalEnv env;
    HookEffects effects;
    env.prog = &prog_;
    env.globals = globals_.data();
    env.seed = seed_;
    env.phase = (static_cast<std::uint64_t>(step_) << 16) | (0xF000u + k);
    env.position = ~std::uint64_t{0};
    env.step = step_;
    env.effects = &effects;
    std::vector<double> frame(std::max<std::size_t>(prog_.hook_frame[k], 1));
    try {
        plant::run(prog_.hooks[k], frame.data(), env);
    } catch (RuntimeError& e) {
        static const char* names[] = {"on start", "on before_step", "on after_step", "on end"};
        e.message = fmt::format("step {}, {}: {}", step_, names[k], e.message);
        throw;
    }
    if (!effects.printed.empty() && opt_.on_print) opt_.on_print(effects.printed);
    if (effects.use_group != -2) group_ = effects.use_group;
    if (effects.stop) stopped_ = true;
}

void Derivation::start() {
    EvalEnv env;
    env.prog = &prog_;
    env.globals = globals_.data();
    auto setting = [&](const Code& c, double fallback) { return c.empty() ? fallback : eval_number(c, nullptr, env); };
    double steps = opt_.steps ? *opt_.steps : setting(prog_.setting_derive, 0);
    if (steps < 0 || steps > 1e6 || steps != std::floor(steps))
        throw RuntimeError{prog_.setting_derive.spans.empty() ? Span{} : prog_.setting_derive.spans.back(),
                           fmt::format("the number of steps must be a whole number from 0 to 1000000, found {}", steps)};
    target_ = static_cast<int>(steps);
    double seed = setting(prog_.setting_seed, 0);
    if (!(seed >= 0 && seed < 9.0e18) || seed != std::floor(seed))
        throw RuntimeError{prog_.setting_seed.spans.empty() ? Span{} : prog_.setting_seed.spans.back(),
                           fmt::format("the seed must be a whole number from 0 to 9e18, found {}", seed)};
    seed_ = opt_.seed ? *opt_.seed : static_cast<std::uint64_t>(seed);
    angle_ = setting(prog_.setting_angle, 90);
    step_length_ = setting(prog_.setting_step, 1);
    width_ = setting(prog_.setting_width, 0.1); // a tenth of the default step: a slender branch
    step_ = 0;
    stopped_ = false;
    group_ = -1;
    next_id_ = 1;
    // the axiom: emitted like a successor, then decomposed
    env.seed = seed_;
    env.phase = 0xFFFF0000ULL;
    ModuleString axiom;
    env.out = &axiom;
    env.max_output = opt_.max_modules;
    env.id_base = next_id_;
    try {
        plant::run(prog_.axiom, nullptr, env);
    } catch (const RuntimeError& e) {
        if (e.message == "the string outgrew the module limit") check_limits(axiom);
        throw;
    }
    next_id_ += env.new_count;
    current_.swap(axiom);
    try {
        decompose(current_, 0);
        apply_cut(current_);
    } catch (RuntimeError& e) {
        if (e.message.rfind("step ", 0) != 0) e.message = "step 0: " + e.message;
        throw;
    }
    started_ = true;
    run_hook(HookKind::Start);
}

bool Derivation::step() {
    if (!started_) start();
    if (stopped_ || step_ >= target_) return false;
    if (opt_.interrupt && opt_.interrupt->load()) throw RuntimeError{Span{}, "interrupted"};
    double t0 = now_ms();
    run_hook(HookKind::BeforeStep);
    if (stopped_) return false;
    std::vector<const RuleSet*> sets;
    if (group_ >= 0 && group_ < static_cast<int>(prog_.groups.size())) sets.push_back(&prog_.groups[group_]);
    sets.push_back(&prog_.rules);
    bool queries = false;
    for (const RuleSet* rs : sets)
        for (const auto& pr : rs->productions) {
            auto is_query = [&](const std::vector<PatternModule>& v) {
                for (const auto& m : v)
                    if (prog_.symbols[m.sym].query) return true;
                return false;
            };
            queries = queries || is_query(pr.strict) || is_query(pr.left) || is_query(pr.right);
        }
    if (queries && opt_.queries) opt_.queries->fill_queries(*this, current_);
    ModuleString next;
    ++step_;
    try {
        rewrite(current_, next, sets, static_cast<std::uint64_t>(step_) << 16, step_);
        current_.swap(next);
        { ModuleString().swap(next); }
        decompose(current_, step_);
        apply_cut(current_);
    } catch (RuntimeError& e) {
        if (e.message.rfind("step ", 0) != 0) e.message = fmt::format("step {}: {}", step_, e.message);
        throw;
    }
    run_hook(HookKind::AfterStep);
    if (opt_.on_step) opt_.on_step(StepStats{step_, current_.size(), current_.bytes(), now_ms() - t0});
    return !stopped_ && step_ < target_;
}

void Derivation::finish() { run_hook(HookKind::End); }

void Derivation::run() {
    start();
    while (step()) {
    }
    finish();
}

// ---- printing --------------------------------------------------------------------------------

std::string format_double(double v) {
    if (v == 0) return "0"; // also for -0
    char buf[64];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    std::string s(buf, r.ptr);
    // to_chars writes exponents as e+21 and e-07; the shortest reading-back form is e21 and e-7
    if (auto e = s.find('e'); e != std::string::npos) {
        std::string mant = s.substr(0, e), exp = s.substr(e + 1);
        bool neg = !exp.empty() && exp[0] == '-';
        if (!exp.empty() && (exp[0] == '+' || exp[0] == '-')) exp.erase(0, 1);
        while (exp.size() > 1 && exp[0] == '0') exp.erase(0, 1);
        s = mant + "e" + (neg ? "-" : "") + exp;
    }
    return s;
}

std::string format_string(const Program& program, const ModuleString& s, bool with_ids) {
    std::string out;
    out.reserve(s.size() * 2);
    // Prefixes of declared multi-letter names: "F" then "b" must be spaced when "Fb..." is declared.
    std::unordered_set<std::string> prefixes;
    for (const auto& info : program.symbols.all())
        if (info.declared && info.name.size() > 1 && std::isalpha(static_cast<unsigned char>(info.name[0])))
            for (std::size_t l = 2; l <= info.name.size(); ++l) prefixes.insert(info.name.substr(0, l));
    const std::string* prev = nullptr; // name of the previous module when it ends in a letter run
    for (std::size_t i = 0; i < s.size(); ++i) {
        const std::string& name = program.symbols[s.sym[i]].name;
        bool letter_start = !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_');
        // a space only where reading back would merge two names
        if (prev && letter_start) {
            if (prev->size() > 1 || *prev == "~" || prefixes.count(*prev + name[0])) out += ' ';
        }
        out += name;
        std::uint32_t k = s.arity(i);
        if (k > 0 || name == ";") { // a bare ';' would end the statement when read back
            out += '(';
            const double* a = s.args(i);
            for (std::uint32_t j = 0; j < k; ++j) {
                if (j) out += ',';
                out += format_double(a[j]);
            }
            out += ')';
        }
        if (with_ids) out += fmt::format("#{}", s.ids[i]);
        bool ends_letters = !name.empty() && (std::isalnum(static_cast<unsigned char>(name.back())) || name.back() == '_');
        // a bare '~' followed by a letter would read back as one surface name
        prev = (k == 0 && !with_ids && (ends_letters || name == "~")) ? &name : nullptr;
    }
    return out;
}

} // namespace plant
