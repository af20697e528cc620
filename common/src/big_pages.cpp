// Page recycling for BigAllocator and PagedAllocator (see plant/big_pages.hpp).
//
// A derivation that doubles its string every step frees, each step, the string before last. With
// plain mmap/munmap every output is fresh memory the kernel must clear first, and on the
// parametric tree that clearing was half of the derivation time. Here freed blocks stay mapped
// in a list; a new block is first reserved as address space, then as much of it as the list
// covers is filled by moving kept pages in with mremap(MREMAP_FIXED), which remaps them without
// copying or clearing. Only the rest of the block is faulted in fresh. The pages a run touches
// are then about its peak footprint instead of the sum of all its strings.
//
// Blocks of 4 KiB to 1 MiB (map_shared) are parts of 2 MiB pages, split in halves as buddies
// until one is the size asked for. Without that, each small string of a derivation's early steps
// took a page of its own, and the first touch of a 2 MiB page costs the kernel clearing all of
// it: ABOP's Fig. 1.24d at n = 10 faulted in two pages for strings of 84 KB and 254 KB, about
// 0.3 ms each on a VM, most of its derivation time (docs/rewriting.md).
#include "plant/big_pages.hpp"

#include <algorithm>
#include <bit>
#include <condition_variable>
#include <mutex>
#include <sys/mman.h>
#include <thread>

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

// clear_ahead's thread, as it goes (guarded by lock). A block that would take fresh pages while
// the thread clears its page waits for that page, which is further along than a fresh one would
// be; if the thread has not started yet, the block takes fresh pages and the thread does nothing.
enum class Ahead { Idle, Starting, Clearing };
Ahead ahead_state = Ahead::Idle;
std::condition_variable ahead_cv;

void await_ahead(std::unique_lock<std::mutex>& guard) {
    if (ahead_state == Ahead::Starting) ahead_state = Ahead::Idle;
    ahead_cv.wait(guard, [] { return ahead_state == Ahead::Idle; });
}

// The free parts of shared pages by size, kShareFrom << k for k = 0..kClasses-1 (guarded by lock).
constexpr int kClasses = std::countr_zero(kShareTo / kShareFrom) + 1;
static_assert((kShareFrom << (kClasses - 1)) == kShareTo);
std::vector<char*> free_parts[kClasses];
std::size_t free_parts_total = 0;

int size_class(std::size_t bytes) {
    int k = 0;
    while ((kShareFrom << k) < bytes) ++k;
    return k;
}

// Takes `p` out of the free parts of class k if it is there.
bool take_free(int k, char* p) {
    auto& list = free_parts[k];
    const auto at = std::find(list.begin(), list.end(), p);
    if (at == list.end()) return false;
    *at = list.back();
    list.pop_back();
    free_parts_total -= kShareFrom << k;
    return true;
}

// (map_shared makes room first; when freeing, a list that cannot grow loses the part until exit
// rather than end the program from a destructor)
void give_free(int k, char* p) noexcept {
    try {
        free_parts[k].push_back(p);
        free_parts_total += kShareFrom << k;
    } catch (...) {
    }
}

void* map_locked(std::size_t bytes);
void unmap_locked(void* p, std::size_t bytes);

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
    std::unique_lock<std::mutex> guard(lock);
    await_ahead(guard);
    return map_locked(bytes);
}

void unmap(void* p, std::size_t bytes) {
    std::lock_guard<std::mutex> guard(lock);
    unmap_locked(p, bytes);
}

void* map_shared(std::size_t bytes) {
    std::unique_lock<std::mutex> guard(lock);
    const int want = size_class(bytes);
    try { // room for the halves split off below: one part of each size at most
        for (auto& list : free_parts)
            if (list.capacity() == list.size()) list.reserve(2 * list.size() + 8);
    } catch (...) {
        return nullptr;
    }
    // the smallest free part that is large enough, halved down to the size asked for; the upper
    // halves stay free
    int k = want;
    while (k < kClasses && free_parts[k].empty()) ++k;
    char* p = nullptr;
    if (k < kClasses) {
        p = free_parts[k].back();
        free_parts[k].pop_back();
        free_parts_total -= kShareFrom << k;
    } else {
        await_ahead(guard);
        p = static_cast<char*>(map_locked(kHuge)); // a kept page when there is one
        if (!p) return nullptr;
        give_free(kClasses - 1, p + kShareTo);
        k = kClasses - 1;
    }
    while (k > want) {
        --k;
        give_free(k, p + (kShareFrom << k));
    }
    return p;
}

