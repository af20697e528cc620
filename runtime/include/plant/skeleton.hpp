// What the turtle drew, as data: axes (polylines with frames, radii, colors and the identity of
// the module that drew each point), organs (placed shapes) and query results. Built by a
// recording sink; the mesher and the skeleton exporter read it.
#pragma once

#include "plant/turtle.hpp"

#include <glm/glm.hpp>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace plant {

// 136 bytes: a tree of 16,000 segments has about twice as many points, so the module's name is
// kept as its symbol (Skeleton::module_name), not as a string in every point.
struct SkeletonPoint {
    glm::dvec3 position, heading, left, up;
    double radius = 0.5;
    ModuleId id = 0; // module that drew the segment ending here (0 for an axis start)
    glm::vec3 color{0.45f, 0.32f, 0.2f};
    int texture = -1;            // an index in Program::textures, -1 for none
    SymbolId symbol = kNoSymbol; // the symbol of module `id` (kNoSymbol for an axis start)
};

// Where a skeleton's points live: one block (or a few) of whole 2 MiB pages (big_pages, so pages a
// finished derivation gave back are used again, not cleared anew), handed out front to back. A
// tree has as many axes as segments, each of two points: one allocation per axis from the heap
// cost more than building the points. Nothing is given back before the arena goes.
class PointArena {
  public:
    explicit PointArena(std::size_t expected_bytes) : first_(expected_bytes) {}
    ~PointArena();
    PointArena(const PointArena&) = delete;
    PointArena& operator=(const PointArena&) = delete;
    void* allocate(std::size_t bytes);

  private:
    struct Block {
        char* at;
        std::size_t bytes;
    };
    std::vector<Block> blocks_;
    char *next_ = nullptr, *end_ = nullptr;
    std::size_t first_;
};

// Allocates from a PointArena shared by the vectors that use it (the last one lets it go), or
// from the heap when it has none. A copy of a vector goes to the heap.
template <typename T> struct PointAllocator {
    using value_type = T;
    using propagate_on_container_move_assignment = std::true_type;
    using propagate_on_container_swap = std::true_type;
    std::shared_ptr<PointArena> arena;

    PointAllocator() noexcept = default;
    explicit PointAllocator(std::shared_ptr<PointArena> a) noexcept : arena(std::move(a)) {}
    template <typename U> PointAllocator(const PointAllocator<U>& o) noexcept : arena(o.arena) {}
    PointAllocator select_on_container_copy_construction() const { return {}; }

    T* allocate(std::size_t n) {
        if (!arena) return std::allocator<T>().allocate(n);
        return static_cast<T*>(arena->allocate(n * sizeof(T)));
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (!arena) std::allocator<T>().deallocate(p, n);
    }
    template <typename U> bool operator==(const PointAllocator<U>& o) const noexcept {
        return arena == o.arena;
    }
};

// One generalized cylinder: consecutive F's of one branch level, lateral branches between them
// do not interrupt it. points[0] is where the turtle stood when the axis began.
struct SkeletonAxis {
    int parent = -1; // the axis this one branches from
    std::vector<SkeletonPoint, PointAllocator<SkeletonPoint>> points;
};

struct SkeletonOrgan {
    OrganShape shape;
    glm::dmat4 transform;
    glm::vec3 color;
    ModuleId id = 0;
    int texture = -1; // an index in Program::textures, -1 for none
};

struct Skeleton {
    std::vector<SkeletonAxis> axes;
    std::vector<SkeletonOrgan> organs;
    // The names of the program's symbols, by SymbolId, so that a skeleton names its modules
    // without the program that drew it.
    std::vector<std::string> symbol_names;

    // The name of the module that drew the segment ending at `p` (empty for an axis start).
    std::string_view module_name(const SkeletonPoint& p) const {
        return p.symbol < symbol_names.size() ? std::string_view(symbol_names[p.symbol]) : std::string_view();
    }
};

class SkeletonBuilder : public TurtleSink {
  public:
    SkeletonBuilder(const Program& program, const ModuleString& string);
    void axis_begin(int axis, int parent, const TurtleState& t) override;
    void segment(const TurtleSegment& s) override;
    void organ(const TurtleOrgan& o) override;
    Skeleton take() { return std::move(skeleton_); }

  private:
    const ModuleString& string_;
    Skeleton skeleton_;
    PointAllocator<SkeletonPoint> points_; // from an arena sized for the string's segments
};

// Interpretation rules, then the turtle, then the skeleton.
Skeleton build_skeleton(const Program& program, const ModuleString& interpreted,
                        const TurtleOptions& options);

} // namespace plant
