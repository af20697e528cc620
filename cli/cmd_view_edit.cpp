// plant view's edits (docs/view.md, editing climbers): the page asks for one call of an
// environment's edit method on the step it shows; the model checks it against the grammar and
// keeps it as a line of an `on before_step` hook compiled after the grammar, as the REPL keeps
// its edits (docs/physics.md, editing from the REPL). The page never sends source text: the
// statement is written here from the environment's name, the method's name and numbers.
#include "cmd_view.hpp"
#include "cmd_view_built.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace plant::cli {

// At most this many edits in a session: each is a line of the hook, run on every rebuild.
constexpr std::size_t kMaxViewEdits = 1000;

// The hook that runs the edits, empty without any.
std::string view_edit_hook(const std::vector<std::pair<int, std::string>>& edits) {
    if (edits.empty()) return {};
    std::string s = "on before_step {\n";
    for (const auto& [step, statement] : edits)
        s += fmt::format("if step() == {} {{ {} }}\n", step, statement);
    return s + "}\n";
}

// The edit methods of the program's environments whose arguments the page can give (numbers
// and vec3s), as JSON rows {"env", "method", "args": ["number" | "vec3"...], "doc"}.
nlohmann::json view_edit_methods(const Program& program) {
    nlohmann::json out = nlohmann::json::array();
    for (const EnvironmentDecl& e : program.environments) {
        if (!e.kind) continue;
        for (const EnvMethod& m : e.kind->methods) {
            if (m.access != EnvAccess::Edit) continue;
            nlohmann::json args = nlohmann::json::array();
            bool simple = true;
            for (std::size_t k = 0; k < m.args.size(); ++k) {
                simple = simple && (m.args[k] == ValueType::Number || m.args[k] == ValueType::Vec3);
                args.push_back(m.args[k] == ValueType::Vec3 ? "vec3" : "number");
            }
            if (simple) out.push_back({{"env", e.name}, {"method", m.name}, {"args", args}, {"doc", m.doc}});
        }
    }
    return out;
}

namespace {

// The statement for `edit` in `out`; an error message when the edit is not one, empty otherwise.
std::string statement(const Program& program, const ViewEdit& edit, std::string& out) {
    const EnvironmentDecl* env = nullptr;
    for (const EnvironmentDecl& e : program.environments)
        if (e.name == edit.env && e.kind) env = &e;
    if (!env) return fmt::format("the grammar has no environment '{}'", edit.env);
    const EnvMethod* m = env->kind->method(edit.method);
    if (!m || m->access != EnvAccess::Edit)
        return fmt::format("'{}' is not an edit method of {} ({})", edit.method, edit.env, env->kind->name);
    if (edit.args.size() != m->args.size())
        return fmt::format("{}.{} takes {} argument{}", edit.env, edit.method, m->args.size(),
                           m->args.size() == 1 ? "" : "s");
    std::string call = edit.env + "." + edit.method + "(";
    for (std::size_t k = 0; k < edit.args.size(); ++k) {
        const bool vec = m->args[k] == ValueType::Vec3;
        if (!vec && m->args[k] != ValueType::Number) return "the page cannot give this method's arguments";
        const auto& a = edit.args[k];
        if (a.size() != (vec ? 3u : 1u))
            return fmt::format("argument {} is {}", k + 1, vec ? "a vec3" : "a number");
        for (double x : a)
            if (!std::isfinite(x) || std::abs(x) > 1e15)
                return fmt::format("argument {}: a finite number", k + 1);
        // shortest round-trip text; a negative number in parentheses reads the same in any place
        auto num = [](double x) { return x < 0 ? fmt::format("({})", x) : fmt::format("{}", x); };
        call += (k ? ", " : "") +
                (vec ? fmt::format("vec3({}, {}, {})", num(a[0]), num(a[1]), num(a[2])) : num(a[0]));
    }
    out = call + ");";
    return {};
}

} // namespace

std::string ViewModel::add_edit(const ViewEdit& edit) {
    {
        std::lock_guard lock(mutex_);
        if (!good_) return "there is no plant to edit (the grammar has an error)";
        if (edits_.size() >= kMaxViewEdits) return fmt::format("at most {} edits", kMaxViewEdits);
        const int last = static_cast<int>(good_->steps.size()) - 1;
        if (edit.step < 0 || edit.step > last) return fmt::format("step: 0 to {}", last);
        std::string s;
        if (std::string why = statement(*good_->program, edit, s); !why.empty()) return why;
        edits_.emplace_back(edit.step, std::move(s));
    }
    rebuild();
    return {};
}

bool ViewModel::undo_edit() {
    {
        std::lock_guard lock(mutex_);
        if (edits_.empty()) return false;
        edits_.pop_back();
    }
    rebuild();
    return true;
}

} // namespace plant::cli
