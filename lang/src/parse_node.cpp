// The parse tree's nodes from a free list (parse_node.hpp says why).
#include "parse_node.hpp"

#include <cstddef>
#include <memory>
#include <new>
#include <vector>

#if defined(__SANITIZE_ADDRESS__)
#define PLANT_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PLANT_ASAN 1
#endif
#endif
#ifdef PLANT_ASAN
#include <sanitizer/asan_interface.h>
#endif

namespace plant {

namespace {

// Freed nodes' memory, handed out again, each free slot holding the next one's address; the
// blocks are kept until the thread ends. Under AddressSanitizer a free slot is poisoned, so that
// a use after free is still reported.
struct NodePool {
    struct alignas(Node) Slot {
        std::byte bytes[sizeof(Node)];
    };
    static constexpr std::size_t kBlock = 1024;
    void* head = nullptr;
    std::vector<std::unique_ptr<Slot[]>> blocks;

    void* take() {
        if (!head) {
            blocks.push_back(std::make_unique<Slot[]>(kBlock));
            for (std::size_t k = kBlock; k-- > 0;) give(&blocks.back()[k]);
        }
        void* p = head;
#ifdef PLANT_ASAN
        ASAN_UNPOISON_MEMORY_REGION(p, sizeof(Slot));
#endif
        head = *static_cast<void**>(p);
        return p;
    }
    void give(void* p) noexcept {
        *static_cast<void**>(p) = head;
        head = p;
#ifdef PLANT_ASAN
        ASAN_POISON_MEMORY_REGION(p, sizeof(Slot));
#endif
    }
    NodePool() = default;
    NodePool(const NodePool&) = delete;
    NodePool& operator=(const NodePool&) = delete;
    ~NodePool() {
#ifdef PLANT_ASAN
        for (auto& b : blocks) ASAN_UNPOISON_MEMORY_REGION(b.get(), sizeof(Slot) * kBlock);
#endif
    }
};

thread_local NodePool node_pool;

} // namespace

void* Node::operator new(std::size_t size) {
    return size == sizeof(Node) ? node_pool.take() : ::operator new(size);
}

void Node::operator delete(void* p, std::size_t size) noexcept {
    if (!p) return;
    if (size != sizeof(Node)) return ::operator delete(p);
    node_pool.give(p);
}

} // namespace plant
