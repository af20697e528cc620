#include "plant/export_text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

namespace plant {

namespace {

// A vector as a JSON array, in its own precision (positions double, colors float).
template <class Vec> void json_vec(std::string& out, const Vec& v) {
    fmt::format_to(std::back_inserter(out), "[{},{},{}]", v.x, v.y, v.z);
}

std::string json_string(const std::string& s) {
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

} // namespace

std::string skeleton_json(const Skeleton& sk) {
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
            fmt::format_to(std::back_inserter(out), ",\"module\":{},\"id\":{}}}", json_string(p.module),
                           p.id);
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
    out += "]}\n";
    return out;
}

std::string skeleton_svg(const Skeleton& sk) {
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
    std::string out =
        fmt::format("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"{} {} {} {}\" width=\"800\" "
                    "height=\"{}\">\n",
                    lo_x - margin, -hi_y - margin, w + 2 * margin, h + 2 * margin,
                    static_cast<int>(800 * (h + 2 * margin) / (w + 2 * margin)));
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
