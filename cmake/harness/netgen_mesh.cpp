// netgen_mesh STEP --dense DENSE --simplified SIMPLIFIED --stl STL [--work DIR]
//             [--grading G] [--spacing S] [--cases a,b,c]
//             [--check [--triangle-tolerance T] [--p50 LOW,HIGH] [--p50-step D]]
//
// Netgen 6.2 (Debian's nglib, OpenCASCADE geometry) meshes the surfaces
// (dimension 2) of a STEP model with an abgs grid as its size field:
//   (a) dense       the dense grid's field
//   (b) simplified  the simplified grid's field
//   (c) stl         the raw STL triangles, sizes computed and graded on the STL
//                   vertices (abgs_compute_size, defaults, as gmsh_mesh does)
//
// What Netgen 6.2.1905 can take. It has no size callback: its size field is an
// octree (LocalH) of piecewise-constant cell sizes, lowered only through
// "restrict h to at most h_i near point p_i" (nglib's Ng_RestrictMeshSizePoint;
// the same call behind a mesh-size file). A restriction refines the cell
// holding p_i until the cell is no larger than h_i, sets that cell to h_i,
// and spreads h_i + grading·(cell size) to the six axis neighbours, and on,
// while that lowers them; a restriction within a factor 1.2 of the current
// value is skipped. So the field Netgen meshes with is a min over sampled
// points, graded in 3-D space (not along the surface: small sizes reach
// through thin walls), constant per cell, and up to 1.2× the given sizes.
// The Python module (python3-netgen) cannot express even that for STEP
// geometry: its OCC GenerateMesh ignores the MeshingParameters it is given
// (maxh, grading, meshsizefilename, RestrictH), because OCCSetLocalMeshSize
// and the surface mesher read the library's global parameters, which only
// nglib's Transfer_Parameters sets.
//
// Here: Netgen's own sizing is neutralised (uselocalh on, as its front and
// smoother need the octree, but curvature safety 0 and elements per edge
// 1e-9, so that its curvature and edge-length restrictions never bind; close
// edges off; maxh = the grid's largest size; minh 0), then the grid's
// piecewise-linear field is handed over as restriction points: every vertex,
// plus the vertices of a midpoint subdivision of each triangle, refined where
// an edge is longer than S·(the smaller size at its corners) (S = 0.5 by
// default: each octree cell the surface passes through gets a point), each
// point with the grid's interpolated size.
// Grading G is Netgen's (default 0.3, its own default; the abgs field is
// already graded with slope ln 1.2 = 0.18, so G ≥ 0.18 does not bind on
// smooth stretches). Surface optimisation on (Netgen's default, 3 steps).
//
// Geometry: Netgen 6.2.1905's STEP reader keeps only the first shape of the
// file (LoadOCCInto: `GetShape(step_shapes.Value(1))`), which is one solid of
// abc_00000050's three. So the STEP is imported by Gmsh's OpenCASCADE (as in
// gmsh_mesh), written as BREP (DIR/netgen_input.brep; DIR defaults to the
// dense grid's folder) and Netgen loads that: both meshers see the same shapes.
// Units: when the STEP's extent differs from the dense grid's by more than a
// factor 2, the restrictions are scaled into the STEP's units by the nearest
// power-of-ten or 25.4 factor, and the mesh back (gmsh_mesh's OCCScaling).
// A first pass (not timed with the cases) runs Netgen's local-size setup and
// edge meshing once, so that OCC's own triangulation of the faces, which that
// setup builds and keeps, is not charged to the first case.
//
// For each case: triangles, nodes, open edges (edges of one triangle: a closed
// solid's surface mesh has none unless a face failed), restriction points,
// seconds for Netgen's local-size setup, for the restrictions and for the edge
// plus surface meshing (wall clock, and CPU time of the meshing: one thread),
// and how the mesh follows the dense field: edge length
// / h_dense(midpoint), mean and 5th, 50th, 95th percentiles. Netgen's own
// messages go to stderr; one JSON object goes to stdout.
// --check (with cases a and b): the simplified grid must give Netgen what the
// dense one gives: triangles of (b) within ±T of (a) (default 0.12), (b)
// closed where (a) is, and edge / h_dense p50 of (a) and (b) within
// [LOW, HIGH] (default 0.8,1.25) and at most D apart (default 0.1). Why
// these: Netgen's octree keeps about the minimum of the sizes given in each
// cell, so it realises a rougher field finer; the dense grid's field varies
// more from vertex to vertex than the simplified grid's, and Netgen meshes it
// up to 9 % finer (−0.5 % to −8.9 % triangles with (b) over the 8 STEP
// models, p50 up by at most 0.055; Gmsh, which samples the field pointwise,
// sees −3 % to +2 %). A simplified field off by the simplifier's own bound
// (1.2×) would move the triangles by −31 % or +44 %, and a broken hand-over
// (units, skipped restrictions) moves p50 far out of [0.8, 1.25].
// Exit status: 0 every case meshed (and the check passed), 1 a case produced
// no triangles, Netgen reported an error or the check failed, 2 error.
#include "gmsh_step.hpp"
#include "harness.hpp"

