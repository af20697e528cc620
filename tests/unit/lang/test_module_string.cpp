// The module string keeps no per-module parameter offset: arities and the offset of every
// kBlock-th module (module_string.hpp). These check every way of writing a string against a
// plain list of modules, across block boundaries and with arities from 0 to the limit.
#include "plant/module_string.hpp"

#include <catch2/catch.hpp>

#include <vector>

using namespace plant;

namespace {

struct Plain {
    std::vector<std::vector<double>> args;
};

// module i has arity (i * 7) % 5, except a few at the limit; parameters count up
Plain plain(std::size_t n) {
    Plain p;
    double v = 0;
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t k = i % 97 == 3 ? ModuleString::kMaxArity : (i * 7) % 5;
        std::vector<double> a(k);
        for (auto& x : a) x = v++;
        p.args.push_back(a);
    }
    return p;
}

void check_same(const ModuleString& s, const Plain& p, std::size_t from = 0) {
    REQUIRE(s.size() == p.args.size() - from);
    std::size_t total = 0;
    for (std::size_t i = 0; i < s.size(); ++i) {
        const auto& want = p.args[from + i];
        REQUIRE(s.arity(i) == want.size());
        REQUIRE(s.offset(i) == total);
        for (std::size_t k = 0; k < want.size(); ++k) REQUIRE(s.args(i)[k] == want[k]);
        total += want.size();
    }
    CHECK(s.offset(s.size()) == s.params.size());
    CHECK(total == s.params.size());
}

ModuleString pushed(const Plain& p) {
    ModuleString s;
    s.keep_ids = false;
    for (std::size_t i = 0; i < p.args.size(); ++i)
        s.push(static_cast<SymbolId>(i % 3), p.args[i].data(), static_cast<std::uint32_t>(p.args[i].size()),
               0);
    return s;
}

} // namespace

TEST_CASE("module string: parameters found from arities and block offsets", "[module_string]") {
    const Plain p = plain(1000);
    const ModuleString s = pushed(p);
    check_same(s, p);

    SECTION("appended in ranges of every length, one module, and whole") {
        const std::size_t lens[] = {1, 2, 63, 64, 65, 200};
        for (std::size_t len : lens) {
            ModuleString t;
            t.keep_ids = false;
            for (std::size_t b = 0; b < s.size(); b += len) t.append_range(s, b, std::min(s.size(), b + len));
            check_same(t, p);
        }
        ModuleString t;
        t.keep_ids = false;
        t.append_range(s, 5, 6);
        t.append_range(s, 6, s.size()); // starts mid-block
        check_same(t, p, 5);
    }
    SECTION("cut back to a prefix, then grown again") {
        const std::size_t sizes[] = {0, 1, 63, 64, 65, 500};
        for (std::size_t m : sizes) {
            ModuleString t = s;
            t.truncate(m);
            Plain q = p;
            q.args.resize(m);
            check_same(t, q);
            t.append_range(s, m, s.size());
            check_same(t, p);
        }
    }
    SECTION("written directly, then indexed in stretches") {
        ModuleString t;
        t.keep_ids = false;
        t.sym = s.sym;
        t.nargs = s.nargs;
        t.params = s.params;
        t.block_at.assign((t.size() + ModuleString::kBlock - 1) / ModuleString::kBlock, 0xdead);
        // two stretches, the second starting inside a block
        t.index_range(0, 300, 0);
        t.index_range(300, t.size(), s.offset(300));
        check_same(t, p);
        CHECK(t.block_at == s.block_at);
    }
    SECTION("a module with more numbers than a byte counts is refused") {
        ModuleString t;
        std::vector<double> a(ModuleString::kMaxArity + 1, 1.0);
        CHECK_THROWS_AS(t.push(0, a.data(), static_cast<std::uint32_t>(a.size()), 0), std::length_error);
    }
}
