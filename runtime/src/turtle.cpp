// The turtle's operations. Rotations are right-handed about the named axis of the turtle's own
// frame (H, L, U with U = H x L), so that '+' turns H toward L, '&' pitches H toward -U and
// '/' rolls L toward U.
#include "plant/turtle.hpp"
#include "plant/derive.hpp"
#include "plant/environment.hpp"
#include "plant/instances.hpp"

#include "geometry.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace plant {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// The cosine and sine of the last few angles turned by: a grammar turns by a handful of angles
// again and again. The same numbers as computing them afresh, only not recomputed.
class AngleCache {
  public:
    void get(double phi, double& c, double& s) {
        for (const Entry& e : entries_)
            if (e.phi == phi && e.valid) {
                c = e.c;
                s = e.s;
                return;
            }
        c = std::cos(phi);
        s = std::sin(phi);
        entries_[next_] = Entry{phi, c, s, true};
        next_ = (next_ + 1) % kSize;
    }

  private:
    static constexpr std::size_t kSize = 4;
    struct Entry {
        double phi = 0, c = 1, s = 0;
        bool valid = false;
    };
    Entry entries_[kSize];
    std::size_t next_ = 0;
};

void rotate_frame(TurtleState& t, const glm::dvec3& axis, double c, double s) {
    t.heading = rotate(t.heading, axis, c, s);
    t.left = rotate(t.left, axis, c, s);
    t.up = rotate(t.up, axis, c, s);
}

void rotate_frame(TurtleState& t, const glm::dvec3& axis, double phi) {
    rotate_frame(t, axis, std::cos(phi), std::sin(phi));
}

// Keeps the frame orthonormal against rounding over long strings.
void orthonormalize(TurtleState& t) {
    t.heading = glm::normalize(t.heading);
    t.left = glm::normalize(t.left - t.heading * glm::dot(t.left, t.heading));
    t.up = glm::cross(t.heading, t.left);
}

// Sets the heading, keeping up as close as possible to `up_hint`.
void set_heading(TurtleState& t, glm::dvec3 h, glm::dvec3 up_hint) {
    // scale first, so that huge components do not overflow the length
    double m = std::max({std::fabs(h.x), std::fabs(h.y), std::fabs(h.z)});
    if (!(m > 0) || !std::isfinite(m)) return;
    h /= m;
    double um = std::max({std::fabs(up_hint.x), std::fabs(up_hint.y), std::fabs(up_hint.z)});
    up_hint = um > 0 && std::isfinite(um) ? up_hint / um : t.up;
    h = glm::normalize(h);
    glm::dvec3 l = glm::cross(up_hint, h);
    if (glm::length(l) < 1e-9) l = glm::cross(glm::dvec3(0, 0, 1), h);
    if (glm::length(l) < 1e-9) l = glm::cross(glm::dvec3(1, 0, 0), h);
    t.heading = h;
    t.left = glm::normalize(l);
    t.up = glm::cross(t.heading, t.left);
}

glm::dmat4 frame_matrix(const TurtleState& t, double scale) {
    // local x = right (-L), y = heading, z = up: a right-handed frame
    glm::dmat4 m(1.0);
    m[0] = glm::dvec4(-t.left * scale, 0.0);
    m[1] = glm::dvec4(t.heading * scale, 0.0);
    m[2] = glm::dvec4(t.up * scale, 0.0);
    m[3] = glm::dvec4(t.position, 1.0);
    return m;
}

} // namespace

std::string organ_label(const OrganShape& shape) {
    if (shape.kind == OrganKind::Sphere) return std::string(turtle_symbol(TurtleOp::Sphere)->name);
    if (shape.kind != OrganKind::Instance) return shape.name;
    // an instance with its argument tuple, as written: Branch(12, 0.5)
    std::string out = shape.name;
    for (std::size_t k = 0; k < shape.args.size(); ++k)
        out += (k ? ", " : "(") + format_double(shape.args[k]);
    return shape.args.empty() ? out : out + ")";
}

glm::vec3 palette_color(int index) {
    static const glm::vec3 palette[] = {
        {0.45f, 0.32f, 0.20f}, // bark
        {0.20f, 0.55f, 0.18f}, // leaf green
        {0.85f, 0.15f, 0.25f}, // rose red
        {0.95f, 0.85f, 0.30f}, // yellow
        {0.95f, 0.95f, 0.92f}, // white
        {0.55f, 0.30f, 0.65f}, // purple
        {0.35f, 0.70f, 0.35f}, // light green
        {0.30f, 0.22f, 0.14f}, // dark bark
    };
    constexpr int n = sizeof(palette) / sizeof(palette[0]);
    return palette[((index % n) + n) % n];
}

