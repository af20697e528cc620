// PNG preview: a small software rasterizer (orthographic 3/4 view, or a perspective camera the
// user places; z-buffer, Gouraud-shaded two-sided Lambert lighting, 2x2 supersampling) and the PNG
// writer on top of it.
// A textured material is drawn in its image's average colour (texture_image.hpp).
//
// Triangles are set up in 28.4 fixed point with exact 64-bit edge functions and a consistent
// tie-breaking rule, so meshes are watertight (no background speckles along shared edges) and
// every sample is covered at most once per mesh surface. Depth and intensity are interpolated
// as float planes. The PNG bytes come from stb_image_write; on Debian its symbols live in
// libstb (link with -lstb, do not define STB_IMAGE_WRITE_IMPLEMENTATION here).

#include "plant/export.hpp"
#include "plant/raster.hpp"

#include "png_camera.hpp"
#include "texture_image.hpp"

#include "plant/skeleton.hpp"

#include <fmt/format.h>
#include <glm/glm.hpp>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <new>
#include <string>
#include <vector>

namespace plant {
namespace {

using detail::Camera;
using detail::finite3;

constexpr float kAmbient = 0.24f;
constexpr float kKey = 0.66f;  // directional light from above, left of the viewer
constexpr float kFill = 0.16f; // a weak headlight so faces turned from the key are not flat
constexpr int kSubBits = 4;    // fixed-point subsample precision: 1/16 sample
constexpr int kSub = 1 << kSubBits;
constexpr double kGuard = double(1 << 20); // screen coordinates are clamped to +-this (samples)
constexpr std::int64_t kMaxPixels = std::int64_t(64) << 20;
constexpr std::int64_t kMaxSupersampledPixels = std::int64_t(4) << 20; // 2048 x 2048 output
// How many times over the triangles may cover the image (rows and samples visited per sample)
// before the preview is given up: a few seconds of drawing. Shipped grammars stay far below.
constexpr std::int64_t kMaxOverdraw = 400;
constexpr int kLutSize = 4096;

struct ScreenVertex {
    std::int32_t x = 0, y = 0;  // fixed point, 1/kSub sample
    float z = 0.0f;             // depth, larger is nearer
    float nl = 0.0f, nv = 0.0f; // dot(normal, light), dot(normal, toward); NaN: no usable normal
    bool ok = false;
};

struct Raster {
    int width = 0, height = 0;
    std::vector<float> depth;
    std::vector<std::uint8_t> rgb; // sRGB samples
    std::array<std::uint8_t, kLutSize> encode{};
    // Rows and samples the rasterizer may still visit. Each triangle is clipped to the image, but
    // many large triangles on top of each other (262,144 leaves, each the size of the view) would
    // still take minutes; past the budget the preview is given up (kMaxOverdraw).
    std::int64_t budget = 0;
};

std::uint8_t linear_to_srgb8(double v) {
    v = std::clamp(v, 0.0, 1.0);
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(s * 255.0));
}

double srgb8_to_linear(int c) {
    const double s = c / 255.0;
    return s <= 0.04045 ? s / 12.92 : std::pow((s + 0.055) / 1.055, 2.4);
}

// floor(a / b) and ceil(a / b) for b > 0.
std::int64_t floor_div(std::int64_t a, std::int64_t b) {
    return a >= 0 ? a / b : -((-a + b - 1) / b);
}
std::int64_t ceil_div(std::int64_t a, std::int64_t b) {
    return -floor_div(-a, b);
}

// Twice the signed area of (a, b, p) in fixed point; positive when p is on the inner side of
// a->b for a positively oriented triangle.
inline std::int64_t orient(std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by,
                           std::int64_t px, std::int64_t py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

// Edges take samples exactly on them only for one of their two directions, so two triangles
// sharing an edge never both skip (or both take) a sample on it.
inline std::int64_t edge_bias(std::int64_t ax, std::int64_t ay, std::int64_t bx, std::int64_t by) {
    const std::int64_t dy = by - ay, dx = bx - ax;
    return (dy > 0 || (dy == 0 && dx < 0)) ? 0 : -1;
}

// Narrows [kmin, kmax] to the k with w + a * k >= 0; false if that leaves nothing.
inline bool clip_span(std::int64_t w, std::int64_t a, std::int64_t& kmin, std::int64_t& kmax) {
    if (a > 0) {
        if (w < 0) kmin = std::max(kmin, ceil_div(-w, a));
    } else if (a < 0) {
        if (w < 0) return false;
        kmax = std::min(kmax, floor_div(w, -a));
    } else if (w < 0) {
        return false;
    }
    return kmin <= kmax;
}

struct ShadedVertex {
    std::int64_t x, y;
    float z, t; // depth, light intensity
};

void fill_triangle(Raster& r, ShadedVertex a, ShadedVertex b, ShadedVertex c,
                   const std::array<float, 3>& color_lut_scale) {
    std::int64_t area = orient(a.x, a.y, b.x, b.y, c.x, c.y);
    if (area == 0) return;
    if (area < 0) {
        std::swap(b, c);
        area = -area;
    }
    const std::int64_t minx = std::min({a.x, b.x, c.x}), maxx = std::max({a.x, b.x, c.x});
    const std::int64_t miny = std::min({a.y, b.y, c.y}), maxy = std::max({a.y, b.y, c.y});
    // Sample (i, j) sits at fixed (i * kSub + kSub / 2, j * kSub + kSub / 2).
    const std::int64_t x0 = std::max<std::int64_t>(0, ceil_div(minx - kSub / 2, kSub));
    const std::int64_t x1 = std::min<std::int64_t>(r.width - 1, floor_div(maxx - kSub / 2, kSub));
    const std::int64_t y0 = std::max<std::int64_t>(0, ceil_div(miny - kSub / 2, kSub));
    const std::int64_t y1 = std::min<std::int64_t>(r.height - 1, floor_div(maxy - kSub / 2, kSub));
    if (x0 > x1 || y0 > y1) return;

    // Edge functions at the first sample, and their steps per sample in x and y.
    const std::int64_t px = x0 * kSub + kSub / 2, py = y0 * kSub + kSub / 2;
    std::int64_t w0row = orient(b.x, b.y, c.x, c.y, px, py) + edge_bias(b.x, b.y, c.x, c.y);
    std::int64_t w1row = orient(c.x, c.y, a.x, a.y, px, py) + edge_bias(c.x, c.y, a.x, a.y);
    std::int64_t w2row = orient(a.x, a.y, b.x, b.y, px, py) + edge_bias(a.x, a.y, b.x, b.y);
    const std::int64_t a0 = -(c.y - b.y) * kSub, b0 = (c.x - b.x) * kSub;
    const std::int64_t a1 = -(a.y - c.y) * kSub, b1 = (a.x - c.x) * kSub;
    const std::int64_t a2 = -(b.y - a.y) * kSub, b2 = (b.x - a.x) * kSub;

    // Depth and intensity planes, per sample.
    const double e1x = double(b.x - a.x) / kSub, e1y = double(b.y - a.y) / kSub;
    const double e2x = double(c.x - a.x) / kSub, e2y = double(c.y - a.y) / kSub;
    const double det = e1x * e2y - e2x * e1y; // > 0
    const double dz1 = double(b.z) - a.z, dz2 = double(c.z) - a.z;
    const double dt1 = double(b.t) - a.t, dt2 = double(c.t) - a.t;
    const double dzdx = (dz1 * e2y - dz2 * e1y) / det, dzdy = (dz2 * e1x - dz1 * e2x) / det;
    const double dtdx = (dt1 * e2y - dt2 * e1y) / det, dtdy = (dt2 * e1x - dt1 * e2x) / det;
    const double ox = double(px) / kSub - double(a.x) / kSub;
    const double oy = double(py) / kSub - double(a.y) / kSub;
    const double zrow0 = a.z + dzdx * ox + dzdy * oy;
    const double trow0 = a.t + dtdx * ox + dtdy * oy;
    const float fdzdx = float(dzdx), fdtdx = float(dtdx);

    const float cr = color_lut_scale[0], cg = color_lut_scale[1], cb = color_lut_scale[2];
    const std::uint8_t* lut = r.encode.data();
    const std::int64_t last = x1 - x0;
    for (std::int64_t y = y0; y <= y1; ++y) {
        const std::int64_t w0 = w0row, w1 = w1row, w2 = w2row;
        w0row += b0;
        w1row += b1;
        w2row += b2;
        // The samples k = 0..last of this row where every edge function is >= 0, solved exactly
        // rather than tested one by one (long slivers have huge, nearly empty bounding boxes).
        std::int64_t kmin = 0, kmax = last;
        --r.budget;
        if (!clip_span(w0, a0, kmin, kmax) || !clip_span(w1, a1, kmin, kmax) ||
            !clip_span(w2, a2, kmin, kmax))
            continue;
        r.budget -= kmax - kmin;
        const double dx = double(kmin), dy = double(y - y0);
        float z = float(zrow0 + dzdx * dx + dzdy * dy);
        float t = float(trow0 + dtdx * dx + dtdy * dy);
        float* zline = r.depth.data() + y * r.width + x0;
        std::uint8_t* cline = r.rgb.data() + (y * r.width + x0) * 3;
        for (std::int64_t k = kmin; k <= kmax; ++k) {
            if (z > zline[k]) {
                zline[k] = z;
                const float tt = std::clamp(t, 0.0f, 1.0f);
                std::uint8_t* px3 = cline + k * 3;
                px3[0] = lut[int(cr * tt + 0.5f)];
                px3[1] = lut[int(cg * tt + 0.5f)];
                px3[2] = lut[int(cb * tt + 0.5f)];
            }
            z += fdzdx;
            t += fdtdx;
        }
    }
}

float clamp01(float v) {
    return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f;
}

// `colors`: per material, what it is drawn in (a texture's average colour, detail::flat_colors).
std::array<float, 3> lut_scale_for(const std::vector<glm::vec3>& colors, std::uint32_t material) {
    glm::vec3 c = Material{}.color;
    if (material < colors.size())
        c = colors[material];
    else if (!colors.empty())
        c = colors.front();
    const float s = float(kLutSize - 1);
    return {clamp01(c.r) * s, clamp01(c.g) * s, clamp01(c.b) * s};
}

// A vertex in a perspective camera's view coordinates (right, up, depth), with its lighting terms.
struct ViewVertex {
    glm::dvec3 p{0.0};
    float nl = 0.0f, nv = 0.0f; // as ScreenVertex
    bool ok = false;
};

struct Renderer {
    const Scene& scene;
    Raster& raster;
    const Camera& cam;
    glm::dvec3 light_view; // the light in (right, up, toward) coordinates
    std::vector<ScreenVertex> verts;
    std::vector<ViewVertex> view_verts; // for a perspective camera
    std::vector<glm::vec3> colors;      // per material: detail::flat_colors

    // Transforms the part's vertices (by `model` first, if given) to a perspective camera's view.
    void transform_perspective(const MeshPart& part, const glm::dmat4* model) {
        const glm::dmat4 m = model ? *model : glm::dmat4(1.0);
        glm::dmat3 normal_mat = glm::transpose(glm::inverse(glm::dmat3(m)));
        bool normals_ok = part.normals.size() == part.positions.size();
        for (int i = 0; i < 3; ++i)
            if (!finite3(normal_mat[i])) normals_ok = false;
        const float nan = std::numeric_limits<float>::quiet_NaN();
        view_verts.resize(part.positions.size());
        for (std::size_t i = 0; i < part.positions.size(); ++i) {
            ViewVertex& v = view_verts[i];
            const glm::dvec3 world = glm::dvec3(m * glm::dvec4(glm::dvec3(part.positions[i]), 1.0));
            const glm::dvec3 rel = world - cam.eye;
            v.p = glm::dvec3(glm::dot(rel, cam.right), glm::dot(rel, cam.up), -glm::dot(rel, cam.toward));
            v.ok = finite3(v.p);
            v.nl = v.nv = nan;
            if (!v.ok || !normals_ok) continue;
            const glm::dvec3 n = normal_mat * glm::dvec3(part.normals[i]);
            const double len = glm::length(n), dist = glm::length(rel);
            if (std::isfinite(len) && len > 1e-10 && dist > 0.0) {
                v.nl = float(glm::dot(n, cam.light) / len);
                v.nv = float(-glm::dot(n, rel) / (len * dist)); // toward the eye
            }
        }
    }

    // Transforms the part's vertices (by `model` first, if given) to screen space.
    void transform(const MeshPart& part, const glm::dmat4* model) {
        if (cam.perspective) {
            transform_perspective(part, model);
            return;
        }
        // screen = R * (M p) + o, with R's rows scale * right, -scale * up, toward.
        glm::dmat3 view_rows(cam.scale * cam.right, -cam.scale * cam.up, cam.toward);
        const glm::dmat3 view = glm::transpose(view_rows); // columns -> rows
        const glm::dvec3 offset = glm::dvec3(cam.cx, cam.cy, 0.0) - view * cam.center;
        glm::dmat3 lin = view;
        glm::dvec3 trans = offset;
        glm::dmat3 normal_mat(1.0);
        bool normals_ok = part.normals.size() == part.positions.size();
        if (model) {
            const glm::dmat3 m3(*model);
            lin = view * m3;
            trans = view * glm::dvec3((*model)[3]) + offset;
            normal_mat = glm::transpose(glm::inverse(m3));
            for (int i = 0; i < 3; ++i)
                if (!finite3(normal_mat[i])) normals_ok = false;
        }
        const glm::mat3 flin(lin);
        const glm::vec3 ftrans(trans);
        const glm::mat3 fnormal(normal_mat);
        const glm::vec3 flight(cam.light), ftoward(cam.toward);
        const float nan = std::numeric_limits<float>::quiet_NaN();

        verts.resize(part.positions.size());
        for (std::size_t i = 0; i < part.positions.size(); ++i) {
            ScreenVertex& v = verts[i];
            const glm::vec3 s = flin * part.positions[i] + ftrans;
            v.ok = std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z);
            if (!v.ok) continue;
            v.x = std::int32_t(std::lround(std::clamp<double>(s.x, -kGuard, kGuard) * kSub));
            v.y = std::int32_t(std::lround(std::clamp<double>(s.y, -kGuard, kGuard) * kSub));
            v.z = s.z;
            v.nl = v.nv = nan;
            if (normals_ok) {
                const glm::vec3 n = fnormal * part.normals[i];
                const float len2 = glm::dot(n, n);
                if (std::isfinite(len2) && len2 > 1e-20f) {
                    const float inv = 1.0f / std::sqrt(len2);
                    v.nl = glm::dot(n, flight) * inv;
                    v.nv = glm::dot(n, ftoward) * inv;
                }
            }
        }
    }

    // Face normal from the screen-space triangle, turned toward the viewer.
    void face_terms(const ScreenVertex& a, const ScreenVertex& b, const ScreenVertex& c, float& nl,
                    float& nv) const {
        const double k = 1.0 / (kSub * cam.scale);
        const glm::dvec3 e1(double(b.x - a.x) * k, -double(b.y - a.y) * k, double(b.z) - a.z);
        const glm::dvec3 e2(double(c.x - a.x) * k, -double(c.y - a.y) * k, double(c.z) - a.z);
        glm::dvec3 n = glm::cross(e1, e2);
        const double len = glm::length(n);
        if (!(len > 0.0) || !std::isfinite(len)) {
            nl = nv = 1.0f;
            return;
        }
        n /= len;
        if (n.z < 0.0) n = -n;
        nl = float(glm::dot(n, light_view));
        nv = float(n.z);
    }

    void draw_triangle(const ScreenVertex& a, const ScreenVertex& b, const ScreenVertex& c,
                       const std::array<float, 3>& color) {
        if (!a.ok || !b.ok || !c.ok) return;
        float nl[3] = {a.nl, b.nl, c.nl}, nv[3] = {a.nv, b.nv, c.nv};
        if (std::isnan(nl[0]) || std::isnan(nl[1]) || std::isnan(nl[2])) {
            float fl = 0.0f, fv = 0.0f;
            face_terms(a, b, c, fl, fv);
            nl[0] = nl[1] = nl[2] = fl;
            nv[0] = nv[1] = nv[2] = fv;
        } else if (nv[0] + nv[1] + nv[2] < 0.0f) {
            // Seen from behind (the back of a leaf): light the side that faces the viewer.
            for (int k = 0; k < 3; ++k) {
                nl[k] = -nl[k];
                nv[k] = -nv[k];
            }
        }
        float t[3];
        for (int k = 0; k < 3; ++k)
            t[k] = kAmbient + kKey * std::max(0.0f, nl[k]) + kFill * std::max(0.0f, nv[k]);
        fill_triangle(raster, {a.x, a.y, a.z, t[0]}, {b.x, b.y, b.z, t[1]}, {c.x, c.y, c.z, t[2]}, color);
    }

    // A perspective triangle: clipped in view coordinates to the near plane and a guard band
    // around the image, projected, then filled as a fan.
    void draw_perspective(const ViewVertex& a, const ViewVertex& b, const ViewVertex& c,
                          const std::array<float, 3>& color) {
        if (!a.ok || !b.ok || !c.ok) return;
        float nl[3] = {a.nl, b.nl, c.nl}, nv[3] = {a.nv, b.nv, c.nv};
        if (std::isnan(nl[0]) || std::isnan(nl[1]) || std::isnan(nl[2])) {
            // the face normal, turned toward the eye (the origin of view coordinates)
            glm::dvec3 n = glm::cross(b.p - a.p, c.p - a.p);
            const double len = glm::length(n), dist = glm::length(a.p);
            float fl = 1.0f, fv = 1.0f;
            if (len > 0.0 && std::isfinite(len) && dist > 0.0) {
                n /= len;
                if (glm::dot(n, a.p) > 0.0) n = -n;
                fl = float(glm::dot(n, glm::dvec3(light_view.x, light_view.y, -light_view.z)));
                fv = float(-glm::dot(n, a.p) / dist);
            }
            nl[0] = nl[1] = nl[2] = fl;
            nv[0] = nv[1] = nv[2] = fv;
        } else if (nv[0] + nv[1] + nv[2] < 0.0f) {
            for (int k = 0; k < 3; ++k) {
                nl[k] = -nl[k];
                nv[k] = -nv[k];
            }
        }
        struct Clip {
            glm::dvec3 p;
            double t; // light intensity
        };
        std::array<Clip, 9> poly{}, next{};
        const ViewVertex* v[3] = {&a, &b, &c};
        for (int k = 0; k < 3; ++k)
            poly[std::size_t(k)] = {v[k]->p,
                                    kAmbient + kKey * std::max(0.0f, nl[k]) + kFill * std::max(0.0f, nv[k])};
        std::size_t n = 3;
        const double g = 0.5 * kGuard, f = cam.focal;
        // inside where plane . (x, y, d, 1) >= 0
        const glm::dvec4 planes[5] = {{0, 0, 1, -cam.near},
                                      {f, 0, cam.cx + g, 0},
                                      {-f, 0, g - cam.cx, 0},
                                      {0, -f, cam.cy + g, 0},
                                      {0, f, g - cam.cy, 0}};
        for (const glm::dvec4& plane : planes) {
            std::size_t m = 0;
            for (std::size_t i = 0; i < n; ++i) {
                const Clip& p = poly[i];
                const Clip& q = poly[(i + 1) % n];
                const double dp = glm::dot(plane, glm::dvec4(p.p, 1.0)),
                             dq = glm::dot(plane, glm::dvec4(q.p, 1.0));
                if (dp >= 0.0) next[m++] = p;
                if ((dp >= 0.0) != (dq >= 0.0)) {
                    const double s = dp / (dp - dq);
                    next[m++] = {p.p + s * (q.p - p.p), p.t + s * (q.t - p.t)};
                }
            }
            poly = next;
            n = m;
            if (n < 3) return;
        }
        std::array<ShadedVertex, 9> screen{};
        for (std::size_t i = 0; i < n; ++i) {
            const glm::dvec3& p = poly[i].p;
            const double sx = cam.cx + f * p.x / p.z, sy = cam.cy - f * p.y / p.z;
            screen[i] = {std::int64_t(std::lround(std::clamp(sx, -kGuard, kGuard) * kSub)),
                         std::int64_t(std::lround(std::clamp(sy, -kGuard, kGuard) * kSub)), float(1.0 / p.z),
                         float(poly[i].t)};
        }
        for (std::size_t i = 1; i + 1 < n; ++i)
            fill_triangle(raster, screen[0], screen[i], screen[i + 1], color);
    }

    void draw_range(const MeshPart& part, std::size_t first, std::size_t count, std::uint32_t material) {
        const std::size_t n = part.indices.size();
        if (first >= n) return;
        const std::size_t end = first + std::min(count, n - first);
        const std::array<float, 3> color = lut_scale_for(colors, material);
        const std::size_t nv = cam.perspective ? view_verts.size() : verts.size();
        for (std::size_t i = first; i + 3 <= end; i += 3) {
            const std::uint32_t ia = part.indices[i], ib = part.indices[i + 1], ic = part.indices[i + 2];
            if (ia >= nv || ib >= nv || ic >= nv) continue;
            if (cam.perspective)
                draw_perspective(view_verts[ia], view_verts[ib], view_verts[ic], color);
            else
                draw_triangle(verts[ia], verts[ib], verts[ic], color);
            if (raster.budget < 0)
                throw ExportError(fmt::format(
                    "the PNG preview is given up: its triangles cover the image more than {} times over "
                    "(large organs on top of each other); leave the .png out and view a .glb instead",
                    kMaxOverdraw));
        }
    }

    // Bands of the line mode, flat-shaded in their colours.
    void draw_quads(const std::vector<detail::ScreenQuad>& quads) {
        constexpr float kLineLight = 0.8f;
        const float s = float(kLutSize - 1);
        for (const detail::ScreenQuad& q : quads) {
            const std::array<float, 3> color = {clamp01(q.color.r) * s, clamp01(q.color.g) * s,
                                                clamp01(q.color.b) * s};
            std::array<ShadedVertex, 4> v{};
            for (std::size_t k = 0; k < 4; ++k)
                v[k] = {std::int64_t(std::lround(std::clamp(q.corner[k].x, -kGuard, kGuard) * kSub)),
                        std::int64_t(std::lround(std::clamp(q.corner[k].y, -kGuard, kGuard) * kSub)),
                        float(q.corner[k].z), kLineLight};
            fill_triangle(raster, v[0], v[1], v[2], color);
            fill_triangle(raster, v[0], v[2], v[3], color);
            if (raster.budget < 0)
                throw ExportError(
                    "the PNG preview is given up: its lines cover the image too many times over");
        }
    }

    void draw_part(const MeshPart& part, const glm::dmat4* model) {
        if (part.indices.empty() || part.positions.empty()) return;
        transform(part, model);
        if (part.primitives.empty()) {
            draw_range(part, 0, part.indices.size(), 0);
            return;
        }
        for (const Primitive& prim : part.primitives) draw_range(part, prim.first, prim.count, prim.material);
    }
};

} // namespace

