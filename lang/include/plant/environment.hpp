// Environment objects (LANGUAGE.md section 8): runtime objects a grammar declares with
// `env name = kind(key: value, ...);` and queries from conditions and expressions with
// `name.method(args)`. The language knows only this interface; the runtime provides the kinds
// (runtime/include/plant/environments.hpp) and updates them from the turtle's skeleton between
// steps.
#pragma once

#include "plant/program.hpp"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace plant {

// One evaluated constructor argument: `key: value` (key empty when positional).
struct EnvArg {
    std::string key;
    ValueType type = ValueType::Number;
    double v[3] = {0, 0, 0};
    Span span;
};

struct EnvMethod {
    std::string name;
    std::vector<ValueType> args;
    ValueType result = ValueType::Number;
    const char* doc = "";
};

class Environment {
public:
    virtual ~Environment() = default;
    virtual const std::vector<EnvMethod>& methods() const = 0;
    // Answers a query. `args` holds the arguments' numbers (three for a vec3), `result` receives
    // up to three. Called from many threads at once while a step is rewritten: it must not
    // change the object.
    virtual void call(std::size_t method, const double* args, double* result) const = 0;
};

// Makes an environment of `kind`. Returns null and explains why in `error` when the kind is
// unknown or an argument is wrong.
using EnvironmentFactory = std::function<std::unique_ptr<Environment>(const std::string& kind,
                                                                      const std::vector<EnvArg>& args,
                                                                      std::string& error)>;

} // namespace plant
