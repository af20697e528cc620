// The module string's allocator: freed blocks keep their pages for the next blocks.
#include "plant/big_allocator.hpp"
#include "plant/big_pages.hpp"

#include <catch2/catch.hpp>

#include <chrono>
#include <cstdint>
#include <memory>
#include <thread>

using namespace plant;

#if defined(__SANITIZE_ADDRESS__)
// Under AddressSanitizer blocks under 64 KiB are malloc's (big_allocator.hpp), so the pages'
// layout is not tested; the blocks still read and write and are charged as the parts they would be.
TEST_CASE("under ASan the string's blocks come from malloc, charged as mapped parts", "[derive]") {
    CHECK(kMallocBelow == 64 * 1024);
    const auto charged = memory::charged();
    {
        BigVector<std::uint16_t> v(5 * 1024); // 10 KiB: a 16 KiB part
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint16_t>(i);
        CHECK(v[5 * 1024 - 1] == 5 * 1024 - 1);
        CHECK(memory::charged() == charged + 16 * 1024);
        CHECK(big_pages::shared_free_bytes() == 0);
    }
    CHECK(memory::charged() == charged);
}
#else

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

TEST_CASE("blocks of 4 KiB to 1 MiB share 2 MiB pages as buddies and give the page back whole", "[derive]") {
    big_pages::trim();
    const std::size_t kib = std::size_t{1} << 10, page = big_pages::kHuge;
    REQUIRE(big_pages::shared_free_bytes() == 0);
    CHECK(big_pages::block_bytes(4 * kib) == 4 * kib);
    CHECK(big_pages::block_bytes(5 * kib) == 8 * kib);
    CHECK(BigAllocator<std::uint16_t>::charged_bytes(2047) == 4094); // under 4 KiB: malloc's
    CHECK(BigAllocator<std::uint16_t>::charged_bytes(2048) == 4 * kib);
    CHECK(big_pages::block_bytes(64 * kib) == 64 * kib);
    CHECK(big_pages::block_bytes(65 * kib) == 128 * kib);
    CHECK(big_pages::block_bytes(1024 * kib) == 1024 * kib);
    CHECK(big_pages::block_bytes(1025 * kib) == page);
    CHECK(BigAllocator<double>::charged_bytes(100 * kib / 8) == 128 * kib);
    auto page_of = [&](const void* p) { return reinterpret_cast<std::uintptr_t>(p) / page; };
    auto offset = [&](const void* p) { return reinterpret_cast<std::uintptr_t>(p) % page; };
    {
        // 84 KB, 254 KB and 764 KB: 1.24d's strings at steps 8 to 10, all in one page
        BigVector<std::uint16_t> a(84 * kib / 2), b(254 * kib / 2), c(764 * kib / 2);
        CHECK(page_of(a.data()) == page_of(b.data()));
        CHECK(page_of(a.data()) == page_of(c.data()));
        CHECK(offset(a.data()) % (128 * kib) == 0);
        CHECK(offset(b.data()) % (256 * kib) == 0);
        CHECK(offset(c.data()) % (1024 * kib) == 0);
        // 2 MiB less 128 + 256 + 1024 KiB is free for the next small blocks
        CHECK(big_pages::shared_free_bytes() == page - 1408 * kib);
        for (std::size_t i = 0; i < a.size(); ++i) a[i] = static_cast<std::uint16_t>(i);
        for (std::size_t i = 0; i < b.size(); ++i) b[i] = static_cast<std::uint16_t>(3 * i);
        for (std::size_t i = 0; i < c.size(); ++i) c[i] = static_cast<std::uint16_t>(7 * i);
        std::size_t bad = 0;
        for (std::size_t i = 0; i < a.size(); ++i) bad += a[i] != static_cast<std::uint16_t>(i);
        for (std::size_t i = 0; i < b.size(); ++i) bad += b[i] != static_cast<std::uint16_t>(3 * i);
        CHECK(bad == 0);
        {
            BigVector<std::uint16_t> d(600 * kib / 2); // no 1 MiB part left: a page of its own
            CHECK(page_of(d.data()) != page_of(a.data()));
        }
    }
    // every part freed: the buddies merged back into whole pages, kept for later blocks
    CHECK(big_pages::shared_free_bytes() == 0);
    CHECK(big_pages::kept_bytes() == 2 * page);
    {
        // freed the other way round (the lower buddy first), and a 64 KiB part split from a
        // larger free one: merged all the same, and charged as the parts they are
        const auto charged = memory::charged();
        auto a = std::make_unique<BigVector<std::uint8_t>>(64 * kib);
        auto b = std::make_unique<BigVector<std::uint8_t>>(64 * kib);
        auto c = std::make_unique<BigVector<std::uint8_t>>(300 * kib);
        CHECK(memory::charged() == charged + 64 * kib + 64 * kib + 512 * kib);
        CHECK(page_of(a->data()) == page_of(c->data()));
        CHECK(reinterpret_cast<std::uintptr_t>(b->data()) ==
              (reinterpret_cast<std::uintptr_t>(a->data()) ^ (64 * kib)));
        CHECK(big_pages::kept_bytes() == page); // one of the two kept pages taken
        a.reset();
        CHECK(big_pages::shared_free_bytes() == page - 64 * kib - 512 * kib);
        b.reset();
        c.reset();
        CHECK(memory::charged() == charged);
    }
    CHECK(big_pages::shared_free_bytes() == 0);
    CHECK(big_pages::kept_bytes() == 2 * page);
    big_pages::trim();
    CHECK(big_pages::kept_bytes() == 0);
}

