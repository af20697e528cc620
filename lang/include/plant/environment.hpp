// Environment objects (docs/language.md, environments): runtime objects a grammar declares with
// `env name = kind(key: value, ...);` and calls from conditions, expressions and hooks with
// `name.method(args)`. The language knows only this interface and each kind's method table; the
// runtime provides the kinds (runtime/include/plant/environments.hpp).
//
// Definitions are data, run state is the derivation's: the compiled Program keeps each
// declaration (EnvironmentDecl in program.hpp) with the object as declared, which never changes;
// every derivation works on its own clones (RunState, run_state.hpp), so copying a derivation
// copies its environments.
#pragma once

#include "plant/program.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace plant {

struct Skeleton; // the plant as the runtime's turtle drew it (runtime/include/plant/skeleton.hpp)

// ---- method tables ---------------------------------------------------------------------------

// What calling a method does to its environment.
enum class EnvAccess : std::uint8_t {
    Pure, // reads it only: const, called from many threads at once while a step is rewritten
    Edit, // changes it (pulls a branch, switches the wind): hooks only, one thread, between steps
};

// A method's argument types, at most three.
struct EnvParams {
    std::array<ValueType, 3> types{};
    std::uint8_t count = 0;
    constexpr EnvParams() = default;
    constexpr EnvParams(std::initializer_list<ValueType> list) {
        for (ValueType t : list) types[count++] = t;
    }
    constexpr std::size_t size() const { return count; }
    constexpr bool empty() const { return count == 0; }
    constexpr ValueType operator[](std::size_t i) const { return types[i]; }
};

// One row of a kind's method table. Each kind numbers its methods with an enum of its own and
// lists one row per method in that order (checked by method_table below); the row says all the
// compiler, the VM, ?E modules and `plant help env KIND` need to know about the method.
struct EnvMethod {
    std::uint8_t index = 0; // the kind's enum value
    const char* name = "";
    EnvParams args;
    ValueType result = ValueType::Number;
    EnvAccess access = EnvAccess::Pure;
    // Answers ?E(env, slots...) modules: methods taking (p) or (p, id) fill the slots in order.
    bool communicates = true;
    const char* doc = ""; // one line
};

template <class Method>
constexpr EnvMethod env_method(Method m, const char* name, EnvParams args, ValueType result, EnvAccess access,
                               bool communicates, const char* doc) {
    return EnvMethod{static_cast<std::uint8_t>(m), name, args, result, access, communicates, doc};
}

// Whether `rows` has one row per value of the kind's method enum, from 0 to `last`, in order.
template <class Method, std::size_t N> constexpr bool method_table(const EnvMethod (&rows)[N], Method last) {
    if (N != static_cast<std::size_t>(last) + 1) return false;
    for (std::size_t i = 0; i < N; ++i)
        if (rows[i].index != i) return false;
    return true;
}

// An environment kind as the compiler and the documentation see it: static data, one per kind,
// read without making an environment.
struct EnvironmentKind {
    const char* name = "";
    const char* doc = ""; // one line
    std::span<const EnvMethod> methods;
    // Modules can be bound to it (`module Seg(len, r) bound ivy;`): it is shown their segments
    // in every step's environment phase and places them (BoundPoses).
    bool holds_segments = false;

    const EnvMethod* method(std::string_view name) const {
        for (const EnvMethod& m : methods)
            if (name == m.name) return &m;
        return nullptr;
    }
};

// ---- bound modules ---------------------------------------------------------------------------

// Where an environment holds the segments of modules bound to it (`module Seg(len, r) bound
// ivy;`): the turtle draws such a module's segment from where it stands to the particle's
// position and takes the particle's frame. A module without a particle yet is drawn like F(len).
class BoundPoses {
  public:
    virtual ~BoundPoses() = default;
    // The particle of module `id`: its position and its frame (+y heading, -x left, +z up).
    virtual bool pose(ModuleId id, glm::dvec3& position, glm::dmat3& frame) const = 0;
    // Whether module `id`'s particle is the first of a part that hangs from nothing (broken off
    // or cut, falling): the turtle draws its segment from its own start, not from where it stands.
    virtual bool starts_loose(ModuleId /*id*/) const { return false; }
};

