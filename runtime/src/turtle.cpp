// The turtle's operations. Rotations are right-handed about the named axis of the turtle's own
// frame (H, L, U with U = H x L), so that '+' turns H toward L, '&' pitches H toward -U and
// '/' rolls L toward U.
#include "plant/turtle.hpp"
#include "plant/derive.hpp"
#include "plant/environment.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace plant {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Rotates a about axis k (unit) by phi, right-handed (Rodrigues).
glm::dvec3 rotate(const glm::dvec3& a, const glm::dvec3& k, double phi) {
    double c = std::cos(phi), s = std::sin(phi);
    return a * c + glm::cross(k, a) * s + k * glm::dot(k, a) * (1 - c);
}

void rotate_frame(TurtleState& t, const glm::dvec3& axis, double phi) {
    t.heading = rotate(t.heading, axis, phi);
    t.left = rotate(t.left, axis, phi);
    t.up = rotate(t.up, axis, phi);
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

struct Symbols {
    SymbolId F = kNoSymbol, f = kNoSymbol, G = kNoSymbol, plus = kNoSymbol, minus = kNoSymbol,
             amp = kNoSymbol, caret = kNoSymbol, back = kNoSymbol, slash = kNoSymbol, pipe = kNoSymbol,
             dollar = kNoSymbol, open = kNoSymbol, close = kNoSymbol, bang = kNoSymbol, semi = kNoSymbol,
             sphere = kNoSymbol, set_head = kNoSymbol, set_head2 = kNoSymbol, move_to = kNoSymbol,
             tropism = kNoSymbol, elasticity = kNoSymbol, set_color = kNoSymbol, qP = kNoSymbol,
             qH = kNoSymbol, qU = kNoSymbol, qL = kNoSymbol, qE = kNoSymbol;
    explicit Symbols(const SymbolTable& st) {
        auto get = [&](const char* n, SymbolId& out) {
            if (auto id = st.find(n)) out = *id;
        };
        get("F", F), get("f", f), get("G", G), get("+", plus), get("-", minus), get("&", amp),
            get("^", caret);
        get("\\", back), get("/", slash), get("|", pipe), get("$", dollar), get("[", open), get("]", close);
        get("!", bang), get(";", semi), get("@O", sphere), get("@R", set_head), get("SetHead", set_head2);
        get("@M", move_to), get("@Tp", tropism), get("@Ts", elasticity), get("SetColor", set_color);
        get("?P", qP), get("?H", qH), get("?U", qU), get("?L", qL), get("?E", qE);
    }
};

} // namespace

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

