// What the turtle drew, as data: axes (polylines with frames, radii, colors and the identity of
// the module that drew each point), organs (placed shapes) and query results. Built by a
// recording sink; the mesher and the skeleton exporter read it.
#pragma once

#include "plant/turtle.hpp"

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace plant {

struct SkeletonPoint {
    glm::dvec3 position, heading, left, up;
    double radius = 0.5;
    glm::vec3 color{0.45f, 0.32f, 0.2f};
    ModuleId id = 0;    // module that drew the segment ending here (0 for an axis start)
    std::string module; // its name
    int texture = -1;   // an index in Program::textures, -1 for none
};

// One generalized cylinder: consecutive F's of one branch level, lateral branches between them
// do not interrupt it. points[0] is where the turtle stood when the axis began.
struct SkeletonAxis {
    int parent = -1; // the axis this one branches from
    std::vector<SkeletonPoint> points;
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
};

class SkeletonBuilder : public TurtleSink {
  public:
    SkeletonBuilder(const Program& program, const ModuleString& string)
        : program_(program), string_(string) {}
    void axis_begin(int axis, int parent, const TurtleState& t) override;
    void segment(const TurtleSegment& s) override;
    void organ(const TurtleOrgan& o) override;
    Skeleton take() { return std::move(skeleton_); }

  private:
    const Program& program_;
    const ModuleString& string_;
    Skeleton skeleton_;
};

// Interpretation rules, then the turtle, then the skeleton.
Skeleton build_skeleton(const Program& program, const ModuleString& interpreted,
                        const TurtleOptions& options);

} // namespace plant
