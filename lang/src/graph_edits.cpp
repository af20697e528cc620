// Edits files (docs/language.md, decomposition graphs: edits files): one edit a line,
//
//     /0.25[0..0.375]    bend = linear(0, 0.4, 0.8)
//     share 1            length = 7
//
// read into GraphEdits with every error at its line and column. Values are evaluated here, with
// the program's params and consts: numbers, arithmetic, and linear(...) / bezier(...) curves.
#include "compiler_internal.hpp"
#include "graph_silhouette.hpp"
#include "plant/derive.hpp"
#include "plant/graph.hpp"
#include "plant/parser.hpp"
#include "plant/program.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <numbers>

namespace plant {

namespace {

constexpr std::size_t kMaxEdits = 100'000;
constexpr std::size_t kMaxPathSteps = 1000;
constexpr int kMaxShareLevel = 1000;
constexpr std::size_t kMaxBezierPoints = 256;

bool blank(char c) {
    return c == ' ' || c == '\t' || c == '\r';
}

struct Failure {
    Span span;
    std::string message;
};

// Reads a node path, POSITION[#INDEX][[LO..HI]] per component ("/0.25#1/0.5[0.4..0.6]"); throws
// Failure at the first problem, placed in `file` from the path's first byte `at`.
struct PathReader {
    std::uint32_t file = 0;

    [[noreturn]] void fail(std::uint32_t b, std::uint32_t e, std::string message) const {
        throw Failure{{file, b, std::max(e, b + 1)}, std::move(message)};
    }

    // A number of the path at `s[i]`, advancing i; `at` is the path's first byte.
    double number(const std::string& s, std::size_t& i, std::uint32_t at, const char* what) const {
        // digits, then '.' and digits only when a digit follows ("0..0.5" is 0, "..", 0.5)
        std::size_t e = i;
        while (e < s.size() && std::isdigit(static_cast<unsigned char>(s[e]))) ++e;
        if (e + 1 < s.size() && s[e] == '.' && std::isdigit(static_cast<unsigned char>(s[e + 1]))) {
            ++e;
            while (e < s.size() && std::isdigit(static_cast<unsigned char>(s[e]))) ++e;
        }
        double v = 0;
        auto r = std::from_chars(s.data() + i, s.data() + e, v);
        if (e == i || r.ec != std::errc{} || r.ptr != s.data() + e || !std::isfinite(v))
            fail(static_cast<std::uint32_t>(at + i), static_cast<std::uint32_t>(at + i + 1),
                 fmt::format("expected {} in the path", what));
        i = static_cast<std::size_t>(r.ptr - s.data());
        return v;
    }

    std::vector<EditStep> path(const std::string& s, std::uint32_t at) const {
        std::vector<EditStep> out;
        if (s == "/") return out;
        std::size_t i = 0;
        while (i < s.size()) {
            auto col = [&](std::size_t k) { return static_cast<std::uint32_t>(at + k); };
            if (s[i] != '/') fail(col(i), col(i + 1), "expected '/' before the next component of the path");
            if (out.size() >= kMaxPathSteps)
                fail(col(i), col(i + 1), fmt::format("a path has at most {} components", kMaxPathSteps));
            ++i;
            EditStep step;
            const std::size_t start = i;
            step.position = number(s, i, at, "a position from 0 to 1");
            if (step.position < 0 || step.position > 1)
                fail(col(start), col(i), "a position along the parent axis is from 0 to 1");
            if (i < s.size() && s[i] == '#') {
                const std::size_t b = ++i;
                const double idx = number(s, i, at, "a branch index after '#'");
                if (idx < 0 || idx > 1e6 || idx != std::floor(idx))
                    fail(col(b), col(i), "a branch index is a whole number from 0 to 1000000");
                step.index = static_cast<int>(idx);
            }
            if (i < s.size() && s[i] == '[') {
                const std::size_t b = ++i;
                step.lo = number(s, i, at, "the range's low end");
                if (s.compare(i, 2, "..") != 0)
                    fail(col(i), col(i + 1), "expected '..' between the ends of the range");
                i += 2;
                step.hi = number(s, i, at, "the range's high end");
                if (i >= s.size() || s[i] != ']') fail(col(i), col(i + 1), "expected ']' to close the range");
                ++i;
                if (!(0 <= step.lo && step.lo <= step.position && step.position <= step.hi && step.hi <= 1))
                    fail(col(b), col(i - 1), "a range LO..HI needs 0 <= LO <= position <= HI <= 1");
                step.ranged = true;
            }
            out.push_back(step);
        }
        return out;
    }
};

// Reads one line; throws Failure at the first problem.
class LineReader {
  public:
    LineReader(const Program& prog, const SourceManager& sm, std::uint32_t file, std::uint32_t b,
               std::uint32_t e)
        : prog_(prog), sm_(sm), file_(file), text_(sm.file(file).text()), pos_(b), end_(e) {}

