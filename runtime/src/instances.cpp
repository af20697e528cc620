// Instances in the scene (docs/language.md, instances and level of detail): every instance the
// turtle placed is derived, interpreted and meshed once per (instance, argument tuple, view
// depth) into a scene prototype, which each placement puts in place by transform (Yan & Chiba,
// section 3.2: object instancing). Instances placed inside an instance are meshed into its
// prototype the same way, sharing the one memo.
#include "plant/instances.hpp"
#include "plant/environment_phase.hpp"
#include "plant/mesh.hpp"
#include "plant/skeleton.hpp"

#include "scene_build.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <optional>

namespace plant {

namespace {

constexpr std::uint64_t kDefaultInstanceMemory = std::uint64_t{4} << 30;

double bytes_of(const MeshPart& m) {
    return double(m.positions.size()) * 32.0 + double(m.indices.size()) * 4.0;
}

// A param of the program as compiled (after -D and import overrides), or `fallback`. Instances
// see every param so (docs/language.md, instances: visibility): a hook's assignment in the outer
// derivation does not reach them, view_depth and max_view_depth included.
double param_value(const Program& p, const char* name, double fallback) {
    auto it = p.global_index.find(name);
    if (it == p.global_index.end()) return fallback;
    const std::uint32_t slot = p.globals[it->second].slot;
    return slot < p.global_values.size() ? p.global_values[slot] : fallback;
}

class InstanceBuilder {
  public:
    InstanceBuilder(const Program& root, const MeshOptions& options) : opt_(options) {
        const Derivation* d = options.derivation;
        if (d) {
            seed_ = d->seed();
            derive_ = d->options();
        }
        derive_.steps.reset(); // each body has its own `derive N;`
        derive_.seed.reset();
        derive_.on_step = nullptr;
        // instances are derived apart from the outer plant's environments; their query modules
        // see the instance's own turtle
        derive_.environment_phase = &phase_;
        view_depth_ = param_value(root, "view_depth", 0.0);
        max_view_depth_ = param_value(root, "max_view_depth", 20.0);
        depth_unit_ = param_value(root, "depth_unit", 0.0);
        budget_ = double(options.max_memory ? options.max_memory : kDefaultInstanceMemory);
    }

    // The scene of one skeleton with its instances placed. `level`: the view depth its placements
    // inherit (none: the top level, where the camera may decide).
    Scene build(const Program& program, const Skeleton& skeleton, std::optional<double> level) {
        Scene scene = detail::mesh_skeleton(program, skeleton, opt_);
        std::map<const Made*, std::uint32_t> local;
        for (const SkeletonOrgan& organ : skeleton.organs) {
            if (organ.shape.kind != OrganKind::Instance) continue;
            const double at = level ? *level : top_level(organ.transform);
            const Made& made = make(program, organ.shape, at);
            auto [it, added] =
                local.emplace(&made, static_cast<std::uint32_t>(scene.scene_prototypes.size()));
            if (added) {
                scene.scene_prototypes.push_back(made.scene);
                scene.scene_prototype_names.push_back(made.name);
                scene.scene_prototype_sources.push_back(made.source);
            }
            scene.scene_instances.push_back(Instance{it->second, glm::mat4(organ.transform)});
        }
        return scene;
    }

    std::size_t derivations() const { return derivations_; }

    // What the scene would take flattened (the exporters that bake everything do): refused past
    // the budget, before anything is flattened.
    double check_flattened(const Scene& scene) const {
        const double bytes = flat_size(scene);
        if (bytes > budget_) memory_error("drawn out in full, the plant's instances", bytes);
        return bytes;
    }

