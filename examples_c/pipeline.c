/* The whole abgs pipeline from C: a CAD surface (STL, OBJ, ...) -> dense
 * background grid -> sizing field -> LBO-ABGS simplification (with a progress
 * bar) -> evaluation against the dense grid -> a few queries -> saved grid.
 *
 * Build (from the repository, after `cargo build --release --lib`):
 *   cc -std=c11 -O2 -Iinclude examples_c/pipeline.c -Ltarget/release -labgs \
 *      -Wl,-rpath,$PWD/target/release -o pipeline
 * Run:
 *   ./pipeline INPUT OUTPUT.vtk [RELATIVE_LENGTH]
 * RELATIVE_LENGTH is the dense grid's edge length as a fraction of the
 * bounding-box diagonal (default 0.01). Every struct is initialised with its
 * struct_size first, as the header's ABI rules ask.
 */
#include <stdio.h>
#include <stdlib.h>

#include "abgs.h"

/* Prints the failure and returns 0 when `st` is not ABGS_OK. */
static int ok(abgs_status st, const char *what) {
    if (st == ABGS_OK) return 1;
    fprintf(stderr, "%s failed: %s (%s)\n", what, abgs_status_name((int)st), abgs_last_error_message());
    return 0;
}

/* Progress callback: redraws one bar line per iteration; return 0 to go on. */
static int32_t progress(const abgs_iteration_record *r, void *user) {
    const uint64_t faces_in = *(const uint64_t *)user;
    int width = 40, filled = (int)(width * (1.0 - (double)r->faces / (double)faces_in));
    if (filled < 0) filled = 0;
    if (filled > width) filled = width;
    char bar[41];
    for (int i = 0; i < width; i++) bar[i] = i < filled ? '#' : '.';
    bar[width] = '\0';
    printf("\r  iteration %3llu [%s] %8llu faces, %6llu collapses", (unsigned long long)r->iteration,
           bar, (unsigned long long)r->faces, (unsigned long long)r->accepted);
    fflush(stdout);
    return 0;
}

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: %s INPUT OUTPUT.vtk [RELATIVE_LENGTH]\n", argv[0]);
        return 2;
    }
    int rc = 1;
    abgs_grid *input = NULL, *dense = NULL, *coarse = NULL;

    if (!ok(abgs_grid_load(argv[1], &input), "abgs_grid_load")) goto done;

    /* Dense grid: isotropic remeshing, features kept. */
    abgs_remesh_params rp = {.struct_size = sizeof rp};
    abgs_remesh_params_default(&rp);
    if (argc > 3) rp.relative_length = atof(argv[3]);
    abgs_remesh_report rr = {.struct_size = sizeof rr};
    if (!ok(abgs_grid_remesh(input, NULL, &rp, &dense, &rr), "abgs_grid_remesh")) goto done;
    printf("dense grid: %llu -> %llu faces, %llu feature lines, %.2f s\n", (unsigned long long)rr.faces_in,
           (unsigned long long)rr.faces_out, (unsigned long long)rr.feature_lines, rr.seconds);

    /* Sizing field: curvature, proximity, gradation. */
    abgs_size_params sp = {.struct_size = sizeof sp};
    abgs_size_params_default(&sp);
    abgs_size_report sr = {.struct_size = sizeof sr};
    if (!ok(abgs_compute_size(dense, &sp, &sr), "abgs_compute_size")) goto done;
    printf("sizes: h in [%g, %g], gradation slope %.4f\n", sr.hmin, sr.hmax, sr.slope);

    /* LBO-ABGS simplification with a progress bar. */
    abgs_simplify_params mp = {.struct_size = sizeof mp};
    abgs_simplify_params_default(&mp);
    uint64_t faces_in = rr.faces_out;
    mp.progress = progress;
    mp.user_data = &faces_in;
    abgs_simplify_report mr = {.struct_size = sizeof mr};
    abgs_status st = abgs_simplify(dense, &mp, &coarse, &mr);
    printf("\n");
    if (!ok(st, "abgs_simplify")) goto done;
    printf("simplified: %llu -> %llu faces in %llu iterations, %.2f s\n", (unsigned long long)mr.faces_in,
           (unsigned long long)mr.faces_out, (unsigned long long)mr.iterations, mr.seconds);

    /* How faithful is the coarse grid to the dense one? */
    abgs_eval_params ep = {.struct_size = sizeof ep};
    abgs_eval_params_default(&ep);
    ep.samples = ep.hausdorff_samples = 20000;
    abgs_evaluation ev = {.struct_size = sizeof ev};
    if (!ok(abgs_evaluate(dense, coarse, &ep, &ev), "abgs_evaluate")) goto done;
    printf("evaluation: reduction %.1f %%, size deviation p95 %.3f, Hausdorff %.3g %% of the diagonal\n",
           100.0 * ev.reduction, ev.size_deviation_p95, 100.0 * ev.hausdorff_relative);

    /* Queries: a hinted walk along the bounding-box diagonal. */
    abgs_grid_stats gs = {.struct_size = sizeof gs};
    if (!ok(abgs_grid_get_stats(coarse, &gs), "abgs_grid_get_stats")) goto done;
    uint32_t hint = ABGS_NO_HINT;
    for (int i = 0; i <= 4; i++) {
        double t = i / 4.0, p[3], h = 0.0;
        for (int k = 0; k < 3; k++) p[k] = gs.bbox_min[k] + t * (gs.bbox_max[k] - gs.bbox_min[k]);
        if (!ok(abgs_query_size_hinted(coarse, p, &hint, &h), "abgs_query_size_hinted")) goto done;
        printf("  size at (%g, %g, %g) = %g\n", p[0], p[1], p[2], h);
    }

    if (!ok(abgs_grid_save(coarse, argv[2]), "abgs_grid_save")) goto done;
    printf("wrote %s\n", argv[2]);
    rc = 0;
done:
    abgs_grid_free(coarse);
    abgs_grid_free(dense);
    abgs_grid_free(input);
    return rc;
}
