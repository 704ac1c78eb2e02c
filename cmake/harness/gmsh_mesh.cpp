// gmsh_mesh STEP --dense DENSE --simplified SIMPLIFIED --stl STL [--threads T]
//           [--work DIR] [--samples N]
//
// Gmsh (C API of the pip wheel) meshes the surfaces (dimension 2) of a STEP
// model with abgs as its size field, the paper's Tables 1-2:
//   (a) dense       size callback: abgs_query_size_hinted on the dense grid
//   (b) simplified  size callback on the simplified grid
//   (c) stl         size callback on the raw STL triangles, sizes computed and
//                   graded on the STL vertices (abgs_compute_size, defaults, as
//                   `abgs run` uses on the dense grid)
//   (d) postview    no callback: the dense grid written by abgs_grid_save as MSH
//                   (one $NodeData view per point array), merged into its own
//                   model; the view named "size" is a PostView background field
// Mesh.MeshSizeFromPoints, MeshSizeFromCurvature and MeshSizeExtendFromBoundary
// are 0 in every case. The callback keeps one hint per thread and counts calls
// and the time spent inside it (atomics: Gmsh may call it from several threads;
// General.NumThreads = T, default 1).
// For each case: triangles, nodes, meshing time (wall clock and the process's
// CPU time: one thread, so CPU time is the steadier number on a shared
// machine), callback calls and time, and
// how the mesh follows the dense field: edge length / h_dense(midpoint) (mean,
// 5th, 50th and 95th percentiles). The size deviation and estimated element count of
// the (b) and (c) fields against the dense one come from abgs_evaluate.
// When the STEP's extent differs from the grids' by more than a factor 2 (units:
// a STEP in mm beside an STL in inches), Geometry.OCCScaling is set to the
// nearest power-of-ten or 25.4 factor.
// Prints progress on stderr and one JSON object on stdout.
// Every surface of the STEP must get triangles (on an assembly, each solid's
// faces are meshed on their own, the touching ones twice: no tolerance or
// minimum size was needed on gmsh_bracket_assembly's 16 solids).
// Exit status: 0 every case meshed, 1 a case produced no triangles, a surface
// none, or a callback query failed, 2 error.
#include "gmsh_step.hpp"
#include "harness.hpp"

#include <atomic>

using namespace harness;

namespace {

/// What the size callback measures.
struct Callback {
    const abgs_grid *grid = nullptr;
    int generation = 0;
    std::atomic<uint64_t> calls{0}, nanos{0}, failures{0};
};

thread_local uint32_t tl_hint = ABGS_NO_HINT;
thread_local int tl_generation = -1;

double size_callback(int, int, double x, double y, double z, double lc, void *data) {
    auto *cb = static_cast<Callback *>(data);
    auto t0 = std::chrono::steady_clock::now();
    if (tl_generation != cb->generation) {
        tl_hint = ABGS_NO_HINT;
        tl_generation = cb->generation;
    }
    const double p[3] = {x, y, z};
    double h = lc;
    if (abgs_query_size_hinted(cb->grid, p, &tl_hint, &h) != ABGS_OK) {
        cb->failures.fetch_add(1, std::memory_order_relaxed);
        h = lc;
    }
    auto dt = std::chrono::steady_clock::now() - t0;
    cb->calls.fetch_add(1, std::memory_order_relaxed);
    cb->nanos.fetch_add(static_cast<uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(dt).count()),
                        std::memory_order_relaxed);
    return std::min(h, lc);
}

/// Triangles of the current model's mesh as node coordinates (9 doubles each).
std::vector<double> mesh_triangles(size_t *n_nodes) {
    int ierr = 0;
    size_t *ntags = nullptr, ntags_n = 0, *etags = nullptr, etags_n = 0, *tnodes = nullptr, tnodes_n = 0;
    double *coord = nullptr, *pc = nullptr;
    size_t coord_n = 0, pc_n = 0;
    gmshModelMeshGetNodes(&ntags, &ntags_n, &coord, &coord_n, &pc, &pc_n, -1, -1, 0, 0, &ierr);
    gcheck(ierr, "gmshModelMeshGetNodes");
    gmshModelMeshGetElementsByType(2, &etags, &etags_n, &tnodes, &tnodes_n, -1, 0, 1, &ierr);
    gcheck(ierr, "gmshModelMeshGetElementsByType");
    size_t max_tag = 0;
    for (size_t i = 0; i < ntags_n; i++) max_tag = std::max(max_tag, ntags[i]);
    std::vector<size_t> where(max_tag + 1, SIZE_MAX);
    for (size_t i = 0; i < ntags_n; i++) where[ntags[i]] = i;
    std::vector<double> out;
    out.reserve(3 * tnodes_n);
    for (size_t i = 0; i < tnodes_n; i++) {
        size_t k = tnodes[i] <= max_tag ? where[tnodes[i]] : SIZE_MAX;
        if (k == SIZE_MAX) {
            std::fprintf(stderr, "triangle node %zu has no coordinates\n", tnodes[i]);
            std::exit(2);
        }
        out.insert(out.end(), {coord[3 * k], coord[3 * k + 1], coord[3 * k + 2]});
    }
    *n_nodes = ntags_n;
    gmshFree(ntags);
    gmshFree(coord);
    gmshFree(pc);
    gmshFree(etags);
    gmshFree(tnodes);
    return out;
}

}  // namespace

