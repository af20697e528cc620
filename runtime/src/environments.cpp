// Environment kinds: bounds (ellipsoid), proximity of other stems (spatial hash over the
// skeleton's segments) and obstacles (signed distances to boxes, spheres and planes).
#include "plant/environments.hpp"

#include <fmt/format.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace plant {

namespace {

constexpr ValueType N = ValueType::Number;
constexpr ValueType V = ValueType::Vec3;
constexpr ValueType B = ValueType::Bool;

glm::dvec3 vec(const EnvArg& a) { return {a.v[0], a.v[1], a.v[2]}; }
glm::dvec3 vec(const double* a) { return {a[0], a[1], a[2]}; }

// Reads keyword arguments of one kind, checking names and types.
class Args {
public:
    Args(const std::string& kind, const std::vector<EnvArg>& args, std::string& error)
        : kind_(kind), args_(args), error_(error) {}
    const EnvArg* find(const std::string& key, ValueType type) {
        for (const auto& a : args_) {
            if (a.key != key) continue;
            if ((type == V) != (a.type == V)) {
                fail(fmt::format("{}: '{}' must be a {}", kind_, key, value_type_name(type)));
                return nullptr;
            }
            return &a;
        }
        return nullptr;
    }
    // Every argument must be named and known.
    bool only(std::initializer_list<const char*> keys) {
        for (const auto& a : args_) {
            bool known = std::any_of(keys.begin(), keys.end(), [&](const char* k) { return a.key == k; });
            if (!known) {
                std::string list;
                for (const char* k : keys) list += (list.empty() ? "" : ", ") + std::string(k);
                fail(a.key.empty() ? fmt::format("{}: arguments are named ({})", kind_, list)
                                   : fmt::format("{}: unknown argument '{}' (known: {})", kind_, a.key, list));
                return false;
            }
        }
        return error_.empty();
    }
    void fail(std::string message) {
        if (error_.empty()) error_ = std::move(message);
    }
    bool ok() const { return error_.empty(); }

private:
    const std::string& kind_;
    const std::vector<EnvArg>& args_;
    std::string& error_;
};

// ---- ellipsoid -----------------------------------------------------------------------------

class Ellipsoid : public Environment {
public:
    Ellipsoid(glm::dvec3 center, glm::dvec3 radii) : center_(center), radii_(radii) {}
    const std::vector<EnvMethod>& methods() const override {
        static const std::vector<EnvMethod> m = {
            {"contains", {V}, B, "p inside the ellipsoid"},
            {"contains_scaled", {V, N}, B, "p inside the ellipsoid scaled by g about its center"},
            {"level", {V}, N, "|(p - center) / radii|: below 1 inside, 1 on the surface"},
        };
        return m;
    }
    void call(std::size_t method, const double* a, double* r) const override {
        double level = glm::length((vec(a) - center_) / radii_);
        switch (method) {
        case 0: r[0] = level <= 1.0; break;
        case 1: r[0] = a[3] > 0 && level <= a[3]; break;
        default: r[0] = level; break;
        }
    }

private:
    glm::dvec3 center_, radii_;
};

// ---- proximity -----------------------------------------------------------------------------

// Segments of the skeleton in a uniform grid of cells one radius wide; a query looks at the 27
// cells around its point. Each segment knows its axis, so the asking stem's own segments are
// skipped, and so is every segment that touches the stem's branching point (its base, where its
// parent and its siblings meet it).
class Proximity : public SkeletonEnvironment {
public:
    explicit Proximity(double radius) : radius_(radius) {}
    const std::vector<EnvMethod>& methods() const override {
        static const std::vector<EnvMethod> m = {
            {"distance", {V, N}, N,
             "distance from p to the nearest segment of another stem than module id's (at most radius)"},
        };
        return m;
    }
    void update(const Skeleton& sk) override {
        segments_.clear();
        axis_of_.clear();
        base_.clear();
        lo_ = glm::dvec3(std::numeric_limits<double>::max());
        glm::dvec3 hi(-std::numeric_limits<double>::max());
        for (std::size_t a = 0; a < sk.axes.size(); ++a) {
            const auto& pts = sk.axes[a].points;
            base_.push_back(pts.empty() ? glm::dvec3(0.0) : pts[0].position);
            for (std::size_t k = 0; k < pts.size(); ++k) {
                if (pts[k].id) axis_of_[pts[k].id] = static_cast<int>(a);
                lo_ = glm::min(lo_, pts[k].position);
                hi = glm::max(hi, pts[k].position);
                if (k > 0) segments_.push_back(Segment{pts[k - 1].position, pts[k].position, static_cast<int>(a)});
            }
        }
        // a dense grid over the plant's box, cells at least one radius wide (wider when the box
        // would need more than 8 million cells), stored as offsets into one index array
        cell_ = radius_;
        if (segments_.empty()) {
            dims_ = glm::ivec3(0);
            return;
        }
        for (;;) {
            glm::dvec3 n = glm::floor((hi - lo_) / cell_) + 1.0;
            if (n.x * n.y * n.z <= 8e6) {
                dims_ = glm::ivec3(n);
                break;
            }
            cell_ *= 2;
        }
        const std::size_t cells = static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z;
        offsets_.assign(cells + 1, 0);
        auto each_cell = [&](const Segment& s, auto&& f) {
            glm::ivec3 a = cell(glm::min(s.a, s.b)), b = cell(glm::max(s.a, s.b));
            for (int z = a.z; z <= b.z; ++z)
                for (int y = a.y; y <= b.y; ++y)
                    for (int x = a.x; x <= b.x; ++x) f(index(x, y, z));
        };
        for (const auto& s : segments_) each_cell(s, [&](std::size_t c) { ++offsets_[c + 1]; });
        for (std::size_t c = 0; c < cells; ++c) offsets_[c + 1] += offsets_[c];
        entries_.assign(offsets_[cells], 0);
        std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
        for (std::uint32_t i = 0; i < segments_.size(); ++i)
            each_cell(segments_[i], [&](std::size_t c) { entries_[fill[c]++] = i; });
    }
    void call(std::size_t, const double* a, double* r) const override {
        const glm::dvec3 p = vec(a);
        int own = -1;
        if (a[3] > 0) {
            auto it = axis_of_.find(static_cast<ModuleId>(a[3]));
            if (it != axis_of_.end()) own = it->second;
        }
        const glm::dvec3 base = own >= 0 ? base_[static_cast<std::size_t>(own)] : glm::dvec3(0.0);
        double best2 = radius_ * radius_;
        if (dims_.x > 0) {
            glm::ivec3 c = cell(p);
            const int reach = 1; // cells are at least one radius wide
            for (int z = std::max(0, c.z - reach); z <= std::min(dims_.z - 1, c.z + reach); ++z)
                for (int y = std::max(0, c.y - reach); y <= std::min(dims_.y - 1, c.y + reach); ++y)
                    for (int x = std::max(0, c.x - reach); x <= std::min(dims_.x - 1, c.x + reach); ++x) {
                        const std::size_t k = index(x, y, z);
                        for (std::uint32_t e = offsets_[k]; e < offsets_[k + 1]; ++e) {
                            const Segment& s = segments_[entries_[e]];
                            if (s.axis == own) continue;
                            if (own >= 0 && (same(s.a, base) || same(s.b, base))) continue; // its branching point
                            best2 = std::min(best2, distance2(p, s));
                        }
                    }
        }
        r[0] = std::sqrt(best2);
    }

private:
    struct Segment {
        glm::dvec3 a, b;
        int axis;
    };
    static bool same(const glm::dvec3& a, const glm::dvec3& b) {
        glm::dvec3 d = a - b;
        return glm::dot(d, d) < 1e-18;
    }
    static double distance2(const glm::dvec3& p, const Segment& s) {
        glm::dvec3 d = s.b - s.a;
        double len2 = glm::dot(d, d);
        double t = len2 > 0 ? std::clamp(glm::dot(p - s.a, d) / len2, 0.0, 1.0) : 0.0;
        glm::dvec3 q = p - (s.a + d * t);
        return glm::dot(q, q);
    }
    glm::ivec3 cell(const glm::dvec3& p) const {
        glm::dvec3 c = glm::floor((p - lo_) / cell_);
        // points outside the box map to just outside the grid, which the loops clip
        return glm::ivec3(glm::clamp(c, glm::dvec3(-2.0), glm::dvec3(dims_) + 1.0));
    }
    std::size_t index(int x, int y, int z) const {
        return (static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_.y) + static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(dims_.x) +
               static_cast<std::size_t>(x);
    }
    double radius_;
    double cell_ = 1;
    glm::dvec3 lo_{0.0};
    glm::ivec3 dims_{0};
    std::vector<Segment> segments_;
    std::vector<std::uint32_t> offsets_, entries_;
    std::unordered_map<ModuleId, int> axis_of_;
    std::vector<glm::dvec3> base_; // where each axis starts
};

// ---- obstacles -----------------------------------------------------------------------------

class Obstacles : public Environment {
public:
    struct Sphere {
        glm::dvec3 c;
        double r;
    };
    struct Box {
        glm::dvec3 lo, hi;
    };
    struct Plane {
        glm::dvec3 p, n;
    };
    std::vector<Sphere> spheres;
    std::vector<Box> boxes;
    std::vector<Plane> planes;