void interpret(const Program& program, const ModuleString& s, const TurtleOptions& options,
               TurtleSink& sink) {
    const Symbols y(program.symbols);
    TurtleState t;
    t.step = options.step;
    t.angle = options.angle;
    t.width = options.width;
    t.color = palette_color(0);
    std::vector<TurtleState> stack;
    int next_axis = 0;
    int parent_axis = -1; // axis the current branch grows from
    std::vector<int> parent_stack;

    auto arg = [&](std::size_t i, std::uint32_t k, double fallback) {
        return s.arity(i) > k ? s.args(i)[k] : fallback;
    };
    auto vec_arg = [&](std::size_t i, std::uint32_t k) {
        const double* a = s.args(i);
        return glm::dvec3(a[k], a[k + 1], a[k + 2]);
    };
    auto check = [&](std::size_t i) {
        auto finite = [](const glm::dvec3& v) {
            return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
        };
        if (!finite(t.position) || !finite(t.heading) || !finite(t.left) || !finite(t.up))
            throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                               fmt::format("the turtle left finite space at module {} ('{}') of the string",
                                           i + 1, program.symbols[s.sym[i]].name));
    };
    auto tropism = [&]() {
        // ABOP p. 58: rotate H toward T by e |H x T| about H x T
        if (t.elasticity == 0) return;
        glm::dvec3 axis = glm::cross(t.heading, t.tropism);
        double len = glm::length(axis);
        if (len < 1e-12) return;
        rotate_frame(t, axis / len, t.elasticity * len);
        orthonormalize(t);
    };

    // the first segment after '[' or a move starts a new axis
    auto start_axis = [&]() {
        if (t.axis >= 0) return;
        t.axis = next_axis++;
        sink.axis_begin(t.axis, parent_axis, t);
    };
    // modules bound to a climber: drawn like F, ending where their particle is
    std::vector<char> bound(program.symbols.size(), 0);
    for (std::size_t k = 0; k < bound.size(); ++k) bound[k] = !program.symbols.all()[k].bound_to.empty();

    for (std::size_t i = 0; i < s.size(); ++i) {
        const SymbolId sym = s.sym[i];
        if (sym < bound.size() && bound[sym]) {
            // Seg(len, r): length and radius; with a particle, the segment ends at its position
            double len = arg(i, 0, t.step);
            if (s.arity(i) > 1) t.width = 2 * s.args(i)[1];
            start_axis();
            glm::dvec3 from = t.position;
            glm::dvec3 p;
            glm::dmat3 frame;
            bool placed = false;
            for (const BoundPoses* bp : options.poses)
                if (bp && bp->pose(s.id(i), p, frame)) {
                    placed = true;
                    break;
                }
            if (placed) {
                t.position = p;
                t.heading = frame[1];
                t.left = -frame[0];
                t.up = frame[2];
            } else {
                t.position += t.heading * len;
            }
            check(i);
            sink.segment(TurtleSegment{from, t.position, &t, i, s.id(i)});
            t.bound_parent = s.id(i);
        } else if (sym == y.F || sym == y.G) {
            double len = arg(i, 0, t.step);
            if (s.arity(i) > 1) t.width = s.args(i)[1];
            start_axis();
            glm::dvec3 from = t.position;
            t.position += t.heading * len;
            tropism();
            check(i);
            sink.segment(TurtleSegment{from, t.position, &t, i, s.id(i)});
        } else if (sym == y.f) {
            t.position += t.heading * arg(i, 0, t.step);
            t.axis = -1;
            check(i);
        } else if (sym == y.plus || sym == y.minus) {
            double a = arg(i, 0, t.angle) * kDeg * (sym == y.plus ? 1 : -1);
            rotate_frame(t, t.up, a);
        } else if (sym == y.amp || sym == y.caret) {
            double a = arg(i, 0, t.angle) * kDeg * (sym == y.amp ? 1 : -1);
            rotate_frame(t, t.left, a);
        } else if (sym == y.slash || sym == y.back) {
            double a = arg(i, 0, t.angle) * kDeg * (sym == y.slash ? 1 : -1);
            rotate_frame(t, t.heading, a);
        } else if (sym == y.pipe) {
            rotate_frame(t, t.up, std::numbers::pi);
        } else if (sym == y.dollar) {
            // roll so that L is horizontal: L = V x H with V the world's up
            glm::dvec3 l = glm::cross(glm::dvec3(0, 1, 0), t.heading);
            if (glm::length(l) > 1e-9) {
                t.left = glm::normalize(l);
                t.up = glm::cross(t.heading, t.left);
            }
        } else if (sym == y.open) {
            stack.push_back(t);
            parent_stack.push_back(parent_axis);
            if (t.axis >= 0) parent_axis = t.axis;
            t.axis = -1;
        } else if (sym == y.close) {
            if (stack.empty())
                throw RuntimeError(RuntimeErrorKind::Turtle, Span{},
                                   fmt::format("']' at module {} of the string closes no '[' (the turtle's "
                                               "stack is empty)",
                                               i + 1));
            t = stack.back();
            stack.pop_back();
            parent_axis = parent_stack.back();
            parent_stack.pop_back();
        } else if (sym == y.bang) {
            t.width = arg(i, 0, t.width);
        } else if (sym == y.semi) {
            t.color_index = static_cast<int>(std::clamp(arg(i, 0, t.color_index + 1), -1e6, 1e6));
            t.color = palette_color(t.color_index);
        } else if (sym == y.set_color) {
            glm::dvec3 c(arg(i, 0, 0), arg(i, 1, 0), arg(i, 2, 0));
            if (c.x > 1 || c.y > 1 || c.z > 1) c /= 255.0;
            t.color = glm::clamp(glm::vec3(c), glm::vec3(0.0f), glm::vec3(1.0f));
        } else if (sym == y.sphere) {
            double r = arg(i, 0, t.width / 2);
            sink.organ(TurtleOrgan{"@O", frame_matrix(t, r), t.color, i, s.id(i)});
        } else if (sym == y.set_head || sym == y.set_head2) {
            if (s.arity(i) >= 6)
                set_heading(t, vec_arg(i, 0), vec_arg(i, 3));
            else if (s.arity(i) >= 3)
                set_heading(t, vec_arg(i, 0), t.up);
            check(i);
        } else if (sym == y.move_to) {
            if (s.arity(i) >= 3) t.position = vec_arg(i, 0);
            t.axis = -1;
            check(i);
        } else if (sym == y.tropism) {
            if (s.arity(i) >= 3) t.tropism = vec_arg(i, 0);
        } else if (sym == y.elasticity) {
            t.elasticity = arg(i, 0, 0);
        } else if (sym == y.qP || sym == y.qH || sym == y.qU || sym == y.qL || sym == y.qE) {
            sink.query(i, t);
        } else {
            const std::string& name = program.symbols[sym].name;
            if (name.size() > 1 && name[0] == '~') {
                double scale = arg(i, 0, 1.0);
                sink.organ(TurtleOrgan{name.substr(1), frame_matrix(t, scale), t.color, i, s.id(i)});
            }
        }
    }
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
