// Environment objects (LANGUAGE.md section 8): runtime objects a grammar declares with
// `env name = kind(key: value, ...);` and queries from conditions and expressions with
// `name.method(args)`. The language knows only this interface; the runtime provides the kinds
// (runtime/include/plant/environments.hpp) and updates them from the turtle's skeleton between
// steps.
#pragma once

#include "plant/program.hpp"

#include <glm/glm.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace plant {

// One evaluated constructor argument: `key: value` (key empty when positional).
struct EnvArg {
    std::string key;
    ValueType type = ValueType::Number; // String for a quoted file name, in `text`
    double v[3] = {0, 0, 0};
    std::string text; // a string argument; a file path resolved against the grammar
    Span span;
};

struct EnvMethod {
    std::string name;
    std::vector<ValueType> args;
    ValueType result = ValueType::Number;
    const char* doc = "";
    // Answers ?E(env, slots...) modules: methods taking (p) or (p, id) fill the slots in order.
    bool communicates = true;
    // Changes the environment (pulling a branch, cutting one, switching wind): callable only from
    // hooks, which run on one thread between steps.
    bool hook_only = false;
};

class Environment {
  public:
    virtual ~Environment() = default;
    virtual const std::vector<EnvMethod>& methods() const = 0;
    // Back to the state it was declared with: a derivation starting again (the REPL's :set, a
    // second run of one compiled program) must not see the last one's plant.
    virtual void reset() {}
    // Whether its state depends on the steps it went through and not only on the string it was
    // last shown (the climber's particles). Going back to an earlier step (the REPL's :back) then
    // means deriving again up to that step, rather than only taking an earlier string.
    virtual bool evolves() const { return false; }
    // Triangles (world space, consecutive corners, wound outward) that show the environment in
    // meshes and previews: the wall a climber clings to, say. `lo` and `hi` bound the plant, for
    // giving an unbounded shape (a plane) a size.
    virtual void geometry(std::vector<glm::dvec3>& triangles, const glm::dvec3& lo,
                          const glm::dvec3& hi) const {
        (void)triangles, (void)lo, (void)hi;
    }
    // Answers a query. `args` holds the arguments' numbers (three for a vec3), `result` receives
    // up to three. Called from many threads at once while a step is rewritten: it must not
    // change the object.
    virtual void call(std::size_t method, const double* args, double* result) const = 0;

    // Fills the slots of a ?E module at `position` with the answers of the methods that take
    // the point (and, for a second number, the module's identity), in their order. `axis` is the
    // index of the axis the turtle was drawing at the module (-1 when none); environments that
    // know axes (proximity) use it to tell which stem is asking.
    virtual void communicate(const glm::dvec3& position, ModuleId id, int axis, double* slots,
                             std::size_t n) const {
        (void)axis;
        std::size_t slot = 0;
        const auto& ms = methods();
        for (std::size_t m = 0; m < ms.size() && slot < n; ++m) {
            const auto& a = ms[m].args;
            bool point = !a.empty() && a[0] == ValueType::Vec3;
            if (!ms[m].communicates || !point || a.size() > 2 || (a.size() == 2 && a[1] == ValueType::Vec3))
                continue;
            double args[4] = {position.x, position.y, position.z, static_cast<double>(id)};
            double result[3] = {0, 0, 0};
            call(m, args, result);
            slots[slot++] = result[0];
        }
    }
};

// Makes an environment of `kind`. Returns null and explains why in `error` when the kind is
// unknown or an argument is wrong.
using EnvironmentFactory = std::function<std::unique_ptr<Environment>(
    const std::string& kind, const std::vector<EnvArg>& args, std::string& error)>;

} // namespace plant
