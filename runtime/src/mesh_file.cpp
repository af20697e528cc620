#include "mesh_file.hpp"

#include "plant/source.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string_view>
#include <vector>

namespace plant {

namespace {

// The text's lines, '\r' dropped, '#' comments and blank lines skipped, from `from`.
class Lines {
  public:
    Lines(std::string_view text, std::size_t from) : text_(text), at_(from) {}
    bool next(std::string_view& line) {
        while (at_ < text_.size()) {
            std::size_t e = text_.find('\n', at_);
            if (e == std::string_view::npos) e = text_.size();
            line = text_.substr(at_, e - at_);
            at_ = e + 1;
            while (!line.empty() &&
                   (line.back() == '\r' || std::isspace(static_cast<unsigned char>(line.back()))))
                line.remove_suffix(1);
            std::size_t b = 0;
            while (b < line.size() && std::isspace(static_cast<unsigned char>(line[b]))) ++b;
            line.remove_prefix(b);
            if (!line.empty() && line[0] != '#') return true;
        }
        return false;
    }
    std::size_t at() const { return std::min(at_, text_.size()); }

  private:
    std::string_view text_;
    std::size_t at_;
};

std::vector<std::string_view> words(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        std::size_t b = i;
        while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
        if (i > b) out.push_back(line.substr(b, i - b));
    }
    return out;
}

bool count_of(std::string_view w, std::uint64_t& n) {
    auto r = std::from_chars(w.data(), w.data() + w.size(), n);
    return r.ec == std::errc() && r.ptr == w.data() + w.size();
}

// A vertex's value: a finite number that a float holds (OpenMesh keeps floats; a coordinate
// of 1e39 or nan would reach the meshes as infinities).
bool float_value(std::string_view w) {
    double v = 0;
    if (!w.empty() && w[0] == '+') w.remove_prefix(1);
    auto r = std::from_chars(w.data(), w.data() + w.size(), v);
    return r.ec == std::errc() && std::isfinite(v) && std::fabs(v) <= FLT_MAX;
}

std::string bad_value(const char* what, std::uint64_t row, std::string_view w) {
    return fmt::format("{} {} has '{}', not a finite number within a float's range", what, row,
                       w.substr(0, 40));
}

// What a face's vertex index may be: below `vertices` (0: not checked).
std::string bad_index(const char* what, std::uint64_t row, std::string_view w, std::uint64_t vertices) {
    return fmt::format("{} {} refers to vertex '{}', but the file has {} vertices (numbered from 0)", what,
                       row, w.substr(0, 40), vertices);
}

// An element's lines must each hold its properties; a list's count must fit in its line. With
// `numbers`, each scalar is a float_value; with `vertices` above 0, each list value is a vertex
// index below it.
std::string vet_rows(Lines& lines, std::uint64_t rows, const std::vector<bool>& is_list, const char* what,
                     bool numbers = false, std::uint64_t vertices = 0) {
    std::string_view line;
    for (std::uint64_t r = 0; r < rows; ++r) {
        if (!lines.next(line)) return fmt::format("it ends before its {} {} (found {})", rows, what, r);
        auto w = words(line);
        std::size_t k = 0;
        for (bool list : is_list) {
            if (k >= w.size()) return fmt::format("{} {} has too few values", what, r + 1);
            if (!list) {
                if (numbers && !float_value(w[k])) return bad_value(what, r + 1, w[k]);
                ++k;
                continue;
            }
            std::uint64_t n = 0;
            if (!count_of(w[k], n) || n > w.size() - k - 1)
                return fmt::format("{} {} announces more values than it holds", what, r + 1);
            for (std::size_t j = k + 1; vertices > 0 && j <= k + n; ++j)
                if (std::uint64_t index = 0; !count_of(w[j], index) || index >= vertices)
                    return bad_index(what, r + 1, w[j], vertices);
            k += 1 + static_cast<std::size_t>(n);
        }
    }
    return {};
}

std::string vet_off(const std::string& text) {
    Lines lines(text, 0);
    std::string_view line;
    if (!lines.next(line)) return "it is empty";
    auto w = words(line);
    const std::string_view key = w.empty() ? std::string_view() : w[0];
    if (key.size() < 3 || key.substr(key.size() - 3) != "OFF") return "it does not start with OFF";
    if (std::find(w.begin(), w.end(), "BINARY") != w.end())
        return "binary OFF is not read: write it as ASCII OFF or OBJ";
    const std::string_view prefix = key.substr(0, key.size() - 3);
    if (prefix.find_first_not_of("STCN") != std::string_view::npos)
        return fmt::format("'{}' files are not read: write it as OFF or OBJ", key);
    std::uint64_t nv = 0, nf = 0;
    w.erase(w.begin());
    if (w.empty()) {
        if (!lines.next(line)) return "it has no counts line";
        w = words(line);
    }
    if (w.size() < 2 || !count_of(w[0], nv) || !count_of(w[1], nf))
        return "its counts line is not 'vertices faces edges'";
    // a vertex takes at least "0 0 0\n", a face "0\n": counts beyond the file's size are lies
    if (nv > text.size() / 6 || nf > text.size() / 2 || nv * 6 + nf * 2 > text.size())
        return fmt::format("it announces {} vertices and {} faces, more than its {} bytes hold", nv, nf,
                           text.size());
    std::string_view v;
    for (std::uint64_t i = 0; i < nv; ++i) {
        if (!lines.next(v)) return fmt::format("it ends before its {} vertices (found {})", nv, i);
        const auto c = words(v);
        if (c.size() < 3) return fmt::format("vertex {} has fewer than 3 coordinates", i + 1);
        for (std::size_t k = 0; k < 3; ++k)
            if (!float_value(c[k])) return bad_value("vertex", i + 1, c[k]);
    }
    return vet_rows(lines, nf, {true}, "face", false, nv);
}

std::string vet_ply(const std::string& text) {
    const std::size_t end = text.find("end_header");
    if (text.compare(0, 3, "ply") != 0) return "it does not start with ply";
    if (end == std::string::npos) return "its header has no end_header";
    Lines header(std::string_view(text).substr(0, end), 0);
    struct Element {
        std::string name;
        std::uint64_t count = 0;
        std::vector<bool> is_list;
    };
    std::vector<Element> elements;
    std::string_view line;
    bool ascii = false;
    while (header.next(line)) {
        auto w = words(line);
        if (w[0] == "format") {
            if (w.size() < 2 || w[1] != "ascii")
                return "binary PLY is not read: write it as ASCII PLY or OBJ";
            ascii = true;
        } else if (w[0] == "element") {
            if (w.size() < 3 || !count_of(w[2], elements.emplace_back().count))
                return "an element line has no count";
            elements.back().name = std::string(w[1]);
        } else if (w[0] == "property") {
            if (elements.empty()) return "a property before any element";
            elements.back().is_list.push_back(w.size() > 1 && w[1] == "list");
        }
    }
    if (!ascii) return "its header has no 'format ascii 1.0'";
    // each value takes at least two bytes (a digit and a separator)
    std::uint64_t least = 0;
    for (const auto& e : elements) {
        const std::uint64_t per_row = 2 * std::max<std::size_t>(1, e.is_list.size());
        if (e.count > text.size() / per_row)
            least = text.size() + 1;
        else
            least += e.count * per_row;
        if (least > text.size())
            return fmt::format("it announces {} {} elements, more than its {} bytes hold", e.count, e.name,
                               text.size());
    }
    Lines body(text, text.find('\n', end) == std::string::npos ? text.size() : text.find('\n', end) + 1);
    std::uint64_t vertices = 0;
    for (const auto& e : elements)
        if (e.name == "vertex") vertices = e.count;
    for (const auto& e : elements) {
        const bool vertex = e.name == "vertex", face = e.name == "face";
        if (std::string why = vet_rows(body, e.count, e.is_list, e.name.c_str(), vertex, face ? vertices : 0);
            !why.empty())
            return why;
        if (face && e.count > 0 && vertices == 0) return "it has faces but no vertex element";
    }
    return {};
}

std::string vet_stl(const std::string& text) {
    // binary STL: an 80-byte header, a triangle count, 50 bytes a triangle, nothing more
    if (text.size() >= 84) {
        std::uint32_t n = 0;
        std::memcpy(&n, text.data() + 80, 4);
        if (text.size() == 84 + std::uint64_t{50} * n) {
            // each triangle: a normal and three corners, 12 little-endian floats, then 2 bytes
            for (std::uint64_t t = 0; t < n; ++t)
                for (std::size_t k = 3; k < 12; ++k) {
                    float f = 0;
                    std::memcpy(&f, text.data() + 84 + 50 * t + 4 * k, 4);
                    if (!std::isfinite(f))
                        return fmt::format("triangle {} has a corner that is not a finite number", t + 1);
                }
            return {};
        }
    }
    return "ASCII STL is not read (and a binary STL's size must be 84 + 50 bytes a triangle): write it as "
           "OBJ";
}

void drop_mtllib(std::string& text) {
    std::size_t at = 0;
    while (at < text.size()) {
        std::size_t e = text.find('\n', at);
        if (e == std::string::npos) e = text.size();
        std::size_t b = at;
        while (b < e && (text[b] == ' ' || text[b] == '\t')) ++b;
        if (text.compare(b, 6, "mtllib") == 0) std::fill(text.begin() + b, text.begin() + e, ' ');
        at = e + 1;
    }
}

} // namespace

