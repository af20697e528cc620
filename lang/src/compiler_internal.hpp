// The compiler's private state, shared by its stages: compiler.cpp (the driver),
// compile_imports.cpp, compile_declarations.cpp, compile_shapes.cpp, compile_expr.cpp,
// compile_stmt.cpp, compile_rules.cpp and check.cpp.
#pragma once

#include "file_access.hpp"
#include "plant/ast.hpp"
#include "plant/compiler.hpp"
#include "plant/program.hpp"

#include <array>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

namespace plant {

struct BuiltinInfo;

enum class CtxKind { Global, Axiom, Production, Hook, Function };
enum class PatternRole { Strict, Left, LeftNew, Right, RightNew };

struct LocalVar {
    std::string name;
    ValueType type = ValueType::Number;
    std::uint16_t slot = 0;
    bool bound = false; // bound by a predecessor pattern: read-only
};

// Where code is being compiled to and which names are in scope.
struct Ctx {
    Code* code = nullptr;
    CtxKind kind = CtxKind::Global;
    std::vector<LocalVar> locals;
    std::uint16_t next_slot = 0;
    ValueType* fn_result = nullptr;
    bool fn_result_known = false;
    std::vector<std::size_t> void_returns; // Return instructions whose width is not known yet
    int depth = 0;                         // operand stack depth after the last instruction
    bool stack_error = false;
    int function = -1; // the function being compiled, if any
};

struct ConstVal {
    ValueType type = ValueType::Number;
    double v[3] = {0, 0, 0};
    Span span;
};

// A letter run split into several modules, remembered for the undeclared-run warning.
struct RawRun {
    std::string text;
    Span span;
    std::vector<std::string> letters;
};

struct LoadedFile {
    ast::File* file = nullptr;
    std::map<std::string, std::pair<const ast::Expr*, Span>> overrides; // from `import ... with { }`
};

inline bool numeric(ValueType t) {
    return t == ValueType::Number || t == ValueType::Bool;
}

std::size_t edit_distance(std::string_view a, std::string_view b);

class Compiler {
  public:
    Compiler(SourceManager& sm, const CompileOptions& opts, Diagnostics& diags)
        : sm_(sm), opts_(opts), diags_(&diags) {}
    std::unique_ptr<Program> compile(std::uint32_t main_file);

    // expressions (compile_expr.cpp), statements (compile_stmt.cpp), rules (compile_rules.cpp),
    // functions (compile_declarations.cpp)
    ValueType compile_expr(Ctx& c, const ast::Expr& e);
    ValueType compile_name(Ctx& c, const ast::Expr& e);
    ValueType compile_method(Ctx& c, const ast::Expr& e);
    ValueType compile_binary(Ctx& c, const ast::Expr& e);
    ValueType compile_call(Ctx& c, const ast::Expr& e);
    std::optional<ConstVal> eval_const(const ast::Expr& e, const char* what);
    std::optional<double> fold_number(const ast::Expr& e);
    void compile_block(Ctx& c, const std::vector<ast::Stmt>& body);
    void compile_stmt(Ctx& c, const ast::Stmt& s);
    void compile_assign(Ctx& c, const ast::Stmt& s);
    void compile_for(Ctx& c, const ast::Stmt& s);
    void compile_use(Ctx& c, const ast::Stmt& s);
    void compile_return(Ctx& c, const ast::Stmt& s);
    void compile_print(Ctx& c, const ast::Expr& e);
    void check_surface_named(const std::string& module, Span at);
    void check_size_argument(const SymbolInfo& info, const ast::ModuleRef& m);
    void compile_successor(Ctx& c, const ast::ModuleList& list);
    std::vector<PatternModule> compile_pattern(Ctx& c, const ast::ModuleList& list, PatternRole role);
    std::vector<std::pair<std::string, Span>> split_run(const ast::ModuleRef& m);
    SymbolId module_symbol(const std::string& name);
    void declare_function(const ast::FnDecl& fd);
    void ensure_function_compiled(std::uint32_t index);
    void infer_function_result(std::uint32_t index);
    ValueType compile_function_body(std::uint32_t index, Code& code, std::uint16_t& frame_size);
    ValueType param_type(const ast::ParamName& p);

    // One instance body as its own program (compile_instances.cpp): `parent` is the compiler of
    // the file or body that declares it, `index` its row in the instance table.
    std::unique_ptr<Program> compile_instance(const Compiler& parent, const ast::InstanceDecl& decl,
                                              int index);

