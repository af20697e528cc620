#include "plant/skeleton.hpp"

#include "plant/derive.hpp"
#include "plant/memory_budget.hpp"

#include <algorithm>
#include <new>

namespace plant {

PointArena::~PointArena() {
    for (const Block& b : blocks_) {
        big_pages::unmap(b.at, b.bytes);
        memory::release(b.bytes);
    }
}

void* PointArena::allocate(std::size_t bytes) {
    bytes = (bytes + 15) / 16 * 16;
    if (static_cast<std::size_t>(end_ - next_) < bytes) {
        // the first block as expected; later ones (more points than segments allow, or an axis
        // that kept growing) at least as large as all before
        std::size_t size = blocks_.empty() ? first_ : 0;
        for (const Block& b : blocks_) size += b.bytes;
        size = big_pages::rounded(std::max({size, bytes, big_pages::kHuge}));
        memory::charge(size); // the skeleton's points, against --max-memory
        void* p = big_pages::map(size);
        if (!p) {
            memory::release(size);
            throw std::bad_alloc();
        }
        blocks_.push_back(Block{static_cast<char*>(p), size});
        next_ = static_cast<char*>(p);
        end_ = next_ + size;
    }
    void* p = next_;
    next_ += bytes;
    return p;
}

namespace {

// The segments `s` draws (each F and each module bound to a climber): an axis has at least one,
// and at most one point more than it has segments.
std::size_t segments_in(const Program& program, const ModuleString& s) {
    std::vector<char> draws(program.symbols.size(), 0);
    for (std::size_t k = 0; k < draws.size(); ++k) {
        const SymbolInfo& info = program.symbols.all()[k];
        draws[k] = info.turtle_op == TurtleOp::Forward || !info.bound_to.empty();
    }
    std::size_t n = 0;
    for (std::size_t i = 0; i < s.size(); ++i) n += s.symbol(i) < draws.size() && draws[s.symbol(i)];
    return n;
}

} // namespace

SkeletonBuilder::SkeletonBuilder(const Program& program, const ModuleString& string) : string_(string) {
    skeleton_.symbol_names.reserve(program.symbols.size());
    for (const SymbolInfo& info : program.symbols.all()) skeleton_.symbol_names.push_back(info.name);
    const std::size_t segments = segments_in(program, string);
    if (segments == 0) return;
    // as many axes as segments at most, each with a point more than its segments; the arena's
    // pages are touched only as far as points are made (256 MB is only the first block's size)
    skeleton_.axes.reserve(segments);
    const std::size_t expected =
        std::min<std::size_t>(2 * segments * sizeof(SkeletonPoint), std::size_t{256} << 20);
    // a small skeleton stays on the heap: a fresh 2 MiB page for a few points costs more to
    // clear than the allocations it saves
    if (expected < (std::size_t{1} << 20)) return;
    points_ = PointAllocator<SkeletonPoint>(std::make_shared<PointArena>(expected));
}

void SkeletonBuilder::axis_begin(int axis, int parent, const TurtleState& t) {
    if (static_cast<std::size_t>(axis) >= skeleton_.axes.size())
        skeleton_.axes.resize(static_cast<std::size_t>(axis) + 1);
    SkeletonAxis& a = skeleton_.axes[static_cast<std::size_t>(axis)];
    a.parent = parent;
    if (a.points.empty()) a.points = decltype(a.points)(points_);
    a.points.reserve(2); // its first point and, nearly always, the end of a segment
    a.points.push_back(
        SkeletonPoint{t.position, t.heading, t.left, t.up, t.width / 2, 0, t.color, t.texture, kNoSymbol});
}

void SkeletonBuilder::segment(const TurtleSegment& s) {
    const TurtleState& t = *s.state;
    SkeletonAxis& a = skeleton_.axes[static_cast<std::size_t>(t.axis)];
    a.points.push_back(SkeletonPoint{t.position, t.heading, t.left, t.up, t.width / 2, s.id, t.color,
                                     t.texture, string_.symbol(s.module)});
}

void SkeletonBuilder::organ(const TurtleOrgan& o) {
    skeleton_.organs.push_back(SkeletonOrgan{o.shape, o.transform, o.color, o.id, o.texture});
}

Skeleton build_skeleton(const Program& program, const ModuleString& interpreted,
                        const TurtleOptions& options) {
    SkeletonBuilder b(program, interpreted);
    interpret(program, interpreted, options, b);
    return b.take();
}

} // namespace plant