namespace {

// One pass of the turtle over a string: its state, the branch stack and the axes begun so far.
class Turtle {
  public:
    Turtle(const Program& program, const ModuleString& s, const TurtleOptions& options, TurtleSink& sink)
        : program_(program), s_(s), options_(options), sink_(sink) {
        t_.step = options.step;
        t_.angle = options.angle;
        t_.width = options.width;
        t_.color = palette_color(0);
        // what each symbol does: bound to a climber (drawn like F, ending where its particle is),
        // or its turtle operation (plant/turtle_symbols.hpp)
        const std::size_t n = program.symbols.size();
        bound_.assign(n, 0);
        ops_.assign(n, TurtleOp::None);
        for (std::size_t k = 0; k < n; ++k) {
            const SymbolInfo& info = program.symbols.all()[k];
            bound_[k] = !info.bound_to.empty();
            ops_[k] = info.turtle_op;
        }
        instance_.assign(n, -1);
        for (std::size_t k = 0; k < n; ++k) instance_[k] = program.symbols.all()[k].instance;
    }

    void run() {
        at_ = s_.params.data();
        for (std::size_t i = 0; i < s_.size(); at_ += s_.stored(i), ++i) {
            const SymbolId sym = s_.symbol(i);
            if (sym >= ops_.size()) continue;
            if (bound_[sym])
                bound_segment(i);
            else if (ops_[sym] != TurtleOp::None)
                apply(ops_[sym], i);
            else if (instance_[sym] >= 0)
                place_instance(i, instance_[sym]);
        }
    }

  private:
    const double* at_ = nullptr; // the parameters of the module run() is at (the string is read in order)

    ModuleArgs args(std::size_t i) const { return s_.args_at(i, at_); }
    double arg(std::size_t i, std::uint32_t k, double fallback) const {
        return s_.arity(i) > k ? args(i)[k] : fallback;
    }
    glm::dvec3 vec_arg(std::size_t i, std::uint32_t k) const {
        const ModuleArgs a = args(i);
        return {a[k], a[k + 1], a[k + 2]};
    }

    void check(std::size_t i) const {
        auto finite = [](const glm::dvec3& v) {
            return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
        };
        const bool at = finite(t_.position);
        if (at && finite(t_.heading) && finite(t_.left) && finite(t_.up)) return;
        throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                           fmt::format("the turtle left finite space at module {} of {}, {}: its {} is "
                                       "past the range of a double (a step or a position too large?)",
                                       i + 1, which_string(), module_text(i),
                                       at ? "orientation" : "position"));
    }

    // the string the turtle reads, as its messages name it: a grammar with interpretation rules
    // has the turtle read what they make of the derived string, whose modules count differently
    const char* which_string() const {
        return program_.interpret.empty() ? "the string"
                                          : "the interpreted string (after the interpret rules)";
    }

    // the module as the string has it, with its parameters: what to look for in the grammar
    std::string module_text(std::size_t i) const {
        std::string text = program_.symbols[s_.symbol(i)].name;
        for (std::uint32_t k = 0; k < s_.arity(i); ++k)
            text += (k == 0 ? "(" : ", ") + format_double(args(i)[k]) + (k + 1 == s_.arity(i) ? ")" : "");
        return text;
    }