  private:
    // the stages after declarations, shared by the main program and instance bodies
    void compile_stages();
    // the stages, in the order data flows
    void load(std::uint32_t file_id, std::map<std::string, std::pair<const ast::Expr*, Span>> overrides,
              std::vector<std::string>& stack);
    std::string resolve_import(const ast::Import& im, std::uint32_t from_file,
                               std::vector<std::string>& searched);
    // A file the grammar names (an import, load(...), a mesh): its identity when it may be read
    // (a missing file keeps `path`, for the reader to report); empty, with an input error
    // naming it as `written`, when it lies outside the allowed folders (file_access.hpp).
    std::string readable(const std::string& written, const std::string& path, Span span);
    void declare();
    void declare_modules(const ast::File& f);
    void declare_values(const LoadedFile& lf);
    void check_override_type(const ast::ValueDecl& v, const ast::Expr& value, const ConstVal& cv);
    void check_param_range(const ast::ValueDecl& v, const ast::Expr& value, const ConstVal& cv, Global& g);
    // instances and level of detail (compile_instances.cpp)
    void declare_instances(const ast::File& f);
    void declare_builtin_params();
    bool builtin_param(const std::string& name);
    void find_assigned_params();
    bool folded_param(const Global& g) const;
    void inherit(const Compiler& parent, const ast::InstanceDecl& decl);
    void compile_instances();
    void check_instance_graph();
    bool instance_arity_ok(const SymbolInfo& info, std::size_t nargs) const;
    void placement_param_used(const std::string& name, Span span);
    bool builtin_param_redeclared(const ast::ValueDecl& v);
    bool outer_name_hidden(Ctx& c, const std::string& name, Span span);
    bool outer_name_explained(const std::string& name, Span span);
    void compile_rules(const ast::File& f);
    void compile_production(const ast::Production& p, RuleSet& set);
    void compile_hooks(const ast::File& f);
    void compile_hook_bodies();
    void compile_settings(const ast::File& f);
    void finish();
    void finish_rule_set(RuleSet& set);
    void assign_kinds();
    void assign_kinds(SuccessorTemplate& t, std::map<std::vector<std::uint64_t>, KindId>& known);

    // whole-program checks (check.cpp)
    void check_defines_used();
    void check_bound_modules();
    void check_group_directions();
    void check_shadowed(const ast::Production& p, const Production& cp, const RuleSet& set);
    // check_shadowed's index of the rule set being compiled: the first production that always
    // applies, by predecessor; rebuilt when another set (or a set that moved) comes
    struct ShadowIndex {
        const RuleSet* set = nullptr;
        std::size_t indexed = 0; // productions looked at
        Span first;              // the first production's span, to know the set again
        std::unordered_map<std::string, std::size_t> first_always;
    };
    ShadowIndex shadow_;
    void check_never_applying();
    void check_raw_runs();
    void build_template(Production& p);
    void compile_surface(const ast::ShapeDecl& s);
    void declare_texture(const ast::ShapeDecl& s);
    std::shared_ptr<const std::string> texture_bytes(const ast::ShapeDecl& s, const std::string& id);
    void compile_curve(const ast::ShapeDecl& s);
    void compile_environment(const ast::ShapeDecl& s);
    ValueType compile_env_call(Ctx& c, const ast::Expr& e, std::size_t env);
    // decomposition graphs (compile_graph.cpp)
    void compile_graph();
    void compile_graph_block(const ast::GraphBlock& g);
    void compile_graph_param(const ast::GraphParam& p);
    ValueType compile_node_read(Ctx& c, const ast::Expr& e, const ast::Expr* object);
    ValueType compile_graph_call(Ctx& c, const ast::Expr& e, const BuiltinInfo& b, int width);
    bool compile_silhouette_method(Ctx& c, const ast::Expr& e, ValueType& result);
    ValueType compile_child_placed(Ctx& c, const ast::Expr& e);
    std::string silhouette_method_list() const;
    std::optional<CurveDef> make_curve(const std::string& name, const std::string& kind, Span kind_span,
                                       const std::vector<ast::ExprPtr>& args, Span span);

    // helpers (compile_expr.cpp; where and duplicate in compiler.cpp)
    void emit(Ctx& c, Op op, std::int32_t a, int n, Span span, std::uint16_t b = 0);
    void emit_const(Ctx& c, double v, Span span);
    std::size_t here(Ctx& c) const;
    void patch(Ctx& c, std::size_t at);
    const LocalVar* find_local(Ctx& c, const std::string& name) const;
    std::uint16_t add_local(Ctx& c, const std::string& name, ValueType t);
    std::vector<std::string> visible_names(Ctx& c) const;
    // What an unknown name was used as: it words the message and picks the suggestions.
    enum class Unknown : std::uint8_t { Name, Function, Variable };
    void unknown_name(Ctx& c, const std::string& name, Span span, Unknown kind);
    void type_error(Span span, const std::string& op, ValueType a, ValueType b);
    void duplicate(const std::string& what, const std::string& name, Span here, Span first);
    std::string where(Span s) const;

