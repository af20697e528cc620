// Backward processing, for productions with a right context in the new string (`>>`): the
// modules are rewritten right to left, each successor becomes a piece, and the pieces are joined
// in string order at the end. (Forward processing, for a left context in the new string `<<`,
// is the general route run left to right on one thread: see run_range and match_left_new.)
#include "rewriter.hpp"

namespace plant {

// Backward processing for `>>`: modules right to left; each successor becomes a piece and
// the new string to the right is the pieces made so far, newest first.
void Rewriter::run_backward(Worker& w) {
    w.frame.assign(plan.frame_size, 0.0);
    piece_starts.clear();
    // Going right to left, a predecessor is found by its last module.
    std::vector<std::vector<std::pair<std::size_t, std::size_t>>> by_last(P.symbols.size());
    for (std::size_t si = 0; si < plan.sets.size(); ++si)
        for (std::size_t pi = 0; pi < plan.sets[si]->productions.size(); ++pi)
            by_last[plan.sets[si]->productions[pi].strict.back().sym].emplace_back(si, pi);
    std::size_t k = n;
    while (k-- > 0) {
        piece_starts.push_back(w.out.size());
        std::size_t used = 0;
        for (const auto& [si, pi] : by_last[in.symbol(k)]) {
            const Production& pr = plan.sets[si]->productions[pi];
            const std::size_t len = pr.strict.size();
            if (len > k + 1) continue;
            const std::size_t start = k + 1 - len;
            w.env.position = start;
            w.env.draw = 0;
            w.env.id = in.id(start);
            if (!matches(w, start, pr)) continue;
            if (!pr.weight.empty()) {
                const auto& cands = plan.sets[si]->by_symbol[pr.strict[0].sym];
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

ModuleString Rewriter::assemble_backward(const ModuleString& pieces) const {
    ModuleString out;
    out.keep_ids = pieces.keep_ids;
    out.use_kinds_of(pieces);
    for (std::size_t p = piece_starts.size() - 1; p-- > 0;)
        out.append_range(pieces, piece_starts[p], piece_starts[p + 1]);
    return out;
}

} // namespace plant