TEST_CASE("a derivation's strings of a few KB take parts of the page its large ones use", "[derive]") {
    big_pages::trim();
    const std::size_t kib = std::size_t{1} << 10, page = big_pages::kHuge;
    auto page_of = [&](const void* p) { return reinterpret_cast<std::uintptr_t>(p) / page; };
    {
        // 1.24d's strings at steps 5 to 10 (kinds, 2 bytes a module): 6 KB to 764 KB, one page
        BigVector<std::uint16_t> s5(6 * kib / 2), s6(18 * kib / 2), s7(56 * kib / 2);
        BigVector<std::uint16_t> s8(84 * kib / 2), s9(254 * kib / 2), s10(764 * kib / 2);
        for (const auto* v : {&s6, &s7, &s8, &s9, &s10}) CHECK(page_of(v->data()) == page_of(s5.data()));
        CHECK(reinterpret_cast<std::uintptr_t>(s5.data()) % (8 * kib) == 0);
        CHECK(big_pages::shared_free_bytes() == page - (8 + 32 + 64 + 128 + 256 + 1024) * kib);
        // under 4 KiB: malloc's, no part taken
        BigVector<std::uint16_t> tiny(2047);
        CHECK(big_pages::shared_free_bytes() == page - (8 + 32 + 64 + 128 + 256 + 1024) * kib);
    }
    CHECK(big_pages::shared_free_bytes() == 0);
    CHECK(big_pages::kept_bytes() == page);
    big_pages::trim();
}

TEST_CASE("clear_ahead clears one page on another thread and keeps it for the next block", "[derive]") {
    big_pages::trim();
    REQUIRE(big_pages::kept_bytes() == 0);
    big_pages::clear_ahead();
    // the thread's page arrives in the kept blocks (a block asked for meanwhile would wait for it)
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (big_pages::kept_bytes() == 0 && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    REQUIRE(big_pages::kept_bytes() == big_pages::kHuge);
    {
        BigVector<std::uint16_t> s(50 * 1024); // 100 KiB: a part of the kept page, which reads zero
        CHECK(big_pages::kept_bytes() == 0);
        std::size_t nonzero = 0;
        for (std::size_t i = 0; i < s.size(); ++i) nonzero += s[i] != 0;
        CHECK(nonzero == 0);
    }
    big_pages::clear_ahead(); // once a process: nothing more is cleared
    CHECK(big_pages::kept_bytes() == big_pages::kHuge);
    big_pages::trim();
}

TEST_CASE("trim gives kept pages back but for the whole pages it is told to keep", "[derive]") {
    big_pages::trim();
    const std::size_t page = big_pages::kHuge;
    {
        BigVector<std::uint8_t> a(3 * page - 5), b(page); // three pages and one
        a[0] = b[0] = 1;
    }
    REQUIRE(big_pages::kept_bytes() == 4 * page);
    big_pages::trim(2 * page + page / 2); // rounded down to two pages
    CHECK(big_pages::kept_bytes() == 2 * page);
    {
        BigVector<std::uint8_t> c(2 * page); // the kept pages serve a block of their size
        c[2 * page - 1] = 7;
        CHECK(c[2 * page - 1] == 7);
        CHECK(big_pages::kept_bytes() == 0);
    }
    big_pages::trim(page);
    CHECK(big_pages::kept_bytes() == page);
    big_pages::trim();
    CHECK(big_pages::kept_bytes() == 0);
}
TEST_CASE("the physics library's arrays take the same pages, zeroed, and charge nothing", "[physics]") {
    big_pages::trim();
    const std::size_t page = big_pages::kHuge;
    const auto charged = memory::charged();
    {
        // 25,000 positions of 24 bytes: a 1 MiB part of a shared page; 25,000 3x3 matrices:
        // a whole page of its own, 2 MiB aligned
        PagedVector<double> x(3 * 25000), m(9 * 25000, 1.0);
        CHECK(reinterpret_cast<std::uintptr_t>(m.data()) % page == 0);
        CHECK(big_pages::shared_free_bytes() == page / 2);
        CHECK(memory::charged() == charged);
        for (double d : x) REQUIRE(d == 0.0); // resize and the size constructor zero, as std::vector
        x.resize(4 * 25000);
        CHECK(x.back() == 0.0);
        CHECK(m[9 * 25000 - 1] == 1.0);
    }
    CHECK(big_pages::shared_free_bytes() == 0);
    CHECK(big_pages::kept_bytes() >= 2 * page); // the matrices' page and the shared one, kept
    PagedVector<int> small(100);                // under 4 KiB: malloc's
    CHECK(small[99] == 0);
    big_pages::trim();
}
#endif
