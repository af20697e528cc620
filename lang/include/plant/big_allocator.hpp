// Allocator for the module string's arrays. Three things a derivation step pays for otherwise:
// - value-initialisation: resize() would zero memory that is overwritten right after, so
//   construct() without arguments default-initialises (leaves numbers as they are);
// - page faults: a step writes its whole output into fresh memory, so blocks of 4 KiB and more
//   live in 2 MiB pages, aligned and marked for transparent huge pages: one fault per 2 MiB
//   instead of one per 4 KiB. Measured on the parametric tree (n = 16): 15 ms -> 6 ms. Blocks
//   of 4 KiB to 1 MiB share 2 MiB pages (a power of two each, split and merged as buddies),
//   so a derivation's small strings fault in one page between them instead of one each, the
//   page its large strings take later (docs/rewriting.md, "Shared pages from 4 KiB");
// - zeroing: the kernel clears every page it hands out, and a growing derivation frees a string
//   every step. Freed blocks are kept (see big_pages) and their pages moved into the next blocks,
//   so a page is cleared once per run, not once per step.
//
// Every block is charged against the memory budget (memory_budget.hpp) before it is taken, and
// given back when it is freed.
#pragma once

#include "plant/big_pages.hpp"
#include "plant/memory_budget.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <vector>

namespace plant {

template <typename T> struct BigAllocator {
    using value_type = T;
    static constexpr std::size_t kMapped = big_pages::kShareFrom;

    BigAllocator() noexcept = default;
    template <typename U> BigAllocator(const BigAllocator<U>&) noexcept {}

    // The bytes a block of n takes, as charged.
    static std::size_t charged_bytes(std::size_t n) {
        const std::size_t bytes = n * sizeof(T);
        return bytes >= kMapped ? big_pages::block_bytes(bytes) : bytes;
    }

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T) / 2) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T), block = charged_bytes(n);
        memory::charge(block);
        void* p = bytes < kMallocBelow           ? std::malloc(bytes ? bytes : 1)
                  : block <= big_pages::kShareTo ? big_pages::map_shared(block)
                                                 : big_pages::map(block);
        if (!p) {
            memory::release(block);
            throw std::bad_alloc();
        }
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        const std::size_t block = charged_bytes(n);
        memory::release(block);
        if (n * sizeof(T) < kMallocBelow)
            std::free(p);
        else if (block <= big_pages::kShareTo)
            big_pages::unmap_shared(p, block);
        else
            big_pages::unmap(p, block);
    }

    template <typename U> void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
        ::new (static_cast<void*>(p)) U;
    }
    template <typename U, typename... Args> void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }

    template <typename U> bool operator==(const BigAllocator<U>&) const noexcept { return true; }
};

template <typename T> using BigVector = std::vector<T, BigAllocator<T>>;

// Sizes v for n elements for a writer that overwrites them all: what v held is discarded when it
// must grow. A new block is taken whole (a block of kMapped bytes or more is a power of two or
// whole 2 MiB pages anyway): with its whole room as capacity, a buffer kept from step to step (the
// symbol kernel's keys, a string kept for a later step) takes the next steps' larger sizes
// without a fresh block; a smaller one is taken twice as large as asked, for the same reason.
// The old block is freed first, so that its pages move into the new one.
template <typename T> void size_whole(BigVector<T>& v, std::size_t n) {
    if (n > v.capacity()) {
        BigVector<T>().swap(v);
        const std::size_t bytes = n * sizeof(T);
        v.reserve(bytes >= BigAllocator<T>::kMapped ? big_pages::block_bytes(bytes) / sizeof(T) : 2 * n);
    }
    v.resize(n);
}

} // namespace plant
