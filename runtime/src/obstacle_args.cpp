#include "obstacle_args.hpp"

#include <fmt/format.h>

namespace plant {

bool ObstacleArgs::is_shape(std::string_view key) {
    return key == "sphere" || key == "sphere_radius" || key == "box_min" || key == "box_max" ||
           key == "plane_point" || key == "plane_normal";
}

bool ObstacleArgs::read(const EnvArg& a, std::string& error) {
    const bool want_vec = a.key != "sphere_radius";
    if ((a.type == ValueType::Vec3) != want_vec) {
        error = fmt::format("{}: '{}' must be a {}", kind_, a.key, want_vec ? "vec3" : "number");
        return false;
    }
    const glm::dvec3 v(a.v[0], a.v[1], a.v[2]);
    if (a.key == "sphere")
        centers_.push_back(v);
    else if (a.key == "sphere_radius")
        radii_.push_back(a.v[0]);
    else if (a.key == "box_min")
        box_min_.push_back(v);
    else if (a.key == "box_max")
        box_max_.push_back(v);
    else if (a.key == "plane_point")
        plane_point_.push_back(v);
    else
        plane_normal_.push_back(v);
    return true;
}

bool ObstacleArgs::mesh(const EnvArg& a, std::string& error) const {
    if (a.type == ValueType::String) return true;
    error = fmt::format("{}: 'mesh' is a quoted file name, as in mesh: \"rock.obj\"", kind_);
    return false;
}

bool ObstacleArgs::paired(std::string& error) const {
    if (centers_.size() == radii_.size() && box_min_.size() == box_max_.size() &&
        plane_point_.size() == plane_normal_.size())
        return true;
    error = fmt::format("{}: give each sphere a sphere_radius, each box_min a box_max and each plane_point a "
                        "plane_normal",
                        kind_);
    return false;
}

bool ObstacleArgs::shapes(std::vector<physics::Obstacle>& out, std::string& error) const {
    auto add = [&](physics::Obstacle::Kind kind, const glm::dvec3& first, const glm::dvec3& second) {
        physics::Obstacle o;
        o.kind = kind, o.a = first, o.b = second;
        out.push_back(o);
    };
    for (std::size_t i = 0; i < centers_.size(); ++i)
        add(physics::Obstacle::Sphere, centers_[i], glm::dvec3(radii_[i], 0, 0));
    for (std::size_t i = 0; i < box_min_.size(); ++i)
        add(physics::Obstacle::Box, glm::min(box_min_[i], box_max_[i]), glm::max(box_min_[i], box_max_[i]));
    for (std::size_t i = 0; i < plane_point_.size(); ++i) {
        if (glm::length(plane_normal_[i]) == 0) {
            error = fmt::format("{}: a plane_normal must not be zero", kind_);
            return false;
        }
        add(physics::Obstacle::Plane, plane_point_[i], glm::normalize(plane_normal_[i]));
    }
    return true;
}

} // namespace plant
