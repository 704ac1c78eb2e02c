/*
 * gmsh_size_callback.c: Gmsh meshes a CAD model (STEP) with abgs as its size field.
 *
 * abgs answers Gmsh's size callback
 *     double cb(int dim, int tag, double x, double y, double z, double lc, void *data)
 * with abgs_query_size_hinted on a background grid. Gmsh may call it from
 * several threads at once (General.NumThreads / Mesh.MaxNumThreads2D): queries
 * on one grid are thread-safe, and each thread keeps its own hint (a
 * _Thread_local variable), so consecutive points of one front start their
 * search where the last one ended.
 *
 * Needs Gmsh's C API: gmshc.h and libgmsh.so (e.g. the `gmsh==4.15.2` wheel
 * from PyPI ships both: <venv>/include/gmshc.h, <venv>/lib/libgmsh.so.4.15).
 * Build with CMake (examples_c/CMakeLists.txt, -DGMSH_ROOT=<venv>), or:
 *   cc -std=c11 -O2 examples_c/gmsh_size_callback.c $(pkg-config --cflags --libs abgs) \
 *      -I<venv>/include <venv>/lib/libgmsh.so.4.15 -Wl,-rpath,<venv>/lib -o gmsh_size_callback
 * Run:
 *   ./gmsh_size_callback MODEL.step GRID [THREADS]
 *   GRID     a background grid with sizes (.abgs, or .vtk from `abgs size`), or a
 *            surface without sizes (e.g. the model's STL), whose sizes are then
 *            computed with the library defaults
 *   THREADS  Gmsh's threads (default 1)
 * Prints the triangles, nodes and meshing time, the callback's calls, and how
 * closely the mesh follows the field (edge length / size at the edge midpoint).
 * Exit status: 0 on success, 1 when meshing failed or made no triangle, 2 on bad usage.
 */
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "abgs.h"
#include "gmshc.h"

/* What the callback needs and counts. */
typedef struct {
    const abgs_grid *grid;
    atomic_ullong calls;
    atomic_ullong failures;
} field;

/* One hint per thread: the triangle of this thread's last answer. */
static _Thread_local uint32_t tl_hint = ABGS_NO_HINT;

/* Gmsh's size callback: the abgs size at (x, y, z), never above Gmsh's own lc. */
static double size_callback(int dim, int tag, double x, double y, double z, double lc, void *data) {
    (void)dim;
    (void)tag;
    field *f = data;
    const double p[3] = {x, y, z};
    double h = lc;
    atomic_fetch_add_explicit(&f->calls, 1, memory_order_relaxed);
    if (abgs_query_size_hinted(f->grid, p, &tl_hint, &h) != ABGS_OK) {
        atomic_fetch_add_explicit(&f->failures, 1, memory_order_relaxed);
        return lc;
    }
    return h < lc ? h : lc;
}

