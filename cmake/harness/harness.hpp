// Shared pieces of the side-by-side harness programs: abgs status checks, an
// owning grid handle with its arrays, a wall clock, deterministic point sets,
// small argument parsing and the one-line JSON summary each program prints.
#pragma once

#include "abgs.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace harness {

/// Exits with status 2 and the library's message when an abgs call failed.
inline void check(abgs_status st, const char *what) {
    if (st != ABGS_OK) {
        std::fprintf(stderr, "%s failed: %s: %s\n", what, abgs_status_name(static_cast<int>(st)),
                     abgs_last_error_message());
        std::exit(2);
    }
}

/// Seconds since an arbitrary origin (steady clock).
inline double now() {
    using namespace std::chrono;
    return duration<double>(steady_clock::now().time_since_epoch()).count();
}

/// CPU seconds of this process, all threads (std::clock): on a machine
/// shared with other jobs, the single-threaded meshers' CPU time is steadier
/// than their wall clock.
inline double cpu_now() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

using Vec3 = std::array<double, 3>;

/// A zeroed abgs struct with its `struct_size` set (the header's growth rule).
template <class T> T versioned() {
    T t{};
    t.struct_size = sizeof(T);
    return t;
}

/// abgs' contact gap as a fraction of the bounding-box diagonal (include/abgs.h,
/// abgs_query_size: "the contact gap c (diagonal / 2000)"): bodies nearer than
/// this touch, and the queries' tie rule reads every body within it.
constexpr double kContactFraction = 1.0 / 2000.0;

/// An abgs grid handle (freed on destruction) with copies of its arrays.
struct Grid {
    abgs_grid *g = nullptr;
    std::vector<double> xyz;     // 3 per vertex
    std::vector<uint32_t> tri;   // 3 per triangle
    std::vector<double> size;    // 1 per vertex (empty without sizes)
    abgs_grid_stats stats = versioned<abgs_grid_stats>();

    Grid() = default;
    Grid(const Grid &) = delete;
    Grid &operator=(const Grid &) = delete;
    ~Grid() {
        if (g) abgs_grid_free(g);
    }

    /// Loads `path` with abgs_grid_load and copies its arrays out.
    void load(const std::string &path) {
        check(abgs_grid_load(path.c_str(), &g), ("abgs_grid_load " + path).c_str());
        refresh();
    }
    /// Builds the grid from arrays (abgs_grid_from_arrays); `h` may be empty.
    void from_arrays(const std::vector<double> &v, const std::vector<uint32_t> &t,
                     const std::vector<double> &h) {
        check(abgs_grid_from_arrays(v.data(), v.size() / 3, t.data(), t.size() / 3,
                                    h.empty() ? nullptr : h.data(), &g),
              "abgs_grid_from_arrays");
        refresh();
    }
    /// Re-reads counts, arrays and statistics from the library.
    void refresh() {
        check(abgs_grid_get_stats(g, &stats), "abgs_grid_get_stats");
        xyz.resize(3 * stats.vertices);
        tri.resize(3 * stats.triangles);
        check(abgs_grid_copy_vertices(g, xyz.data(), xyz.size()), "abgs_grid_copy_vertices");
        check(abgs_grid_copy_triangles(g, tri.data(), tri.size()), "abgs_grid_copy_triangles");
        size.clear();
        if (stats.has_sizes) {
            size.resize(stats.vertices);
            check(abgs_grid_copy_sizes(g, size.data(), size.size()), "abgs_grid_copy_sizes");
        }
    }
    size_t vertices() const { return xyz.size() / 3; }
    size_t triangles() const { return tri.size() / 3; }
    Vec3 vertex(size_t i) const { return {xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]}; }
};

/// Bodies as abgs counts them (`abgs_grid_stats::bodies`, the queries' tie
/// rule): connected components of the triangles joined through manifold edges
/// (edges of exactly two triangles), numbered 0.. in order of each body's
/// lowest triangle. The grids `abgs run` writes carry no body ids, so the
/// harness labels them with the library's definition (`bodies.count` is
/// checked against the grid's statistics by `Bodies::of`). O(F log F).
struct Bodies {
    std::vector<uint32_t> face;  // body of each triangle
    uint32_t count = 0;

