// The module string: flat arrays, no per-module heap objects (docs/design.md, the module
// string). Module i has symbol sym[i], parameters params[poff[i] .. poff[i+1]) and
// the identity ids[i] (docs/language.md, module identity). Vec3 parameters occupy three consecutive doubles.
//
// A string may go without identities (keep_ids false, ids empty): a derivation whose identities
// nobody can observe (`plant derive` without --ids, a program that never calls id() and has no
// query modules or environments) saves the 8 bytes per module they cost, about a third of the
// memory a parametric derivation writes. id(i) is 0 in such a string.
#pragma once

#include "plant/big_allocator.hpp"

#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace plant {

// 16 bits: the string's largest array after the parameters and identities, so two bytes saved
// per module are about a tenth of a derivation's memory traffic. A program has at most
// kNoSymbol - 1 symbols (the compiler says so past that); kNoSymbol itself means "none".
using SymbolId = std::uint16_t;
constexpr SymbolId kNoSymbol = 0xFFFF;
using ModuleId = std::uint64_t;

struct ModuleString {
    BigVector<SymbolId> sym;
    BigVector<std::uint32_t> poff{0}; // size() + 1 entries
    BigVector<double> params;
    BigVector<ModuleId> ids; // empty when !keep_ids
    bool keep_ids = true;

    std::size_t size() const { return sym.size(); }
    ModuleId id(std::size_t i) const { return keep_ids ? ids[i] : 0; }
    bool empty() const { return sym.empty(); }
    std::uint32_t arity(std::size_t i) const { return poff[i + 1] - poff[i]; }
    const double* args(std::size_t i) const { return params.data() + poff[i]; }
    std::span<const double> arg_span(std::size_t i) const { return {params.data() + poff[i], arity(i)}; }

    void clear() {
        sym.clear();
        poff.assign(1, 0);
        params.clear();
        ids.clear();
    }
    void push(SymbolId s, const double* p, std::uint32_t k, ModuleId id) {
        sym.push_back(s);
        for (std::uint32_t i = 0; i < k; ++i) params.push_back(p[i]);
        poff.push_back(static_cast<std::uint32_t>(params.size()));
        if (keep_ids) ids.push_back(id);
    }
    // Appends modules [b, e) of another string (which keeps identities if this one does).
    void append_range(const ModuleString& o, std::size_t b, std::size_t e);
    void append(const ModuleString& o) { append_range(o, 0, o.size()); }
    // Bytes held by the arrays (capacity, not size: what the process really pays).
    std::size_t bytes() const {
        return sym.capacity() * sizeof(SymbolId) + poff.capacity() * sizeof(std::uint32_t) +
               params.capacity() * sizeof(double) + ids.capacity() * sizeof(ModuleId);
    }
    void swap(ModuleString& o) noexcept {
        sym.swap(o.sym);
        poff.swap(o.poff);
        params.swap(o.params);
        ids.swap(o.ids);
        std::swap(keep_ids, o.keep_ids);
    }
};

// Fills `match` (resized to s.size()): for each '[' the index of its ']' and for each ']' the
// index of its '['; other entries are left as they were. Unbalanced brackets map to size() (no
// partner). Built once per step, only when some production has context.
void bracket_table(const ModuleString& s, SymbolId open, SymbolId close, std::vector<std::uint32_t>& match);

// Removes every module for which `cuts(i)` holds together with the rest of its branch, up to the
// ']' that closes it (kept) or the string's end: what '%' does, and what a climber does to a
// part that broke off.
void cut_branches(ModuleString& s, SymbolId open, SymbolId close,
                  const std::function<bool(std::size_t)>& cuts);

} // namespace plant
