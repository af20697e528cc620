// Memory in 2 MiB pages marked for transparent huge pages, for the large arrays that a derivation
// or a physics step writes into fresh memory: one page fault per 2 MiB instead of one per 4 KiB,
// and freed pages kept and moved into later blocks instead of cleared again by the kernel
// (common/src/big_pages.cpp; docs/rewriting.md, "Shared pages from 4 KiB"). The module string's
// allocator (plant/big_allocator.hpp) adds the memory budget on top; PagedAllocator is the same
// memory without the budget, for the physics runtime's per-particle arrays (docs/physics.md,
// "Memory").
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

namespace plant {

// Blocks of whole 2 MiB pages, 2 MiB aligned, for BigAllocator. A freed block is not returned to
// the system at once: its pages are kept (up to a cap) and moved by mremap into the blocks asked
// for later, which then need no fresh, kernel-cleared pages for that part. Thread-safe.
namespace big_pages {
constexpr std::size_t kHuge = std::size_t{2} << 20;
inline std::size_t rounded(std::size_t bytes) {
    return (bytes + kHuge - 1) / kHuge * kHuge;
}
void* map(std::size_t bytes);           // bytes: a multiple of kHuge; nullptr when out of memory
void unmap(void* p, std::size_t bytes); // a block from map(), whole
// Gives kept pages back to the system, all but `keep` bytes of them (rounded down to whole 2 MiB
// pages): a process that derives again soon (a batch of variants, the REPL, the view server)
// then reuses a warm page instead of clearing a fresh one.
void trim(std::size_t keep = 0);
std::size_t kept_bytes();
// Starts a thread that maps one fresh 2 MiB page, has the kernel clear it and keeps it, so that
// the first block a derivation asks for later is a kept page instead of one cleared on its clock.
// For a process about to parse a grammar with a second core idle: the clearing (0.1-0.3 ms on the
// VMs measured) overlaps the parsing (docs/rewriting.md, "A page cleared ahead"). Once a process;
// later calls do nothing. The thread is joined at exit.
void clear_ahead();

// Blocks of kShareFrom to kShareTo bytes share 2 MiB pages: each is a power of two at an offset
// that is a multiple of its size, split from a larger free one and merged with its free buddy
// when freed; a page whose parts are all free again goes back to the kept blocks.
constexpr std::size_t kShareFrom = std::size_t{4} << 10;
constexpr std::size_t kShareTo = kHuge / 2;
// The bytes a block asked for takes: a power of two from kShareFrom up to kShareTo, whole 2 MiB
// pages beyond. Only for bytes >= kShareFrom.
inline std::size_t block_bytes(std::size_t bytes) {
    if (bytes > kShareTo) return rounded(bytes);
    std::size_t b = kShareFrom;
    while (b < bytes) b *= 2;
    return b;
}
void* map_shared(std::size_t bytes);           // bytes: block_bytes of at most kShareTo
void unmap_shared(void* p, std::size_t bytes); // a block from map_shared(), whole
std::size_t shared_free_bytes();               // free parts of pages that are partly in use
} // namespace big_pages

// Built with AddressSanitizer (make test-sanitize), blocks under 64 KiB come from malloc, which
// ASan guards (it cannot see past the end of a part of a mapped page), as they did before parts
// started at 4 KiB; sizes and charges are the same. Larger ones stay mapped: ASan keeps freed
// malloc blocks resident in its quarantine, and the resident-memory backstop would count them.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr std::size_t kMallocBelow = std::size_t{64} << 10;
#else
inline constexpr std::size_t kMallocBelow = big_pages::kShareFrom;
#endif

// Blocks of kMallocBelow bytes and more come from big_pages, smaller ones from malloc; built with
// AddressSanitizer, every block comes from malloc, so that ASan guards the physics arrays (they
// are kept from step to step, not freed and taken again as strings are, so its quarantine holds
// little of them). Unlike BigAllocator, elements are constructed as std::allocator constructs
// them (resize() zeroes numbers) and nothing is charged to the memory budget.
template <typename T> struct PagedAllocator {
    using value_type = T;

    PagedAllocator() noexcept = default;
    template <typename U> PagedAllocator(const PagedAllocator<U>&) noexcept {}

#if defined(__SANITIZE_ADDRESS__)
    static constexpr std::size_t kFromMallocBelow = std::size_t(-1); // every block
#else
    static constexpr std::size_t kFromMallocBelow = kMallocBelow;
#endif

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T) / 2) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T);
        void* p = nullptr;
        if (bytes < kFromMallocBelow)
            p = std::malloc(bytes ? bytes : 1);
        else if (const std::size_t block = big_pages::block_bytes(bytes); block <= big_pages::kShareTo)
            p = big_pages::map_shared(block);
        else
            p = big_pages::map(block);
        if (!p) throw std::bad_alloc();
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        const std::size_t bytes = n * sizeof(T);
        if (bytes < kFromMallocBelow)
            std::free(p);
        else if (const std::size_t block = big_pages::block_bytes(bytes); block <= big_pages::kShareTo)
            big_pages::unmap_shared(p, block);
        else
            big_pages::unmap(p, block);
    }

    template <typename U> bool operator==(const PagedAllocator<U>&) const noexcept {
        return true;
    }
};

template <typename T> using PagedVector = std::vector<T, PagedAllocator<T>>;

} // namespace plant
