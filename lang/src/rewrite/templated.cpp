// The templated route: every rewritten symbol has a direct template or a context table, so a
// module's successor is found by a table lookup and its output is bounded by the longest
// template; the output is written through plain pointers.
#include "rewriter.hpp"

#include <algorithm>

namespace plant {

// run_range for a templated plan (every rewritten symbol has a direct template or a context
// table). The output is written through plain pointers into arrays opened up to their
// capacity (which the derivation reserved from the last step's growth), checked once per
// module against the longest template, and cut to what was written at the end. A module that
// needs matching after all (its parameter count differs from the pattern's) goes through
// apply() with the arrays at their true size.
// The room left is checked for a run of modules at a time rather than per module: a module
// writes at most `per_module` modules and, copied, its own parameters or, rewritten, at most
// Pmax, so the next k modules fit in `per_module` k modules and their own parameters plus Pmax k.
// A run is as long as the room opened lets it be (the arrays grow only when not even one module
// fits), and it ends at `next_check`, where the interrupt and the limits are looked at too.
template <bool Ids> void Rewriter::run_templates(Worker& w, std::size_t b, std::size_t e) {
    w.frame.assign(plan.frame_size, 0.0);
    ModuleString& out = w.out;
    EvalEnv& env = w.env;
    const std::size_t Mmax = plan.max_modules_out, Pmax = plan.max_params_out;
    double values[256];
    std::size_t m = out.size(), p = out.params.size();
    std::size_t mcap = 0, pcap = 0;
    std::size_t m_open = m, p_open = p; // the string is indexed (block_at) up to module m_open
    KindId* S = nullptr;
    double* PA = nullptr;
    ModuleId* ID = nullptr;
    auto open = [&](std::size_t need_m, std::size_t need_p) {
        mcap = std::max({out.kinds.capacity(), need_m, 2 * m});
        pcap = std::max({out.params.capacity(), need_p, 2 * p});
        if (S) out.index_upto(m_open, m, p_open); // open already: index what was written
        m_open = m;
        p_open = p;
        out.resize_arrays(mcap, pcap);
        S = out.kinds.data();
        PA = out.params.data();
        if constexpr (Ids) ID = out.ids.data();
    };
    auto close = [&] {
        out.resize_arrays(m, p);
        out.index_from(m_open, p_open);
        S = nullptr;
    };
    const SymbolReader sym_of = in.symbols();
    std::size_t q = in.offset(b); // where input module i's parameters start
    const std::size_t per_module = std::max<std::size_t>(Mmax, 1);
    std::size_t next_limits = b + 65536, next_check = b;
    std::size_t i = b;
    auto run_length = [&] {
        std::size_t k = std::min({e - i, next_limits - i, std::size_t{4096}, (mcap - m) / per_module});
        while (k > 0 && p + in.params_of(i, i + k) + Pmax * k > pcap) k /= 2;
        return k;
    };
    open(m + per_module, p + Pmax);
    while (i < e) {
        if (i >= next_check) {
            if (i >= next_limits) {
                next_limits = i + 65536;
                if (env.interrupt && env.interrupt->load())
                    throw RuntimeError{RuntimeErrorKind::Interrupted, Span{}, "interrupted"};
                if (m > env.max_output || p > env.max_params) {
                    close();
                    limit_error();
                }
            }
            std::size_t k = run_length();
            if (k == 0) {
                open(m + per_module, p + in.stored(i) + Pmax);
                k = run_length(); // at least 1 now
            }
            next_check = i + k;
        }
        const SymbolId sym = sym_of(i);
        const std::uint32_t arity = in.arity(i), stored = in.stored(i);
        const Production* pr = nullptr;
        if (plan.has_prod[sym]) {
            pr = plan.direct[sym];
            if (pr && arity == pr->strict[0].width) {
                if (!pr->tmpl.holes.empty()) bind_args(w, i, in.params.data() + q, pr->strict[0]);
            } else if (!pr && arity == 0) {
                pr = table_lookup(i); // nullptr: no production applies, the module is copied
            } else {                  // matching after all, with the arrays at their true size
                close();
                std::size_t used = apply(w, i);
                if (used == 0) {
                    out.append_range(in, i, i + 1);
                    used = 1;
                }
                q += in.params_of(i, i + used);
                i += used;
                m = out.size();
                p = out.params.size();
                open(m + per_module, p + Pmax);
                next_check = i; // room is made again from here
                continue;
            }
        }
        if (!pr) { // copied as it is
            S[m] = in.kinds[i];
            if constexpr (Ids) ID[m] = in.ids[i];
            for (std::uint32_t k = 0; k < stored; ++k) PA[p++] = in.params[q + k];
            q += stored;
            ++m;
            ++i;
            continue;
        }
        const SuccessorTemplate& t = pr->tmpl;
        if (!t.holes.empty()) {
            env.position = i;
            env.draw = 0;
            env.id = Ids ? in.ids[i] : 0;
            env.out = nullptr;
            compute_holes(w, t, values);
            check_holes(t, values);
        }
        ModuleId next_new = env.id_base + env.new_count;
        put_template<Ids>(t, values, Ids ? in.ids[i] : 0, next_new, S + m, PA + p, Ids ? ID + m : nullptr);
        env.new_count = next_new - env.id_base;
        m += t.syms.size();
        p += t.stored.size();
        q += stored;
        ++i;
    }
    close();
    if (out.size() > env.max_output || out.params.size() > env.max_params) limit_error();
}

template void Rewriter::run_templates<true>(Worker&, std::size_t, std::size_t);
template void Rewriter::run_templates<false>(Worker&, std::size_t, std::size_t);

} // namespace plant
