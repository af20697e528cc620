// The 3D turtle (docs/language.md, the turtle; its symbols are plant/turtle_symbols.hpp): state as plain
// data, one operation per module, output to a sink. y is up; the turtle starts at the origin with heading H =
// +Y, left L = -X and up U = H x L = +Z, so a 2D grammar draws in the XY plane and '+' turns toward L.
#pragma once

#include "plant/diagnostics.hpp"
#include "plant/environment.hpp" // BoundPoses
#include "plant/module_string.hpp"
#include "plant/program.hpp"

#include <glm/glm.hpp>

#include <compare>
#include <cstdint>
#include <string>
#include <vector>

namespace plant {

struct TurtleState {
    glm::dvec3 position{0.0};
    glm::dvec3 heading{0.0, 1.0, 0.0}; // H
    glm::dvec3 left{-1.0, 0.0, 0.0};   // L
    glm::dvec3 up{0.0, 0.0, 1.0};      // U = H x L
    double width = 1.0;                // diameter, set by !(w)
    double step = 1.0;                 // default F length
    double angle = 90.0;               // default turn in degrees
    int color_index = 0;               // ;(c)
    glm::vec3 color{0.45f, 0.32f, 0.2f};
    int texture = -1;                   // SetTexture: an index in Program::textures, -1 for none
    glm::dvec3 tropism{0.0, -1.0, 0.0}; // @Tp
    double elasticity = 0.0;            // @Ts; 0: no tropism
    int axis = -1;                      // axis being drawn, -1 when the next F starts a new one
    ModuleId bound_parent = 0;          // the last module bound to a climber on this path (0: none)
};

// A drawn segment: from the state before an F to the state after it.
struct TurtleSegment {
    glm::dvec3 from, to;
    const TurtleState* state; // after the move
    std::size_t module;       // index in the interpreted string
    ModuleId id;
};

// What an organ is. Instance: an instanced sub-L-system (plant/program.hpp InstanceDef), meshed
// as a prototype that is a whole scene (scene.hpp).
enum class OrganKind : std::uint8_t { Sphere, Surface, Instance };

struct OrganShape {
    OrganKind kind = OrganKind::Sphere;
    std::string name;         // Surface: the surface's name; Instance: the instance's; Sphere: empty
    int instance = -1;        // Instance: its index in *Program::instances
    std::vector<double> args; // Instance: the argument tuple (the placement scale not included)
    auto operator<=>(const OrganShape&) const = default;
};

// The name outputs show for a shape (skeleton files, mesh and node names): "@O", the symbol that
// places a sphere, or the surface's or prototype's name.
std::string organ_label(const OrganShape& shape);

// A surface, sphere or other organ placed in the turtle's frame.
struct TurtleOrgan {
    OrganShape shape;
    glm::dmat4 transform;
    glm::vec3 color;
    std::size_t module;
    ModuleId id;
    int texture = -1; // the turtle's texture (an index in Program::textures), -1 for none
};

// Receives what the turtle does. Every method has a no-op default (PlantGL's split of turtle,
// state and sink).
class TurtleSink {
  public:
    virtual ~TurtleSink() = default;
    // A new axis starts at `from` (a lateral branch starts inside its parent).
    virtual void axis_begin(int /*axis*/, int /*parent*/, const TurtleState&) {}
    virtual void segment(const TurtleSegment&) {}
    virtual void organ(const TurtleOrgan&) {}
    // The turtle reached a query module (?P ?H ?U ?L).
    virtual void query(std::size_t /*module*/, const TurtleState&) {}
};

struct TurtleOptions {
    double angle = 90.0;                  // the grammar's `angle`
    double step = 1.0;                    // the grammar's `step`
    double width = 0.1;                   // the grammar's `width`
    std::vector<const BoundPoses*> poses; // the program's climbers: poses of bound modules
};
class Derivation;
// The grammar's own `angle`, `step` and `width`, as the derivation read them, and its climbers.
TurtleOptions turtle_options(const Derivation& d);

// Interprets `s` (already passed through the interpretation rules). Throws RuntimeError for a
// ']' without '[' (naming its place in the string) and for non-finite results.
void interpret(const Program& program, const ModuleString& s, const TurtleOptions& options, TurtleSink& sink);

// Named colors for ;(c): index c in a small palette of plant colors.
glm::vec3 palette_color(int index);

} // namespace plant