// A segment the turtle drew for a module bound to an environment, shown to it in the
// environment phase of a step.
struct BoundSegment {
    ModuleId id = 0;
    ModuleId parent = 0; // the module bound to it before this one on the path (0: none)
    glm::dvec3 from{0.0}, to{0.0};
    glm::dmat3 frame{1.0}; // columns: -left, heading, up
    double radius = 0, length = 0;
};

// ---- the interface ---------------------------------------------------------------------------

class Environment : public BoundPoses {
  public:
    ~Environment() override = default;
    virtual const EnvironmentKind& kind() const = 0;
    // A copy with the same state: a copied derivation goes on from here on its own.
    virtual std::unique_ptr<Environment> clone() const = 0;

    // Answers a Pure method (an index into kind().methods). `args` holds the arguments'
    // numbers (three for a vec3), `result` receives up to three. Called from many threads at
    // once while a step is rewritten: it must not change the object.
    virtual void query(std::size_t method, const double* args, double* result) const = 0;
    // Runs an Edit method: only from hooks, on one thread, between steps.
    virtual void edit(std::size_t /*method*/, const double* /*args*/) {}

    // Fills the slots of a ?E module at `position` with the answers of the methods that take
    // the point (and, for a second number, the module's identity), in their order. `axis` is the
    // index of the axis the turtle was drawing at the module (-1 when none); environments that
    // know axes (proximity) use it to tell which stem is asking.
    virtual void communicate(const glm::dvec3& position, ModuleId id, int /*axis*/, double* slots,
                             std::size_t n) const {
        std::size_t slot = 0;
        for (const EnvMethod& m : kind().methods) {
            if (slot >= n) break;
            const auto& a = m.args;
            bool point = !a.empty() && a[0] == ValueType::Vec3;
            if (!m.communicates || m.access != EnvAccess::Pure || !point || a.size() > 2 ||
                (a.size() == 2 && a[1] == ValueType::Vec3))
                continue;
            double args[4] = {position.x, position.y, position.z, static_cast<double>(id)};
            double result[3] = {0, 0, 0};
            query(m.index, args, result);
            slots[slot++] = result[0];
        }
    }

    // Triangles (world space, consecutive corners, wound outward) that show the environment in
    // meshes and previews: the wall a climber clings to, say. `lo` and `hi` bound the plant, for
    // giving an unbounded shape (a plane) a size.
    virtual void geometry(std::vector<glm::dvec3>& /*triangles*/, const glm::dvec3& /*lo*/,
                          const glm::dvec3& /*hi*/) const {}

    // ---- the environment phase of a step (EnvironmentPhase in derive.hpp), in this order ----
    // 1. A kind that holds segments is shown, between begin_segments() and advance(), the
    //    segments the turtle drew for the modules bound to it, in string order. advance() then
    //    updates it (a climber runs its physics) and adds to `left` the modules that leave the
    //    string (broken off, cut).
    virtual void begin_segments() {}
    virtual void segment(const BoundSegment&) {}
    virtual void advance(std::set<ModuleId>& /*left*/) {}
    // 2. Every environment sees the plant as the turtle draws it now.
    virtual void see(const Skeleton&) {}
    // Whether see() looks at the skeleton: when no environment of a run does, the phase does not
    // build one (a climber, which holds its own segments, does not; building the skeleton of Fig.
    // 14 right's 25,000 segments and their leaves every step was about a tenth of its run).
    virtual bool sees_plant() const { return true; }
    // Bound modules' poses, for every turtle pass (kinds that hold segments).
    bool pose(ModuleId, glm::dvec3&, glm::dmat3&) const override { return false; }
};

// Makes an environment of `kind` as declared. Returns null and explains why in `error` when the
// kind is unknown or an argument is wrong.
using EnvironmentFactory = std::function<std::unique_ptr<Environment>(
    const std::string& kind, const std::vector<EnvArg>& args, std::string& error)>;

} // namespace plant
