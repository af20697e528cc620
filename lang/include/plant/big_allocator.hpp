// Allocator for the module string's arrays. Three things a derivation step pays for otherwise:
// - value-initialisation: resize() would zero memory that is overwritten right after, so
//   construct() without arguments default-initialises (leaves numbers as they are);
// - page faults: a step writes its whole output into fresh memory, so blocks of 64 KiB and more
//   are whole 2 MiB pages, aligned and marked for transparent huge pages: one fault per 2 MiB
//   instead of one per 4 KiB. Measured on the parametric tree (n = 16): 15 ms -> 6 ms;
// - zeroing: the kernel clears every page it hands out, and a growing derivation frees a string
//   every step. Freed blocks are kept (see big_pages) and their pages moved into the next blocks,
//   so a page is cleared once per run, not once per step.
//
// Every block is charged against the memory budget (memory_budget.hpp) before it is taken, and
// given back when it is freed.
#pragma once

#include "plant/memory_budget.hpp"

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <type_traits>
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
void trim();                            // gives every kept page back to the system
std::size_t kept_bytes();
} // namespace big_pages

template <typename T> struct BigAllocator {
    using value_type = T;
    static constexpr std::size_t kMapped = std::size_t{64} << 10;

    BigAllocator() noexcept = default;
    template <typename U> BigAllocator(const BigAllocator<U>&) noexcept {}

    // The bytes a block of n takes, as charged.
    static std::size_t charged_bytes(std::size_t n) {
        const std::size_t bytes = n * sizeof(T);
        return bytes >= kMapped ? big_pages::rounded(bytes) : bytes;
    }

    T* allocate(std::size_t n) {
        if (n > std::size_t(-1) / sizeof(T) / 2) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T);
        memory::charge(charged_bytes(n));
        void* p =
            bytes >= kMapped ? big_pages::map(big_pages::rounded(bytes)) : std::malloc(bytes ? bytes : 1);
        if (!p) {
            memory::release(charged_bytes(n));
            throw std::bad_alloc();
        }
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        memory::release(charged_bytes(n));
        if (n * sizeof(T) >= kMapped)
            big_pages::unmap(p, big_pages::rounded(n * sizeof(T)));
        else
            std::free(p);
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
// must grow. A new block is taken whole (a block of kMapped bytes or more is mapped in whole
// 2 MiB pages anyway): with its whole room as capacity, a buffer kept from step to step (the
// symbol kernel's keys, a string kept for a later step) takes the next steps' larger sizes
// without a fresh block; a smaller one is taken twice as large as asked, for the same reason.
// The old block is freed first, so that its pages move into the new one.
template <typename T> void size_whole(BigVector<T>& v, std::size_t n) {
    if (n > v.capacity()) {
        BigVector<T>().swap(v);
        const std::size_t bytes = n * sizeof(T);
        v.reserve(bytes >= BigAllocator<T>::kMapped ? big_pages::rounded(bytes) / sizeof(T) : 2 * n);
    }
    v.resize(n);
}

} // namespace plant
