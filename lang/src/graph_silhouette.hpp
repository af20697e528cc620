// A silhouette value, silhouette(axis: polyline(...) | bezier(...), top: ..., bottom: ..., px: ...,
// pz: ..., nx: ..., nz: ..., top_shape: ..., bottom_shape: ..., tip: ...), built from its keyed
// arguments (docs/language.md, decomposition graphs: silhouettes). The graph block (compiler) and
// edits files evaluate the arguments each their own way, so they pass their evaluators in.
#pragma once

#include "plant/ast.hpp"
#include "plant/silhouette.hpp"

#include <functional>
#include <memory>
#include <optional>
#include <string>

namespace plant {

struct SilhouetteEval {
    // Each returns nullopt after reporting its own error (or throws, as the edits reader does).
    std::function<std::optional<glm::dvec3>(const ast::Expr&)> vec;
    std::function<std::optional<double>(const ast::Expr&)> number;
    std::function<void(Span, std::string)> error;
};

// Null after reporting an error through `ev.error`.
std::shared_ptr<const Silhouette> build_silhouette(const ast::Expr& e, const SilhouetteEval& ev);

} // namespace plant