Image render_scene(const Scene& scene, int width, int height, const std::optional<PngView>& view) {
    PngOptions options;
    options.camera = view;
    return render_scene(scene, width, height, options);
}

PngViewKind resolved_view(const Scene& scene, const PngOptions& options) {
    return detail::view_of(scene, options);
}

std::optional<glm::dvec2> project_to_image(const Scene& scene, int width, int height,
                                           const PngOptions& options, const glm::dvec3& p) {
    // the same supersampling and camera as render_scene
    const int ss = std::int64_t(width) * height <= kMaxSupersampledPixels ? 2 : 1;
    const Camera cam = detail::png_camera(scene, width * ss, height * ss, options);
    const auto s = detail::project(cam, p);
    if (!s) return std::nullopt;
    return glm::dvec2(s->x / ss, s->y / ss);
}

Image render_scene(const Scene& scene, int width, int height, const PngOptions& options) {
    // placed scenes are drawn flattened; an instance of a prototype the scene does not have is
    // skipped rather than failing, as befits a preview
    if (scene.nested()) return render_scene(flatten(scene), width, height, options);
    if (width <= 0 || height <= 0)
        throw ExportError("PNG size must be positive, got " + std::to_string(width) + "x" +
                          std::to_string(height));
    const std::int64_t pixels = std::int64_t(width) * height;
    if (pixels > kMaxPixels)
        throw ExportError("PNG size " + std::to_string(width) + "x" + std::to_string(height) +
                          " is too large");
    const int ss = pixels <= kMaxSupersampledPixels ? 2 : 1;

    Raster r;
    r.width = width * ss;
    r.height = height * ss;
    const std::size_t samples = std::size_t(r.width) * std::size_t(r.height);
    try {
        r.depth.assign(samples, -std::numeric_limits<float>::infinity());
        r.rgb.assign(samples * 3, 255);
    } catch (const std::bad_alloc&) {
        throw ExportError("out of memory rendering a " + std::to_string(width) + "x" +
                          std::to_string(height) + " PNG");
    }
    for (int i = 0; i < kLutSize; ++i) r.encode[i] = linear_to_srgb8(double(i) / (kLutSize - 1));
    r.budget = kMaxOverdraw * std::int64_t(samples);

    const Camera cam = detail::png_camera(scene, r.width, r.height, options);
    Renderer ren{scene,
                 r,
                 cam,
                 glm::dvec3(glm::dot(cam.light, cam.right), glm::dot(cam.light, cam.up),
                            glm::dot(cam.light, cam.toward)),
                 {},
                 {},
                 detail::flat_colors(scene)};
    // line mode (PngLines): bands of at least min_line_px under (or instead of) the tubes
    bool tubes = true;
    if (options.skeleton && options.lines != PngLines::Tubes) {
        tubes = options.lines == PngLines::Auto &&
                detail::widest_tube(*options.skeleton, cam, options.width_scale) >= kAutoLinePx * ss;
        const double min_samples = std::clamp(options.min_line_px, 0.0, 1000.0) * ss;
        // under tubes, bands only min_line_px wide: hidden inside every tube wider than that
        ren.draw_quads(
            detail::line_quads(*options.skeleton, cam, tubes ? 0.0 : options.width_scale, min_samples));
    }
    if (tubes) ren.draw_part(scene.tubes, nullptr);
    for (const Instance& inst : scene.instances) {
        if (inst.prototype >= scene.prototypes.size()) continue;
        const glm::dmat4 model(inst.transform);
        ren.draw_part(scene.prototypes[inst.prototype], &model);
    }

    Image img;
    img.width = width;
    img.height = height;
    if (ss == 1) {
        img.rgb = std::move(r.rgb);
        return img;
    }
    // Box filter in linear light.
    std::array<float, 256> decode{};
    for (int i = 0; i < 256; ++i) decode[i] = float(srgb8_to_linear(i));
    img.rgb.resize(std::size_t(pixels) * 3);
    const std::size_t row = std::size_t(r.width) * 3;
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* s0 = r.rgb.data() + std::size_t(2 * y) * row;
        const std::uint8_t* s1 = s0 + row;
        std::uint8_t* out = img.rgb.data() + std::size_t(y) * width * 3;
        for (int x = 0; x < width; ++x) {
            for (int ch = 0; ch < 3; ++ch) {
                const std::size_t k = std::size_t(x) * 6 + ch;
                if (s0[k] == s0[k + 3] && s0[k] == s1[k] && s0[k] == s1[k + 3]) {
                    out[x * 3 + ch] = s0[k];
                    continue;
                }
                const float v =
                    0.25f * (decode[s0[k]] + decode[s0[k + 3]] + decode[s1[k]] + decode[s1[k + 3]]);
                out[x * 3 + ch] = r.encode[std::size_t(v * (kLutSize - 1) + 0.5f)];
            }
        }
    }
    return img;
}