#define OCCGEOMETRY
namespace nglib {
#include <nglib.h>
}

#include <iostream>
#include <unordered_map>

using namespace harness;

namespace {

/// The sizes Netgen is given: points and their sizes, in the STEP's units.
struct Restrictions {
    std::vector<double> xyz, h;
    double hmax = 0;
};

/// Adds the edge midpoints of triangle (p, h) with their interpolated sizes
/// and recurses into its four halves while its longest edge is above
/// `spacing`·min(corner sizes): points at most that far apart, each with the
/// grid's (linear) size there. Depth-limited (a sliver of a huge triangle
/// with a tiny size must not explode).
template <class Push>
void subdivide(const Vec3 (&p)[3], const double (&h)[3], double spacing, int depth, Push &push) {
    double longest = 0;
    for (int e = 0; e < 3; e++) longest = std::max(longest, norm(sub(p[(e + 1) % 3], p[e])));
    if (!(longest > spacing * std::min({h[0], h[1], h[2]})) || depth >= 16) return;
    const Vec3 m[3] = {mul(add(p[0], p[1]), 0.5), mul(add(p[1], p[2]), 0.5), mul(add(p[2], p[0]), 0.5)};
    const double hm[3] = {0.5 * (h[0] + h[1]), 0.5 * (h[1] + h[2]), 0.5 * (h[2] + h[0])};
    for (int e = 0; e < 3; e++) push(m[e], hm[e]);
    const Vec3 c0[3] = {p[0], m[0], m[2]}, c1[3] = {m[0], p[1], m[1]}, c2[3] = {m[2], m[1], p[2]},
               c3[3] = {m[0], m[1], m[2]};
    const double h0[3] = {h[0], hm[0], hm[2]}, h1[3] = {hm[0], h[1], hm[1]}, h2[3] = {hm[2], hm[1], h[2]},
                 h3[3] = {hm[0], hm[1], hm[2]};
    subdivide(c0, h0, spacing, depth + 1, push);
    subdivide(c1, h1, spacing, depth + 1, push);
    subdivide(c2, h2, spacing, depth + 1, push);
    subdivide(c3, h3, spacing, depth + 1, push);
}

/// The grid's vertices with their sizes, plus the vertices of each triangle's
/// midpoint subdivision down to spacing ≤ `spacing`·(local size) (see
/// `subdivide`), sizes interpolated; coordinates and sizes divided by
/// `scale`. O(number of points).
Restrictions sample_field(const Grid &g, double spacing, double scale) {
    Restrictions r;
    auto push = [&](const Vec3 &p, double h) {
        r.xyz.insert(r.xyz.end(), {p[0] / scale, p[1] / scale, p[2] / scale});
        r.h.push_back(h / scale);
        r.hmax = std::max(r.hmax, h / scale);
    };
    for (size_t v = 0; v < g.vertices(); v++) push(g.vertex(v), g.size[v]);
    for (size_t t = 0; t < g.triangles(); t++) {
        const uint32_t *ix = &g.tri[3 * t];
        const Vec3 p[3] = {g.vertex(ix[0]), g.vertex(ix[1]), g.vertex(ix[2])};
        const double h[3] = {g.size[ix[0]], g.size[ix[1]], g.size[ix[2]]};
        subdivide(p, h, spacing, 0, push);
    }
    return r;
}

/// nglib parameters with Netgen's own size restrictions switched off (see the
/// file comment); `maxh` and `grading` as given.
nglib::Ng_Meshing_Parameters params(double maxh, double grading) {
    nglib::Ng_Meshing_Parameters mp;
    mp.uselocalh = 1;
    mp.maxh = maxh;
    mp.minh = 0.0;
    mp.grading = grading;
    mp.elementsperedge = 1e-9;  // edge length / 1e-9: never binds
    mp.elementspercurve = 0.0;  // curvature safety 0: ComputeH gives maxh
    mp.closeedgeenable = 0;
    mp.optsurfmeshenable = 1;
    mp.quad_dominated = 0;
    mp.second_order = 0;
    return mp;
}

/// Triangles of a Netgen mesh as coordinates (9 doubles each, times `scale`),
/// and the count of open edges (edges of exactly one triangle).
std::vector<double> triangles(nglib::Ng_Mesh *mesh, double scale, size_t *open_edges, size_t *others) {
    const int np = nglib::Ng_GetNP(mesh), nse = nglib::Ng_GetNSE(mesh);
    std::vector<double> pts(3 * static_cast<size_t>(np));
    for (int i = 0; i < np; i++) nglib::Ng_GetPoint(mesh, i + 1, &pts[3 * static_cast<size_t>(i)]);
    std::vector<double> out;
    out.reserve(9 * static_cast<size_t>(nse));
    std::unordered_map<uint64_t, int> edge_count;
    edge_count.reserve(3 * static_cast<size_t>(nse));
    *others = 0;
    for (int e = 0; e < nse; e++) {
        int pi[NG_SURFACE_ELEMENT_MAXPOINTS];
        if (nglib::Ng_GetSurfaceElement(mesh, e + 1, pi) != nglib::NG_TRIG) {
            ++*others;
            continue;
        }
        for (int k = 0; k < 3; k++) {
            if (pi[k] < 1 || pi[k] > np) {
                std::fprintf(stderr, "surface element %d has point %d of %d\n", e + 1, pi[k], np);
                std::exit(2);
            }
            for (int c = 0; c < 3; c++) out.push_back(scale * pts[3 * static_cast<size_t>(pi[k] - 1) + c]);
            const uint64_t a = static_cast<uint64_t>(pi[k]), b = static_cast<uint64_t>(pi[(k + 1) % 3]);
            edge_count[std::min(a, b) << 32 | std::max(a, b)]++;
        }
    }
    *open_edges = 0;
    for (const auto &kv : edge_count) *open_edges += kv.second == 1;
    return out;
}

}  // namespace

