// Environment kinds: bounds (ellipsoid), crown silhouettes (envelope), proximity of other stems
// (spatial hash over the skeleton's segments) and obstacles (signed distances to boxes, spheres
// and planes).
#include "plant/environments.hpp"

#include "plant/grid_cell.hpp"

#include "plant/climber.hpp"
#include "plant/silhouette.hpp"

#include "geometry.hpp"
#include "obstacle_args.hpp"
#include "triangle_mesh.hpp"

#include <fmt/format.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace plant {

namespace {

// a grid's cell for a point that may lie far outside it (cell_index, plant/grid_cell.hpp)
glm::ivec3 cell_of(const glm::dvec3& u, int lo, const glm::ivec3& hi) {
    return {cell_index(u.x, lo, hi.x), cell_index(u.y, lo, hi.y), cell_index(u.z, lo, hi.z)};
}

constexpr ValueType N = ValueType::Number;
constexpr ValueType V = ValueType::Vec3;
constexpr ValueType B = ValueType::Bool;
constexpr EnvAccess Pure = EnvAccess::Pure;

using plant::vec; // geometry.hpp
glm::dvec3 vec(const EnvArg& a) {
    return vec(a.v);
}

// Reads keyword arguments of one kind, checking names and types.
class Args {
  public:
    Args(const char* kind, const std::vector<EnvArg>& args, std::string& error)
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
                fail(a.key.empty()
                         ? fmt::format("{}: arguments are named ({})", kind_, list)
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
    const char* kind_;
    const std::vector<EnvArg>& args_;
    std::string& error_;
};

// ---- ellipsoid -----------------------------------------------------------------------------

enum class EllipsoidMethod : std::uint8_t { Contains, ContainsScaled, Level, Distance };
constexpr EnvMethod kEllipsoidMethods[] = {
    env_method(EllipsoidMethod::Contains, "contains", {V}, B, Pure, true, "p inside the ellipsoid"),
    env_method(EllipsoidMethod::ContainsScaled, "contains_scaled", {V, N}, B, Pure, false,
               "p inside the ellipsoid scaled by g about its center"),
    env_method(EllipsoidMethod::Level, "level", {V}, N, Pure, true,
               "|(p - center) / radii|: below 1 inside, 1 on the surface"),
    env_method(EllipsoidMethod::Distance, "distance", {V}, N, Pure, true,
               "signed distance to the surface along the ray from the center (negative inside)"),
};
static_assert(method_table(kEllipsoidMethods, EllipsoidMethod::Distance));
constexpr EnvironmentKind kEllipsoid{"ellipsoid", "an ellipsoid: center, radii", kEllipsoidMethods};

class Ellipsoid : public Environment {
  public:
    Ellipsoid(glm::dvec3 center, glm::dvec3 radii) : center_(center), radii_(radii) {}
    const EnvironmentKind& kind() const override { return kEllipsoid; }
    std::unique_ptr<Environment> clone() const override { return std::make_unique<Ellipsoid>(*this); }
    void query(std::size_t method, const double* a, double* r) const override {
        const glm::dvec3 p = vec(a);
        double level = glm::length((p - center_) / radii_);
        switch (static_cast<EllipsoidMethod>(method)) {
        case EllipsoidMethod::Contains:
            r[0] = level <= 1.0;
            break;
        case EllipsoidMethod::ContainsScaled:
            r[0] = a[3] > 0 && level <= a[3];
            break;
        case EllipsoidMethod::Level:
            r[0] = level;
            break;
        case EllipsoidMethod::Distance:
            // the surface point on the ray from the center through p is center + (p - center) / level
            r[0] = level > 0 ? glm::length(p - center_) * (1 - 1 / level)
                             : -std::min({radii_.x, radii_.y, radii_.z});
            break;
        }
    }

