#include "plant/export_text.hpp"

#include <fmt/format.h>

#include <fmt/ranges.h>

#include <algorithm>
#include <limits>
#include <map>

namespace plant {

namespace {

// A vector as a JSON array, in its own precision (positions double, colors float).
template <class Vec> void json_vec(std::string& out, const Vec& v) {
    fmt::format_to(std::back_inserter(out), "[{},{},{}]", v.x, v.y, v.z);
}

std::string json_string(std::string_view s) {
    std::string out = "\"";
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) < 0x20) {
            out += fmt::format("\\u{:04x}", static_cast<int>(c));
            continue;
        }
        out += c;
    }
    return out + "\"";
}

// Every scene prototype reachable from `scene`, each once, in the order first met.
void collect_prototypes(const Scene& scene, std::map<const Scene*, std::size_t>& index,
                        std::vector<std::pair<const Scene*, const SceneSource*>>& out) {
    for (std::size_t k = 0; k < scene.scene_prototypes.size(); ++k) {
        const Scene* p = scene.scene_prototypes[k].get();
        if (!p || index.count(p)) continue;
        index[p] = out.size();
        out.emplace_back(p, k < scene.scene_prototype_sources.size() ? &scene.scene_prototype_sources[k]
                                                                     : nullptr);
        collect_prototypes(*p, index, out);
    }
}

template <class Matrix> void json_matrix(std::string& out, const Matrix& m) {
    out += "[";
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            fmt::format_to(std::back_inserter(out), "{}{}", c || r ? "," : "", m[c][r]);
    out += "]";
}

// The placements of `scene`'s scene prototypes, by index in the collected list.
void json_placements(std::string& out, const Scene& scene, const std::map<const Scene*, std::size_t>& index) {
    out += "[";
    for (std::size_t k = 0; k < scene.scene_instances.size(); ++k) {
        const Instance& i = scene.scene_instances[k];
        const Scene* p =
            i.prototype < scene.scene_prototypes.size() ? scene.scene_prototypes[i.prototype].get() : nullptr;
        auto it = index.find(p);
        fmt::format_to(std::back_inserter(out), "{}{{\"prototype\":{},\"matrix\":", k ? ",\n" : "\n",
                       it == index.end() ? -1 : static_cast<long>(it->second));
        json_matrix(out, i.transform);
        out += "}";
    }
    out += "]";
}

// Placements drawn when `scene` is drawn out in full, its scene prototypes' own counted in.
double placements_drawn(const Scene& scene, std::map<const Scene*, double>& memo) {
    double n = 0;
    for (const Instance& i : scene.scene_instances) {
        const Scene* p =
            i.prototype < scene.scene_prototypes.size() ? scene.scene_prototypes[i.prototype].get() : nullptr;
        if (!p) continue;
        auto it = memo.find(p);
        if (it == memo.end()) it = memo.emplace(p, placements_drawn(*p, memo)).first;
        n += 1 + it->second;
    }
    return n;
}

// The prototypes and placements, appended to the skeleton's JSON object.
void json_instances(std::string& out, const Scene& scene) {
    std::map<const Scene*, std::size_t> index;
    std::vector<std::pair<const Scene*, const SceneSource*>> protos;
    collect_prototypes(scene, index, protos);
    out += ",\"prototypes\":[";
    for (std::size_t k = 0; k < protos.size(); ++k) {
        const SceneSource* src = protos[k].second;
        out += k ? ",\n" : "\n";
        fmt::format_to(std::back_inserter(out),
                       "{{\"instance\":{},\"args\":[{}],\"view_depth\":{},\"placements\":",
                       json_string(src ? src->instance : ""),
                       src ? fmt::format("{}", fmt::join(src->args, ",")) : "", src ? src->view_depth : 0.0);
        json_placements(out, *protos[k].first, index);
        out += "}";
    }
    out += "],\"placements\":";
    json_placements(out, scene, index);
}

} // namespace

std::string scene_prototype_summary(const Scene& scene) {
    if (scene.scene_prototypes.empty()) return {};
    std::map<const Scene*, std::size_t> index;
    std::vector<std::pair<const Scene*, const SceneSource*>> protos;
    collect_prototypes(scene, index, protos);
    std::map<const Scene*, double> memo;
    return fmt::format("scene prototypes {}\nscene placements {}\nplacements drawn {}\n", protos.size(),
                       scene.scene_instances.size(), placements_drawn(scene, memo));
}