// An OBJ's vertices (`v x y z`) and its faces' vertex indices (`f a b c`, each `a`, `a/t` or
// `a/t/n`): 1 up to the number of vertices given before the face, or -1 down to minus it.
std::string vet_obj(const std::string& text) {
    Lines lines(text, 0);
    std::string_view line;
    std::uint64_t v = 0, f = 0;
    while (lines.next(line)) {
        const auto w = words(line);
        if (w[0] == "v") {
            ++v;
            if (w.size() < 4) return fmt::format("vertex {} has fewer than 3 coordinates", v);
            for (std::size_t k = 1; k < 4; ++k)
                if (!float_value(w[k])) return bad_value("vertex", v, w[k]);
        } else if (w[0] == "f") {
            ++f;
            for (std::size_t k = 1; k < w.size(); ++k) {
                std::string_view index = w[k].substr(0, w[k].find('/'));
                const bool negative = !index.empty() && index[0] == '-';
                std::uint64_t i = 0;
                if (!count_of(negative ? index.substr(1) : index, i) || i == 0 || i > v)
                    return fmt::format("face {} refers to vertex '{}', but {} vertices come before it "
                                       "(numbered from 1, or from -1 backwards)",
                                       f, w[k].substr(0, 40), v);
            }
        }
    }
    return {};
}

std::string vet_mesh_text(const std::string& ext, std::string& text) {
    if (ext == "obj") {
        drop_mtllib(text);
        return vet_obj(text);
    }
    if (ext == "off") return vet_off(text);
    if (ext == "ply") return vet_ply(text);
    if (ext == "stl") return vet_stl(text);
    return fmt::format("'.{}' files are not read: use .obj, .off, .ply or .stl", ext);
}

MeshRead read_mesh_file(const std::string& path, OpenMeshTriangles& mesh, OpenMesh::IO::Options& options,
                        std::string& why) {
    std::string ext = std::filesystem::path(path).extension().string();
    if (!ext.empty()) ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    std::string text;
    if (ReadFailure f = read_input_file(path, text); f != ReadFailure::None) {
        why = describe(f);
        return f == ReadFailure::Missing ? MeshRead::Failed : MeshRead::Refused;
    }
    why = vet_mesh_text(ext, text);
    if (!why.empty()) return MeshRead::Refused;
    quiet_openmesh();
    if (ext == "stl") options += OpenMesh::IO::Options::Binary;
    std::istringstream in(std::move(text));
    return OpenMesh::IO::read_mesh(mesh, in, ext, options) ? MeshRead::Ok : MeshRead::Failed;
}

} // namespace plant
