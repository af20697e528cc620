// Instances (docs/language.md, instances): `instance Name(params) { items }` declares the module
// Name and compiles its body as a program of its own, which sees the outer program's params,
// consts, functions, curves, surfaces, modules and instances. The instance table and the graph of
// which instance places which are shared by every compiler of one grammar; the graph is checked
// for cycles and depth once everything is compiled. Also the built-in params of level of detail.
#include "compiler_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>

namespace plant {

namespace {

constexpr int kMaxInstanceDepth = 8; // instances placed inside instances, the outermost counted
// Each body's program holds its own copy of the declared modules, params, consts and functions it
// sees: the product is bounded (a body's program is made in time and memory proportional to what
// it sees).
constexpr std::size_t kMaxInstances = 256;
// instances times the names each sees (modules, params, consts, functions)
constexpr std::size_t kMaxInheritedSymbols = 1'000'000;

struct BuiltinParam {
    const char* name;
    double value;
};
// Level of detail (Yan & Chiba, section 3.3): the view depth and its maximum.
constexpr BuiltinParam kBuiltinParams[] = {{"view_depth", 0.0}, {"max_view_depth", 20.0}};

std::string chain_text(const std::vector<InstanceDef>& table, const std::vector<int>& chain) {
    std::string out;
    for (int k : chain) out += (out.empty() ? "" : " -> ") + table[static_cast<std::size_t>(k)].name;
    return out;
}

} // namespace

void Compiler::declare_instances(const ast::File& f) {
    for (const auto& inst : f.instances) {
        SymbolId id = P_.symbols.intern(inst.name);
        SymbolInfo& info = P_.symbols[id];
        if (info.turtle || info.query) {
            diags_->error(inst.span, fmt::format("'{}' is a built-in turtle or query module and cannot name "
                                                 "an instance",
                                                 inst.name));
            continue;
        }
        if (info.arity >= 0) {
            duplicate(info.instance >= 0 ? "instance" : "module", inst.name, inst.span, info.decl_span);
            continue;
        }
        // names are unique in the whole grammar, so a prototype's name says which body it is
        const auto same = std::find_if(table_->begin(), table_->end(),
                                       [&](const InstanceDef& d) { return d.name == inst.name; });
        if (same != table_->end()) {
            duplicate("instance", inst.name, inst.span, same->span);
            continue;
        }
        if (table_->size() >= kMaxInstances) {
            if (too_many_instances_) continue; // said once
            too_many_instances_ = true;
            diags_->error(inst.span, fmt::format("a grammar may declare at most {} instances: this is one "
                                                 "more; give one instance a parameter instead of declaring "
                                                 "variants",
                                                 kMaxInstances));
            continue;
        }
        InstanceDef def;
        def.name = inst.name;
        def.span = inst.span;
        for (const auto& p : inst.params) {
            def.param_types.push_back(param_type(p));
            def.param_names.push_back(p.name);
        }
        const int index = static_cast<int>(table_->size());
        info.declared = true;
        info.arity = static_cast<int>(inst.params.size());
        info.param_types = def.param_types;
        info.param_names = def.param_names;
        info.decl_span = inst.span;
        info.instance = index;
        max_declared_len_ = std::max(max_declared_len_, inst.name.size());
        table_->push_back(std::move(def));
        graph_->places.emplace_back();
        graph_->declared_in.push_back(self_index_);
        own_instances_.emplace_back(&inst, index);
    }
}

// view_depth and max_view_depth: made when the grammar has instances or -D sets them, and on
// first use otherwise (builtin_param), so that grammars without them keep their globals.
void Compiler::declare_builtin_params() {
    for (const BuiltinParam& b : kBuiltinParams)
        if (!table_->empty() || defines_.count(b.name)) builtin_param(b.name);
}

bool Compiler::builtin_param(const std::string& name) {
    const BuiltinParam* b = nullptr;
    for (const BuiltinParam& p : kBuiltinParams)
        if (name == p.name) b = &p;
    if (!b || P_.global_index.count(name) || consts_.count(name) || value_spans_.count(name)) return false;
    double value = b->value;
    if (auto it = defines_.find(name); it != defines_.end()) {
        defines_used_.insert(name);
        if (auto cv = eval_const(*it->second.first, "the initial value")) {
            if (cv->type == ValueType::Vec3)
                diags_->error(it->second.first->span, fmt::format("-D {}: needs a number", name));
            else
                value = cv->v[0];
        }
    }
    Global g;
    g.name = name;
    g.kind = GlobalKind::Param;
    g.slot = static_cast<std::uint32_t>(P_.global_values.size());
    P_.global_values.push_back(value);
    P_.global_index[name] = static_cast<std::uint32_t>(P_.globals.size());
    P_.globals.push_back(std::move(g));
    return true;
}

// A param read as a constant in the code compile_stages compiles: one no hook of this program
// assigns (find_assigned_params), whose value is neither set per placement (an instance's own
// params) nor read by the runtime from outside the code (view_depth, max_view_depth). Its value
// cannot change during a derivation, so folding it changes no result; it lets the rewriting
// engine treat `l * r1` or `&(a1)` as it treats `l * 0.9` or `&(5)` (docs/design.md).
bool Compiler::folded_param(const Global& g) const {
    if (!fold_params_ || compile_time_ || g.kind != GlobalKind::Param) return false;
    if (placement_params_.count(g.name) || assigned_params_.count(g.name)) return false;
    for (const BuiltinParam& b : kBuiltinParams)
        if (g.name == b.name) return false;
    return true;
}

// An instance's module takes its params, or its params and one more number: the placement scale.
bool Compiler::instance_arity_ok(const SymbolInfo& info, std::size_t nargs) const {
    return info.instance >= 0 && static_cast<int>(nargs) == info.arity + 1;
}

void Compiler::placement_param_used(const std::string& name, Span span) {
    const std::string self = (*table_)[static_cast<std::size_t>(self_index_)].name;
    diags_->error(span, name == "view_depth"
                            ? fmt::format("'view_depth' is set for each derivation of instance '{}', so it "
                                          "is not known in {}: use it in rules or settings instead",
                                          self, compile_time_)
                            : fmt::format("'{}' is a parameter of instance '{}', known only where it is "
                                          "placed, so it cannot be used in {}: use it in rules or "
                                          "settings instead",
                                          name, self, compile_time_));
}

// view_depth and max_view_depth are params of the whole grammar (docs/language.md, level of
// detail): a body cannot declare them (each of its derivations gets view_depth from where it is
// placed, and max_view_depth from the top level), nor can a var or const take their names.
bool Compiler::builtin_param_redeclared(const ast::ValueDecl& v) {
    const bool builtin = std::any_of(std::begin(kBuiltinParams), std::end(kBuiltinParams),
                                     [&](const BuiltinParam& b) { return v.name == b.name; });
    if (!builtin || (v.kind == ast::DeclKind::Param && self_index_ < 0)) return false;
    const char* kind = v.kind == ast::DeclKind::Const ? "const"
                       : v.kind == ast::DeclKind::Var ? "var"
                                                      : "param";
    if (self_index_ >= 0)
        diags_->error(
            v.name_span,
            fmt::format("'{}' is a built-in param of the whole grammar, so instance '{}' cannot declare "
                        "it: {}; declare 'param {} = ...;' at the top level or set it with -D",
                        v.name, (*table_)[static_cast<std::size_t>(self_index_)].name,
                        v.name == std::string("view_depth")
                            ? "each derivation of an instance gets it from where it is placed"
                            : "every instance takes it from the top level",
                        v.name));
    else
        diags_->error(v.name_span,
                      fmt::format("'{}' is a built-in param and cannot be a {}: write 'param {} = "
                                  "...;' (lod() and the instances read it)",
                                  v.name, kind, v.name));
    return true;
}

// Inside an outer function that a body compiles when it calls it: a name the function's own scope
// does not have (a param of the body or of an enclosing instance) is an error naming the body,
// never the body's value of the same name.
bool Compiler::outer_name_hidden(Ctx& c, const std::string& name, Span span) {
    if (c.kind != CtxKind::Function || c.function < 0 ||
        static_cast<std::size_t>(c.function) >= inherited_functions_)
        return false;
    const auto outer = enclosing_params_.find(name);
    if (outer == enclosing_params_.end() && !own_instance_params_.count(name)) return false;
    const std::string self = (*table_)[static_cast<std::size_t>(self_index_)].name;
    const std::string& fn = P_.functions[static_cast<std::size_t>(c.function)].name;
    diags_->error(
        span, outer != enclosing_params_.end()
                  ? fmt::format("function '{}' reads '{}', a parameter of instance '{}', which instance "
                                "'{}' (calling it) does not see: give '{}' a parameter for it and pass "
                                "the value",
                                fn, name, outer->second, self, fn)
                  : fmt::format("function '{}' is declared outside instance '{}' (calling it) and cannot "
                                "read its parameter '{}': give '{}' a parameter for it and pass the value",
                                fn, self, name, fn));
    return true;
}

// An unknown name that the program around a body has: says why the body does not see it.
bool Compiler::outer_name_explained(const std::string& name, Span span) {
    if (self_index_ < 0) return false;
    const std::string self = (*table_)[static_cast<std::size_t>(self_index_)].name;
    if (auto it = enclosing_params_.find(name); it != enclosing_params_.end()) {
        diags_->error(span,
                      fmt::format("'{}' is a parameter of the enclosing instance '{}', which instance '{}' "
                                  "does not see: pass it to '{}' as an argument",
                                  name, it->second, self, self));
        return true;
    }
    if (outer_vars_.count(name)) {
        diags_->error(span,
                      fmt::format("'{}' is a var of the program around instance '{}', which the instance "
                                  "does not see (a var changes as the outer plant grows): pass its value "
                                  "to '{}' as an argument",
                                  name, self, self));
        return true;
    }
    return false;
}

// What a body sees of the program around it (docs/language.md, instances: visibility).
void Compiler::inherit(const Compiler& parent, const ast::InstanceDecl& decl) {
    table_ = parent.table_;
    graph_ = parent.graph_;
    main_file_ = parent.main_file_;
    current_file_ = decl.body->source;
    for (const SymbolInfo& s : parent.P_.symbols.all()) {
        if (s.turtle || s.query || (!s.declared && s.instance < 0)) continue;
        SymbolInfo& info = P_.symbols[P_.symbols.intern(s.name)];
        info = s;
        info.bound_to.clear(); // environments stay outside: a bound module is an ordinary one here
        info.bound_env = -1;
    }
    max_declared_len_ = parent.max_declared_len_;
    enclosing_params_ = parent.enclosing_params_;
    outer_vars_ = parent.outer_vars_;
    if (parent.self_index_ >= 0)
        for (const auto& name : parent.own_instance_params_)
            enclosing_params_[name] = (*table_)[static_cast<std::size_t>(parent.self_index_)].name;
    for (const Global& g : parent.P_.globals) {
        if (g.kind != GlobalKind::Param) outer_vars_.insert(g.name);
        if (g.kind != GlobalKind::Param || parent.own_instance_params_.count(g.name)) continue;
        Global copy = g;
        copy.slot = static_cast<std::uint32_t>(P_.global_values.size());
        for (int k = 0; k < value_width(g.type); ++k)
            P_.global_values.push_back(parent.P_.global_values[g.slot + k]);
        P_.global_index[g.name] = static_cast<std::uint32_t>(P_.globals.size());
        P_.globals.push_back(std::move(copy));
    }
    consts_ = parent.consts_;
    value_spans_ = parent.value_spans_;
    for (const auto& name : parent.own_instance_params_) value_spans_.erase(name);
    for (const ast::FnDecl* fd : parent.fn_decls_) declare_function(*fd);
    inherited_functions_ = P_.functions.size();
    P_.curves = parent.P_.curves;
    curve_names_ = parent.curve_names_;
    P_.surfaces = parent.P_.surfaces;
    inherited_surfaces_ = P_.surfaces.size();
    P_.textures = parent.P_.textures; // their names came with the consts
    texture_index_ = parent.texture_index_;
    inherited_textures_ = P_.textures.size();
    texture_files_ = parent.texture_files_;
    placement_params_.insert("view_depth");
    // the instance's own params: globals whose values each derivation sets
    InstanceDef& def = (*table_)[static_cast<std::size_t>(self_index_)];
    def.param_slots.clear();
    for (std::size_t i = 0; i < decl.params.size(); ++i) {
        const ast::ParamName& p = decl.params[i];
        if (auto it = value_spans_.find(p.name); it != value_spans_.end()) {
            duplicate("param", p.name, p.span, it->second);
            continue;
        }
        value_spans_[p.name] = p.span;
        Global g;
        g.name = p.name;
        g.kind = GlobalKind::Param;
        g.type = def.param_types[i];
        g.slot = static_cast<std::uint32_t>(P_.global_values.size());
        g.span = p.span;
        def.param_slots.push_back(g.slot);
        P_.global_values.insert(P_.global_values.end(), static_cast<std::size_t>(value_width(g.type)), 0.0);
        P_.global_index[g.name] = static_cast<std::uint32_t>(P_.globals.size());
        P_.globals.push_back(std::move(g));
        placement_params_.insert(p.name);
        own_instance_params_.insert(p.name);
    }
}

std::unique_ptr<Program> Compiler::compile_instance(const Compiler& parent, const ast::InstanceDecl& decl,
                                                    int index) {
    self_index_ = index;
    inherit(parent, decl);
    const ast::File& body = *decl.body;
    for (const auto& im : body.imports)
        diags_->error(im.span, fmt::format("instance '{}' cannot import: write 'import {};' at the top of "
                                           "the file, and what it declares is visible inside the instance",
                                           decl.name, im.is_path ? "\"" + im.target + "\"" : im.target));
    order_.push_back({decl.body.get(), {}});
    declare();
    for (const ast::ShapeDecl* e : env_decls_)
        diags_->error(e->span, fmt::format("instance '{}' cannot declare an environment: an instance is "
                                           "derived apart from the plant, so declare 'env {} = ...;' at the "
                                           "top level and use it in the outer rules",
                                           decl.name, e->name));
    env_decls_.clear();
    compile_stages();
    if (!has_axiom_)
        diags_->error(decl.span, fmt::format("instance '{}' has no axiom: add a line such as 'axiom: F;' to "
                                             "its body",
                                             decl.name));
    if (diags_->has_errors()) return nullptr;
    P_.instances = table_.get();
    return std::move(program_);
}

void Compiler::compile_instances() {
    if (own_instances_.empty()) return;
    std::size_t declared = 0;
    for (const SymbolInfo& s : P_.symbols.all()) declared += s.declared && !s.turtle && !s.query ? 1 : 0;
    const std::size_t values = P_.globals.size() + consts_.size() + fn_decls_.size();
    if ((declared + values) * table_->size() > kMaxInheritedSymbols) {
        diags_->error(own_instances_.front().first->span,
                      fmt::format("{} instances each see the {} modules and {} params, consts and functions "
                                  "declared around them, more than plant compiles ({} in all): declare fewer "
                                  "of them or fewer instances (an instance parameter can stand for variants)",
                                  table_->size(), declared, values, kMaxInheritedSymbols));
        return;
    }
    for (const auto& [decl, index] : own_instances_) {
        // bodies declared inside bodies: as deep as instances may be placed
        std::vector<int> chain{index};
        for (int k = graph_->declared_in[static_cast<std::size_t>(index)]; k >= 0;
             k = graph_->declared_in[static_cast<std::size_t>(k)])
            chain.insert(chain.begin(), k);
        if (static_cast<int>(chain.size()) > kMaxInstanceDepth) {
            diags_->error(decl->span, fmt::format("instances declared more than {} deep ({}): declare "
                                                  "this one further out",
                                                  kMaxInstanceDepth, chain_text(*table_, chain)));
            continue;
        }
        Compiler child(sm_, opts_, *diags_);
        std::unique_ptr<Program> body = child.compile_instance(*this, *decl, index);
        if (body) (*table_)[static_cast<std::size_t>(index)].program = std::move(body);
    }
}

// No instance places itself, directly or through others, and none is nested deeper than
// kMaxInstanceDepth; each instance's depth is filled in.
void Compiler::check_instance_graph() {
    const std::vector<InstanceDef>& table = *table_;
    const std::size_t n = table.size();
    enum : std::uint8_t { Unseen, Open, Done };
    std::vector<std::uint8_t> state(n, Unseen);
    std::vector<int> depth(n, 1), deepest(n, -1);
    std::vector<int> chain;
    bool stop = false;
    std::function<void(int)> visit = [&](int k) {
        const auto K = static_cast<std::size_t>(k);
        state[K] = Open;
        chain.push_back(k);
        for (const auto& [j, span] : graph_->places[K]) {
            if (stop) break;
            const auto J = static_cast<std::size_t>(j);
            if (state[J] == Open) {
                std::vector<int> cycle(std::find(chain.begin(), chain.end(), j), chain.end());
                cycle.push_back(j);
                diags_->error(span, fmt::format("instance cycle: {}: an instance cannot place itself, "
                                                "directly or through others; to repeat a shape, place "
                                                "it several times from the outer rules or give the "
                                                "repeated part its own instance",
                                                chain_text(table, cycle)));
                stop = true;
                break;
            }
            if (state[J] == Unseen) {
                if (static_cast<int>(chain.size()) >= kMaxInstanceDepth) { // j would be one too deep
                    std::vector<int> path = chain;
                    path.push_back(j);
                    diags_->error(span, fmt::format("instances nested more than {} deep: {}",
                                                    kMaxInstanceDepth, chain_text(table, path)));
                    stop = true;
                    break;
                }
                visit(j);
                if (stop) break;
            }
            if (depth[J] + 1 > depth[K]) {
                depth[K] = depth[J] + 1;
                deepest[K] = j;
            }
            if (depth[K] + static_cast<int>(chain.size()) - 1 > kMaxInstanceDepth) {
                std::vector<int> path = chain;
                for (int d = j; d >= 0; d = deepest[static_cast<std::size_t>(d)]) path.push_back(d);
                diags_->error(span, fmt::format("instances nested more than {} deep: {}", kMaxInstanceDepth,
                                                chain_text(table, path)));
                stop = true;
                break;
            }
        }
        chain.pop_back();
        state[K] = Done;
    };
    for (std::size_t k = 0; k < n && !stop; ++k)
        if (state[k] == Unseen) visit(static_cast<int>(k));
    for (std::size_t k = 0; k < n; ++k) (*table_)[k].depth = depth[k];
}

} // namespace plant