    SourceManager& sm_;
    const CompileOptions& opts_;
    Diagnostics* diags_; // swapped for a scratch list while a function's result type is inferred
    bool inferring_ = false;
    std::unique_ptr<Program> program_ = std::make_unique<Program>();
    Program& P_ = *program_;
    std::uint32_t current_file_ = 0;

    std::vector<std::unique_ptr<ast::File>> files_; // the syntax trees, in the order they were read
    std::vector<LoadedFile> order_;                 // files after the files they import
    std::vector<const ast::ShapeDecl*> curve_decls_, surface_decls_, env_decls_; // in load order
    std::set<std::string> loaded_paths_; // by identity: each file is imported once
    std::unique_ptr<FileAccess> access_; // made on first use, from the main file's folder
    std::uint32_t main_file_ = 0;
    std::map<std::string, std::string> shown_; // a loaded file's identity -> its name as shown
    std::unordered_map<std::string, ConstVal> consts_;
    std::unordered_map<std::string, Span> value_spans_;
    std::unordered_map<std::string, std::uint32_t> fn_index_;
    std::vector<const ast::FnDecl*> fn_decls_;
    std::vector<int> fn_state_; // 0 pending, 1 compiling, 2 done
    std::vector<bool> fn_result_known_;
    std::vector<bool> fn_random_;                  // the function (or one it calls) draws random numbers
    std::map<std::string, std::string> env_names_; // env name -> kind
    std::set<std::string> curve_names_;
    std::set<std::string> used_groups_;
    std::set<SymbolId> produced_;
    // (symbol, count of numbers) of every Emit compiled: each gets a plain kind (assign_kinds)
    std::set<std::pair<SymbolId, std::uint32_t>> emitted_;
    bool bare_width_told_ = false; // the warning for a bare '!' was given
    std::vector<RawRun> raw_runs_;
    std::size_t max_declared_len_ = 1;
    std::map<std::string, std::pair<ast::ExprPtr, std::uint32_t>> defines_; // -D name -> expr, source
    std::set<std::string> defines_used_;
    std::unordered_map<std::string, Span> shape_spans_;
    std::set<SymbolId> ignore_syms_, consider_syms_;
    bool has_ignore_ = false, has_consider_ = false, has_axiom_ = false;
    std::vector<std::pair<std::string, Span>> group_decls_;
    std::array<std::vector<const ast::Hook*>, ast::kHooks.size()> hook_bodies_;

    // instances (compile_instances.cpp). The table and the placement graph are shared by the
    // main program's compiler and every body's.
    struct InstanceGraph {
        std::vector<std::vector<std::pair<int, Span>>> places; // per instance: what it places, where
        std::vector<int> declared_in;                          // the enclosing instance (-1: top level)
    };
    std::shared_ptr<std::vector<InstanceDef>> table_ = std::make_shared<std::vector<InstanceDef>>();
    std::shared_ptr<InstanceGraph> graph_ = std::make_shared<InstanceGraph>();
    int self_index_ = -1; // the instance this compiler compiles (-1: the main program)
    std::vector<std::pair<const ast::InstanceDecl*, int>> own_instances_; // declared here, by index
    std::set<std::string> placement_params_;    // values known only per derivation (instance params)
    std::set<std::string> own_instance_params_; // this body's params: not visible in nested bodies
    // names a body does not see, for messages and for the outer functions it compiles: the params
    // of the enclosing instances (-> the instance's name) and the outer programs' vars
    std::map<std::string, std::string> enclosing_params_;
    std::set<std::string> outer_vars_;
    const char* compile_time_ = nullptr; // while eval_const runs: what it evaluates
    // Params that no hook assigns keep the value they were compiled with for the whole run, so
    // the code compiled in compile_stages reads them as constants (folded_param): the names some
    // hook of this program assigns, and whether the stages have begun.
    std::set<std::string> assigned_params_;
    bool fold_params_ = false;
    std::size_t inherited_surfaces_ = 0; // surfaces of the outer program, which a body may replace
    std::set<std::string> body_surfaces_;
    std::size_t inherited_functions_ = 0; // the outer program's, compiled only when called

    // textures (compile_shapes.cpp): each name's index in P_.textures, those inherited from the
    // outer program (a body may replace each once), and the image files read so far by identity,
    // shared by every compiler of one grammar so that a file is read once and all of them
    // together stay within kMaxTextureBytes
    std::unordered_map<std::string, std::size_t> texture_index_;
    std::size_t inherited_textures_ = 0;
    std::set<std::string> body_textures_;
    bool too_many_textures_ = false;
    struct TextureFiles {
        std::map<std::string, std::shared_ptr<const std::string>> by_identity;
        std::size_t bytes = 0;
    };
    std::shared_ptr<TextureFiles> texture_files_ = std::make_shared<TextureFiles>();
    bool too_many_instances_ = false;
};

} // namespace plant