int main(int argc, char **argv) {
    Args args(argc, argv);
    if (args.pos.size() != 1 || !args.has("dense") || !args.has("simplified") || !args.has("stl")) {
        std::fprintf(stderr, "usage: gmsh_mesh STEP --dense DENSE --simplified SIMPLIFIED --stl STL [--threads T] "
                             "[--work DIR] [--samples N]\n");
        return 2;
    }
    const std::string step = args.pos[0], dense_path = args.str("dense", "");
    const int threads = static_cast<int>(args.num("threads", 1));
    std::string work = args.str("work", "");
    if (work.empty()) {
        size_t s = dense_path.find_last_of('/');
        work = s == std::string::npos ? "." : dense_path.substr(0, s);
    }
    abgs_eval_params ep{};
    ep.struct_size = sizeof ep;
    check(abgs_eval_params_default(&ep), "abgs_eval_params_default");
    ep.samples = ep.hausdorff_samples = static_cast<uint64_t>(args.num("samples", 100000));

    Grid dense, simp, stl;
    dense.load(dense_path);
    simp.load(args.str("simplified", ""));
    stl.load(args.str("stl", ""));
    abgs_size_params sp{};
    sp.struct_size = sizeof sp;
    check(abgs_size_params_default(&sp), "abgs_size_params_default");
    abgs_size_report sr = versioned<abgs_size_report>();
    double t0 = now();
    check(abgs_compute_size(stl.g, &sp, &sr), "abgs_compute_size (STL)");
    const double stl_size_seconds = now() - t0;
    stl.refresh();
    abgs_evaluation e_simp{}, e_stl{};
    e_simp.struct_size = e_stl.struct_size = sizeof(abgs_evaluation);
    check(abgs_evaluate(dense.g, simp.g, &ep, &e_simp), "abgs_evaluate (simplified)");
    check(abgs_evaluate(dense.g, stl.g, &ep, &e_stl), "abgs_evaluate (STL)");
    const std::string msh = work + "/dense_background.msh";
    t0 = now();
    check(abgs_grid_save(dense.g, msh.c_str()), "abgs_grid_save (MSH)");
    const double msh_write = now() - t0;

    int ierr = 0;
    gmshInitialize(0, nullptr, 0, 0, &ierr);
    gcheck(ierr, "gmshInitialize");
    set_number("General.Terminal", 1);
    set_number("General.Verbosity", 1);
    set_number("General.NumThreads", threads);
    set_number("Mesh.MaxNumThreads2D", threads);
    set_number("Mesh.MeshSizeFromPoints", 0);
    set_number("Mesh.MeshSizeFromCurvature", 0);
    set_number("Mesh.MeshSizeExtendFromBoundary", 0);

    // Units: compare the STEP's extent with the grids'.
    import_step(step);
    const double occ_scale = unit_scale(dense.stats.diagonal, step_diagonal());
    if (occ_scale != 1.0) {
        std::fprintf(stderr, "STEP extent / grid extent = %.4g: Geometry.OCCScaling = %.6g\n",
                     step_diagonal() / dense.stats.diagonal, occ_scale);
        set_number("Geometry.OCCScaling", occ_scale);
    }
    gmshClear(&ierr);
    gcheck(ierr, "gmshClear");

    Json out;
    out.str("step", step)
        .num("threads", threads)
        .num("occ_scale", occ_scale)
        .num("dense_faces", static_cast<double>(dense.triangles()))
        .num("simplified_faces", static_cast<double>(simp.triangles()))
        .num("stl_faces", static_cast<double>(stl.triangles()))
        .num("stl_size_s", stl_size_seconds)
        .num("msh_write_s", msh_write)
        .evaluation("field_simplified_", e_simp)
        .evaluation("field_stl_", e_stl);

    Callback cb;
    bool ok = true;
    const struct {
        const char *name;
        const Grid *grid;
    } cases[] = {{"dense", &dense}, {"simplified", &simp}, {"stl", &stl}, {"postview", nullptr}};
    for (const auto &c : cases) {
        gmshClear(&ierr);
        gcheck(ierr, "gmshClear");
        double setup = 0.0;
        if (c.grid) {
            cb.grid = c.grid->g;
            cb.generation++;
            cb.calls = 0;
            cb.nanos = 0;
            cb.failures = 0;
            import_step(step);
            gmshModelMeshSetSizeCallback(size_callback, &cb, &ierr);
            gcheck(ierr, "gmshModelMeshSetSizeCallback");
        } else {
            gmshModelMeshRemoveSizeCallback(&ierr);
            gcheck(ierr, "gmshModelMeshRemoveSizeCallback");
            t0 = now();
            gmshModelAdd("background", &ierr);
            gcheck(ierr, "gmshModelAdd");
            gmshMerge(msh.c_str(), &ierr);
            gcheck(ierr, "gmshMerge");
            int *tags = nullptr;
            size_t tags_n = 0;
            gmshViewGetTags(&tags, &tags_n, &ierr);
            gcheck(ierr, "gmshViewGetTags");
            // One view per point array of the grid: take the one named "size".
            int view = -1;
            for (size_t i = 0; i < tags_n && view < 0; i++) {
                char *name = nullptr;
                gmshViewOptionGetString(tags[i], "Name", &name, &ierr);
                gcheck(ierr, "gmshViewOptionGetString");
                if (name && std::string(name) == "size") view = tags[i];
                gmshFree(name);
            }
            gmshFree(tags);
            if (view < 0) {
                std::fprintf(stderr, "no view named \"size\" among the %zu of %s\n", tags_n, msh.c_str());
                return 2;
            }
            setup = now() - t0;
            import_step(step);
            int field = gmshModelMeshFieldAdd("PostView", -1, &ierr);
            gcheck(ierr, "gmshModelMeshFieldAdd");
            gmshModelMeshFieldSetNumber(field, "ViewTag", view, &ierr);
            gcheck(ierr, "gmshModelMeshFieldSetNumber");
            gmshModelMeshFieldSetAsBackgroundMesh(field, &ierr);
            gcheck(ierr, "gmshModelMeshFieldSetAsBackgroundMesh");
        }
        t0 = now();
        const double c0 = cpu_now();
        gmshModelMeshGenerate(2, &ierr);
        const double seconds = now() - t0, cpu = cpu_now() - c0;
        gcheck(ierr, "gmshModelMeshGenerate");
        size_t nodes = 0;
        std::vector<double> tris = mesh_triangles(&nodes);
        const size_t nt = tris.size() / 9, surfaces = entity_count(2), empty = empty_surfaces();
        const EdgeRatio q = EdgeRatio::of(dense, tris);
        const double cb_s = c.grid ? static_cast<double>(cb.nanos.load()) * 1e-9 : 0.0;
        const double calls = c.grid ? static_cast<double>(cb.calls.load()) : 0.0;
        std::string k = c.name;
        out.num(k + "_triangles", static_cast<double>(nt))
            .num(k + "_nodes", static_cast<double>(nodes))
            .num(k + "_surfaces", static_cast<double>(surfaces))
            .num(k + "_empty_surfaces", static_cast<double>(empty))
            .num(k + "_seconds", seconds)
            .num(k + "_cpu_s", cpu)
            .num(k + "_setup_s", setup)
            .num(k + "_calls", calls)
            .num(k + "_callback_s", cb_s)
            .num(k + "_callback_failures", c.grid ? static_cast<double>(cb.failures.load()) : 0.0)
            .num(k + "_ratio_mean", q.mean)
            .num(k + "_ratio_p5", q.p5)
            .num(k + "_ratio_p50", q.p50)
            .num(k + "_ratio_p95", q.p95);
        std::fprintf(stderr,
                     "(%s) %-10s %8zu triangles %8zu nodes  meshing %.3f s  callback %.0f calls %.3f s (%.0f ns/call)"
                     "  edge/h_dense mean %.3f p5 %.3f p50 %.3f p95 %.3f%s\n",
                     c.grid ? (c.grid == &dense ? "a" : c.grid == &simp ? "b" : "c") : "d", c.name, nt, nodes,
                     seconds, calls, cb_s, calls > 0 ? 1e9 * cb_s / calls : 0.0, q.mean, q.p5, q.p50, q.p95,
                     c.grid ? "" : "  (no callback: PostView background field)");
        if (empty) std::fprintf(stderr, "(%s) %zu of %zu surfaces got no triangle\n", c.name, empty, surfaces);
        if (nt == 0 || empty || (c.grid && cb.failures.load() > 0)) ok = false;
    }
    gmshFinalize(&ierr);
    out.boolean("ok", ok).print();
    if (!ok) std::fprintf(stderr, "gmsh_mesh: a case produced no triangles, a surface none, or a callback query failed\n");
    return ok ? 0 : 1;
}
