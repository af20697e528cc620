// The lower bound for `plant run grammars/abop/fig2_7a.plant -n N -o FILE.glb` (bench/run-glb):
// ABOP Fig. 2.7a (Honda's sympodial tree, table row a) grown, meshed and written to a GLB by hand,
// with nothing general about it: no grammar, no string, no skeleton, every array sized from the
// counts the model implies. It makes the same tubes as plant (an axis continues into the branch
// that turns 5 degrees; the branch that turns 65 degrees starts a tube of its own), so the same
// triangles, vertices and file layout: one mesh, POSITION, NORMAL, TEXCOORD_0 and indices in
// four buffer views. The geometry is close to plant's, not identical (joints are not mitered).
//
//   plant_glb_bound N SIDES OUT.glb      prints: triangles=T vertices=V ms=M
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <string>
#include <vector>

namespace {

struct V3 {
    double x = 0, y = 0, z = 0;
};
V3 operator+(V3 a, V3 b) {
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
V3 operator-(V3 a, V3 b) {
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
V3 operator*(V3 a, double s) {
    return {a.x * s, a.y * s, a.z * s};
}
double dot(V3 a, V3 b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
V3 cross(V3 a, V3 b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
V3 unit(V3 a) {
    return a * (1.0 / std::sqrt(dot(a, a)));
}

// The turtle's frame: heading, left, up = heading x left.
struct Turtle {
    V3 pos, h{0, 1, 0}, l{-1, 0, 0}, u{0, 0, 1};
};
// Turns a toward b by phi degrees (both unit and perpendicular).
void turn(V3& a, V3& b, double deg) {
    const double c = std::cos(deg * std::numbers::pi / 180), s = std::sin(deg * std::numbers::pi / 180);
    const V3 na = a * c + b * s, nb = b * c - a * s;
    a = na, b = nb;
}
void level_left(Turtle& t) { // $: L horizontal
    const V3 l = cross(V3{0, 1, 0}, t.h);
    if (dot(l, l) < 1e-18) return;
    t.l = unit(l);
    t.u = cross(t.h, t.l);
}

// A branch still to grow: where it starts, its parameters, the steps left.
struct Bud {
    Turtle t;
    double len, width;
    int left;
    bool apex; // A (the axiom) rather than B
};

struct Point {
    V3 pos;
    double radius;
    V3 left; // the turtle's left at the tube's first point, for the ring frame
};

constexpr double r1 = 0.9, r2 = 0.7, a1 = 5, a2 = 65, wr = 0.707, width_scale = 0.02;

// Grows the tree: points of every tube, one after another; tube k is points[starts[k], starts[k+1]).
void grow(int n, std::vector<Point>& points, std::vector<std::uint32_t>& starts) {
    std::vector<Bud> buds{{Turtle{}, 1.0, 10.0, n, true}};
    while (!buds.empty()) {
        Bud b = buds.back();
        buds.pop_back();
        starts.push_back(static_cast<std::uint32_t>(points.size()));
        points.push_back({b.t.pos, b.width * width_scale / 2, b.t.l});
        while (b.left > 0) { // !(w) F(l) [ strong branch ] [ weak branch ]: the strong one continues
            b.t.pos = b.t.pos + b.t.h * b.len;
            points.push_back({b.t.pos, b.width * width_scale / 2, b.t.l});
            Turtle strong = b.t, weak = b.t;
            if (b.apex) { // &(a1) B ... /(180) &(a2) B
                turn(strong.h, strong.u, -a1);
                turn(weak.l, weak.u, 180);
                turn(weak.h, weak.u, -a2);
            } else { // +(a1) $ B ... -(a2) $ B
                turn(strong.h, strong.l, a1);
                level_left(strong);
                turn(weak.h, weak.l, -a2);
                level_left(weak);
            }
            if (b.left > 1) buds.push_back({weak, b.len * r2, b.width * wr, b.left - 1, false});
            b = {strong, b.len * r1, b.width * wr, b.left - 1, false};
        }
    }
    starts.push_back(static_cast<std::uint32_t>(points.size()));
}

struct Mesh {
    std::vector<float> pos, nrm, uv;
    std::vector<std::uint32_t> idx;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
};

// Rings of sides + 1 vertices (a seam copy for texture coordinates) at every point of a tube.
void mesh(const std::vector<Point>& points, const std::vector<std::uint32_t>& starts, int sides, Mesh& m) {
    const std::size_t tubes = starts.size() - 1, stride = std::size_t(sides) + 1;
    const std::size_t nv = points.size() * stride, segments = points.size() - tubes;
    m.pos.resize(nv * 3), m.nrm.resize(nv * 3), m.uv.resize(nv * 2), m.idx.resize(segments * 6 * sides);
    std::vector<double> cs(stride), sn(stride);
    for (std::size_t j = 0; j < stride; ++j)
        cs[j] = std::cos(2 * std::numbers::pi * double(j % sides) / sides),
        sn[j] = std::sin(2 * std::numbers::pi * double(j % sides) / sides);
    float *p = m.pos.data(), *q = m.nrm.data(), *w = m.uv.data();
    std::uint32_t* x = m.idx.data();
    for (std::size_t k = 0; k < tubes; ++k) {
        const std::size_t a = starts[k], b = starts[k + 1];
        V3 normal, prev_tangent;
        double arc = 0;
        for (std::size_t i = a; i < b; ++i) {
            const V3 in = i > a ? unit(points[i].pos - points[i - 1].pos) : V3{},
                     out = i + 1 < b ? unit(points[i + 1].pos - points[i].pos) : V3{};
            const V3 tangent = unit(in + out);
            if (i == a) {
                normal = unit(points[i].left - tangent * dot(points[i].left, tangent));
            } else { // the frame carried along by the smallest rotation
                arc += std::sqrt(dot(points[i].pos - points[i - 1].pos, points[i].pos - points[i - 1].pos));
                const V3 axis = cross(prev_tangent, tangent);
                const double s = std::sqrt(dot(axis, axis)), c = dot(prev_tangent, tangent);
                if (s > 1e-12) {
                    const V3 ax = axis * (1 / s);
                    normal = normal * c + cross(ax, normal) * s + ax * (dot(ax, normal) * (1 - c));
                }
                normal = unit(normal - tangent * dot(normal, tangent));
            }
            prev_tangent = tangent;
            const V3 binormal = cross(tangent, normal);
            for (std::size_t j = 0; j < stride; ++j) {
                const V3 radial = normal * cs[j] + binormal * sn[j];
                const V3 v = points[i].pos + radial * points[i].radius;
                const float f[3] = {float(v.x), float(v.y), float(v.z)};
                for (int c = 0; c < 3; ++c) {
                    *p++ = f[c];
                    m.lo[c] = f[c] < m.lo[c] ? f[c] : m.lo[c];
                    m.hi[c] = f[c] > m.hi[c] ? f[c] : m.hi[c];
                }
                *q++ = float(radial.x), *q++ = float(radial.y), *q++ = float(radial.z);
                *w++ = float(double(j) / sides), *w++ = float(arc);
            }
            if (i + 1 == b) continue;
            for (std::uint32_t j = 0; j < std::uint32_t(sides); ++j) {
                const std::uint32_t v0 = std::uint32_t(i * stride + j), v1 = v0 + 1,
                                    v3 = v0 + std::uint32_t(stride), v2 = v3 + 1;
                *x++ = v0, *x++ = v1, *x++ = v2, *x++ = v0, *x++ = v2, *x++ = v3;
            }
        }
    }
}

bool put(std::FILE* f, const void* data, std::size_t size) {
    return std::fwrite(data, 1, size, f) == size;
}
bool put32(std::FILE* f, std::uint32_t v) { // little-endian machines only, as is plant
    return put(f, &v, 4);
}

// One mesh, one node, one material; the views in plant's order.
bool write_glb(const Mesh& m, const char* path) {
    const std::size_t nv = m.pos.size() / 3, ni = m.idx.size();
    const std::size_t lp = nv * 12, ln = nv * 12, lu = nv * 8, li = ni * 4, total = lp + ln + lu + li;
    char head[1024];
    std::snprintf(head, sizeof head,
                  R"({"accessors":[{"bufferView":0,"componentType":5126,"count":%zu,"max":[%.9g,%.9g,%.9g],)"
                  R"("min":[%.9g,%.9g,%.9g],"type":"VEC3"},{"bufferView":1,"componentType":5126,"count":%zu,)"
                  R"("type":"VEC3"},{"bufferView":2,"componentType":5126,"count":%zu,"type":"VEC2"},)"
                  R"({"bufferView":3,"componentType":5125,"count":%zu,"type":"SCALAR"}],)"
                  R"("asset":{"generator":"plant","version":"2.0"},"bufferViews":[)"
                  R"({"buffer":0,"byteLength":%zu,"target":34962},)"
                  R"({"buffer":0,"byteLength":%zu,"byteOffset":%zu,"target":34962},)"
                  R"({"buffer":0,"byteLength":%zu,"byteOffset":%zu,"target":34962},)"
                  R"({"buffer":0,"byteLength":%zu,"byteOffset":%zu,"target":34963}],)",
                  nv, m.hi[0], m.hi[1], m.hi[2], m.lo[0], m.lo[1], m.lo[2], nv, nv, ni, lp, ln, lp, lu,
                  lp + ln, li, lp + ln + lu);
    std::string json = head;
    json += R"("buffers":[{"byteLength":)" + std::to_string(total) + "}],";
    json +=
        R"("materials":[{"doubleSided":true,"name":"material0","pbrMetallicRoughness":)"
        R"({"baseColorFactor":[0.45,0.32,0.2,1.0],"metallicFactor":0.0,"roughnessFactor":0.9}}],)"
        R"("meshes":[{"name":"tubes","primitives":[{"attributes":{"NORMAL":1,"POSITION":0,"TEXCOORD_0":2},)"
        R"("indices":3,"material":0,"mode":4}]}],"nodes":[{"mesh":0,"name":"tubes"}],"scene":0,)"
        R"("scenes":[{"name":"plant","nodes":[0]}]})";
    while (json.size() % 4) json += ' ';
    std::FILE* f = std::fopen(path, "wb");
    if (!f) return false;
    bool ok =
        put32(f, 0x46546C67) && put32(f, 2) && put32(f, std::uint32_t(12 + 8 + json.size() + 8 + total)) &&
        put32(f, std::uint32_t(json.size())) && put32(f, 0x4E4F534A) && put(f, json.data(), json.size()) &&
        put32(f, std::uint32_t(total)) && put32(f, 0x004E4942) && put(f, m.pos.data(), lp) &&
        put(f, m.nrm.data(), ln) && put(f, m.uv.data(), lu) && put(f, m.idx.data(), li);
    return (std::fclose(f) == 0) && ok;
}

} // namespace

int main(int argc, char** argv) {
    if (argc != 4) {
        std::fprintf(stderr, "usage: plant_glb_bound N SIDES OUT.glb\n");
        return 2;
    }
    const int n = std::atoi(argv[1]), sides = std::atoi(argv[2]);
    if (n < 1 || n > 24 || sides < 3 || sides > 64) {
        std::fprintf(stderr, "plant_glb_bound: N must be 1..24 and SIDES 3..64\n");
        return 2;
    }
    const auto t0 = std::chrono::steady_clock::now();
    // 2^n - 1 segments in 2^(n-1) tubes, each with one more point than segments
    const std::size_t segments = (std::size_t(1) << n) - 1, tubes = std::size_t(1) << (n - 1);
    std::vector<Point> points;
    std::vector<std::uint32_t> starts;
    points.reserve(segments + tubes);
    starts.reserve(tubes + 1);
    grow(n, points, starts);
    Mesh m;
    mesh(points, starts, sides, m);
    if (!write_glb(m, argv[3])) {
        std::fprintf(stderr, "plant_glb_bound: cannot write %s\n", argv[3]);
        return 1;
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::printf("triangles=%zu vertices=%zu ms=%.3f\n", m.idx.size() / 3, m.pos.size() / 3, ms);
    return 0;
}