static double now(void) {
    struct timespec t;
    timespec_get(&t, TIME_UTC);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int abgs_ok(abgs_status st, const char *what) {
    if (st == ABGS_OK) return 1;
    fprintf(stderr, "%s failed: %s (%s)\n", what, abgs_status_name((int)st), abgs_last_error_message());
    return 0;
}

static int gmsh_ok(int ierr, const char *what) {
    if (ierr == 0) return 1;
    char *msg = NULL;
    int e2 = 0;
    gmshLoggerGetLastError(&msg, &e2);
    fprintf(stderr, "%s failed (%d): %s\n", what, ierr, msg ? msg : "");
    if (msg) gmshFree(msg);
    return 0;
}

static int set_number(const char *name, double v) {
    int ierr = 0;
    gmshOptionSetNumber(name, v, &ierr);
    return gmsh_ok(ierr, name);
}

/* Edge length / size at the edge midpoint over every triangle edge (the mesh
 * follows the field when this is near 1): prints the mean and the range. */
static int report_fit(const abgs_grid *grid) {
    int ierr = 0;
    size_t *ntags = NULL, ntags_n = 0, *etags = NULL, etags_n = 0, *tnodes = NULL, tnodes_n = 0;
    double *coord = NULL, *pc = NULL;
    size_t coord_n = 0, pc_n = 0;
    gmshModelMeshGetNodes(&ntags, &ntags_n, &coord, &coord_n, &pc, &pc_n, -1, -1, 0, 0, &ierr);
    if (!gmsh_ok(ierr, "gmshModelMeshGetNodes")) return 0;
    gmshModelMeshGetElementsByType(2, &etags, &etags_n, &tnodes, &tnodes_n, -1, 0, 1, &ierr);
    if (!gmsh_ok(ierr, "gmshModelMeshGetElementsByType")) return 0;
    size_t max_tag = 0;
    for (size_t i = 0; i < ntags_n; i++) max_tag = ntags[i] > max_tag ? ntags[i] : max_tag;
    size_t *where = malloc((max_tag + 1) * sizeof *where);
    double *mid = malloc(3 * (tnodes_n + 1) * sizeof *mid), *h = malloc((tnodes_n + 1) * sizeof *h);
    double *len = malloc((tnodes_n + 1) * sizeof *len);
    int good = where && mid && h && len;
    if (good) {
        for (size_t i = 0; i < ntags_n; i++) where[ntags[i]] = i;
        for (size_t t = 0; t + 2 < tnodes_n; t += 3)
            for (int e = 0; e < 3; e++) {
                const double *a = &coord[3 * where[tnodes[t + (size_t)e]]];
                const double *b = &coord[3 * where[tnodes[t + (size_t)(e + 1) % 3]]];
                double l2 = 0.0;
                for (int k = 0; k < 3; k++) {
                    mid[3 * (t + (size_t)e) + (size_t)k] = 0.5 * (a[k] + b[k]);
                    l2 += (a[k] - b[k]) * (a[k] - b[k]);
                }
                len[t + (size_t)e] = sqrt(l2);
            }
        good = abgs_ok(abgs_query_sizes(grid, mid, tnodes_n, h), "abgs_query_sizes");
    }
    if (good && tnodes_n > 0) {
        double sum = 0.0, lo = INFINITY, hi = 0.0;
        for (size_t i = 0; i < tnodes_n; i++) {
            double r = len[i] / h[i];
            sum += r;
            lo = r < lo ? r : lo;
            hi = r > hi ? r : hi;
        }
        printf("edge length / size at its midpoint: mean %.3f, min %.3f, max %.3f (%zu edges)\n",
               sum / (double)tnodes_n, lo, hi, tnodes_n);
    }
    free(where);
    free(mid);
    free(h);
    free(len);
    gmshFree(ntags);
    gmshFree(coord);
    gmshFree(pc);
    gmshFree(etags);
    gmshFree(tnodes);
    return good;
}

int main(int argc, char **argv) {
    if (argc < 3 || argc > 4) {
        fprintf(stderr, "usage: %s MODEL.step GRID [THREADS]\n", argc > 0 ? argv[0] : "gmsh_size_callback");
        return 2;
    }
    const int threads = argc > 3 ? atoi(argv[3]) : 1;
    if (threads < 1) {
        fprintf(stderr, "THREADS must be >= 1\n");
        return 2;
    }

    /* The background grid, with sizes. */
    abgs_grid *grid = NULL;
    if (!abgs_ok(abgs_grid_load(argv[2], &grid), "abgs_grid_load")) return 1;
    abgs_grid_stats st = {.struct_size = sizeof st};
    if (!abgs_ok(abgs_grid_get_stats(grid, &st), "abgs_grid_get_stats")) return 1;
    if (!st.has_sizes) {
        abgs_size_params sp = {.struct_size = sizeof sp};
        abgs_size_report sr = {.struct_size = sizeof sr};
        if (!abgs_ok(abgs_size_params_default(&sp), "abgs_size_params_default") ||
            !abgs_ok(abgs_compute_size(grid, &sp, &sr), "abgs_compute_size") ||
            !abgs_ok(abgs_grid_get_stats(grid, &st), "abgs_grid_get_stats"))
            return 1;
        printf("sizes computed on %s\n", argv[2]);
    }
    printf("background grid %s: %llu triangles, sizes %g to %g\n", argv[2], (unsigned long long)st.triangles,
           st.size_min, st.size_max);

    int ierr = 0, rc = 1;
    gmshInitialize(0, NULL, 0, 0, &ierr);
    if (!gmsh_ok(ierr, "gmshInitialize")) return 1;
    field f = {.grid = grid};
    atomic_init(&f.calls, 0);
    atomic_init(&f.failures, 0);
    /* Only the callback sizes the mesh; MeshSizeMin > 0 and a looser
     * geometric tolerance let some STEP files (tiny edges, gaps) mesh. */
    if (!set_number("General.Terminal", 1) || !set_number("General.Verbosity", 2) ||
        !set_number("General.NumThreads", threads) || !set_number("Mesh.MaxNumThreads2D", threads) ||
        !set_number("Geometry.Tolerance", 1e-6) || !set_number("Mesh.MeshSizeMin", 0.5 * st.size_min) ||
        !set_number("Mesh.MeshSizeFromPoints", 0) || !set_number("Mesh.MeshSizeFromCurvature", 0) ||
        !set_number("Mesh.MeshSizeExtendFromBoundary", 0))
        goto done;
    gmshModelAdd("cad", &ierr);
    if (!gmsh_ok(ierr, "gmshModelAdd")) goto done;
    int *dim_tags = NULL;
    size_t dim_tags_n = 0;
    gmshModelOccImportShapes(argv[1], &dim_tags, &dim_tags_n, 1, "", &ierr);
    gmshFree(dim_tags);
    if (!gmsh_ok(ierr, "gmshModelOccImportShapes")) goto done;
    gmshModelOccSynchronize(&ierr);
    if (!gmsh_ok(ierr, "gmshModelOccSynchronize")) goto done;
    gmshModelMeshSetSizeCallback(size_callback, &f, &ierr);
    if (!gmsh_ok(ierr, "gmshModelMeshSetSizeCallback")) goto done;

    double t0 = now();
    gmshModelMeshGenerate(2, &ierr);
    double seconds = now() - t0;
    if (!gmsh_ok(ierr, "gmshModelMeshGenerate")) goto done;

    size_t *etags = NULL, etags_n = 0, *enodes = NULL, enodes_n = 0;
    gmshModelMeshGetElementsByType(2, &etags, &etags_n, &enodes, &enodes_n, -1, 0, 1, &ierr);
    gmshFree(etags);
    gmshFree(enodes);
    if (!gmsh_ok(ierr, "gmshModelMeshGetElementsByType")) goto done;
    unsigned long long calls = atomic_load(&f.calls), failures = atomic_load(&f.failures);
    printf("gmsh: %zu triangles in %.3f s with %d thread%s; size callback: %llu calls, %llu failed\n", etags_n,
           seconds, threads, threads == 1 ? "" : "s", calls, failures);
    if (!report_fit(grid)) goto done;
    rc = etags_n > 0 && failures == 0 ? 0 : 1;
done:
    gmshFinalize(&ierr);
    abgs_grid_free(grid);
    return rc;
}
