// The module string's allocator: freed blocks keep their pages for the next blocks.
#include "plant/big_allocator.hpp"

#include <catch2/catch.hpp>

#include <cstdint>

using namespace plant;

TEST_CASE("freed string blocks lend their pages to later ones, which read and write normally", "[derive]") {
    big_pages::trim();
    REQUIRE(big_pages::kept_bytes() == 0);
    const std::size_t mib = std::size_t{1} << 20;
    {
        BigVector<std::uint64_t> a(3 * mib / 8); // 3 MiB: two 2 MiB pages
        for (std::size_t i = 0; i < a.size(); ++i) a[i] = i;
    }
    CHECK(big_pages::kept_bytes() == 4 * mib);
    {
        // larger than anything kept: the kept pages are moved in, the rest is fresh
        BigVector<std::uint64_t> b(9 * mib / 8);
        CHECK(big_pages::kept_bytes() == 0);
        for (std::size_t i = 0; i < b.size(); ++i) b[i] = 3 * i + 1;
        std::uint64_t bad = 0;
        for (std::size_t i = 0; i < b.size(); ++i) bad += b[i] != 3 * i + 1;
        CHECK(bad == 0);
    }
    CHECK(big_pages::kept_bytes() == 10 * mib);
    {
        // smaller: the head of a kept block, its tail stays kept
        BigVector<double> c(mib / 8);
        CHECK(big_pages::kept_bytes() == 8 * mib);
        for (std::size_t i = 0; i < c.size(); ++i) c[i] = 0.5 * static_cast<double>(i);
        CHECK(c[c.size() - 1] == 0.5 * static_cast<double>(c.size() - 1));
    }
    CHECK(big_pages::kept_bytes() == 10 * mib);
    big_pages::trim();
    CHECK(big_pages::kept_bytes() == 0);
}