int main(int argc, char **argv) {
    Args args(argc, argv);
    if (args.pos.size() != 1 || !args.has("dense") || !args.has("simplified") || !args.has("stl")) {
        std::fprintf(stderr, "usage: netgen_mesh STEP --dense DENSE --simplified SIMPLIFIED --stl STL [--work DIR] "
                             "[--grading G] [--spacing S] [--cases a,b,c] "
                             "[--check [--triangle-tolerance T] [--p50 LOW,HIGH] [--p50-step D]]\n");
        return 2;
    }
    const std::string step = args.pos[0], cases_arg = args.str("cases", "a,b,c");
    const double grading = args.num("grading", 0.3), spacing = args.num("spacing", 0.5);
    if (!(grading > 0 && grading <= 1) || !(spacing > 0 && spacing <= 10)) {
        std::fprintf(stderr, "--grading must be in (0, 1] and --spacing in (0, 10]\n");
        return 2;
    }
    const bool check_on = args.has("check");
    const double tri_tol = args.num("triangle-tolerance", 0.12), p50_step = args.num("p50-step", 0.1);
    double p50_lo = 0.8, p50_hi = 1.25;
    if (args.has("p50") && std::sscanf(args.str("p50", "").c_str(), "%lf,%lf", &p50_lo, &p50_hi) != 2) {
        std::fprintf(stderr, "--p50 takes LOW,HIGH\n");
        return 2;
    }
    if (check_on && (cases_arg.find('a') == std::string::npos || cases_arg.find('b') == std::string::npos ||
                     !(tri_tol > 0) || !(p50_step > 0) || !(p50_lo < p50_hi))) {
        std::fprintf(stderr, "--check needs cases a and b, positive tolerances and LOW < HIGH\n");
        return 2;
    }
    // Netgen writes its progress to std::cout: send it to stderr (stdout is
    // the JSON line, written with printf).
    std::cout.rdbuf(std::cerr.rdbuf());

    Grid dense, simp, stl;
    dense.load(args.str("dense", ""));
    simp.load(args.str("simplified", ""));
    stl.load(args.str("stl", ""));
    if (dense.size.empty() || simp.size.empty()) {
        std::fprintf(stderr, "the dense and simplified grids must carry sizes\n");
        return 2;
    }
    abgs_size_params sp{};
    sp.struct_size = sizeof sp;
    check(abgs_size_params_default(&sp), "abgs_size_params_default");
    abgs_size_report sr = versioned<abgs_size_report>();
    double t0 = now();
    check(abgs_compute_size(stl.g, &sp, &sr), "abgs_compute_size (STL)");
    const double stl_size_seconds = now() - t0;
    stl.refresh();

    // The STEP through Gmsh's OpenCASCADE into a BREP Netgen reads whole.
    std::string work = args.str("work", "");
    if (work.empty()) {
        const std::string d = args.str("dense", "");
        const size_t sl = d.find_last_of('/');
        work = sl == std::string::npos ? "." : d.substr(0, sl);
    }
    const std::string brep = work + "/netgen_input.brep";
    int ierr = 0;
    gmshInitialize(0, nullptr, 0, 0, &ierr);
    gcheck(ierr, "gmshInitialize");
    set_number("General.Terminal", 1);
    set_number("General.Verbosity", 1);
    t0 = now();
    import_step(step);
    const size_t volumes = entity_count(3), surfaces = entity_count(2);
    const double scale = unit_scale(dense.stats.diagonal, step_diagonal());
    gmshWrite(brep.c_str(), &ierr);
    gcheck(ierr, "gmshWrite (BREP)");
    const double convert_seconds = now() - t0;
    gmshFinalize(&ierr);
    std::fprintf(stderr, "STEP: %zu volumes, %zu surfaces, written as %s in %.3f s%s\n", volumes, surfaces,
                 brep.c_str(), convert_seconds, scale != 1.0 ? "; units differ from the grids'" : "");
    if (scale != 1.0) std::fprintf(stderr, "sizes go to Netgen divided by %.6g\n", scale);

    nglib::Ng_Init();
    t0 = now();
    nglib::Ng_OCC_Geometry *geo = nglib::Ng_OCC_Load_BREP(brep.c_str());
    const double load_seconds = now() - t0;
    if (!geo) {
        std::fprintf(stderr, "Netgen could not read %s\n", brep.c_str());
        return 2;
    }
    // OCC's triangulation of the faces, built once by the local-size setup.
    double probe_seconds = 0;
    {
        nglib::Ng_Mesh *probe = nglib::Ng_NewMesh();
        auto mp = params(dense.stats.diagonal / scale, grading);
        t0 = now();
        if (nglib::Ng_OCC_SetLocalMeshSize(geo, probe, &mp) != nglib::NG_OK ||
            nglib::Ng_OCC_GenerateEdgeMesh(geo, probe, &mp) != nglib::NG_OK) {
            std::fprintf(stderr, "Netgen could not mesh the edges of %s\n", brep.c_str());
            return 2;
        }
        probe_seconds = now() - t0;
        nglib::Ng_DeleteMesh(probe);  // no surface mesh: freeing it is safe
    }

    Json out;
    out.str("step", step)
        .num("scale", scale)
        .num("grading", grading)
        .num("spacing", spacing)
        .num("step_volumes", static_cast<double>(volumes))
        .num("step_surfaces", static_cast<double>(surfaces))
        .num("brep_s", convert_seconds)
        .num("load_s", load_seconds)
        .num("probe_s", probe_seconds)
        .num("dense_faces", static_cast<double>(dense.triangles()))
        .num("simplified_faces", static_cast<double>(simp.triangles()))
        .num("stl_faces", static_cast<double>(stl.triangles()))
        .num("stl_size_s", stl_size_seconds);

    bool ok = true;
    struct Outcome {
        double triangles = 0, open = 0, p50 = NAN;
    } result[3];
    const struct {
        const char *tag, *name;
        const Grid *grid;
    } cases[] = {{"a", "dense", &dense}, {"b", "simplified", &simp}, {"c", "stl", &stl}};
    for (const auto &c : cases) {
        if (cases_arg.find(c.tag) == std::string::npos) continue;
        const Restrictions r = sample_field(*c.grid, spacing, scale);
        nglib::Ng_Mesh *mesh = nglib::Ng_NewMesh();
        auto mp = params(r.hmax, grading);
        t0 = now();
        const bool set = nglib::Ng_OCC_SetLocalMeshSize(geo, mesh, &mp) == nglib::NG_OK;
        const double local_h_s = now() - t0;
        t0 = now();
        std::vector<double> p(3);
        for (size_t i = 0; i < r.h.size(); i++) {
            p.assign(&r.xyz[3 * i], &r.xyz[3 * i] + 3);
            nglib::Ng_RestrictMeshSizePoint(mesh, p.data(), r.h[i]);
        }
        const double restrict_s = now() - t0;
        t0 = now();
        const double c0 = cpu_now();
        const bool edges = set && nglib::Ng_OCC_GenerateEdgeMesh(geo, mesh, &mp) == nglib::NG_OK;
        const double edge_s = now() - t0;
        const bool surface = edges && nglib::Ng_OCC_GenerateSurfaceMesh(geo, mesh, &mp) == nglib::NG_OK;
        const double seconds = now() - t0, cpu = cpu_now() - c0;
        size_t open = 0, others = 0;
        const std::vector<double> tris = triangles(mesh, scale, &open, &others);
        const size_t nt = tris.size() / 9, nodes = static_cast<size_t>(nglib::Ng_GetNP(mesh));
        // Not freed: Ng_DeleteMesh of a surface-meshed OCC mesh crashes in
        // ~Mesh in this Netgen version (free of an invalid pointer); the
        // process ends after the three cases.
        const EdgeRatio q = EdgeRatio::of(dense, tris);
        // Against the field Netgen was given (the same as q for the dense grid).
        const EdgeRatio own = c.grid == &dense ? q : EdgeRatio::of(*c.grid, tris);
        const std::string k = c.name;
        out.num(k + "_triangles", static_cast<double>(nt))
            .num(k + "_nodes", static_cast<double>(nodes))
            .num(k + "_open_edges", static_cast<double>(open))
            .num(k + "_other_elements", static_cast<double>(others))
            .num(k + "_points", static_cast<double>(r.h.size()))
            .num(k + "_local_h_s", local_h_s)
            .num(k + "_restrict_s", restrict_s)
            .num(k + "_edge_s", edge_s)
            .num(k + "_seconds", seconds)
            .num(k + "_cpu_s", cpu)
            .num(k + "_ratio_mean", q.mean)
            .num(k + "_ratio_p5", q.p5)
            .num(k + "_ratio_p50", q.p50)
            .num(k + "_ratio_p95", q.p95)
            .num(k + "_own_ratio_p5", own.p5)
            .num(k + "_own_ratio_p50", own.p50)
            .num(k + "_own_ratio_p95", own.p95)
            .boolean(k + "_ok", surface);
        std::fprintf(stderr,
                     "(%s) %-10s %8zu triangles %8zu nodes %6zu open edges  %zu points  local h %.3f s"
                     "  restrict %.3f s  meshing %.3f s (edges %.3f, CPU %.3f)  edge/h_dense mean %.3f p5 %.3f "
                     "p50 %.3f p95 %.3f (own grid: p5 %.3f p50 %.3f p95 %.3f)%s\n",
                     c.tag, c.name, nt, nodes, open, r.h.size(), local_h_s, restrict_s, seconds, edge_s, cpu, q.mean,
                     q.p5, q.p50, q.p95, own.p5, own.p50, own.p95, surface ? "" : "  (Netgen reported an error)");
        if (nt == 0 || !surface) ok = false;
        result[&c - cases] = {static_cast<double>(nt), static_cast<double>(open), q.p50};
    }
    if (check_on) {
        const Outcome &a = result[0], &b = result[1];
        const bool tri_ok = a.triangles > 0 && std::fabs(b.triangles / a.triangles - 1) <= tri_tol;
        const bool closed_ok = a.open > 0 || b.open == 0;
        auto in = [&](double x) { return x >= p50_lo && x <= p50_hi; };
        const bool p50_ok = in(a.p50) && in(b.p50) && std::fabs(b.p50 - a.p50) <= p50_step;
        out.num("check_triangle_tolerance", tri_tol)
            .num("check_p50_low", p50_lo)
            .num("check_p50_high", p50_hi)
            .num("check_p50_step", p50_step)
            .boolean("check_triangles", tri_ok && closed_ok)
            .boolean("check_p50", p50_ok);
        std::fprintf(stderr,
                     "check: simplified / dense triangles %.4f (within ±%.3g: %s), open edges %.0f vs %.0f (%s); "
                     "edge/h_dense p50 %.3f, %.3f in [%.2f, %.2f], apart by at most %.2f: %s\n",
                     a.triangles > 0 ? b.triangles / a.triangles : NAN, tri_tol, tri_ok ? "yes" : "NO", b.open,
                     a.open, closed_ok ? "ok" : "NO: a closed surface came out open", a.p50, b.p50, p50_lo, p50_hi,
                     p50_step, p50_ok ? "yes" : "NO");
        ok = ok && tri_ok && closed_ok && p50_ok;
    }
    nglib::Ng_OCC_DeleteGeometry(geo);
    nglib::Ng_Exit();
    out.boolean("ok", ok).print();
    if (!ok) std::fprintf(stderr, "netgen_mesh: a case produced no triangles, Netgen reported an error or the check failed\n");
    return ok ? 0 : 1;
}