    static Bodies of(const Grid &g) {
        const size_t nt = g.triangles();
        std::vector<std::array<uint32_t, 3>> half;  // (min, max, face) per triangle edge
        half.reserve(3 * nt);
        for (size_t f = 0; f < nt; f++)
            for (int k = 0; k < 3; k++) {
                uint32_t a = g.tri[3 * f + k], b = g.tri[3 * f + (k + 1) % 3];
                half.push_back({std::min(a, b), std::max(a, b), static_cast<uint32_t>(f)});
            }
        std::sort(half.begin(), half.end());
        std::vector<uint32_t> parent(nt);
        for (size_t f = 0; f < nt; f++) parent[f] = static_cast<uint32_t>(f);
        auto find = [&](uint32_t x) {
            while (parent[x] != x) x = parent[x] = parent[parent[x]];
            return x;
        };
        for (size_t i = 0; i < half.size();) {
            size_t j = i;
            std::vector<uint32_t> faces;
            while (j < half.size() && half[j][0] == half[i][0] && half[j][1] == half[i][1]) {
                if (faces.empty() || faces.back() != half[j][2]) faces.push_back(half[j][2]);
                j++;
            }
            if (faces.size() == 2) parent[find(faces[0])] = find(faces[1]);
            i = j;
        }
        Bodies b;
        b.face.resize(nt);
        std::vector<uint32_t> label(nt, UINT32_MAX);
        for (size_t f = 0; f < nt; f++) {
            uint32_t r = find(static_cast<uint32_t>(f));
            if (label[r] == UINT32_MAX) label[r] = b.count++;
            b.face[f] = label[r];
        }
        if (b.count != g.stats.bodies) {
            std::fprintf(stderr, "body labelling: %u bodies here, the library counts %llu\n", b.count,
                         static_cast<unsigned long long>(g.stats.bodies));
            std::exit(2);
        }
        return b;
    }
};

