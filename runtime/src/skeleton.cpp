#include "plant/skeleton.hpp"

#include "plant/derive.hpp"

namespace plant {

void SkeletonBuilder::axis_begin(int axis, int parent, const TurtleState& t) {
    if (static_cast<std::size_t>(axis) >= skeleton_.axes.size())
        skeleton_.axes.resize(static_cast<std::size_t>(axis) + 1);
    SkeletonAxis& a = skeleton_.axes[static_cast<std::size_t>(axis)];
    a.parent = parent;
    a.points.reserve(2); // its first point and, nearly always, the end of a segment
    a.points.push_back(
        SkeletonPoint{t.position, t.heading, t.left, t.up, t.width / 2, t.color, 0, {}, t.texture});
}

void SkeletonBuilder::segment(const TurtleSegment& s) {
    const TurtleState& t = *s.state;
    SkeletonAxis& a = skeleton_.axes[static_cast<std::size_t>(t.axis)];
    a.points.push_back(SkeletonPoint{t.position, t.heading, t.left, t.up, t.width / 2, t.color, s.id,
                                     program_.symbols[string_.sym[s.module]].name, t.texture});
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