  private:
    glm::dvec3 center_, radii_;
};

// ---- proximity -----------------------------------------------------------------------------

// Segments of the skeleton in a uniform grid of cells one radius wide, each listed in the cells it
// passes through; a query looks at the 27 cells around its point. Each segment knows its axis, so the asking
// stem's own segments are skipped, and so is every segment that touches the stem's branching point (its base,
// where its parent and its siblings meet it).
enum class ProximityMethod : std::uint8_t { Distance, Clearance };
constexpr EnvMethod kProximityMethods[] = {
    env_method(ProximityMethod::Distance, "distance", {V, N}, N, Pure, true,
               "distance from p to the nearest segment of another stem than module id's (at most radius)"),
    env_method(ProximityMethod::Clearance, "clearance", {N}, N, Pure, true,
               "smallest distance from a node of module id's stem to an older stem (at most radius)"),
};
static_assert(method_table(kProximityMethods, ProximityMethod::Clearance));
constexpr EnvironmentKind kProximity{"proximity", "distances between the plant's stems: radius",
                                     kProximityMethods};

class Proximity : public Environment {
  public:
    explicit Proximity(double radius) : radius_(radius) {}
    const EnvironmentKind& kind() const override { return kProximity; }
    std::unique_ptr<Environment> clone() const override { return std::make_unique<Proximity>(*this); }
    void see(const Skeleton& sk) override {
        segments_.clear();
        axis_of_.clear();
        base_.clear();
        first_id_.clear();
        nodes_.clear();
        node_off_.assign(1, 0);
        lo_ = glm::dvec3(std::numeric_limits<double>::max());
        glm::dvec3 hi(-std::numeric_limits<double>::max());
        for (std::size_t a = 0; a < sk.axes.size(); ++a) {
            const auto& pts = sk.axes[a].points;
            base_.push_back(pts.empty() ? glm::dvec3(0.0) : pts[0].position);
            first_id_.push_back(pts.size() > 1 ? pts[1].id : std::numeric_limits<ModuleId>::max());
            for (std::size_t k = 1; k < pts.size(); ++k) nodes_.push_back(pts[k].position);
            node_off_.push_back(static_cast<std::uint32_t>(nodes_.size()));
            for (std::size_t k = 0; k < pts.size(); ++k) {
                if (pts[k].id) axis_of_[pts[k].id] = static_cast<int>(a);
                lo_ = glm::min(lo_, pts[k].position);
                hi = glm::max(hi, pts[k].position);
                if (k > 0)
                    segments_.push_back(Segment{pts[k - 1].position, pts[k].position, static_cast<int>(a)});
            }
        }
        // a dense grid over the plant's box, cells at least one radius wide (wider when the box
        // would need more than 8 million cells), stored as offsets into one index array
        cell_ = radius_;
        if (segments_.empty()) {
            dims_ = glm::ivec3(0);
            return;
        }
        // the cells a segment passes through: the boxes of its pieces, each at most a cell across
        // on every axis, so a long slanting segment is listed along its length, not in every cell
        // of its bounding box (512 diagonals 141 m long in a grid of 1 m cells were 1.9 GB of
        // entries and 23 s); a cell of the last piece's box is not listed again. The pieces are
        // counted from the largest of the segment's spans along the axes, which unlike its length
        // cannot overflow for a segment inside the (finite) box.
        auto each_cell = [&](const Segment& s, auto&& f) {
            const glm::dvec3 span = glm::abs(s.b - s.a);
            const double pieces_wanted = std::ceil(std::max({span.x, span.y, span.z}) / cell_);
            const std::size_t pieces =
                pieces_wanted >= 1 && pieces_wanted < 1e9 ? static_cast<std::size_t>(pieces_wanted) : 1;
            glm::ivec3 last_a(1), last_b(0); // empty
            for (std::size_t k = 0; k < pieces; ++k) {
                const glm::dvec3 p = k == 0 ? s.a : s.a + (s.b - s.a) * (double(k) / double(pieces));
                const glm::dvec3 q =
                    k + 1 == pieces ? s.b : s.a + (s.b - s.a) * (double(k + 1) / double(pieces));
                // (widened by a rounding's worth: the pieces' ends are computed points)
                const glm::dvec3 slack(1e-9 * cell_);
                const glm::ivec3 a = glm::max(cell(glm::min(p, q) - slack), glm::ivec3(0)),
                                 b = glm::min(cell(glm::max(p, q) + slack), dims_ - 1);
                for (int z = a.z; z <= b.z; ++z)
                    for (int y = a.y; y <= b.y; ++y)
                        for (int x = a.x; x <= b.x; ++x)
                            if (x < last_a.x || x > last_b.x || y < last_a.y || y > last_b.y ||
                                z < last_a.z || z > last_b.z)
                                f(index(x, y, z));
                last_a = a, last_b = b;
            }
        };
        // the grid: at most 8 million cells and 2^28 entries (cells twice as wide until both hold)
        std::size_t cells = 0;
        const glm::dvec3 extent = hi - lo_;
        // a box too large for a double's range (stems near +-1e308): one cell, a table of every
        // segment
        const bool overflows = !std::isfinite(extent.x + extent.y + extent.z);
        if (overflows) cell_ = std::numeric_limits<double>::max();
        for (;;) {
            const glm::dvec3 n = overflows ? glm::dvec3(1.0) : glm::floor(extent / cell_) + 1.0;
            if (n.x * n.y * n.z > 8e6) {
                cell_ *= 2;
                continue;
            }
            dims_ = glm::ivec3(n);
            cells = static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z;
            offsets_.assign(cells + 1, 0);
            std::size_t total = 0;
            for (const auto& s : segments_) each_cell(s, [&](std::size_t c) { ++offsets_[c + 1], ++total; });
            if (total <= kMaxEntries || cells == 1) break;
            cell_ *= 2;
        }
        for (std::size_t c = 0; c < cells; ++c) offsets_[c + 1] += offsets_[c];
        entries_.assign(offsets_[cells], 0);
        std::vector<std::uint32_t> fill(offsets_.begin(), offsets_.end() - 1);
        for (std::uint32_t i = 0; i < segments_.size(); ++i)
            each_cell(segments_[i], [&](std::size_t c) { entries_[fill[c]++] = i; });
    }
    void query(std::size_t method, const double* a, double* r) const override {
        switch (static_cast<ProximityMethod>(method)) {
        case ProximityMethod::Distance:
            r[0] = distance(vec(a), axis_of(a[3]), false);
            break;
        case ProximityMethod::Clearance:
            r[0] = clearance(axis_of(a[0]));
            break;
        }
    }
    // ?E(space, distance, clearance): the asking stem is the axis the turtle was drawing there
    // (a ?E module is not a segment, so its own identity names no stem).
    void communicate(const glm::dvec3& p, ModuleId, int axis, double* slots, std::size_t n) const override {
        if (axis >= static_cast<int>(base_.size())) axis = -1;
        if (n > 0) slots[0] = distance(p, axis, false);
        if (n > 1) slots[1] = clearance(axis);
    }

