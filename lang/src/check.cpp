// The whole-program checks, in one place: -D values that name no param, modules bound to
// something that cannot hold segments, rule groups that read new context both ways, productions
// shadowed by an earlier one or with a condition that is always false, and, after everything
// is compiled, letter runs read as separate letters that mean nothing, productions that can
// never apply and rule groups never selected.
#include "compiler_internal.hpp"
#include "habits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <set>
#include <string_view>

namespace plant {

// -D name=value must name a param of the grammar.
void Compiler::check_defines_used() {
    for (const auto& [name, d] : defines_) {
        if (!defines_used_.count(name)) {
            if (auto c = consts_.find(name); c != consts_.end()) {
                diags_->error(c->second.span,
                              fmt::format("-D {}: '{}' is a const, which -D cannot set; declare it as "
                                          "'param {} = ...;' to set it from the command line",
                                          name, name, name));
                continue;
            }
            // clang 14 cannot capture a structured binding, so the lambda gets a plain reference
            const std::string& wanted = name;
            const auto var = std::find_if(P_.globals.begin(), P_.globals.end(), [&](const Global& g) {
                return g.name == wanted && g.kind != GlobalKind::Param;
            });
            if (var != P_.globals.end()) {
                diags_->error(var->span, fmt::format("-D {}: '{}' is a var, which hooks change and -D cannot "
                                                     "set; declare it as 'param {} = ...;' to set its start "
                                                     "from the command line",
                                                     name, name, name));
                continue;
            }
            std::vector<std::string> params;
            for (const auto& g : P_.globals)
                if (g.kind == GlobalKind::Param) params.push_back(g.name);
            std::string near = nearest_name(name, params);
            diags_->error(
                Span{}, near.empty() ? fmt::format("-D {}: the grammar has no param '{}'", name, name)
                                     : fmt::format("-D {}: the grammar has no param '{}'; did you mean '{}'?",
                                                   name, name, near));
        }
    }
}

// `module Seg(len, r) bound ivy;` needs ivy to be of a kind that holds segments (a climber); the
// module keeps ivy's index, so that nothing looks it up by name while deriving
void Compiler::check_bound_modules() {
    for (std::size_t k = 0; k < P_.symbols.size(); ++k) {
        SymbolInfo& info = P_.symbols[static_cast<SymbolId>(k)];
        if (info.bound_to.empty()) continue;
        const EnvironmentDecl* decl = nullptr;
        for (std::size_t e = 0; e < P_.environments.size(); ++e)
            if (P_.environments[e].name == info.bound_to) {
                decl = &P_.environments[e];
                info.bound_env = static_cast<int>(e);
            }
        if (!decl)
            diags_->error(info.decl_span,
                          fmt::format("module '{}' is bound to '{}', which is not an environment; "
                                      "declare it first, as in env {} = climber(...);",
                                      info.name, info.bound_to, info.bound_to));
        else if (decl->kind && !decl->kind->holds_segments)
            diags_->error(info.decl_span,
                          fmt::format("module '{}' is bound to '{}', which is not a climber (it is "
                                      "'{}'); only a climber can hold segments",
                                      info.name, info.bound_to, decl->kind_name));
    }
}

// A named group runs together with the unnamed one: together they may read only one direction
// of new context.
void Compiler::check_group_directions() {
    for (const auto& g : P_.groups) {
        bool left = g.uses_left_new || P_.rules.uses_left_new,
             right = g.uses_right_new || P_.rules.uses_right_new;
        if (left && right)
            diags_->error(g.span,
                          fmt::format("rule group '{}' and the unnamed rules together read both the forward "
                                      "(<<) and the backward (>>) new context; use one direction",
                                      g.name));
    }
}

namespace {

// A predecessor's modules and their parameter counts, as a key.
std::string pattern_key(const Production& p) {
    std::string key;
    for (const auto& m : p.strict) {
        key.append(reinterpret_cast<const char*>(&m.sym), sizeof m.sym);
        key.append(reinterpret_cast<const char*>(&m.width), sizeof m.width);
    }
    return key;
}

// A production that applies to every module its predecessor names: no condition, weight,
// body, context or literal parameter.
bool always_applies(const Production& q) {
    for (const auto& m : q.strict)
        for (const auto& a : m.args)
            if (!a.bind) return false;
    return q.condition.empty() && q.weight.empty() && !q.body_form && !q.has_context() &&
           !q.has_new_context();
}

} // namespace

// A production about to join `set`: an earlier production that always applies to the same
// predecessor shadows it, and so does a condition that is always false. The set's productions
// that always apply are indexed by predecessor as they join (shadow_), so a rule set of n
// productions is checked in about n steps, not n * n.
void Compiler::check_shadowed(const ast::Production& p, const Production& cp, const RuleSet& set) {
    ShadowIndex& ix = shadow_;
    const bool same_set = ix.set == &set && ix.indexed <= set.productions.size() &&
                          (ix.indexed == 0 || (set.productions[0].span.file == ix.first.file &&
                                               set.productions[0].span.begin == ix.first.begin));
    if (!same_set) ix = ShadowIndex{&set, 0, set.productions.empty() ? Span{} : set.productions[0].span, {}};
    for (; ix.indexed < set.productions.size(); ++ix.indexed)
        if (always_applies(set.productions[ix.indexed]))
            ix.first_always.try_emplace(pattern_key(set.productions[ix.indexed]), ix.indexed);
    if (cp.weight.empty()) {
        if (auto it = ix.first_always.find(pattern_key(cp)); it != ix.first_always.end()) {
            const Production& q = set.productions[it->second];
            Diagnostic d{
                Severity::Warning,
                p.span,
                fmt::format("this production can never apply: the production at {} always applies first "
                            "to '{}'",
                            where(q.span), P_.symbols[cp.strict[0].sym].name),
                {}};
            diags_->add(std::move(d));
        }
    }
    if (p.condition) {
        if (auto v = fold_number(*p.condition); v && *v == 0)
            diags_->warning(p.condition->span,
                            "this production can never apply: its condition is always false");
    }
}

namespace {

// `F leaf F` with leaf undeclared reads l e a f, and the 'f' moves the turtle: a word that looks
// like a name and splits into letters of which some mean something and some nothing is named.
void warn_name_split(const Program& P_, Diagnostics* diags_, const RawRun& run,
                     const std::vector<bool>& has_rule, std::set<std::string>& words) {
    if (run.letters.size() != run.text.size() || !habits::looks_like_a_name(run.text)) return;
    std::vector<std::string> meaning, idle;
    for (const auto& l : run.letters) {
        auto id = P_.symbols.find(l);
        bool means = id && (has_rule[*id] || P_.symbols[*id].turtle || P_.symbols[*id].declared);
        (means ? meaning : idle).push_back(l);
    }
    if (idle.empty() || !words.insert(run.text).second) return;
    std::string list;
    for (const auto& l : meaning) list += (list.empty() ? "'" : ", '") + l + "'";
    diags_->warning(run.span,
                    fmt::format("'{}' is not a declared module and is read as {} separate letters, of "
                                "which {} {} a rule or a turtle meaning; declare it with 'module {};'",
                                run.text, run.letters.size(), list, meaning.size() == 1 ? "has" : "have",
                                run.text));
}

} // namespace

void Compiler::check_raw_runs() {
    std::vector<bool> has_rule(P_.symbols.size(), false);
    auto mark = [&](const RuleSet& rs) {
        for (const auto& p : rs.productions)
            for (const auto& m : p.strict) has_rule[m.sym] = true;
    };
    mark(P_.rules);
    for (const auto& g : P_.groups) mark(g);
    mark(P_.decompose);
    mark(P_.interpret);
    std::vector<std::string> declared;
    for (const auto& s : P_.symbols.all())
        if (s.declared && s.arity >= 0) declared.push_back(s.name);
    std::set<std::pair<std::uint32_t, std::uint32_t>> reported;
    std::set<std::string> words; // name-like words already warned about, once each
    for (const auto& run : raw_runs_) {
        bool meaningful = false;
        for (const auto& l : run.letters) {
            auto id = P_.symbols.find(l);
            if (id && (has_rule[*id] || P_.symbols[*id].turtle || P_.symbols[*id].declared))
                meaningful = true;
        }
        if (meaningful) {
            warn_name_split(P_, diags_, run, has_rule, words);
            continue;
        }
        if (!reported.insert({run.span.file, run.span.begin}).second) continue;
        std::string near = nearest_name(run.text, declared);
        diags_->warning(
            run.span,
            near.empty()
                ? fmt::format("'{}' is not a declared module and is read as {} separate letters, none of "
                              "which has a rule or a turtle meaning; declare it with 'module {}(...);'",
                              run.text, run.letters.size(), run.text)
                : fmt::format("'{}' is not a declared module and is read as {} separate letters, none of "
                              "which has a rule or a turtle meaning; did you mean '{}'?",
                              run.text, run.letters.size(), near));
    }
}

void Compiler::check_never_applying() {
    auto check = [&](const RuleSet& rs) {
        for (const auto& p : rs.productions) {
            // every module of the predecessor and of its context must be produced by something,
            // with as many numbers as its pattern takes (the first that is not is named)
            auto never = [&](const PatternModule& m, const char* role) {
                if (!produced_.count(m.sym)) {
                    diags_->warning(role[0] ? m.span : p.span,
                                    fmt::format("this production can never apply: neither the axiom nor any "
                                                "successor produces '{}'{}",
                                                P_.symbols[m.sym].name, role));
                    return true;
                }
                if (emitted_.count({m.sym, m.width})) return false;
                std::string widths;
                for (auto it = emitted_.lower_bound({m.sym, 0}); it != emitted_.end() && it->first == m.sym;
                     ++it)
                    widths += fmt::format("{}{}", widths.empty() ? "" : " or ", it->second);
                diags_->warning(
                    m.span, fmt::format("this production can never apply: the axiom and the successors "
                                        "write '{}' with {} number{}, and this pattern takes {}",
                                        P_.symbols[m.sym].name, widths, widths == "1" ? "" : "s", m.width));
                return true;
            };
            bool told = false;
            for (const auto& m : p.strict)
                if (!told) told = never(m, "");
            for (const auto* context : {&p.left, &p.right, &p.left_new, &p.right_new})
                for (const auto& m : *context)
                    if (!told) told = never(m, ", which its context needs");
        }
    };
    check(P_.rules);
    for (const auto& g : P_.groups) check(g);
    check(P_.decompose);
    check(P_.interpret);
    // rules with no `derive N;` derive 0 steps unless the command line says how many
    // (only for rules of the main file: the REPL's session imports the grammar and steps itself)
    if (P_.setting(ast::SettingKey::Derive).empty() && !opts_.steps_given && !P_.rules.productions.empty() &&
        P_.rules.productions[0].span.file == current_file_ && sm_.file(current_file_).name() != "<session>")
        // a note, not a warning: grammars meant for `-n` (and their tests) stay warning-free
        diags_->add({Severity::Note,
                     P_.rules.productions[0].span,
                     "the grammar has rules but no 'derive N;': it derives 0 steps unless given -n; "
                     "add a line such as 'derive 5;'",
                     {}});
    for (const auto& [name, span] : group_decls_) {
        if (!used_groups_.count(name))
            diags_->warning(
                span, fmt::format("rule group '{}' is never selected: no hook says 'use {};'", name, name));
    }
}

} // namespace plant