    GraphEdit read() {
        GraphEdit edit;
        edit.span = {file_, pos_, end_};
        const std::uint32_t first = pos_;
        std::string word = token();
        if (word == "share") {
            edit.share = true;
            skip();
            const std::uint32_t at = pos_;
            std::string level = token();
            int v = -1;
            auto r = std::from_chars(level.data(), level.data() + level.size(), v);
            if (level.empty() || r.ec != std::errc{} || r.ptr != level.data() + level.size() || v < 0 ||
                v > kMaxShareLevel)
                fail(at, static_cast<std::uint32_t>(at + std::max<std::size_t>(level.size(), 1)),
                     fmt::format("expected a level (a depth from 0 to {}) after 'share'", kMaxShareLevel));
            edit.level = v;
        } else if (!word.empty() && word[0] == '/') {
            edit.path = PathReader{file_}.path(word, first);
        } else {
            fail(first, static_cast<std::uint32_t>(first + std::max<std::size_t>(word.size(), 1)),
                 fmt::format(
                     "expected a node path ('/', '/0.25', '/0.5#1[0.4..0.6]') or 'share LEVEL', found '{}'",
                     word));
        }
        skip();
        parameter(edit);
        return edit;
    }

  private:
    [[noreturn]] void fail(std::uint32_t b, std::uint32_t e, std::string message) const {
        throw Failure{{file_, b, std::max(e, b + 1)}, std::move(message)};
    }
    void skip() {
        while (pos_ < end_ && blank(text_[pos_])) ++pos_;
    }
    std::string token() {
        const std::uint32_t b = pos_;
        while (pos_ < end_ && !blank(text_[pos_])) ++pos_;
        return text_.substr(b, pos_ - b);
    }
    std::string identifier() {
        const std::uint32_t b = pos_;
        while (pos_ < end_ && (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_'))
            ++pos_;
        return text_.substr(b, pos_ - b);
    }

    void parameter(GraphEdit& edit) {
        const GraphDecl& g = prog_.graph;
        const std::uint32_t at = pos_;
        const std::string name = identifier();
        if (name.empty()) fail(at, at + 1, "expected a parameter name after the path");
        edit.param = g.find(name);
        if (edit.param < 0) {
            std::vector<std::string> names;
            if (name.size() <= 64) // (a suggestion for a short name only: the distance is quadratic)
                for (const auto& p : g.params) names.push_back(p.name);
            const std::string near = nearest_name(name, names);
            fail(at, static_cast<std::uint32_t>(at + name.size()),
                 near.empty()
                     ? fmt::format("the graph has no parameter '{}'", name)
                     : fmt::format("the graph has no parameter '{}'; did you mean '{}'?", name, near));
        }
        const GraphParamDecl& p = g.params[static_cast<std::size_t>(edit.param)];
        skip();
        const std::uint32_t op_at = pos_;
        std::string op = text_.substr(pos_, 2);
        if (op == "+=" || op == "*=") {
            edit.op = op == "+=" ? EditOp::Offset : EditOp::Fraction;
            pos_ += 2;
        } else if (pos_ < end_ && text_[pos_] == '=') {
            edit.op = EditOp::Set;
            ++pos_;
        } else {
            const std::string word = identifier();
            if (word == "inherit" || word == "private" || word == "public") {
                edit.op = word == "inherit"   ? EditOp::Inherit
                          : word == "private" ? EditOp::Private
                                              : EditOp::Public;
            } else {
                fail(op_at, op_at + 1,
                     "expected '=', '+=', '*=', 'inherit', 'private' or 'public' after the parameter");
            }
        }
        const std::uint32_t op_end = pos_;
        auto wrong = [&](const char* what) { fail(op_at, op_end, what); };
        const bool root = !edit.share && edit.path.empty();
        if (edit.share && edit.op != EditOp::Set)
            wrong("a share gives one explicit value to a level: only 'share LEVEL NAME = VALUE'");
        if (root && edit.op == EditOp::Private)
            wrong("the root's parameters are always public: 'private' on '/'");
        if (root && (edit.op == EditOp::Offset || edit.op == EditOp::Fraction || edit.op == EditOp::Inherit))
            wrong("the root inherits nothing: give it an explicit value with '='");
        if (p.kind == GraphParamKind::Silhouette &&
            (edit.op == EditOp::Offset || edit.op == EditOp::Fraction))
            wrong("a silhouette can be explicit or inherited, not relative");
        skip();
        if (edit.op == EditOp::Inherit || edit.op == EditOp::Private || edit.op == EditOp::Public) {
            if (pos_ < end_)
                fail(pos_, end_, fmt::format("nothing may follow '{}'", text_.substr(op_at, op_end - op_at)));
            return;
        }
        if (pos_ >= end_) fail(pos_, pos_ + 1, "expected a value after the operator");
        std::uint32_t e = end_;
        while (e > pos_ && blank(text_[e - 1])) --e;
        edit.value_text = text_.substr(pos_, e - pos_);
        value(edit, p, pos_, e);
    }

    void value(GraphEdit& edit, const GraphParamDecl& p, std::uint32_t b, std::uint32_t e) {
        Diagnostics local;
        ast::ExprPtr expr = parse_expression(sm_, file_, b, e, local);
        if (!expr || local.has_errors()) { // (a number out of range parses, as 0, with its error)
            const Diagnostic& d = local.all().front();
            throw Failure{d.span, d.message};
        }
        const bool is_curve =
            expr->kind == ast::ExprKind::Call && (expr->text == "linear" || expr->text == "bezier");
        const bool is_silhouette = expr->kind == ast::ExprKind::Call && expr->text == "silhouette";
        if (is_silhouette != (p.kind == GraphParamKind::Silhouette))
            fail(
                expr->span.begin, expr->span.end,
                is_silhouette
                    ? fmt::format("'{}' is a {}, found a silhouette", p.name, graph_param_kind_name(p.kind))
                    : fmt::format("'{}' is a silhouette: give silhouette(axis: ..., top: ..., ...)", p.name));
        if (p.kind == GraphParamKind::Silhouette) {
            edit.silhouette = silhouette(*expr);
            return;
        }
        if (p.kind == GraphParamKind::Number && is_curve)
            fail(expr->span.begin, expr->span.end,
                 fmt::format("'{}' is a number, found a curve: give a number expression", p.name));
        if (p.kind == GraphParamKind::Number) {
            edit.number = eval(*expr);
            return;
        }
        CurveDef c;
        c.name = p.name;
        c.span = expr->span;
        if (!is_curve) { // a number for a curve: the constant curve (`bend *= 0.5` scales it)
            const double v = eval(*expr);
            c.xs = {0, 1};
            c.ys = {v, v};
        } else {
            curve(*expr, c);
        }
        edit.curve = std::make_shared<const CurveDef>(std::move(c));
    }

    std::shared_ptr<const Silhouette> silhouette(const ast::Expr& e) const {
        SilhouetteEval ev;
        ev.vec = [&](const ast::Expr& x) -> std::optional<glm::dvec3> { return point(x); };
        ev.number = [&](const ast::Expr& x) -> std::optional<double> { return eval(x); };
        ev.error = [&](Span s, std::string m) { fail(s.begin, s.end, std::move(m)); };
        return build_silhouette(e, ev);
    }

    // vec3(x, y, z) of number expressions, or a vec3 param or const
    glm::dvec3 point(const ast::Expr& e) const {
        if (e.kind == ast::ExprKind::Call && e.text == "vec3" && e.args.size() == 3)
            return {eval(*e.args[0]), eval(*e.args[1]), eval(*e.args[2])};
        if (e.kind == ast::ExprKind::Name) {
            if (auto it = prog_.global_index.find(e.text); it != prog_.global_index.end()) {
                const Global& g = prog_.globals[it->second];
                if (g.type == ValueType::Vec3)
                    return {prog_.global_values[g.slot], prog_.global_values[g.slot + 1],
                            prog_.global_values[g.slot + 2]};
            }
            for (const auto& c : prog_.constants)
                if (c.name == e.text && c.type == ValueType::Vec3) return {c.v[0], c.v[1], c.v[2]};
        }
        fail(e.span.begin, e.span.end,
             "a silhouette's point is vec3(x, y, z) of numbers, or a vec3 param or const");
    }

    void curve(const ast::Expr& e, CurveDef& c) const {
        c.bezier = e.text == "bezier";
        // a Bezier curve costs the square of its control points at every t: bound what a file asks
        if (c.bezier && e.args.size() > kMaxBezierPoints)
            fail(e.span.begin, e.span.end,
                 fmt::format("a bezier(...) curve takes at most {} control values here, given {}: use "
                             "linear(...) for more",
                             kMaxBezierPoints, e.args.size()));
        bool points = false;
        for (std::size_t i = 0; i < e.args.size(); ++i) {
            const ast::Expr& a = *e.args[i];
            const bool vec = a.kind == ast::ExprKind::Call && a.text == "vec3";
            if (i == 0) points = vec;
            if (vec != points)
                fail(a.span.begin, a.span.end, "a curve's control values are all numbers or all vec3 points");
            if (vec) {
                if (a.args.size() != 3) fail(a.span.begin, a.span.end, "vec3 takes three numbers here");
                c.xs.push_back(eval(*a.args[0]));
                c.ys.push_back(eval(*a.args[1]));
            } else {
                c.xs.push_back(0);
                c.ys.push_back(eval(a));
            }
        }
        if (c.ys.size() < 2) fail(e.span.begin, e.span.end, "a curve needs at least two control values");
        if (!points)
            for (std::size_t i = 0; i < c.xs.size(); ++i) c.xs[i] = double(i) / double(c.xs.size() - 1);
        for (std::size_t i = 1; i < c.xs.size(); ++i)
            if (c.xs[i] < c.xs[i - 1])
                fail(e.args[i]->span.begin, e.args[i]->span.end,
                     "the x of a curve's points must not decrease");
    }

    // Numbers, the program's params, vars and consts, pi, - + * / and parentheses.
    double eval(const ast::Expr& e) const {
        using K = ast::ExprKind;
        double v = 0;
        switch (e.kind) {
        case K::Number:
        case K::Bool:
            v = e.number;
            break;
        case K::Name:
            v = name(e);
            break;
        case K::Unary:
            v = e.unary == ast::UnaryOp::Neg ? -eval(*e.args[0]) : (eval(*e.args[0]) == 0 ? 1 : 0);
            break;
        case K::Binary: {
            const double a = eval(*e.args[0]), b = eval(*e.args[1]);
            using B = ast::BinaryOp;
            if (e.binary == B::Add)
                v = a + b;
            else if (e.binary == B::Sub)
                v = a - b;
            else if (e.binary == B::Mul)
                v = a * b;
            else if (e.binary == B::Div && b != 0)
                v = a / b;
            else if (e.binary == B::Div)
                fail(e.span.begin, e.span.end, "division by zero");
            else
                fail(e.span.begin, e.span.end, "an edit's value uses only + - * / on numbers");
            break;
        }
        default:
            fail(e.span.begin, e.span.end,
                 "an edit's value is a number expression (numbers, params, consts, + - * /) or "
                 "linear(...) / bezier(...)");
        }
        if (!std::isfinite(v)) fail(e.span.begin, e.span.end, "the value is not a finite number");
        return v;
    }

    double name(const ast::Expr& e) const {
        if (auto it = prog_.global_index.find(e.text); it != prog_.global_index.end()) {
            const Global& g = prog_.globals[it->second];
            if (g.type != ValueType::Vec3) return prog_.global_values[g.slot];
        }
        for (const auto& c : prog_.constants)
            if (c.name == e.text && c.type != ValueType::Vec3) return c.v[0];
        if (e.text == "pi") return std::numbers::pi;
        std::vector<std::string> names;
        for (const auto& g : prog_.globals)
            if (e.text.size() <= 64) names.push_back(g.name);
        for (const auto& c : prog_.constants)
            if (e.text.size() <= 64) names.push_back(c.name);
        const std::string near = nearest_name(e.text, names);
        fail(e.span.begin, e.span.end,
             near.empty()
                 ? fmt::format("unknown name '{}': an edit's value may use the grammar's params and consts",
                               e.text)
                 : fmt::format("unknown name '{}'; did you mean '{}'?", e.text, near));
    }

    const Program& prog_;
    const SourceManager& sm_;
    std::uint32_t file_;
    const std::string& text_;
    std::uint32_t pos_, end_;
};

// Where a comment starts on the line [b, e): a '#' first on the line or after a blank (a '#'
// inside a path is a branch index).
std::uint32_t comment_start(const std::string& text, std::uint32_t b, std::uint32_t e) {
    for (std::uint32_t i = b; i < e; ++i)
        if (text[i] == '#' && (i == b || blank(text[i - 1]))) return i;
    return e;
}

} // namespace

std::shared_ptr<const GraphEdits> parse_edits(const Program& program, const SourceManager& sources,
                                              std::uint32_t file_id, Diagnostics& diags) {
    auto out = std::make_shared<GraphEdits>();
    const std::string& text = sources.file(file_id).text();
    const std::size_t errors = diags.error_count();
    std::uint32_t b = 0;
    const auto size = static_cast<std::uint32_t>(text.size());
    while (b < size) {
        std::uint32_t e = b;
        while (e < size && text[e] != '\n') ++e;
        const std::uint32_t next = e + 1;
        e = comment_start(text, b, e);
        while (b < e && blank(text[b])) ++b;
        while (e > b && blank(text[e - 1])) --e;
        if (b < e) {
            if (!program.graph.declared) {
                diags.error({file_id, b, e}, "the grammar declares no graph, so it takes no edits");
                break;
            }
            if (out->edits.size() >= kMaxEdits) {
                diags.error({file_id, b, e}, fmt::format("an edits file holds at most {} edits", kMaxEdits));
                break;
            }
            try {
                out->edits.push_back(LineReader(program, sources, file_id, b, e).read());
            } catch (const Failure& f) {
                diags.error(f.span, f.message);
                if (diags.error_count() - errors >= 20) break;
            }
        }
        b = next;
    }
    if (diags.error_count() != errors) return nullptr;
    return out;
}

std::optional<std::vector<EditStep>> parse_node_path(const std::string& text) {
    try {
        return PathReader{}.path(text, 0);
    } catch (const Failure&) {
        return std::nullopt;
    }
}

std::string edit_path_text(const GraphEdit& e) {
    if (e.share) return fmt::format("share {}", e.level);
    if (e.path.empty()) return "/";
    std::string out;
    for (const EditStep& s : e.path) {
        out += "/" + format_double(s.position);
        if (s.index != 0) out += fmt::format("#{}", s.index);
        if (s.ranged) out += "[" + format_double(s.lo) + ".." + format_double(s.hi) + "]";
    }
    return out;
}

} // namespace plant