  private:
    int axis_of(double id) const {
        if (!(id > 0)) return -1;
        auto it = axis_of_.find(static_cast<ModuleId>(id));
        return it == axis_of_.end() ? -1 : it->second;
    }
    // Distance from p to the nearest segment of an axis other than `own`, skipping segments that
    // touch own's branching point; with `older_only`, only axes whose first segment was drawn by
    // a module with a smaller identity (made in an earlier step, or earlier in the string).
    double distance(const glm::dvec3& p, int own, bool older_only) const {
        const glm::dvec3 base = own >= 0 ? base_[static_cast<std::size_t>(own)] : glm::dvec3(0.0);
        const ModuleId own_id = own >= 0 ? first_id_[static_cast<std::size_t>(own)] : 0;
        double best2 = radius_ * radius_;
        if (dims_.x == 0) return radius_;
        glm::ivec3 c = cell(p);
        const int reach = 1; // cells are at least one radius wide
        for (int z = std::max(0, c.z - reach); z <= std::min(dims_.z - 1, c.z + reach); ++z)
            for (int y = std::max(0, c.y - reach); y <= std::min(dims_.y - 1, c.y + reach); ++y)
                for (int x = std::max(0, c.x - reach); x <= std::min(dims_.x - 1, c.x + reach); ++x) {
                    const std::size_t k = index(x, y, z);
                    for (std::uint32_t e = offsets_[k]; e < offsets_[k + 1]; ++e) {
                        const Segment& s = segments_[entries_[e]];
                        if (s.axis == own) continue;
                        if (older_only && first_id_[static_cast<std::size_t>(s.axis)] >= own_id) continue;
                        if (own >= 0 && (same(s.a, base) || same(s.b, base))) continue; // its branching point
                        best2 = std::min(best2, distance2(p, s));
                    }
                }
        return std::sqrt(best2);
    }
    // Umezawa & Mukai, Eq. 3, read sequentially: the smallest distance from a node of the stem
    // (its branching point excluded) to a segment of an older stem. A new stem closer than
    // delta_min to one is removed; younger stems answer for themselves.
    double clearance(int own) const {
        if (own < 0) return radius_;
        double best = radius_;
        for (std::uint32_t k = node_off_[static_cast<std::size_t>(own)];
             k < node_off_[static_cast<std::size_t>(own) + 1]; ++k)
            best = std::min(best, distance(nodes_[k], own, true));
        return best;
    }
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
        // points outside the box map to just outside the grid, which the loops clip
        return cell_of((p - lo_) / cell_, -2, dims_ + 1);
    }
    std::size_t index(int x, int y, int z) const {
        return (static_cast<std::size_t>(z) * static_cast<std::size_t>(dims_.y) +
                static_cast<std::size_t>(y)) *
                   static_cast<std::size_t>(dims_.x) +
               static_cast<std::size_t>(x);
    }
    double radius_;
    double cell_ = 1;
    glm::dvec3 lo_{0.0};
    glm::ivec3 dims_{0};
    std::vector<Segment> segments_;
    static constexpr std::size_t kMaxEntries = std::size_t{1} << 28;
    std::vector<std::uint32_t> offsets_, entries_;
    std::unordered_map<ModuleId, int> axis_of_;
    std::vector<glm::dvec3> base_;   // where each axis starts
    std::vector<ModuleId> first_id_; // identity of the module that drew each axis's first segment
    std::vector<glm::dvec3> nodes_;  // every axis's points after its first, axis after axis
    std::vector<std::uint32_t> node_off_;
};

// ---- obstacles -----------------------------------------------------------------------------

enum class ObstaclesMethod : std::uint8_t { Distance, Inside };
constexpr EnvMethod kObstaclesMethods[] = {
    env_method(ObstaclesMethod::Distance, "distance", {V}, N, Pure, true,
               "signed distance to the nearest obstacle (negative inside)"),
    env_method(ObstaclesMethod::Inside, "inside", {V}, B, Pure, true, "p inside an obstacle"),
};
static_assert(method_table(kObstaclesMethods, ObstaclesMethod::Inside));
constexpr EnvironmentKind kObstacles{"obstacles", "spheres, boxes, planes and meshes, as signed distances",
                                     kObstaclesMethods};

class Obstacles : public Environment {
  public:
    // spheres, boxes and planes as the climbers' physics has them (one distance function for both)
    std::vector<physics::Obstacle> shapes;
    std::vector<Triangle> triangles; // of loaded meshes, each a closed surface with outward faces