    // a width, radius or scale below 0 would turn a tube, a sphere or a surface inside out
    double size_arg(std::size_t i, std::uint32_t k, double fallback, const char* what) const {
        const double v = arg(i, k, fallback);
        if (v >= 0) return v;
        throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                           fmt::format("module {} of {}, {}, gives a {} below 0; a {} is at least 0 "
                                       "(max(w, 0) keeps a computed one there)",
                                       i + 1, which_string(), module_text(i), what, what));
    }

    void tropism() {
        // ABOP p. 58: rotate H toward T by e |H x T| about H x T
        if (t_.elasticity == 0) return;
        glm::dvec3 axis = glm::cross(t_.heading, t_.tropism);
        double len = glm::length(axis);
        if (len < 1e-12) return;
        rotate_frame(t_, axis / len, t_.elasticity * len);
        orthonormalize(t_);
    }

    // the first segment after '[' or a move starts a new axis
    void start_axis() {
        if (t_.axis >= 0) return;
        t_.axis = next_axis_++;
        sink_.axis_begin(t_.axis, parent_axis_, t_);
    }

    // Seg(len, r) bound to a climber: length and radius; with a particle, the segment ends at
    // its position and the turtle takes its frame
    void bound_segment(std::size_t i) {
        double len = arg(i, 0, t_.step);
        if (s_.arity(i) > 1) t_.width = 2 * size_arg(i, 1, t_.width / 2, "radius");
        glm::dvec3 p;
        glm::dmat3 frame;
        const BoundPoses* placed_by = nullptr;
        for (const BoundPoses* bp : options_.poses)
            if (bp && bp->pose(s_.id(i), p, frame)) {
                placed_by = bp;
                break;
            }
        const bool placed = placed_by != nullptr;
        if (placed && placed_by->starts_loose(s_.id(i))) {
            // the first segment of a part that broke off or was cut and is falling: a tube of its
            // own, from its particle's length back along its heading
            t_.axis = -1;
            t_.heading = frame[1];
            t_.left = -frame[0];
            t_.up = frame[2];
            t_.position = p - t_.heading * len;
        }
        start_axis();
        glm::dvec3 from = t_.position;
        if (placed) {
            t_.position = p;
            t_.heading = frame[1];
            t_.left = -frame[0];
            t_.up = frame[2];
        } else {
            t_.position += t_.heading * len;
        }
        check(i);
        sink_.segment(TurtleSegment{from, t_.position, &t_, i, s_.id(i)});
        t_.bound_parent = s_.id(i);
    }

    void forward(std::size_t i) {
        double len = arg(i, 0, t_.step);
        if (s_.arity(i) > 1) t_.width = size_arg(i, 1, t_.width, "width");
        start_axis();
        glm::dvec3 from = t_.position;
        t_.position += t_.heading * len;
        tropism();
        check(i);
        sink_.segment(TurtleSegment{from, t_.position, &t_, i, s_.id(i)});
    }

    // a turn of the parameter's degrees (default the grammar's angle) about one of the
    // turtle's own axes, `sign` giving the direction
    void turn(std::size_t i, const glm::dvec3& axis, int sign) {
        double c, s;
        angles_.get(arg(i, 0, t_.angle) * kDeg * sign, c, s);
        rotate_frame(t_, axis, c, s);
    }

    void push() {
        stack_.push_back(t_);
        parent_stack_.push_back(parent_axis_);
        if (t_.axis >= 0) parent_axis_ = t_.axis;
        t_.axis = -1;
    }

    void pop(std::size_t i) {
        if (stack_.empty())
            throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                               fmt::format("']' at module {} of {} closes no '[' (the turtle's "
                                           "stack is empty)",
                                           i + 1, which_string()));
        t_ = stack_.back();
        stack_.pop_back();
        parent_axis_ = parent_stack_.back();
        parent_stack_.pop_back();
    }

    void apply(TurtleOp op, std::size_t i);

    // SetTexture(t): t is a declared texture's index (its name in the grammar), -1 or nothing for
    // none (docs/language.md, textures).
    void set_texture(std::size_t i) {
        const double t = arg(i, 0, -1.0);
        if (t == -1) {
            t_.texture = -1;
            return;
        }
        const std::size_t n = program_.textures.size();
        if (!(t >= 0) || t != std::floor(t) || t >= static_cast<double>(n))
            throw RuntimeError(
                RuntimeErrorKind::Turtle, Span{},
                fmt::format("module {} ('{}') of {} sets texture {}, but the grammar declares {}: "
                            "declare one with 'texture bark = image(\"bark.png\");' and write "
                            "SetTexture(bark), or SetTexture(-1) for none",
                            i + 1, program_.symbols[s_.symbol(i)].name, which_string(), format_double(t),
                            n == 0   ? std::string("no textures")
                            : n == 1 ? std::string("only texture 0")
                                     : fmt::format("textures 0 to {}", n - 1)));
        t_.texture = static_cast<int>(t);
    }

    // An instance's module (docs/language.md, instances): its arguments, then an optional scale;
    // the instance is placed in the turtle's frame at that scale (the width does not scale it).
    void place_instance(std::size_t i, int index) {
        const std::size_t width = program_.instances ? instance_arg_width((*program_.instances)[index]) : 0;
        const std::uint32_t n = s_.arity(i);
        const ModuleArgs a = this->args(i);
        std::vector<double> args(width, 0.0);
        for (std::size_t k = 0; k < std::min<std::size_t>(n, width); ++k) args[k] = a[k];
        const double scale = n > width ? a[width] : 1.0;
        if (!std::isfinite(scale) || scale <= 0)
            throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                               fmt::format("module {} ('{}') of {} places an instance at scale {}: the "
                                           "scale must be a positive number",
                                           i + 1, program_.symbols[s_.symbol(i)].name, which_string(),
                                           scale));
        sink_.organ(
            TurtleOrgan{{OrganKind::Instance, program_.symbols[s_.symbol(i)].name, index, std::move(args)},
                        frame_matrix(t_, scale),
                        t_.color,
                        i,
                        s_.id(i)});
    }

    const Program& program_;
    const ModuleString& s_;
    const TurtleOptions& options_;
    TurtleSink& sink_;
    TurtleState t_;
    std::vector<TurtleState> stack_;
    int next_axis_ = 0;
    int parent_axis_ = -1; // axis the current branch grows from
    std::vector<int> parent_stack_;
    std::vector<char> bound_;
    std::vector<TurtleOp> ops_;
    std::vector<int> instance_; // per symbol: the instance it places, or -1
    AngleCache angles_;
};