namespace {

struct PngSink {
    std::string bytes;
    bool failed = false;
};

void png_sink_write(void* context, void* data, int size) {
    auto* sink = static_cast<PngSink*>(context);
    if (sink->failed || size <= 0) return;
    try {
        sink->bytes.append(static_cast<const char*>(data), std::size_t(size));
    } catch (...) { // never unwind through the C encoder
        sink->failed = true;
    }
}

} // namespace

std::string png_bytes(const Scene& scene, int width, int height, const std::string& path,
                      const std::optional<PngView>& view) {
    PngOptions options;
    options.camera = view;
    return png_bytes(scene, width, height, path, options);
}

std::string png_bytes(const Scene& scene, int width, int height, const std::string& path,
                      const PngOptions& options) {
    const Image img = render_scene(scene, width, height, options);
    PngSink sink;
    const int ok = stbi_write_png_to_func(png_sink_write, &sink, img.width, img.height, 3, img.rgb.data(),
                                          img.width * 3);
    if (!ok || sink.failed || sink.bytes.empty()) throw ExportError("cannot encode PNG for " + path);
    return std::move(sink.bytes);
}

void write_png(const Scene& scene, const std::string& path, int width, int height,
               const std::optional<PngView>& view) {
    write_file_atomically(path, png_bytes(scene, width, height, path, view));
}

} // namespace plant