    const EnvironmentKind& kind() const override { return kObstacles; }
    std::unique_ptr<Environment> clone() const override { return std::make_unique<Obstacles>(*this); }
    double distance(const glm::dvec3& p) const {
        double d = std::numeric_limits<double>::infinity();
        for (const auto& o : shapes) d = std::min(d, o.distance(p));
        if (!triangles.empty()) d = std::min(d, signed_distance(triangles, p));
        return d;
    }
    void geometry(std::vector<glm::dvec3>& out, const glm::dvec3& lo, const glm::dvec3& hi) const override {
        for (const auto& o : shapes) obstacle_triangles(o, lo, hi, out);
        for (const auto& t : triangles) out.insert(out.end(), {t.a, t.b, t.c});
    }
    void query(std::size_t method, const double* a, double* r) const override {
        double d = distance(vec(a));
        switch (static_cast<ObstaclesMethod>(method)) {
        case ObstaclesMethod::Distance:
            r[0] = std::isfinite(d) ? d : 1e300;
            break;
        case ObstaclesMethod::Inside:
            r[0] = d < 0 ? 1.0 : 0.0;
            break;
        }
    }
};

// ---- envelope ------------------------------------------------------------------------------

// Cescatti's asymmetric crown envelope (Boudon et al. 2003, Fig. 6), with the axis and the
// control point T of a silhouette (section 3): the geometry is plant::Silhouette
// (lang/include/plant/silhouette.hpp), here in world coordinates.
enum class EnvelopeMethod : std::uint8_t { Contains, Level, Reach, Axis, Heading, Base, Tip };
constexpr EnvMethod kEnvelopeMethods[] = {
    env_method(EnvelopeMethod::Contains, "contains", {V}, B, Pure, true, "p inside the envelope"),
    env_method(EnvelopeMethod::Level, "level", {V}, N, Pure, true,
               "how far out p is: below 1 inside, 1 on the surface"),
    env_method(EnvelopeMethod::Reach, "reach", {V, V}, N, Pure, false,
               "distance from p along d to where the ray leaves the envelope (0 if p is outside)"),
    env_method(EnvelopeMethod::Axis, "axis", {N}, V, Pure, false, "the point of the axis at t in [0, 1]"),
    env_method(EnvelopeMethod::Heading, "heading", {N}, V, Pure, false, "the axis's unit tangent at t"),
    env_method(EnvelopeMethod::Base, "base", {}, V, Pure, false, "the axis's first point B"),
    env_method(EnvelopeMethod::Tip, "tip", {}, V, Pure, false, "the control point T"),
};
static_assert(method_table(kEnvelopeMethods, EnvelopeMethod::Tip));
constexpr EnvironmentKind kEnvelope{"envelope", "Cescatti's asymmetric crown envelope", kEnvelopeMethods};

class EnvelopeEnv : public Environment {
  public:
    explicit EnvelopeEnv(Silhouette s) : s_(std::move(s)) {}
    const EnvironmentKind& kind() const override { return kEnvelope; }
    std::unique_ptr<Environment> clone() const override { return std::make_unique<EnvelopeEnv>(*this); }
    void query(std::size_t method, const double* a, double* r) const override {
        auto put = [&](const glm::dvec3& v) {
            r[0] = v.x;
            r[1] = v.y;
            r[2] = v.z;
        };
        switch (static_cast<EnvelopeMethod>(method)) {
        case EnvelopeMethod::Contains:
            r[0] = s_.envelope.level(vec(a)) <= 1.0 ? 1.0 : 0.0;
            break;
        case EnvelopeMethod::Level:
            r[0] = s_.envelope.level(vec(a));
            break;
        case EnvelopeMethod::Reach:
            r[0] = s_.envelope.reach(vec(a), vec(a + 3));
            break;
        case EnvelopeMethod::Axis:
            put(s_.axis.point(a[0]));
            break;
        case EnvelopeMethod::Heading:
            put(s_.axis.heading(a[0]));
            break;
        case EnvelopeMethod::Base:
            put(s_.base());
            break;
        case EnvelopeMethod::Tip:
            put(s_.tip);
            break;
        }
    }