// One row of plant/turtle_symbols.hpp each (its doc says what the case does).
void Turtle::apply(TurtleOp op, std::size_t i) {
    switch (op) {
    case TurtleOp::None:
    case TurtleOp::Cut:
        break;
    case TurtleOp::Forward:
        forward(i);
        break;
    case TurtleOp::Move:
        t_.position += t_.heading * arg(i, 0, t_.step);
        t_.axis = -1;
        check(i);
        break;
    case TurtleOp::TurnLeft:
    case TurtleOp::TurnRight:
        turn(i, t_.up, op == TurtleOp::TurnLeft ? 1 : -1);
        break;
    case TurtleOp::PitchDown:
    case TurtleOp::PitchUp:
        turn(i, t_.left, op == TurtleOp::PitchDown ? 1 : -1);
        break;
    case TurtleOp::RollRight:
    case TurtleOp::RollLeft:
        turn(i, t_.heading, op == TurtleOp::RollRight ? 1 : -1);
        break;
    case TurtleOp::TurnAround:
        rotate_frame(t_, t_.up, std::numbers::pi);
        break;
    case TurtleOp::RollLevel: {
        // roll so that L is horizontal: L = V x H with V the world's up
        glm::dvec3 l = glm::cross(glm::dvec3(0, 1, 0), t_.heading);
        if (glm::length(l) > 1e-9) {
            t_.left = glm::normalize(l);
            t_.up = glm::cross(t_.heading, t_.left);
        }
        break;
    }
    case TurtleOp::Push:
        push();
        break;
    case TurtleOp::Pop:
        pop(i);
        break;
    case TurtleOp::Width:
        t_.width = size_arg(i, 0, t_.width, "width");
        break;
    case TurtleOp::PaletteColor:
        t_.color_index = static_cast<int>(std::clamp(arg(i, 0, t_.color_index + 1), -1e6, 1e6));
        t_.color = palette_color(t_.color_index);
        break;
    case TurtleOp::RgbColor: {
        glm::dvec3 c(arg(i, 0, 0), arg(i, 1, 0), arg(i, 2, 0));
        if (c.x > 1 || c.y > 1 || c.z > 1) c /= 255.0;
        t_.color = glm::clamp(glm::vec3(c), glm::vec3(0.0f), glm::vec3(1.0f));
        break;
    }
    case TurtleOp::Sphere:
        sink_.organ(TurtleOrgan{{OrganKind::Sphere, {}, -1, {}},
                                frame_matrix(t_, size_arg(i, 0, t_.width / 2, "radius")),
                                t_.color,
                                i,
                                s_.id(i),
                                t_.texture});
        break;
    case TurtleOp::Surface:
        // "~name": the surface's name follows the prefix row's name
        sink_.organ(TurtleOrgan{
            {OrganKind::Surface,
             program_.symbols[s_.symbol(i)].name.substr(turtle_symbol(TurtleOp::Surface)->name.size()),
             -1,
             {}},
            frame_matrix(t_, size_arg(i, 0, 1.0, "scale")),
            t_.color,
            i,
            s_.id(i),
            t_.texture});
        break;
    case TurtleOp::SetHeading:
        if (s_.arity(i) >= 6)
            set_heading(t_, vec_arg(i, 0), vec_arg(i, 3));
        else if (s_.arity(i) >= 3)
            set_heading(t_, vec_arg(i, 0), t_.up);
        check(i);
        break;
    case TurtleOp::MoveTo:
        if (s_.arity(i) >= 3) t_.position = vec_arg(i, 0);
        t_.axis = -1;
        check(i);
        break;
    case TurtleOp::SetTexture:
        set_texture(i);
        break;
    case TurtleOp::Tropism:
        if (s_.arity(i) >= 3) t_.tropism = vec_arg(i, 0);
        break;
    case TurtleOp::Elasticity:
        t_.elasticity = arg(i, 0, 0);
        break;
    case TurtleOp::QueryPosition:
    case TurtleOp::QueryHeading:
    case TurtleOp::QueryUp:
    case TurtleOp::QueryLeft:
    case TurtleOp::Communicate:
        sink_.query(i, t_);
        break;
    }
}

} // namespace

void interpret(const Program& program, const ModuleString& s, const TurtleOptions& options,
               TurtleSink& sink) {
    Turtle(program, s, options, sink).run();
}

TurtleOptions turtle_options(const Derivation& d) {
    TurtleOptions o{d.default_angle(), d.default_step(), d.default_width(), {}};
    const RunState& state = d.run_state();
    for (std::size_t e = 0; e < state.size(); ++e)
        if (const Environment* env = state.environment(e); env && env->kind().holds_segments)
            o.poses.push_back(env);
    return o;
}

} // namespace plant
