// The module string's helpers and its printed form (docs/language.md, printing strings).
#include "plant/derive.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstring>
#include <unordered_set>

namespace plant {

const KindTable* KindTable::none() {
    static const KindTable t = [] {
        KindTable k;
        k.reset(0x8000);
        return k;
    }();
    return &t;
}

std::uint32_t ModuleString::grow_kinds(SymbolId s, std::uint32_t k) {
    if (!own_table || own_table.get() != kind_table || own_table.use_count() > 1) {
        own_table = std::make_shared<KindTable>(*kind_table);
        use_kinds(own_table.get());
    }
    const std::uint32_t kind = own_table->add_plain(s, k);
    if (kind == KindTable::kNoKind) throw std::length_error("too many kinds of module in one string");
    return kind;
}

bool ModuleString::has_table_kinds() const {
    if (kind_table->size() == 0) return false;
    const KindId* k = kinds.data();
    std::uint32_t any = 0;
    for (std::size_t i = 0, n = size(); i < n; ++i) any |= k[i] >= plain_below;
    return any != 0;
}

bool ModuleString::same_modules(const ModuleString& o) const {
    if (size() != o.size()) return false;
    if (kinds == o.kinds && kind_table == o.kind_table) return params == o.params;
    for (std::size_t i = 0, at = 0, o_at = 0; i < size(); at += stored(i), o_at += o.stored(i), ++i) {
        if (symbol(i) != o.symbol(i) || arity(i) != o.arity(i)) return false;
        const ModuleArgs a = args_at(i, params.data() + at), b = o.args_at(i, o.params.data() + o_at);
        for (std::uint32_t k = 0; k < a.size(); ++k)
            if (a[k] != b[k]) return false;
    }
    return true;
}

void ModuleString::append_range(const ModuleString& o, std::size_t b, std::size_t e) {
    if (b >= e) return;
    if (kind_table != o.kind_table) {
        if (empty()) {
            use_kinds_of(o);
        } else { // another table's kinds: module by module, as plain kinds of this one
            double v[kMaxArity];
            for (std::size_t i = b, at = o.offset(b); i < e; at += o.stored(i), ++i) {
                const ModuleArgs a = o.args_at(i, o.params.data() + at);
                a.copy_to(v);
                push(o.symbol(i), v, a.size(), o.id(i));
            }
            return;
        }
    }
    const std::size_t m0 = kinds.size(), p0 = params.size();
    if (e - b == 1) { // the common case in context-sensitive grammars: one module between rewrites
        if ((m0 & (kBlock - 1)) == 0) block_at.push_back(static_cast<std::uint32_t>(p0));
        kinds.push_back(o.kinds[b]);
        if (keep_ids) ids.push_back(o.ids[b]);
        const double* a = o.params.data() + o.offset(b);
        for (std::uint32_t k = 0; k < o.stored(b); ++k) params.push_back(a[k]);
        return;
    }
    const std::size_t n = e - b, pb = o.offset(b), pe = o.offset(e);
    kinds.resize(m0 + n);
    if (keep_ids) ids.resize(m0 + n);
    params.resize(p0 + (pe - pb));
    std::memcpy(kinds.data() + m0, o.kinds.data() + b, n * sizeof(KindId));
    if (keep_ids) std::memcpy(ids.data() + m0, o.ids.data() + b, n * sizeof(ModuleId));
    if (pe > pb) std::memcpy(params.data() + p0, o.params.data() + pb, (pe - pb) * sizeof(double));
    index_from(m0, p0);
}

void ModuleString::truncate(std::size_t m) {
    if (m >= size()) return;
    params.resize(offset(m));
    kinds.resize(m);
    if (keep_ids) ids.resize(m);
    block_at.resize((m + kBlock - 1) >> kBlockShift);
}

void ModuleString::index_range(std::size_t b, std::size_t e, std::size_t p) {
    const KindId* k = kinds.data();
    const std::uint8_t* st = kind_table->stored.data();
    std::size_t i = b;
    // up to the first block start at or after b
    for (; i < e && (i & (kBlock - 1)) != 0; ++i) p += st[k[i]];
    // whole blocks: one entry, then a sum of kBlock counts looked up by kind
    for (; i < e; i += kBlock) {
        block_at[i >> kBlockShift] = static_cast<std::uint32_t>(p);
        const std::size_t end = std::min(e, i + kBlock);
        std::uint32_t sum = 0;
        for (std::size_t j = i; j < end; ++j) sum += st[k[j]];
        p += sum;
    }
}

void bracket_table(const ModuleString& s, SymbolId open, SymbolId close, std::vector<std::uint32_t>& match) {
    const auto n = static_cast<std::uint32_t>(s.size());
    match.resize(s.size());
    // The stack of open brackets is kept in the table itself: an open '[' holds the index of the
    // '[' below it until its ']' is found. No allocation besides the table.
    std::uint32_t top = n;
    const SymbolReader sym_of = s.symbols();
    for (std::uint32_t i = 0; i < n; ++i) {
        const SymbolId x = sym_of(i);
        if (x == open) {
            match[i] = top;
            top = i;
        } else if (x == close) {
            if (top == n) {
                match[i] = n;
                continue;
            }
            const std::uint32_t below = match[top];
            match[top] = i;
            match[i] = top;
            top = below;
        }
    }
    while (top != n) { // unclosed: no partner
        const std::uint32_t below = match[top];
        match[top] = n;
        top = below;
    }
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

std::string format_string(const Program& program, const ModuleString& s, bool with_ids,
                          std::size_t max_chars) {
    std::string out;
    out.reserve(s.size() * 2);
    // Prefixes of declared multi-letter names: "F" then "b" must be spaced when "Fb..." is declared.
    std::unordered_set<std::string> prefixes;
    for (const auto& info : program.symbols.all())
        if (info.declared && info.name.size() > 1 && std::isalpha(static_cast<unsigned char>(info.name[0])))
            for (std::size_t l = 2; l <= info.name.size(); ++l) prefixes.insert(info.name.substr(0, l));
    const std::string* prev = nullptr; // name of the previous module when it ends in a letter run
    const SymbolReader sym_of = s.symbols();
    const double* at = s.params.data(); // module i's stored numbers (the string is read in order)
    const std::uint8_t* stored = s.kind_table->stored.data();
    for (std::size_t i = 0; i < s.size() && out.size() <= max_chars; at += stored[sym_of.kinds[i]], ++i) {
        const std::string& name = program.symbols[sym_of(i)].name;
        bool letter_start =
            !name.empty() && (std::isalpha(static_cast<unsigned char>(name[0])) || name[0] == '_');
        // a space only where reading back would merge two names
        if (prev && letter_start) {
            if (prev->size() > 1 || *prev == "~" || prefixes.count(*prev + name[0])) out += ' ';
        }
        out += name;
        const KindId kind = sym_of.kinds[i];
        const std::uint32_t k = kind < sym_of.plain ? 0 : s.kind_table->arity[kind - sym_of.plain];
        if (k > 0 || name == ";") { // a bare ';' would end the statement when read back
            out += '(';
            const ModuleArgs a = s.args_at(i, at);
            for (std::uint32_t j = 0; j < k; ++j) {
                if (j) out += ',';
                out += format_double(a[j]);
            }
            out += ')';
        }
        if (with_ids) out += fmt::format("#{}", s.id(i));
        bool ends_letters =
            !name.empty() && (std::isalnum(static_cast<unsigned char>(name.back())) || name.back() == '_');
        // a bare '~' followed by a letter would read back as one surface name
        prev = (k == 0 && !with_ids && (ends_letters || name == "~")) ? &name : nullptr;
    }
    return out;
}

void cut_branches(ModuleString& s, SymbolId open, SymbolId close,
                  const std::function<bool(std::size_t)>& cuts) {
    ModuleString out;
    out.keep_ids = s.keep_ids;
    out.use_kinds_of(s);
    const std::size_t n = s.size();
    std::size_t i = 0;
    while (i < n) {
        if (!cuts(i)) {
            out.append_range(s, i, i + 1);
            ++i;
            continue;
        }
        // skip to the ']' closing the current branch (kept) or to the end
        int depth = 0;
        ++i;
        while (i < n) {
            if (s.symbol(i) == open)
                ++depth;
            else if (s.symbol(i) == close) {
                if (depth == 0) break;
                --depth;
            }
            ++i;
        }
    }
    s.swap(out);
}

} // namespace plant