  private:
    Silhouette s_;
};

// ---- light ---------------------------------------------------------------------------------

// Occlusion by the plant itself: the plant's box is cut into resolution^3 cells; a cell a
// segment passes through (or an organ sits in) is occupied. A point's exposure is the fraction
// of light left after the occupied cells between it and the light, each keeping (1 - opacity).
enum class LightMethod : std::uint8_t { Exposure, Occlusion };
constexpr EnvMethod kLightMethods[] = {
    env_method(LightMethod::Exposure, "exposure", {V}, N, Pure, true,
               "fraction of the light reaching p, from 0 (shaded) to 1"),
    env_method(LightMethod::Occlusion, "occlusion", {V}, N, Pure, true,
               "occupied cells between p and the light"),
};
static_assert(method_table(kLightMethods, LightMethod::Occlusion));
constexpr EnvironmentKind kLight{
    "light", "self-shading by the plant's segments and organs: direction, resolution, opacity",
    kLightMethods};

class Light : public Environment {
  public:
    Light(glm::dvec3 toward_light, int resolution, double opacity)
        : dir_(glm::normalize(toward_light)), res_(resolution), opacity_(opacity) {}
    const EnvironmentKind& kind() const override { return kLight; }
    std::unique_ptr<Environment> clone() const override { return std::make_unique<Light>(*this); }
    void see(const Skeleton& sk) override {
        lo_ = glm::dvec3(std::numeric_limits<double>::max());
        glm::dvec3 hi(-std::numeric_limits<double>::max());
        for (const auto& a : sk.axes)
            for (const auto& p : a.points) {
                lo_ = glm::min(lo_, p.position);
                hi = glm::max(hi, p.position);
            }
        for (const auto& o : sk.organs) {
            glm::dvec3 p(o.transform[3]);
            lo_ = glm::min(lo_, p);
            hi = glm::max(hi, p);
        }
        occupied_.assign(static_cast<std::size_t>(res_) * res_ * res_, 0);
        if (lo_.x > hi.x) return;
        cell_ = std::max({hi.x - lo_.x, hi.y - lo_.y, hi.z - lo_.z, 1e-9}) / res_ * 1.0001;
        for (const auto& a : sk.axes)
            for (std::size_t k = 1; k < a.points.size(); ++k) {
                glm::dvec3 from = a.points[k - 1].position, to = a.points[k].position;
                // half a cell a sample; a segment inside the box is at most 2 sqrt(3) res samples long,
                // so the cap only bounds a length that overflowed (stems near +-1e308)
                const double samples = std::ceil(glm::length(to - from) / (cell_ * 0.5));
                const int n = !(samples > 1)             ? 1
                              : samples < 4.0 * res_ + 4 ? static_cast<int>(samples)
                                                         : 4 * res_ + 4;
                for (int j = 0; j <= n; ++j) mark(from + (to - from) * (double(j) / n));
            }
        for (const auto& o : sk.organs) mark(glm::dvec3(o.transform[3]));
    }
    void query(std::size_t method, const double* a, double* r) const override {
        int count = occlusion(vec(a));
        switch (static_cast<LightMethod>(method)) {
        case LightMethod::Exposure:
            r[0] = std::pow(1 - opacity_, count);
            break;
        case LightMethod::Occlusion:
            r[0] = count;
            break;
        }
    }

