// The module string: flat arrays, no per-module heap objects (docs/design.md, the module
// string). Module i has the kind kinds[i] (its symbol, arity and the count of numbers stored,
// from the KindTable), its stored numbers from params[offset(i)] and the identity ids[i] (docs/language.md,
// module identity). Vec3 parameters occupy three consecutive doubles.
//
// Readers go through symbol(i) and args(i) (or args_at for one that walks the string in order,
// keeping its own position in `params`, advanced by stored(i)), never through `kinds` and
// `params` directly: that leaves room for kinds whose constant numbers are kept in a table
// rather than in `params` (docs/rewriting.md, memory).
//
// A string may go without identities (keep_ids false, ids empty): a derivation whose identities
// nobody can observe (`plant derive` without --ids, a program that never calls id() and has no
// query modules or environments) saves the 8 bytes per module they cost, about a third of the
// memory a parametric derivation writes. id(i) is 0 in such a string.
#pragma once

#include "plant/big_allocator.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

namespace plant {

// 16 bits: the string's largest array after the parameters and identities, so two bytes saved
// per module are about a tenth of a derivation's memory traffic. A program has at most
// kNoSymbol - 1 symbols (the compiler says so past that); kNoSymbol itself means "none".
using SymbolId = std::uint16_t;
constexpr SymbolId kNoSymbol = 0xFFFF;
using ModuleId = std::uint64_t;
// What the string stores per module in place of its symbol. A *plain* kind's id is its symbol's
// and the string stores all of its numbers. The compiler adds a kind for each module of a
// successor template that has constant numbers (`&(30)`, `A(1, w)`): the string stores only
// its computed numbers, the table the rest (docs/rewriting.md, memory).
using KindId = std::uint16_t;

struct KindTable {
    static constexpr std::uint32_t kAllStored = 0xFFFFFFFF;
    // Kinds below `plain` are their symbol's, without numbers. Kind k >= plain is entry
    // k - plain of the arrays below: a plain kind of some arity (layout_at kAllStored: the
    // string stores all its numbers) or a template kind (its layout in `slot` and `value`).
    std::uint32_t plain = 0x8000;
    std::vector<SymbolId> symbol;
    std::vector<std::uint8_t> arity;
    std::vector<std::uint32_t> layout_at; // its numbers' entries in `slot` and `value`
    std::vector<std::int16_t> slot;       // per number: its place among the stored ones, or -1
    std::vector<double> value;            // per number: the constant (when slot is -1)
    // Per kind, every kind (indexed by the kind itself, plain + size() entries): how many
    // numbers the string stores for a module of that kind.
    std::vector<std::uint8_t> stored;
    // Per symbol: its plain kinds of arity above 0 (or of a symbol at or past `plain`), as
    // (arity, kind).
    std::vector<std::vector<std::pair<std::uint8_t, KindId>>> by_symbol;
    std::size_t size() const { return symbol.size(); }
    std::size_t kinds() const { return plain + size(); }
    // Starts a table whose kinds below p are the symbols'.
    void reset(std::uint32_t p) {
        *this = KindTable{};
        plain = p;
        stored.assign(p, 0);
    }
    // The plain kind of symbol s with n numbers, or kNoKind when the table has none.
    static constexpr std::uint32_t kNoKind = 0x10000;
    std::uint32_t find_plain(SymbolId s, std::uint32_t n) const {
        if (n == 0 && s < plain) return s;
        if (s >= by_symbol.size()) return kNoKind;
        for (const auto& [a, k] : by_symbol[s])
            if (a == n) return k;
        return kNoKind;
    }
    // Appends a kind of symbol s with n numbers, `count` of them stored, its layout at `layout`
    // in `slot` and `value` (kAllStored: none); the caller checks there is room (kinds() below
    // kNoSymbol).
    KindId append(SymbolId s, std::uint32_t n, std::uint32_t count, std::uint32_t layout) {
        const auto k = static_cast<KindId>(kinds());
        symbol.push_back(s);
        arity.push_back(static_cast<std::uint8_t>(n));
        layout_at.push_back(layout);
        stored.push_back(static_cast<std::uint8_t>(count));
        return k;
    }
    // Adds (or finds) the plain kind of symbol s with n numbers; kNoKind when the table is full.
    std::uint32_t add_plain(SymbolId s, std::uint32_t n) {
        if (const std::uint32_t k = find_plain(s, n); k != kNoKind) return k;
        if (kinds() >= kNoSymbol) return kNoKind;
        const KindId k = append(s, n, n, kAllStored);
        if (by_symbol.size() <= s) by_symbol.resize(std::size_t{s} + 1);
        by_symbol[s].emplace_back(static_cast<std::uint8_t>(n), k);
        return k;
    }
    // The table of a string made without a program: every symbol below 0x8000 plain.
    static const KindTable* none();
};

// Module symbols for a loop over many modules: the string's arrays read through copies the
// compiler keeps in registers (members read through the string are reloaded after every store
// through a byte pointer, which may alias them).
struct SymbolReader {
    const KindId* kinds;
    std::uint32_t plain;
    const SymbolId* table;
    SymbolId operator()(std::size_t i) const {
        const KindId k = kinds[i];
        return k < plain ? k : table[k - plain];
    }
};

// A module's numbers, read one at a time (not a pointer: see the note at the top).
class ModuleArgs {
  public:
    ModuleArgs(const double* stored, std::uint32_t n, const std::int16_t* slot = nullptr,
               const double* value = nullptr)
        : p_(stored), n_(n), slot_(slot), value_(value) {}
    double operator[](std::size_t k) const {
        if (!slot_) return p_[k];
        return slot_[k] >= 0 ? p_[slot_[k]] : value_[k];
    }
    std::uint32_t size() const { return n_; }
    bool empty() const { return n_ == 0; }
    // Copies the numbers to out[0 .. size()).
    void copy_to(double* out) const {
        for (std::uint32_t k = 0; k < n_; ++k) out[k] = (*this)[k];
    }
    std::vector<double> vector() const {
        std::vector<double> v(n_);
        copy_to(v.data());
        return v;
    }

