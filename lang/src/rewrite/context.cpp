// Context matching beyond the one-module walks in rewriter.hpp: right contexts with brackets or
// several modules, contexts in the new string (forward `<<` and backward `>>` processing), and
// the REPL's :find.
#include "rewriter.hpp"

namespace plant {

namespace {

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

} // namespace

bool Rewriter::match_right(std::size_t e, std::span<const PatternModule> pats, double* frame) const {
    std::size_t j = e;
    const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
    for (const auto& p : pats) {
        if (p.sym == open) {
            while (j < n && P.ignored[in.symbol(j)]) ++j;
            if (j >= n || in.symbol(j) != open) return false;
            ++j;
            continue;
        }
        if (p.sym == close) { // skip the rest of the current branch
            while (j < n && in.symbol(j) != close) {
                if (in.symbol(j) == open) {
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
bool Rewriter::match_left_new(const ModuleString& out, const std::vector<PatternModule>& pats,
                              double* frame) const {
    const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
    auto j = static_cast<std::int64_t>(out.size()) - 1;
    for (std::size_t k = pats.size(); k-- > 0;) {
        for (;;) {
            if (j < 0) return false;
            SymbolId s = out.symbol(static_cast<std::size_t>(j));
            if (s == close) { // skip the whole preceding branch
                int depth = 0;
                for (; j >= 0; --j) {
                    SymbolId t = out.symbol(static_cast<std::size_t>(j));
                    if (t == close)
                        ++depth;
                    else if (t == open && --depth == 0)
                        break;
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

bool Rewriter::match_right_new(const ModuleString& out, const std::vector<PatternModule>& pats,
                               double* frame) const {
    const SymbolId open = P.symbols.open_bracket, close = P.symbols.close_bracket;
    PieceIter it(piece_starts);
    for (const auto& pat : pats) {
        for (;;) {
            if (!it.valid) return false;
            SymbolId s = out.symbol(it.i);
            if (s == open && pat.sym != open) { // skip the lateral branch
                int depth = 0;
                for (; it.valid; it.next()) {
                    SymbolId t = out.symbol(it.i);
                    if (t == open)
                        ++depth;
                    else if (t == close && --depth == 0)
                        break;
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

// Whether production `pr` (pattern, context and condition) matches at module i: the REPL's
// :find. Binds the worker's frame.
bool Rewriter::matches_at(Worker& w, std::size_t i, const Production& pr) {
    if (w.frame.size() < plan.frame_size) w.frame.assign(plan.frame_size, 0.0);
    w.env.position = i;
    w.env.draw = 0;
    w.env.id = in.id(i);
    return matches(w, i, pr);
}

std::vector<std::size_t> find_matches(const Derivation& d, const Program& program, const RuleSet& rules) {
    std::vector<std::size_t> out;
    if (rules.productions.empty()) return out;
    const ModuleString& s = d.string();
    RulePlan plan(program, {&rules});
    Rewriter rw(plan, s);
    Worker w;
    w.env.prog = &program;
    // another program (the REPL's :find compiles one) sees its environments as declared
    w.env.run = &program == &d.program() ? &d.run_state() : nullptr;
    std::vector<double> globals =
        d.globals(); // a copy: conditions may not write it, but the VM takes it writable
    w.env.globals = globals.data();
    w.env.seed = d.seed();
    w.env.step = d.steps_done();
    const Production& pr = rules.productions[0];
    for (std::size_t i = 0; i < s.size(); ++i)
        if (s.symbol(i) == pr.strict[0].sym && rw.matches_at(w, i, pr)) out.push_back(i);
    return out;
}

} // namespace plant