    // The scene's bounds: exact (every point placed) while that is cheap, else the box around its
    // placed scene prototypes' boxes, which holds every point too. Cheap: few bytes and few
    // placements drawn out (placements of instances that draw nothing cost time all the same).
    void set_bounds(Scene& scene, double bytes, double drawn_placements) const {
        constexpr double kExactBoundsBytes = 64.0 * 1024 * 1024, kExactBoundsPlacements = 1 << 20;
        if ((bytes <= kExactBoundsBytes && drawn_placements <= kExactBoundsPlacements) || !scene.nested()) {
            scene.update_bounds();
            return;
        }
        glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
        auto add = [&](const glm::vec3& p) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        };
        for (const auto& p : scene.tubes.positions) add(p);
        for (const auto& inst : scene.instances)
            for (const auto& p : scene.prototypes[inst.prototype].positions)
                add(glm::vec3(inst.transform * glm::vec4(p, 1.0f)));
        for (const Instance& i : scene.scene_instances) {
            const Scene& p = *scene.scene_prototypes[i.prototype];
            if (flat_bytes(&p) == 0) continue; // draws nothing: its bounds are no point of the plant
            for (int c = 0; c < 8; ++c)
                add(glm::vec3(i.transform * glm::vec4((c & 1) ? p.bounds_max.x : p.bounds_min.x,
                                                      (c & 2) ? p.bounds_max.y : p.bounds_min.y,
                                                      (c & 4) ? p.bounds_max.z : p.bounds_min.z, 1.0f)));
        }
        if (lo.x > hi.x) lo = hi = glm::vec3(0.0f);
        scene.bounds_min = lo;
        scene.bounds_max = hi;
    }

    // How many placements `scene` draws out, at every level.
    double placements_of(const Scene& scene) const {
        double n = double(scene.instances.size());
        for (const Instance& i : scene.scene_instances) {
            auto it = placements_.find(scene.scene_prototypes[i.prototype].get());
            n += 1 + (it == placements_.end() ? 0.0 : it->second);
        }
        return n;
    }

    // What `scene` would take with every placement drawn out.
    double flat_size(const Scene& scene) const {
        double bytes = bytes_of(scene.tubes);
        for (const Instance& i : scene.instances) bytes += bytes_of(scene.prototypes[i.prototype]);
        for (const Instance& i : scene.scene_instances)
            bytes += flat_bytes(scene.scene_prototypes[i.prototype].get());
        return bytes;
    }

  private:
    struct Made {
        std::shared_ptr<const Scene> scene;
        std::string name; // Branch(12) or Branch(12)@5
        SceneSource source;
        double flat_bytes = 0; // its geometry with every placement inside it drawn out
    };

    double flat_bytes(const Scene* s) const {
        auto it = flat_.find(s);
        return it == flat_.end() ? 0.0 : it->second;
    }

    [[noreturn]] void memory_error(const char* what, double bytes) const {
        throw RuntimeError(RuntimeErrorKind::Memory, Span{},
                           fmt::format("{} would take about {:.1f} GB but --max-memory allows {:.1f} GB: "
                                       "place fewer instances or fewer distinct ones, or raise --max-memory",
                                       what, bytes / 1e9, budget_ / 1e9));
    }

    // Per-placement level of detail: the view depth of a placement at `transform`'s origin.
    double top_level(const glm::dmat4& transform) const {
        if (!opt_.camera || !(depth_unit_ > 0)) return view_depth_;
        const double d = glm::distance(glm::dvec3(transform[3]), *opt_.camera) / depth_unit_;
        return std::clamp(std::round(d), 0.0, std::max(0.0, max_view_depth_));
    }