  private:
    const double* p_;
    std::uint32_t n_;
    const std::int16_t* slot_;
    const double* value_;
};

// Module i's parameters start at the sum of the numbers stored before it. No per-module offset
// or count is stored (4 and then 1 of the 12.2 bytes a module cost on the parametric tree, issue
// 22): a module's kind gives how many numbers it stores (KindTable::stored), and `block_at` holds
// the offset of every kBlock-th module, so that a random access adds at most kBlock - 1 counts.
// Sequential readers keep a running offset instead (`offset` once, then `+= stored(i)`).
struct ModuleString {
    static constexpr std::size_t kBlockShift = 6;
    static constexpr std::size_t kBlock = std::size_t{1} << kBlockShift;
    static constexpr std::uint32_t kMaxArity = 255;

    BigVector<KindId> kinds;
    BigVector<double> params;
    BigVector<std::uint32_t> block_at; // block_at[j]: where module j * kBlock's parameters start
    BigVector<ModuleId> ids;           // empty when !keep_ids
    bool keep_ids = true;
    const KindTable* kind_table = KindTable::none();
    std::uint32_t plain_below = 0x8000; // kinds below are symbols without numbers
    // A table of this string's own, grown by push for kinds its program's table lacks (a string
    // made without a program); never shared with another string while it grows.
    std::shared_ptr<KindTable> own_table;

    void use_kinds(const KindTable* t) {
        kind_table = t ? t : KindTable::none();
        plain_below = kind_table->plain;
    }
    // Takes another string's kinds (and shares its own table, if it has one).
    void use_kinds_of(const ModuleString& o) {
        use_kinds(o.kind_table);
        own_table = o.own_table;
    }
    // Whether some module has a kind that is not a symbol's without numbers.
    bool has_table_kinds() const;

    std::size_t size() const { return kinds.size(); }
    ModuleId id(std::size_t i) const { return keep_ids ? ids[i] : 0; }
    bool empty() const { return kinds.empty(); }
    SymbolReader symbols() const { return {kinds.data(), plain_below, kind_table->symbol.data()}; }
    SymbolId symbol(std::size_t i) const {
        const KindId k = kinds[i];
        return k < plain_below ? k : kind_table->symbol[k - plain_below];
    }
    std::uint32_t arity(std::size_t i) const {
        const KindId k = kinds[i];
        return k < plain_below ? 0 : kind_table->arity[k - plain_below];
    }
    // How many of module i's numbers `params` holds.
    std::uint32_t stored(std::size_t i) const { return kind_table->stored[kinds[i]]; }
    // Where module i's parameters start (i == size(): the end of the parameters).
    std::size_t offset(std::size_t i) const {
        if (i >= size()) return params.size();
        std::size_t at = block_at[i >> kBlockShift];
        const std::uint8_t* st = kind_table->stored.data();
        for (std::size_t j = i & ~(kBlock - 1); j < i; ++j) at += st[kinds[j]];
        return at;
    }
    ModuleArgs args(std::size_t i) const { return args_at(i, params.data() + offset(i)); }
    // Module i's numbers for a reader whose own position in `params` is `at` (offset(i)).
    ModuleArgs args_at(std::size_t i, const double* at) const {
        const KindId k = kinds[i];
        if (k < plain_below) return {at, 0};
        const std::size_t e = k - plain_below, l = kind_table->layout_at[e];
        if (l == KindTable::kAllStored) return {at, kind_table->arity[e]};
        return {at, kind_table->arity[e], kind_table->slot.data() + l, kind_table->value.data() + l};
    }
    // Where module i's stored numbers can be written in place (all its numbers for a plain kind:
    // query and communication modules always are).
    double* stored_args(std::size_t i) { return params.data() + offset(i); }
    // Whether both strings hold the same modules, symbol and numbers (their kinds may differ).
    bool same_modules(const ModuleString& o) const;