    const std::vector<EnvMethod>& methods() const override {
        static const std::vector<EnvMethod> m = {
            {"distance", {V}, N, "signed distance to the nearest obstacle (negative inside)"},
            {"inside", {V}, B, "p inside an obstacle"},
        };
        return m;
    }
    double distance(const glm::dvec3& p) const {
        double d = std::numeric_limits<double>::infinity();
        for (const auto& s : spheres) d = std::min(d, glm::length(p - s.c) - s.r);
        for (const auto& b : boxes) {
            // the usual box distance: outside part plus the (negative) inside part
            glm::dvec3 c = (b.lo + b.hi) * 0.5, h = (b.hi - b.lo) * 0.5;
            glm::dvec3 q = glm::abs(p - c) - h;
            double outside = glm::length(glm::max(q, glm::dvec3(0.0)));
            double inside = std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
            d = std::min(d, outside + inside);
        }
        for (const auto& pl : planes) d = std::min(d, glm::dot(p - pl.p, pl.n));
        return d;
    }
    void call(std::size_t method, const double* a, double* r) const override {
        double d = distance(vec(a));
        r[0] = method == 0 ? (std::isfinite(d) ? d : 1e300) : (d < 0 ? 1.0 : 0.0);
    }
};

} // namespace

EnvironmentFactory runtime_environments() {
    return [](const std::string& kind, const std::vector<EnvArg>& args, std::string& error) -> std::unique_ptr<Environment> {
        Args a(kind, args, error);
        if (kind == "ellipsoid") {
            if (!a.only({"center", "radii"})) return nullptr;
            const EnvArg* c = a.find("center", V);
            const EnvArg* r = a.find("radii", V);
            if (!a.ok()) return nullptr;
            glm::dvec3 radii = r ? vec(*r) : glm::dvec3(1.0);
            if (radii.x <= 0 || radii.y <= 0 || radii.z <= 0) {
                error = "ellipsoid: radii must be positive";
                return nullptr;
            }
            return std::make_unique<Ellipsoid>(c ? vec(*c) : glm::dvec3(0.0), radii);
        }
        if (kind == "proximity") {
            if (!a.only({"radius"})) return nullptr;
            const EnvArg* r = a.find("radius", N);
            if (!a.ok()) return nullptr;
            double radius = r ? r->v[0] : 1.0;
            if (!(radius > 0)) {
                error = "proximity: radius must be positive";
                return nullptr;
            }
            return std::make_unique<Proximity>(radius);
        }
        if (kind == "obstacles") {
            if (!a.only({"sphere", "sphere_radius", "box_min", "box_max", "plane_point", "plane_normal"})) return nullptr;
            auto o = std::make_unique<Obstacles>();
            // shapes pair up in the order they are written: each sphere with the next radius, ...
            std::vector<glm::dvec3> centers, box_min, box_max, plane_p, plane_n;
            std::vector<double> radii;
            for (const auto& arg : args) {
                bool is_vec = arg.type == V;
                bool want_vec = arg.key != "sphere_radius";
                if (is_vec != want_vec) {
                    error = fmt::format("obstacles: '{}' must be a {}", arg.key, want_vec ? "vec3" : "number");
                    return nullptr;
                }
                if (arg.key == "sphere") centers.push_back(vec(arg));
                else if (arg.key == "sphere_radius") radii.push_back(arg.v[0]);
                else if (arg.key == "box_min") box_min.push_back(vec(arg));
                else if (arg.key == "box_max") box_max.push_back(vec(arg));
                else if (arg.key == "plane_point") plane_p.push_back(vec(arg));
                else plane_n.push_back(vec(arg));
            }
            if (centers.size() != radii.size() || box_min.size() != box_max.size() || plane_p.size() != plane_n.size()) {
                error = "obstacles: give each sphere a sphere_radius, each box_min a box_max and each plane_point a "
                        "plane_normal";
                return nullptr;
            }
            for (std::size_t i = 0; i < centers.size(); ++i) o->spheres.push_back({centers[i], radii[i]});
            for (std::size_t i = 0; i < box_min.size(); ++i)
                o->boxes.push_back({glm::min(box_min[i], box_max[i]), glm::max(box_min[i], box_max[i])});
            for (std::size_t i = 0; i < plane_p.size(); ++i) {
                if (glm::length(plane_n[i]) == 0) {
                    error = "obstacles: a plane_normal must not be zero";
                    return nullptr;
                }
                o->planes.push_back({plane_p[i], glm::normalize(plane_n[i])});
            }
            return o;
        }
        error = fmt::format("unknown environment kind '{}': this version has ellipsoid, proximity and obstacles",
                            kind);
        return nullptr;
    };
}

} // namespace plant
