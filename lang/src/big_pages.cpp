// Page recycling for BigAllocator (see big_allocator.hpp).
//
// A derivation that doubles its string every step frees, each step, the string before last. With
// plain mmap/munmap every output is fresh memory the kernel must clear first, and on the
// parametric tree that clearing was half of the derivation time. Here freed blocks stay mapped
// in a list; a new block is first reserved as address space, then as much of it as the list
// covers is filled by moving kept pages in with mremap(MREMAP_FIXED), which remaps them without
// copying or clearing. Only the rest of the block is faulted in fresh. The pages a run touches
// are then about its peak footprint instead of the sum of all its strings.
#include "plant/big_allocator.hpp"

#include <algorithm>
#include <mutex>
#include <sys/mman.h>

namespace plant::big_pages {

namespace {

struct Block {
    char* at;
    std::size_t bytes;
};

// Kept blocks beyond this are given back at once: a cache, not a leak.
constexpr std::size_t kKeepAtMost = std::size_t{1} << 30;

std::mutex lock;
std::vector<Block> kept; // guarded by lock
std::size_t kept_total = 0;

// Fresh address space for `bytes`, 2 MiB aligned, marked for transparent huge pages.
char* reserve(std::size_t bytes) {
    void* raw = ::mmap(nullptr, bytes + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) return nullptr;
    auto begin = reinterpret_cast<std::uintptr_t>(raw);
    auto aligned = (begin + kHuge - 1) / kHuge * kHuge;
    if (aligned > begin) ::munmap(raw, aligned - begin);
    if (aligned + bytes < begin + bytes + kHuge)
        ::munmap(reinterpret_cast<void*>(aligned + bytes), begin + kHuge - aligned);
    auto* p = reinterpret_cast<char*>(aligned);
    ::madvise(p, bytes, MADV_HUGEPAGE);
    return p;
}

} // namespace

void* map(std::size_t bytes) {
    std::lock_guard<std::mutex> guard(lock);
    // a kept block large enough is used as it is (its tail stays kept)
    auto fit = std::find_if(kept.begin(), kept.end(), [&](const Block& b) { return b.bytes >= bytes; });
    if (fit != kept.end()) {
        char* p = fit->at;
        if (fit->bytes == bytes) {
            kept.erase(fit);
        } else {
            fit->at += bytes;
            fit->bytes -= bytes;
        }
        kept_total -= bytes;
        return p;
    }
    char* p = reserve(bytes);
    if (!p) return nullptr;
    // every kept block is smaller than the request: move them in, back to back, as far as they go
    std::size_t filled = 0;
    while (!kept.empty() && filled < bytes) {
        Block& b = kept.back();
        const std::size_t take = std::min(b.bytes, bytes - filled);
        if (::mremap(b.at, take, take, MREMAP_MAYMOVE | MREMAP_FIXED, p + filled) == MAP_FAILED)
            break; // the rest of the block is faulted in fresh
        filled += take;
        kept_total -= take;
        if (take == b.bytes) {
            kept.pop_back();
        } else {
            b.at += take;
            b.bytes -= take;
        }
    }
    return p;
}

void unmap(void* p, std::size_t bytes) {
    std::lock_guard<std::mutex> guard(lock);
    if (kept_total + bytes > kKeepAtMost) {
        ::munmap(p, bytes);
        return;
    }
    kept.push_back(Block{static_cast<char*>(p), bytes});
    kept_total += bytes;
}

void trim() {
    std::lock_guard<std::mutex> guard(lock);
    for (const Block& b : kept) ::munmap(b.at, b.bytes);
    kept.clear();
    kept_total = 0;
}

std::size_t kept_bytes() {
    std::lock_guard<std::mutex> guard(lock);
    return kept_total;
}

} // namespace plant::big_pages