    void clear() {
        kinds.clear();
        params.clear();
        block_at.clear();
        ids.clear();
    }
    // Appends a module of symbol s (a plain kind) and its k numbers.
    void push(SymbolId s, const double* p, std::uint32_t k, ModuleId id) {
        if (k > kMaxArity) throw std::length_error("a module can carry at most 255 numbers");
        std::uint32_t kind = kind_table->find_plain(s, k);
        if (kind == KindTable::kNoKind) kind = grow_kinds(s, k);
        push_kind(static_cast<KindId>(kind), p, k, id);
    }
    // Appends a module of kind `kind` whose k stored numbers are p[0 .. k).
    void push_kind(KindId kind, const double* p, std::uint32_t k, ModuleId id) {
        if ((kinds.size() & (kBlock - 1)) == 0) block_at.push_back(static_cast<std::uint32_t>(params.size()));
        kinds.push_back(kind);
        for (std::uint32_t i = 0; i < k; ++i) params.push_back(p[i]);
        if (keep_ids) ids.push_back(id);
    }
    // Appends modules [b, e) of another string (which keeps identities if this one does, and
    // whose kinds this one's table knows: a string without modules takes the other's table).
    void append_range(const ModuleString& o, std::size_t b, std::size_t e);
    void append(const ModuleString& o) { append_range(o, 0, o.size()); }
    // Cuts the string to its first m modules.
    void truncate(std::size_t m);
    // The number of parameters modules [b, e) carry.
    std::size_t params_of(std::size_t b, std::size_t e) const {
        std::size_t sum = 0;
        const std::uint8_t* st = kind_table->stored.data();
        for (std::size_t j = b; j < e; ++j) sum += st[kinds[j]];
        return sum;
    }
    // Sizes the arrays for m modules and p parameters without indexing them (for writers that
    // fill them directly, then call index_from or index_range).
    void resize_arrays(std::size_t m, std::size_t p) {
        kinds.resize(m);
        if (keep_ids) ids.resize(m);
        params.resize(p);
    }
    // After kinds and params were written directly: sizes block_at for size() modules and
    // fills its entries for modules from b on, module b's parameters starting at p. index_range
    // fills those of modules [b, e) only, block_at being sized already (a thread's stretch).
    // index_upto sizes block_at for e modules and fills those of [b, e) (a writer whose arrays
    // are open past e).
    void index_from(std::size_t b, std::size_t p) { index_upto(b, size(), p); }
    void index_upto(std::size_t b, std::size_t e, std::size_t p) {
        block_at.resize((e + kBlock - 1) >> kBlockShift);
        index_range(b, e, p);
    }
    void index_range(std::size_t b, std::size_t e, std::size_t p);
    // Bytes held by the arrays (capacity, not size: what the process really pays).
    std::size_t bytes() const {
        return kinds.capacity() * sizeof(KindId) + params.capacity() * sizeof(double) +
               block_at.capacity() * sizeof(std::uint32_t) + ids.capacity() * sizeof(ModuleId);
    }
    void swap(ModuleString& o) noexcept {
        kinds.swap(o.kinds);
        params.swap(o.params);
        block_at.swap(o.block_at);
        ids.swap(o.ids);
        std::swap(keep_ids, o.keep_ids);
        std::swap(kind_table, o.kind_table);
        std::swap(plain_below, o.plain_below);
        own_table.swap(o.own_table);
    }

  private:
    // Gives the string a table of its own that has a plain kind for (s, k) (push's slow path).
    std::uint32_t grow_kinds(SymbolId s, std::uint32_t k);
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