inline Vec3 sub(const Vec3 &a, const Vec3 &b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3 add(const Vec3 &a, const Vec3 &b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 mul(const Vec3 &a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline double dot(const Vec3 &a, const Vec3 &b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3 cross(const Vec3 &a, const Vec3 &b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3 &a) { return std::sqrt(dot(a, a)); }

/// Area-weighted random points on the grid, each with its triangle and unit normal.
struct SurfaceSampler {
    const Grid &grid;
    std::vector<double> cdf;
    explicit SurfaceSampler(const Grid &gr) : grid(gr) {
        double acc = 0.0;
        cdf.reserve(gr.triangles());
        for (size_t f = 0; f < gr.triangles(); f++) {
            acc += 0.5 * norm(normal2(f));
            cdf.push_back(acc);
        }
    }
    Vec3 normal2(size_t f) const {
        Vec3 a = grid.vertex(grid.tri[3 * f]), b = grid.vertex(grid.tri[3 * f + 1]),
             c = grid.vertex(grid.tri[3 * f + 2]);
        return cross(sub(b, a), sub(c, a));
    }
    /// A uniform point on the surface; `*face` and `*unit_normal` receive its triangle's.
    template <class Rng> Vec3 sample(Rng &rng, size_t *face = nullptr, Vec3 *unit_normal = nullptr) const {
        std::uniform_real_distribution<double> u(0.0, 1.0);
        double r = u(rng) * cdf.back();
        size_t f = std::min<size_t>(std::lower_bound(cdf.begin(), cdf.end(), r) - cdf.begin(),
                                    cdf.size() - 1);
        double s = u(rng), t = u(rng);
        if (s + t > 1.0) {
            s = 1.0 - s;
            t = 1.0 - t;
        }
        Vec3 a = grid.vertex(grid.tri[3 * f]), b = grid.vertex(grid.tri[3 * f + 1]),
             c = grid.vertex(grid.tri[3 * f + 2]);
        if (face) *face = f;
        if (unit_normal) {
            Vec3 n = normal2(f);
            double l = norm(n);
            *unit_normal = l > 0 ? mul(n, 1.0 / l) : Vec3{0, 0, 0};
        }
        return add(a, add(mul(sub(b, a), s), mul(sub(c, a), t)));
    }
};

/// How a mesh follows a size field: every triangle edge's length over the
/// field's size at the edge midpoint (1 = the mesh follows the field), mean
/// and percentiles; `edges` counts edges with their multiplicity (an edge
/// shared by two triangles counts twice). All NaN for an empty mesh.
struct EdgeRatio {
    double mean = NAN, p5 = NAN, p50 = NAN, p95 = NAN;
    size_t edges = 0;

    /// Measures the triangles `tris` (9 coordinates each) against `field`'s
    /// sizes (abgs_query_sizes, all threads). O(T log T).
    static EdgeRatio of(const Grid &field, const std::vector<double> &tris) {
        EdgeRatio r;
        const size_t nt = tris.size() / 9;
        if (nt == 0) return r;
        std::vector<double> mid(9 * nt), len(3 * nt), h(3 * nt);
        for (size_t t = 0; t < nt; t++)
            for (int e = 0; e < 3; e++) {
                const double *a = &tris[9 * t + 3 * e], *b = &tris[9 * t + 3 * ((e + 1) % 3)];
                double l2 = 0;
                for (int k = 0; k < 3; k++) {
                    mid[3 * (3 * t + e) + k] = 0.5 * (a[k] + b[k]);
                    l2 += (a[k] - b[k]) * (a[k] - b[k]);
                }
                len[3 * t + e] = std::sqrt(l2);
            }
        check(abgs_query_sizes(field.g, mid.data(), h.size(), h.data()), "abgs_query_sizes");
        double sum = 0;
        for (size_t i = 0; i < h.size(); i++) {
            len[i] /= h[i];
            sum += len[i];
        }
        std::sort(len.begin(), len.end());
        auto pct = [&](double q) { return len[static_cast<size_t>(q * static_cast<double>(len.size() - 1))]; };
        r.mean = sum / static_cast<double>(len.size());
        r.p5 = pct(0.05);
        r.p50 = pct(0.5);
        r.p95 = pct(0.95);
        r.edges = len.size();
        return r;
    }
};

/// Minimal `--key value` / `--flag` parsing; positional arguments in order.
struct Args {
    std::vector<std::string> pos;
    std::map<std::string, std::string> opt;
    Args(int argc, char **argv) {
        for (int i = 1; i < argc; i++) {
            std::string a = argv[i];
            if (a.rfind("--", 0) == 0) {
                std::string v = (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) ? argv[++i] : "1";
                opt[a.substr(2)] = v;
            } else {
                pos.push_back(a);
            }
        }
    }
    double num(const std::string &k, double def) const {
        auto it = opt.find(k);
        return it == opt.end() ? def : std::atof(it->second.c_str());
    }
    std::string str(const std::string &k, const std::string &def) const {
        auto it = opt.find(k);
        return it == opt.end() ? def : it->second;
    }
    bool has(const std::string &k) const { return opt.count(k) != 0; }
};

/// Number of threads for "all threads" runs: RAYON_NUM_THREADS if set (so that
/// abgs' batch queries and the harness's own threads agree), else the hardware's.
inline unsigned all_threads() {
    if (const char *e = std::getenv("RAYON_NUM_THREADS")) {
        int n = std::atoi(e);
        if (n > 0) return static_cast<unsigned>(n);
    }
    unsigned n = std::thread::hardware_concurrency();
    return n ? n : 1;
}

/// Runs `f(begin, end, thread_index)` over [0, n) split into `threads` contiguous chunks.
template <class F> void parallel_chunks(size_t n, unsigned threads, F f) {
    std::vector<std::thread> pool;
    size_t per = (n + threads - 1) / threads;
    for (unsigned k = 0; k < threads; k++) {
        size_t b = std::min(n, k * per), e = std::min(n, b + per);
        pool.emplace_back([=, &f] { f(b, e, k); });
    }
    for (auto &t : pool) t.join();
}

/// A flat JSON object printed on one line (keys in insertion order).
class Json {
    std::ostringstream s_;
    bool first_ = true;
    void key(const std::string &k) {
        s_ << (first_ ? "{" : ", ") << '"' << k << "\": ";
        first_ = false;
    }

  public:
    Json &num(const std::string &k, double v) {
        key(k);
        if (std::isfinite(v)) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.17g", v);
            s_ << buf;
        } else {
            s_ << "null";
        }
        return *this;
    }
    Json &str(const std::string &k, const std::string &v) {
        key(k);
        s_ << '"';
        for (char c : v) {
            if (c == '"' || c == '\\') s_ << '\\';
            s_ << c;
        }
        s_ << '"';
        return *this;
    }
    Json &boolean(const std::string &k, bool v) {
        key(k);
        s_ << (v ? "true" : "false");
        return *this;
    }
    /// Adds every field of an evaluation under `prefix`.
    Json &evaluation(const std::string &p, const abgs_evaluation &e) {
        num(p + "faces", static_cast<double>(e.faces_candidate));
        num(p + "reduction", e.reduction);
        num(p + "size_dev_mean", e.size_deviation_mean);
        num(p + "size_dev_p95", e.size_deviation_p95);
        num(p + "size_dev_max", e.size_deviation_max);
        num(p + "hausdorff", e.hausdorff);
        num(p + "hausdorff_rel", e.hausdorff_relative);
        num(p + "elements_ref", e.element_count_reference);
        num(p + "elements", e.element_count_candidate);
        num(p + "elements_change", e.element_count_change);
        num(p + "min_angle", e.angles_candidate.min);
        num(p + "min_angle_p1", e.angles_candidate.min_p1);
        num(p + "max_angle_p99", e.angles_candidate.max_p99);
        num(p + "eval_seconds", e.seconds);
        return *this;
    }
    /// Prints `{...}` and a newline to stdout.
    void print() {
        std::printf("%s}\n", first_ ? "{" : s_.str().c_str());
        std::fflush(stdout);
    }
};

}  // namespace harness