std::string skeleton_json(const Skeleton& sk, const Scene* scene) {
    std::string out = "{\"format\":\"plant-skeleton\",\"version\":1,\"axes\":[";
    for (std::size_t a = 0; a < sk.axes.size(); ++a) {
        const SkeletonAxis& axis = sk.axes[a];
        out += a ? ",\n" : "\n";
        fmt::format_to(std::back_inserter(out), "{{\"parent\":{},\"points\":[", axis.parent);
        for (std::size_t k = 0; k < axis.points.size(); ++k) {
            const SkeletonPoint& p = axis.points[k];
            out += k ? "," : "";
            out += "{\"position\":";
            json_vec(out, p.position);
            out += ",\"heading\":";
            json_vec(out, p.heading);
            out += ",\"left\":";
            json_vec(out, p.left);
            out += ",\"up\":";
            json_vec(out, p.up);
            fmt::format_to(std::back_inserter(out), ",\"radius\":{},\"color\":", p.radius);
            json_vec(out, p.color);
            fmt::format_to(std::back_inserter(out), ",\"module\":{},\"id\":{}}}",
                           json_string(sk.module_name(p)), p.id);
        }
        out += "]}";
    }
    out += "],\"organs\":[";
    for (std::size_t o = 0; o < sk.organs.size(); ++o) {
        const SkeletonOrgan& g = sk.organs[o];
        out += o ? ",\n" : "\n";
        fmt::format_to(std::back_inserter(out), "{{\"shape\":{},\"matrix\":[",
                       json_string(organ_label(g.shape)));
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                fmt::format_to(std::back_inserter(out), "{}{}", c || r ? "," : "", g.transform[c][r]);
        out += "],\"color\":";
        json_vec(out, g.color);
        fmt::format_to(std::back_inserter(out), ",\"id\":{}}}", g.id);
    }
    out += "]";
    if (scene && !scene->scene_prototypes.empty()) json_instances(out, *scene);
    out += "}\n";
    return out;
}

std::string skeleton_svg(const Skeleton& sk, const SvgOptions& options) {
    double lo_x = std::numeric_limits<double>::max(), lo_y = lo_x, hi_x = -lo_x, hi_y = -lo_x;
    for (const auto& a : sk.axes)
        for (const auto& p : a.points) {
            lo_x = std::min(lo_x, p.position.x);
            hi_x = std::max(hi_x, p.position.x);
            lo_y = std::min(lo_y, p.position.y);
            hi_y = std::max(hi_y, p.position.y);
        }
    if (lo_x > hi_x) lo_x = lo_y = hi_x = hi_y = 0;
    double w = std::max(hi_x - lo_x, 1e-6), h = std::max(hi_y - lo_y, 1e-6);
    double margin = 0.05 * std::max(w, h);
    double stroke = 0.003 * std::max(w, h);
    const int width = std::max(options.width, 1);
    const int height =
        options.height > 0 ? options.height : static_cast<int>(width * (h + 2 * margin) / (w + 2 * margin));
    // the default preserveAspectRatio (xMidYMid meet) fits the view box inside, centred
    std::string out =
        fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"{}\" "
                    "height=\"{}\">\n",
                    lo_x - margin, -hi_y - margin, w + 2 * margin, h + 2 * margin, width, height);
    out += "<rect x=\"-1e9\" y=\"-1e9\" width=\"2e9\" height=\"2e9\" fill=\"white\"/>\n";
    for (const auto& a : sk.axes) {
        if (a.points.size() < 2) continue;
        out += fmt::format("<polyline fill=\"none\" stroke=\"rgb({},{},{})\" stroke-width=\"{}\" "
                           "stroke-linecap=\"round\" stroke-linejoin=\"round\" points=\"",
                           static_cast<int>(a.points.back().color.x * 255),
                           static_cast<int>(a.points.back().color.y * 255),
                           static_cast<int>(a.points.back().color.z * 255), stroke);
        for (const auto& p : a.points) out += fmt::format("{},{} ", p.position.x, -p.position.y);
        out += "\"/>\n";
    }
    out += "</svg>\n";
    return out;
}

void write_skeleton_json(const Skeleton& s, const std::string& path) {
    write_file_atomically(path, skeleton_json(s));
}
void write_svg(const Skeleton& s, const std::string& path) {
    write_file_atomically(path, skeleton_svg(s));
}

} // namespace plant