    const Made& make(const Program& program, const OrganShape& shape, double level) {
        using Key = std::tuple<int, std::vector<std::uint64_t>, std::uint64_t>;
        Key key{shape.instance, {}, std::bit_cast<std::uint64_t>(level == 0 ? 0.0 : level)};
        for (double a : shape.args)
            std::get<1>(key).push_back(std::bit_cast<std::uint64_t>(a == 0 ? 0.0 : a));
        if (auto it = memo_.find(key); it != memo_.end()) return it->second;
        if (!program.instances || shape.instance < 0 ||
            static_cast<std::size_t>(shape.instance) >= program.instances->size())
            throw RuntimeError(RuntimeErrorKind::Geometry, Span{},
                               fmt::format("'{}' places an instance the program does not have", shape.name));
        const InstanceDef& def = (*program.instances)[static_cast<std::size_t>(shape.instance)];
        Made made;
        made.name = organ_label(shape) + (level == 0 ? "" : "@" + format_double(level));
        made.source = SceneSource{shape.name, shape.args, level};
        if (++derivations_ > opt_.max_instance_derivations)
            throw RuntimeError(RuntimeErrorKind::Memory, def.span,
                               fmt::format("the plant needs more than {} distinct instance derivations (one "
                                           "per instance, argument tuple and view depth; the last was {}): "
                                           "round the arguments to fewer distinct values",
                                           opt_.max_instance_derivations, made.name));
        if (derive_.interrupt && derive_.interrupt->load())
            throw RuntimeError(RuntimeErrorKind::Interrupted, Span{}, "interrupted while deriving instances");
        // all instance derivations together may reach --max-modules once: each gets what is left
        DeriveOptions o = derive_;
        o.max_modules = derive_.max_modules > modules_ ? derive_.max_modules - modules_ : 1;
        Derivation d = instance_derivation(def, shape.instance, shape.args, level, seed_, std::move(o));
        try {
            d.run();
        } catch (RuntimeError& e) {
            e.message = fmt::format("instance {}{}: {}", made.name,
                                    e.kind == RuntimeErrorKind::ModuleLimit && modules_ > 0
                                        ? " (with the instances before it)"
                                        : "",
                                    e.message);
            throw;
        }
        modules_ += d.string().size();
        // what the derivation took, while it lives: its string, then the skeleton
        used_ += double(d.string().size()) * 16.0;
        if (used_ > budget_) memory_error("deriving the instances", used_);
        Skeleton skeleton;
        try {
            skeleton = build_skeleton(*def.program, d.interpreted(d.string()), turtle_options(d));
        } catch (RuntimeError& e) { // the module count is of the instance's own string
            e.message = fmt::format("instance {}: {}", made.name, e.message);
            throw;
        }
        std::uint64_t points = 0;
        for (const auto& a : skeleton.axes) points += a.points.size();
        used_ += double(points) * double(std::max(opt_.sides, 3) + 1) * 44.0 +
                 256.0 * double(skeleton.organs.size());
        if (used_ > budget_) memory_error("meshing the instances", used_);
        Scene scene = build(*def.program, skeleton, level);
        double own = bytes_of(scene.tubes);
        for (const auto& p : scene.prototypes) own += bytes_of(p);
        used_ += own - double(d.string().size()) * 16.0; // the string is freed with the derivation
        made.flat_bytes = flat_size(scene);
        if (made.flat_bytes > budget_)
            memory_error(fmt::format("drawn out in full, instance {}", made.name).c_str(), made.flat_bytes);
        const double placements = placements_of(scene);
        set_bounds(scene, made.flat_bytes, placements);
        detail::check_single_precision(scene);
        made.scene = std::make_shared<const Scene>(std::move(scene));
        flat_[made.scene.get()] = made.flat_bytes;
        placements_[made.scene.get()] = placements;
        return memo_.emplace(std::move(key), std::move(made)).first->second;
    }

    const MeshOptions& opt_;
    TurtleEnvironmentPhase phase_;
    std::uint64_t seed_ = 0;
    DeriveOptions derive_;
    double view_depth_ = 0, max_view_depth_ = 20, depth_unit_ = 0;
    double budget_ = 0, used_ = 0;
    std::size_t derivations_ = 0;
    std::size_t modules_ = 0; // in the strings of every instance derivation so far
    std::map<std::tuple<int, std::vector<std::uint64_t>, std::uint64_t>, Made> memo_;
    std::map<const Scene*, double> flat_;       // per prototype: Made::flat_bytes
    std::map<const Scene*, double> placements_; // per prototype: the placements it draws out
};

} // namespace

Scene build_scene(const Program& program, const Skeleton& skeleton, const MeshOptions& options) {
    InstanceBuilder builder(program, options);
    Scene scene = builder.build(program, skeleton, std::nullopt);
    scene.instance_derivations = builder.derivations();
    builder.set_bounds(scene, builder.check_flattened(scene), builder.placements_of(scene));
    detail::check_single_precision(scene);
    return scene;
}

} // namespace plant