  private:
    bool inside(const glm::ivec3& c) const {
        return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < res_ && c.y < res_ && c.z < res_;
    }
    // (a point far outside the box maps to just outside it)
    glm::ivec3 cell(const glm::dvec3& p) const {
        return cell_of((p - lo_) / cell_, -2, glm::ivec3(res_ + 1));
    }
    std::size_t index(const glm::ivec3& c) const {
        return (static_cast<std::size_t>(c.z) * res_ + static_cast<std::size_t>(c.y)) * res_ +
               static_cast<std::size_t>(c.x);
    }
    void mark(const glm::dvec3& p) {
        glm::ivec3 c = cell(p);
        if (inside(c)) occupied_[index(c)] = 1;
    }
    // Occupied cells met walking from p toward the light, p's own cell excluded, in steps of
    // half a cell (each cell counted once).
    int occlusion(const glm::dvec3& p) const {
        if (occupied_.empty() || lo_.x > 1e300) return 0;
        glm::ivec3 start = cell(p), last = start;
        int count = 0;
        const double step = cell_ * 0.5;
        const int max_steps = 4 * res_ + 8;
        for (int k = 1; k < max_steps; ++k) {
            glm::ivec3 c = cell(p + dir_ * (step * k));
            if (c == last) continue;
            last = c;
            if (!inside(c)) {
                // outside the box now: nothing more can be in the way unless we are still
                // approaching it from outside
                glm::dvec3 q = (p + dir_ * (step * k) - lo_) / cell_;
                bool leaving = (q.x < 0 && dir_.x <= 0) || (q.y < 0 && dir_.y <= 0) ||
                               (q.z < 0 && dir_.z <= 0) || (q.x >= res_ && dir_.x >= 0) ||
                               (q.y >= res_ && dir_.y >= 0) || (q.z >= res_ && dir_.z >= 0);
                if (leaving) break;
                continue;
            }
            if (c != start && occupied_[index(c)]) ++count;
        }
        return count;
    }
    glm::dvec3 dir_;
    int res_;
    double opacity_;
    glm::dvec3 lo_{1e301};
    double cell_ = 1;
    std::vector<std::uint8_t> occupied_;
};

using Made = std::unique_ptr<Environment>;

Made make_ellipsoid(const std::vector<EnvArg>& args, std::string& error) {
    Args a(kEllipsoid.name, args, error);
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

Made make_proximity(const std::vector<EnvArg>& args, std::string& error) {
    Args a(kProximity.name, args, error);
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

Made make_obstacles(const std::vector<EnvArg>& args, std::string& error) {
    Args a(kObstacles.name, args, error);
    if (!a.only({"sphere", "sphere_radius", "box_min", "box_max", "plane_point", "plane_normal", "mesh"}))
        return nullptr;
    auto o = std::make_unique<Obstacles>();
    ObstacleArgs shapes(kObstacles.name);
    for (const auto& arg : args) {
        if (arg.key == "mesh") {
            if (!shapes.mesh(arg, error)) return nullptr;
            if (!load_triangles(arg.text, o->triangles, kObstacles.name, error)) return nullptr;
            continue;
        }
        if (!shapes.read(arg, error)) return nullptr;
    }
    if (!shapes.paired(error) || !shapes.shapes(o->shapes, error)) return nullptr;
    return o;
}

// The envelope's axis: `axis` points make a polyline, `bezier` points a Bezier curve (each key
// as often as needed, not both); without either, the vertical from the bottom to the top's height.
bool envelope_axis(const std::vector<EnvArg>& args, const Envelope& e, AxisCurve& axis, std::string& error) {
    std::vector<glm::dvec3> polyline, bezier;
    for (const auto& arg : args) {
        if (arg.key != "axis" && arg.key != "bezier") continue;
        if (arg.type != V) {
            error = fmt::format("envelope: '{}' must be a vec3", arg.key);
            return false;
        }
        (arg.key == "axis" ? polyline : bezier).push_back(vec(arg));
    }
    if (!polyline.empty() && !bezier.empty()) {
        error = "envelope: the axis is either a polyline (`axis` points) or a Bezier curve (`bezier` points)";
        return false;
    }
    if (polyline.empty() && bezier.empty()) polyline = {e.bottom, e.control_point(0)};
    axis = AxisCurve::make(bezier.empty() ? AxisCurve::Kind::Polyline : AxisCurve::Kind::Bezier,
                           bezier.empty() ? polyline : bezier, error);
    if (!error.empty()) error = "envelope: " + error;
    return error.empty();
}

Made make_envelope(const std::vector<EnvArg>& args, std::string& error) {
    Args a(kEnvelope.name, args, error);
    if (!a.only(
            {"top", "bottom", "px", "pz", "nx", "nz", "top_shape", "bottom_shape", "axis", "bezier", "tip"}))
        return nullptr;
    const EnvArg *t = a.find("top", V), *b = a.find("bottom", V);
    const EnvArg* side[4] = {a.find("px", V), a.find("pz", V), a.find("nx", V), a.find("nz", V)};
    const EnvArg *ct = a.find("top_shape", N), *cb = a.find("bottom_shape", N), *tip = a.find("tip", V);
    if (!a.ok()) return nullptr;
    if (!t || !b || !side[0] || !side[1] || !side[2] || !side[3]) {
        error = "envelope: needs top, bottom and the four widest points px, pz, nx, nz";
        return nullptr;
    }
    Silhouette s;
    std::string why;
    s.envelope = Envelope::make(vec(*t), vec(*b), vec(*side[0]), vec(*side[1]), vec(*side[2]), vec(*side[3]),
                                ct ? ct->v[0] : 2.0, cb ? cb->v[0] : 2.0, why);
    if (!why.empty()) {
        error = "envelope: " + why;
        return nullptr;
    }
    if (!envelope_axis(args, s.envelope, s.axis, error)) return nullptr;
    s.tip = tip ? vec(*tip) : vec(*t);
    return std::make_unique<EnvelopeEnv>(std::move(s));
}

Made make_light(const std::vector<EnvArg>& args, std::string& error) {
    Args a(kLight.name, args, error);
    if (!a.only({"direction", "resolution", "opacity"})) return nullptr;
    const EnvArg *d = a.find("direction", V), *res = a.find("resolution", N), *op = a.find("opacity", N);
    if (!a.ok()) return nullptr;
    glm::dvec3 dir = d ? vec(*d) : glm::dvec3(0, 1, 0);
    int resolution = res ? static_cast<int>(res->v[0]) : 32;
    double opacity = op ? op->v[0] : 0.3;
    if (glm::length(dir) == 0 || resolution < 1 || resolution > 512 || !(opacity >= 0 && opacity <= 1)) {
        error = "light: direction must not be zero, resolution 1 to 512, opacity 0 to 1";
        return nullptr;
    }
    return std::make_unique<Light>(dir, resolution, opacity);
}

// The runtime's kinds: one row each, in the order messages and `plant help env` list them.
struct KindRow {
    const EnvironmentKind* kind;
    Made (*make)(const std::vector<EnvArg>& args, std::string& error);
};
const KindRow kKinds[] = {
    {&kEllipsoid, make_ellipsoid}, {&kEnvelope, make_envelope},   {&kProximity, make_proximity},
    {&kLight, make_light},         {&kObstacles, make_obstacles}, {&climber_kind(), make_climber},
};

} // namespace

EnvironmentFactory runtime_environments() {
    return [](const std::string& kind, const std::vector<EnvArg>& args, std::string& error) -> Made {
        for (const KindRow& row : kKinds)
            if (kind == row.kind->name) return row.make(args, error);
        std::string names;
        for (std::size_t k = 0; k < std::size(kKinds); ++k)
            names += fmt::format("{}{}",
                                 k == 0                       ? ""
                                 : k + 1 == std::size(kKinds) ? " and "
                                                              : ", ",
                                 kKinds[k].kind->name);
        error = fmt::format("unknown environment kind '{}': this version has {}", kind, names);
        return nullptr;
    };
}

std::span<const EnvironmentKind* const> environment_kinds() {
    static const std::vector<const EnvironmentKind*> kinds = [] {
        std::vector<const EnvironmentKind*> v;
        for (const KindRow& row : kKinds) v.push_back(row.kind);
        return v;
    }();
    return kinds;
}

} // namespace plant
