// Shapes and environments: `curve` and `surface` declarations evaluated at compile time, `env`
// declarations made by the runtime's factory, and the method calls that query them.
#include "compiler_internal.hpp"

#include <fmt/format.h>

#include <unistd.h>

#include <filesystem>

namespace plant {

namespace fs = std::filesystem;

namespace {

// Textures (docs/language.md, textures): how many a program may declare, and how many bytes of
// image files a grammar may read for them in all.
constexpr std::size_t kMaxTextures = 1024;
constexpr std::size_t kMaxTextureBytes = kMaxSourceBytes;

// The image's MIME type from its first bytes (the PNG signature, JPEG's start-of-image marker),
// or empty when it is neither.
std::string image_mime_type(const std::string& bytes) {
    static constexpr unsigned char png[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    static constexpr unsigned char jpeg[] = {0xff, 0xd8, 0xff};
    auto starts = [&](const unsigned char* magic, std::size_t n) {
        return bytes.size() >= n && std::equal(magic, magic + n, bytes.begin(), [](unsigned char m, char c) {
                   return m == static_cast<unsigned char>(c);
               });
    };
    if (starts(png, sizeof png)) return "image/png";
    if (starts(jpeg, sizeof jpeg)) return "image/jpeg";
    return {};
}

} // namespace

void Compiler::compile_curve(const ast::ShapeDecl& s) {
    for (const auto& other : P_.curves) {
        if (other.name == s.name) {
            duplicate("curve", s.name, s.span, other.span);
            return;
        }
    }
    if (auto def = make_curve(s.name, s.kind, s.kind_span, s.args, s.span))
        P_.curves.push_back(std::move(*def));
}

// A curve from its kind and control values (a `curve` declaration, a graph parameter).
std::optional<CurveDef> Compiler::make_curve(const std::string& name, const std::string& kind, Span kind_span,
                                             const std::vector<ast::ExprPtr>& args, Span span) {
    CurveDef def;
    def.name = name;
    def.span = span;
    if (kind != "linear" && kind != "bezier") {
        diags_->error(kind_span,
                      fmt::format("unknown curve kind '{}': expected linear(...) or bezier(...)", kind));
        return std::nullopt;
    }
    def.bezier = kind == "bezier";
    bool points = false;
    for (std::size_t i = 0; i < args.size(); ++i) {
        auto v = eval_const(*args[i], "a curve's control value");
        if (!v) return std::nullopt;
        bool vec = v->type == ValueType::Vec3;
        if (i == 0) points = vec;
        if (vec != points) {
            diags_->error(args[i]->span, "a curve's control values are all numbers or all vec3 points");
            return std::nullopt;
        }
        def.xs.push_back(vec ? v->v[0] : 0.0);
        def.ys.push_back(vec ? v->v[1] : v->v[0]);
    }
    if (def.ys.size() < 2) {
        diags_->error(span, fmt::format("curve '{}' needs at least two control values", name));
        return std::nullopt;
    }
    if (!points)
        for (std::size_t i = 0; i < def.xs.size(); ++i) def.xs[i] = double(i) / double(def.xs.size() - 1);
    for (std::size_t i = 1; i < def.xs.size(); ++i) {
        if (def.xs[i] < def.xs[i - 1]) {
            diags_->error(args[i]->span, "the x of a curve's points must not decrease (x is t, from 0 to 1)");
            return std::nullopt;
        }
    }
    return def;
}

void Compiler::compile_surface(const ast::ShapeDecl& s) {
    SurfaceDef def;
    def.name = s.name;
    def.span = s.span;
    // a surface in an importing file replaces the library's (libraries are compiled first), so a
    // user swaps a default leaf for load("my_leaf.obj"); twice in one file is an error
    std::size_t replace = P_.surfaces.size();
    for (std::size_t i = 0; i < P_.surfaces.size(); ++i) {
        if (P_.surfaces[i].name != s.name) continue;
        // an instance body's surface replaces the outer program's (inherited_surfaces_) once
        const bool inherited = i < inherited_surfaces_ && !body_surfaces_.count(s.name);
        if (P_.surfaces[i].span.file == s.span.file && !inherited) {
            duplicate("surface", s.name, s.span, P_.surfaces[i].span);
            return;
        }
        replace = i;
    }
    if (s.kind == "polygon") {
        def.kind = SurfaceKind::Polygon;
        for (const auto& a : s.args) {
            auto v = eval_const(*a, "a polygon corner");
            if (!v) return;
            if (v->type != ValueType::Vec3) {
                diags_->error(a->span, "a polygon corner must be a vec3, as in vec3(0, 1, 0)");
                return;
            }
            def.points.push_back({v->v[0], v->v[1], v->v[2]});
        }
        if (def.points.size() < 3) {
            diags_->error(s.span, fmt::format("polygon '{}' needs at least 3 corners, found {}", s.name,
                                              def.points.size()));
            return;
        }
    } else if (s.kind == "load") {
        def.kind = SurfaceKind::Load;
        if (s.args.size() != 1 || s.args[0]->kind != ast::ExprKind::String) {
            diags_->error(s.span, "load(...) takes one quoted file name, as in load(\"leaf.obj\")");
            return;
        }
        fs::path p(s.args[0]->text);
        if (p.is_relative()) p = fs::path(sm_.file(s.span.file).name()).parent_path() / p;
        def.path = p.lexically_normal().string();
        const std::string id = readable(s.args[0]->text, def.path, s.args[0]->span);
        if (id.empty()) return;
        // a missing or unreadable file is an input error now, for check as for run (exit 66);
        // with reads confined (the plant command, the Python module) the compiler is the one
        // place that vets the files a grammar reads, so it looks here; a program embedding the
        // compiler without confinement finds out when the scene is built
        std::error_code ec;
        const auto status = fs::status(id, ec);
        const char* why = !opts_.confine_reads              ? nullptr
                          : !fs::exists(status)             ? "no such file"
                          : !fs::is_regular_file(status)    ? "not a regular file"
                          : ::access(id.c_str(), R_OK) != 0 ? "permission denied"
                                                            : nullptr;
        if (why) {
            diags_->input_error(s.args[0]->span,
                                fmt::format("cannot read surface file '{}': {}", s.args[0]->text, why));
            return;
        }
    } else {
        diags_->error(
            s.kind_span,
            fmt::format("unknown surface kind '{}': expected polygon(...) or load(\"file\")", s.kind));
        return;
    }
    if (replace < inherited_surfaces_) body_surfaces_.insert(s.name);
    if (replace < P_.surfaces.size())
        P_.surfaces[replace] = std::move(def);
    else
        P_.surfaces.push_back(std::move(def));
}

// `texture name = image("file");`: the name becomes a const holding the texture's index, declared
// even when the image cannot be used (so that uses of the name are not reported as unknown too).
// A texture in an importing file or an instance body replaces the one of the same name it sees,
// keeping its index; twice in one file is an error, as for surfaces.
void Compiler::declare_texture(const ast::ShapeDecl& s) {
    std::size_t index = P_.textures.size();
    if (auto it = texture_index_.find(s.name); it != texture_index_.end()) {
        const TextureDef& first = P_.textures[it->second];
        const bool inherited = it->second < inherited_textures_ && !body_textures_.count(s.name);
        if (first.span.file == s.span.file && !inherited) {
            duplicate("texture", s.name, s.span, first.span);
            return;
        }
        index = it->second;
    } else if (auto v = value_spans_.find(s.name); v != value_spans_.end()) {
        duplicate("texture", s.name, s.span, v->second);
        return;
    } else if (P_.textures.size() >= kMaxTextures) {
        if (!too_many_textures_) // said once
            diags_->error(s.span, fmt::format("a program may declare at most {} textures: this is one more",
                                              kMaxTextures));
        too_many_textures_ = true;
        return;
    }
    TextureDef def;
    def.name = s.name;
    def.span = s.span;
    if (s.kind != "image") {
        diags_->error(s.kind_span,
                      fmt::format("unknown texture kind '{}': expected image(\"file.png\")", s.kind));
    } else if (s.args.size() != 1 || s.args[0]->kind != ast::ExprKind::String) {
        diags_->error(s.span, "image(...) takes one quoted file name, as in image(\"bark.png\")");
    } else {
        fs::path p(s.args[0]->text);
        if (p.is_relative()) p = fs::path(sm_.file(s.span.file).name()).parent_path() / p;
        def.path = p.lexically_normal().string();
        if (std::string id = readable(s.args[0]->text, def.path, s.args[0]->span); !id.empty())
            def.bytes = texture_bytes(s, id);
        if (def.bytes) {
            def.mime_type = image_mime_type(*def.bytes);
            if (def.mime_type.empty())
                diags_->error(s.args[0]->span,
                              fmt::format("'{}' is not a PNG or JPEG image (its first bytes are neither "
                                          "signature): a texture must be a .png or .jpg file",
                                          s.args[0]->text));
        }
    }
    ConstVal value;
    value.v[0] = static_cast<double>(index);
    value.span = s.span;
    consts_[s.name] = value;
    value_spans_[s.name] = s.span;
    texture_index_[s.name] = index;
    if (index < inherited_textures_) body_textures_.insert(s.name);
    if (index < P_.textures.size())
        P_.textures[index] = std::move(def);
    else
        P_.textures.push_back(std::move(def));
}

// The bytes of the image file of identity `id`, read once per grammar; null after an input error.
std::shared_ptr<const std::string> Compiler::texture_bytes(const ast::ShapeDecl& s, const std::string& id) {
    if (auto it = texture_files_->by_identity.find(id); it != texture_files_->by_identity.end())
        return it->second;
    const std::string& written = s.args[0]->text;
    const std::size_t left = kMaxTextureBytes - texture_files_->bytes;
    auto text = std::make_shared<std::string>();
    if (ReadFailure why = read_input_file(id, *text, left); why != ReadFailure::None) {
        diags_->input_error(s.args[0]->span,
                            why == ReadFailure::TooLarge && left < kMaxTextureBytes
                                ? fmt::format("cannot read texture image '{}': the grammar's texture images "
                                              "together may take at most {} MB",
                                              written, kMaxTextureBytes >> 20)
                                : fmt::format("cannot read texture image '{}': {}", written, describe(why)));
        return nullptr;
    }
    texture_files_->bytes += text->size();
    texture_files_->by_identity[id] = text;
    return text;
}

void Compiler::compile_environment(const ast::ShapeDecl& s) {
    for (const ast::ShapeDecl* other : env_decls_) {
        if (other == &s) break;
        if (other->name == s.name) {
            duplicate("environment", s.name, s.span, other->span);
            return;
        }
    }
    P_.environments.emplace_back();
    EnvironmentDecl& decl = P_.environments.back(); // without an object until made
    decl.name = s.name;
    decl.kind_name = s.kind;
    decl.span = s.span;
    if (!opts_.environments) return; // no runtime: using it is reported where it is used
    std::vector<EnvArg>& args = decl.args;
    for (std::size_t i = 0; i < s.args.size(); ++i) {
        if (s.args[i]->kind == ast::ExprKind::String) { // a file, relative to the grammar
            EnvArg a;
            a.key = s.keys[i];
            a.type = ValueType::String;
            fs::path path(s.args[i]->text);
            if (path.is_relative()) path = fs::path(sm_.file(s.span.file).name()).parent_path() / path;
            a.text = path.lexically_normal().string();
            a.span = s.args[i]->span;
            if (readable(s.args[i]->text, a.text, a.span).empty()) return;
            args.push_back(a);
            continue;
        }
        auto v = eval_const(*s.args[i], "an environment's argument");
        if (!v) return;
        EnvArg a;
        a.key = s.keys[i];
        a.type = v->type;
        std::copy(v->v, v->v + 3, a.v);
        a.span = s.args[i]->span;
        args.push_back(a);
    }
    std::string error;
    std::unique_ptr<Environment> env;
    try {
        env = opts_.environments(s.kind, args, error);
    } catch (const InputError& e) { // a file it reads (a mesh) is unreadable or malformed
        diags_->input_error(s.kind_span, e.message);
        return;
    } catch (RuntimeError& e) { // its particles do not fit in --max-memory: a runtime error still
        if (!e.span.valid()) e.span = s.kind_span;
        throw;
    }
    if (!env) {
        diags_->error(s.kind_span,
                      error.empty() ? fmt::format("unknown environment kind '{}'", s.kind) : error);
        return;
    }
    decl.kind = &env->kind();
    decl.initial = std::shared_ptr<const Environment>(std::move(env));
}

ValueType Compiler::compile_env_call(Ctx& c, const ast::Expr& e, std::size_t env) {
    const EnvironmentDecl& decl = P_.environments[env];
    const std::string& env_name = decl.name;
    const auto& methods = decl.kind->methods;
    std::size_t m = 0;
    while (m < methods.size() && methods[m].name != e.text) ++m;
    if (m == methods.size()) {
        std::vector<std::string> names;
        for (const auto& mm : methods) names.push_back(mm.name);
        std::string near = nearest_name(e.text, names);
        diags_->error(e.span, near.empty()
                                  ? fmt::format("environment '{}' has no method '{}'", env_name, e.text)
                                  : fmt::format("environment '{}' has no method '{}'; did you mean '{}'?",
                                                env_name, e.text, near));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    const EnvMethod& method = methods[m];
    if (method.access == EnvAccess::Edit && c.kind != CtxKind::Hook)
        diags_->error(e.span, fmt::format("'{}.{}' changes the environment and can be called only in hooks "
                                          "({})",
                                          env_name, e.text, ast::hook_list("on ", ", ")));
    const std::size_t given = e.args.size() - 1;
    if (given != method.args.size()) {
        diags_->error(e.span, fmt::format("'{}.{}' takes {} argument{}, given {}", env_name, e.text,
                                          method.args.size(), method.args.size() == 1 ? "" : "s", given));
        emit_const(c, 0, e.span);
        return ValueType::Number;
    }
    int width = 0;
    for (std::size_t i = 0; i < given; ++i) {
        ValueType t = compile_expr(c, *e.args[i + 1]);
        bool fits = method.args[i] == ValueType::Vec3 ? t == ValueType::Vec3 : numeric(t);
        if (!fits)
            diags_->error(e.args[i + 1]->span,
                          fmt::format("argument {} of '{}.{}' must be a {}, found a {}", i + 1, env_name,
                                      e.text, value_type_name(method.args[i]), value_type_name(t)));
        width += value_width(t);
    }
    // the method's index and its result's width share b (program.hpp), so the stack check is exact
    emit(c, Op::EnvCall, static_cast<std::int32_t>(env), width, e.span,
         env_call_operand(m, value_width(method.result)));
    return method.result;
}

} // namespace plant