void unmap_shared(void* p, std::size_t bytes) {
    std::lock_guard<std::mutex> guard(lock);
    int k = size_class(bytes);
    auto at = reinterpret_cast<std::uintptr_t>(p);
    // pages are 2 MiB aligned, so a part's buddy differs from it in the bit of its size
    while (k < kClasses) {
        const std::uintptr_t buddy = at ^ (kShareFrom << k);
        if (!take_free(k, reinterpret_cast<char*>(buddy))) break;
        at = std::min(at, buddy);
        ++k;
    }
    if (k == kClasses)
        unmap_locked(reinterpret_cast<void*>(at), kHuge); // the whole page is free again
    else
        give_free(k, reinterpret_cast<char*>(at));
}

std::size_t shared_free_bytes() {
    std::lock_guard<std::mutex> guard(lock);
    return free_parts_total;
}

namespace {

void* map_locked(std::size_t bytes) {
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

void unmap_locked(void* p, std::size_t bytes) {
    if (kept_total + bytes > kKeepAtMost) {
        ::munmap(p, bytes);
        return;
    }
    kept.push_back(Block{static_cast<char*>(p), bytes});
    kept_total += bytes;
}

} // namespace

void trim(std::size_t keep) {
    std::lock_guard<std::mutex> guard(lock);
    std::size_t keep_left = keep / kHuge * kHuge;
    std::vector<Block> still;
    if (keep_left > 0) {
        try {
            still.reserve(kept.size());
        } catch (...) {
            keep_left = 0; // (called from destructors: give everything back rather than throw)
        }
    }
    // the blocks freed last are kept first; a block is split at a 2 MiB boundary if need be
    for (auto b = kept.rbegin(); b != kept.rend(); ++b) {
        const std::size_t stay = std::min(keep_left, b->bytes);
        if (stay < b->bytes) ::munmap(b->at + stay, b->bytes - stay);
        if (stay > 0) still.push_back(Block{b->at, stay});
        keep_left -= stay;
    }
    kept = std::move(still);
    kept_total = 0;
    for (const Block& b : kept) kept_total += b.bytes;
}

std::size_t kept_bytes() {
    std::lock_guard<std::mutex> guard(lock);
    return kept_total;
}

namespace {

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23 // Linux 5.14
#endif

// clear_ahead's thread, joined when the process exits normally.
struct AheadThread {
    std::thread thread;
    ~AheadThread() {
        if (thread.joinable()) thread.join();
    }
};

} // namespace

void clear_ahead() {
    static AheadThread ahead;
    static std::once_flag once;
    std::call_once(once, [] {
        {
            std::lock_guard<std::mutex> guard(lock);
            if (kept_total > 0) return; // a kept page is waiting already
            ahead_state = Ahead::Starting;
        }
        auto done = [](void* p) {
            {
                std::lock_guard<std::mutex> guard(lock);
                if (p) unmap_locked(p, kHuge);
                ahead_state = Ahead::Idle;
            }
            ahead_cv.notify_all();
        };
        try {
            ahead.thread = std::thread([done] {
                void* p = nullptr;
                {
                    std::lock_guard<std::mutex> guard(lock);
                    if (ahead_state != Ahead::Starting) return; // a block was taken fresh meanwhile
                    ahead_state = Ahead::Clearing;
                    p = map_locked(kHuge);
                }
                // one call maps the page (a huge page when the kernel has one); where the kernel
                // is older than MADV_POPULATE_WRITE, a write to each 4 KiB page does it
                if (p && ::madvise(p, kHuge, MADV_POPULATE_WRITE) != 0)
                    for (std::size_t at = 0; at < kHuge; at += 4096) static_cast<volatile char*>(p)[at] = 0;
                done(p);
            });
        } catch (...) {
            done(nullptr); // no thread to be had: the page is cleared when first needed, as before
        }
    });
}

} // namespace plant::big_pages
