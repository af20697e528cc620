// Silhouettes of branching systems (Boudon et al. 2003, sections 2.4 and 3): an axis curve,
// Cescatti's asymmetric crown envelope and the control point T, and the placement of a child
// silhouette inside its parent's (Fig. 8). Pure geometry: no program, no derivation. The
// `envelope` environment kind (runtime/src/environments.cpp) and the decomposition graph's
// silhouette parameters both compute with it.
#pragma once

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace plant {

// Cescatti's asymmetric crown envelope (Boudon et al. 2003, Fig. 6): P1 the top, P2 the bottom,
// P3 and P5 the widest points on the +x and -x sides, P4 and P6 on the +z and -z sides (each at
// its own height), C1 and C2 the shapes above and below the peripheral line. Radii are measured
// from the vertical through the bottom point, so only the heights of the top and of the four
// widest points count (and the x or z of a widest point on its own side). Between two
// neighbouring widest points the peripheral line is a quarter ellipse; above it the crown is the
// superellipse (r/R)^C1 + ((y - Y)/(top - Y))^C1 = 1, below it the same with C2.
struct Envelope {
    glm::dvec3 top{0, 1, 0}, bottom{0.0};
    double radius[4] = {1, 1, 1, 1}; // +x, +z, -x, -z, from the vertical through the bottom point
    double height[4] = {0.5, 0.5, 0.5, 0.5};
    double c_top = 2, c_bottom = 2;

    // An envelope from its six control points and two shape coefficients; an empty `error`
    // when they make one (each widest point on its own side of the vertical through the bottom
    // point and strictly between the bottom's and the top's heights, positive coefficients).
    static Envelope make(const glm::dvec3& top, const glm::dvec3& bottom, const glm::dvec3& px,
                         const glm::dvec3& pz, const glm::dvec3& nx, const glm::dvec3& nz, double c_top,
                         double c_bottom, std::string& error);

    // How far out p is: below 1 inside, 1 on the envelope, 1e300 above the top, below the
    // bottom or for a point that is not finite.
    double level(const glm::dvec3& p) const;
    bool contains(const glm::dvec3& p) const { return level(p) <= 1.0; }
    // The distance from p along the direction d (any length but zero) to where the ray first
    // leaves the envelope; 0 when p is outside or d is zero or not finite. Samples the ray every
    // 1/128 of its chord through the envelope's box, then bisects the first step that leaves.
    // Remembers its last answers (per thread, keyed on every bit of the envelope and the ray),
    // so asking again costs a lookup; reach_uncached always computes.
    double reach(const glm::dvec3& p, const glm::dvec3& d) const;
    double reach_uncached(const glm::dvec3& p, const glm::dvec3& d) const;
    // The box holding the envelope.
    glm::dvec3 lo() const;
    glm::dvec3 hi() const;
    // The six control points P1..P6 as the envelope sees them: the top on the vertical through
    // the bottom, then the bottom, +x, +z, -x, -z. Each has level 1.
    glm::dvec3 control_point(int k) const;
};

// A silhouette's axis: a polyline through its points (parametrized by arc length) or the
// Bezier curve with them as control points, t in [0, 1] (clamped).
struct AxisCurve {
    enum class Kind { Polyline, Bezier };
    Kind kind = Kind::Polyline;
    std::vector<glm::dvec3> points;

    // An axis of at least two points that are not all the same and all finite; an empty `error`
    // when it is one.
    static AxisCurve make(Kind kind, std::vector<glm::dvec3> points, std::string& error);
    glm::dvec3 point(double t) const;
    // The unit tangent at t (for a Bezier curve whose derivative vanishes there, the direction
    // it leaves in; failing that, the chord from the first point to the last).
    glm::dvec3 heading(double t) const;
    double length() const; // of the polyline; of the control polygon for a Bezier curve
};

// A silhouette in its own coordinates: its axis (B = axis.point(0) is its base), its envelope
// and the control point T that places it inside its parent's.
struct Silhouette {
    AxisCurve axis;
    Envelope envelope;
    glm::dvec3 tip{0, 1, 0};
    glm::dvec3 base() const { return axis.point(0); }
};

// A similarity: world = translation + scale * rotation * local (rotation a proper rotation,
// scale > 0).
struct Placement {
    glm::dvec3 translation{0.0};
    glm::dmat3 rotation{1.0};
    double scale = 1;

    glm::dvec3 to_world(const glm::dvec3& local) const { return translation + scale * (rotation * local); }
    glm::dvec3 to_local(const glm::dvec3& world) const {
        return (glm::transpose(rotation) * (world - translation)) / scale;
    }
    glm::dvec3 direction_to_world(const glm::dvec3& d) const { return rotation * d; }
    glm::dvec3 direction_to_local(const glm::dvec3& d) const { return glm::transpose(rotation) * d; }
};

// A silhouette under a placement, asked in world coordinates.
struct PlacedSilhouette {
    const Silhouette* silhouette = nullptr;
    Placement placement;

    double level(const glm::dvec3& p) const { return silhouette->envelope.level(placement.to_local(p)); }
    bool contains(const glm::dvec3& p) const { return level(p) <= 1.0; }
    // Remembers its last answers (per thread, keyed on every bit of the envelope and the ray),
    // so asking again costs a lookup; reach_uncached always computes.
    double reach(const glm::dvec3& p, const glm::dvec3& d) const;
    double reach_uncached(const glm::dvec3& p, const glm::dvec3& d) const;
    glm::dvec3 axis(double t) const { return placement.to_world(silhouette->axis.point(t)); }
    glm::dvec3 heading(double t) const { return placement.direction_to_world(silhouette->axis.heading(t)); }
    glm::dvec3 base() const { return placement.to_world(silhouette->base()); }
    glm::dvec3 tip() const { return placement.to_world(silhouette->tip); }
};

// The placement of a child silhouette inside its parent's (Boudon et al. 2003, section 3 and
// Fig. 8): B at `base`, the vector BT turned onto `dir` and the child scaled so that T lies on the
// parent's placed envelope, where the ray from base along dir leaves it. The rotation is the
// parent's followed by the smallest rotation that takes BT (as the parent's rotation turns it)
// onto dir, so the child keeps its parent's roll about the branch; when BT points straight
// against dir, the half turn is about the parent's frame axis most nearly perpendicular to it.
struct ChildPlacement {
    Placement placement;
    double reach = 0;  // |base T| after placement: the ray's length inside the parent
    std::string error; // empty when placed
    bool ok() const { return error.empty(); }
};
ChildPlacement place_child(const Silhouette& parent, const Placement& parent_placement,
                           const Silhouette& child, const glm::dvec3& base, const glm::dvec3& dir);

// The smallest rotation taking the unit vector a onto the unit vector b (a half turn about an
// axis perpendicular to a, chosen from `frame`'s columns, when b = -a).
glm::dmat3 minimal_rotation(const glm::dvec3& a, const glm::dvec3& b, const glm::dmat3& frame);

} // namespace plant
