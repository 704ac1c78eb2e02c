/* Sizing through the C ABI: defaults, compute, gradation, LBO, edges, and
   every error path. */
#include <math.h>
#include <stdlib.h>
#include "check.h"

int main(void) {
    /* A bumpy plate: z = 0.05 sin(8x) so curvature varies. */
    enum { N = 16, NV = (N + 1) * (N + 1), NT = 2 * N * N };
    static double xyz[3 * NV], sizes[NV];
    static uint32_t tris[3 * NT];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) xyz[3 * i + 2] = 0.05 * sin(8.0 * xyz[3 * i]);

    abgs_size_params p = {.struct_size = sizeof p};
    CHECK_STATUS(abgs_size_params_default(&p), ABGS_OK);
    CHECK(p.n_circle == 24.0 && p.n_gap == 3.0 && p.beta == 1.2 && p.slope == 0.0);
    CHECK(p.hmin == 0.0 && p.hmax == 0.0 && p.feature_angle_deg == 30.0);
    CHECK(p.curvature == 1 && p.proximity == 1 && p.gradation == 1 && p.sources == NULL && p.n_sources == 0);
    CHECK_STATUS(abgs_size_params_default(NULL), ABGS_ERR_NULL);

    abgs_grid *g = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_OK);

    /* Queries fail before sizes exist; gradation and LBO too. */
    double lv[NV];
    CHECK_STATUS(abgs_apply_gradation(g, 1.2, 0.0, NULL), ABGS_ERR_NO_SIZES);
    CHECK_STATUS(abgs_lbo(g, lv, NV, NULL, 0), ABGS_ERR_NO_SIZES);

    /* Compute with a point source in the middle. */
    abgs_size_source src = {.struct_size = sizeof src, .kind = ABGS_SOURCE_POINT,
                           .points = {0.5, 0.5, 0.05 * sin(4.0)}, .size = 0.002, .radius = 0.05};
    p.sources = &src;
    p.n_sources = 1;
    abgs_size_report r = {.struct_size = sizeof r};
    CHECK_STATUS(abgs_compute_size(g, &p, &r), ABGS_OK);
    CHECK(r.hmin > 0.0 && r.hmax > r.hmin && fabs(r.slope - log(1.2)) < 1e-15);
    CHECK(r.limited_by_source >= 1 && r.limited_by_curvature > 0);
    CHECK(r.max_slope_ratio <= 1.0 + 1e-9);
    CHECK(r.seconds_gradation >= 0.0);
    CHECK_STATUS(abgs_grid_copy_sizes(g, sizes, NV), ABGS_OK);
    int in_range = 1;
    for (int i = 0; i < NV; i++)
        if (!(sizes[i] >= r.hmin && sizes[i] <= r.hmax)) in_range = 0;
    CHECK(in_range);
    double centre[3] = {0.5, 0.5, 0.05 * sin(4.0)}, hc = 0;
    CHECK_STATUS(abgs_query_size(g, centre, &hc), ABGS_OK);
    CHECK(fabs(hc - 0.002) < 1e-12);
    /* NULL report is fine. */
    CHECK_STATUS(abgs_compute_size(g, &p, NULL), ABGS_OK);

    /* Parameter errors leave the sizes untouched. */
    abgs_size_params bad = p;
    bad.n_circle = 0.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.hmin = 2.0; bad.hmax = 1.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.beta = 1.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.slope = NAN;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.slope = -1.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.hmax = NAN;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.n_sources = 3; bad.sources = NULL;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_NULL);
    abgs_size_source s2 = src;
    bad = p; bad.sources = &s2;
    s2.kind = 7;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    s2 = src; s2.size = 0.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_SIZE);
    s2 = src; s2.points[1] = INFINITY;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_NON_FINITE);
    s2 = src; s2.radius = -1.0;
    CHECK_STATUS(abgs_compute_size(g, &bad, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_compute_size(NULL, &p, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_compute_size(g, NULL, NULL), ABGS_ERR_NULL);
    double after[NV];
    CHECK_STATUS(abgs_grid_copy_sizes(g, after, NV), ABGS_OK);
    CHECK(memcmp(after, sizes, sizeof sizes) == 0);

    /* Gradation on user sizes: a spike is smoothed, nothing rises. */
    for (int i = 0; i < NV; i++) sizes[i] = 0.2;
    sizes[NV / 2] = 0.001;
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV), ABGS_OK);
    uint64_t fixed = 12345;
    CHECK_STATUS(abgs_apply_gradation(g, 1.2, 0.0, &fixed), ABGS_OK);
    CHECK(fixed != 12345);
    CHECK_STATUS(abgs_grid_copy_sizes(g, after, NV), ABGS_OK);
    int below = 1, smoothed = 0;
    for (int i = 0; i < NV; i++) {
        if (after[i] > sizes[i]) below = 0;
        if (after[i] < 0.2) smoothed++;
    }
    CHECK(below && smoothed > 1);
    CHECK_STATUS(abgs_apply_gradation(g, 0.9, 0.0, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_apply_gradation(g, 1.2, -0.5, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_apply_gradation(g, NAN, 0.0, NULL), ABGS_ERR_NON_FINITE);
    CHECK_STATUS(abgs_apply_gradation(g, 1.0, 0.1, NULL), ABGS_OK); /* slope overrides beta */
    CHECK_STATUS(abgs_apply_gradation(NULL, 1.2, 0.0, NULL), ABGS_ERR_NULL);

    /* Edges and LBO: a linear field has zero LBO at interior vertices. */
    size_t ne = 0;
    CHECK_STATUS(abgs_grid_edge_count(g, &ne), ABGS_OK);
    CHECK(ne == (size_t)(3 * N * N + 2 * N));
    uint32_t *edges = malloc(2 * ne * sizeof *edges);
    double *le = malloc(ne * sizeof *le);
    CHECK_STATUS(abgs_grid_copy_edges(g, edges, 2 * ne - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_grid_copy_edges(g, edges, 2 * ne), ABGS_OK);
    int sorted = 1;
    for (size_t e = 0; e < ne; e++) {
        if (edges[2 * e] >= edges[2 * e + 1]) sorted = 0;
        if (e > 0 && (edges[2 * e - 2] > edges[2 * e] || (edges[2 * e - 2] == edges[2 * e] && edges[2 * e - 1] >= edges[2 * e + 1]))) sorted = 0;
    }
    CHECK(sorted);
    abgs_grid *flat = NULL;
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) sizes[i] = 0.1 + 0.05 * xyz[3 * i] + 0.02 * xyz[3 * i + 1];
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &flat), ABGS_OK);
    CHECK_STATUS(abgs_lbo(flat, lv, NV, le, ne), ABGS_OK);
    int zero = 1;
    for (int j = 1; j < N; j++)
        for (int i = 1; i < N; i++)
            if (fabs(lv[j * (N + 1) + i]) > 1e-9) zero = 0;
    CHECK(zero);
    CHECK_STATUS(abgs_lbo(flat, NULL, 0, le, ne), ABGS_OK);
    CHECK_STATUS(abgs_lbo(flat, NULL, 0, NULL, 0), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_lbo(flat, lv, NV - 1, NULL, 0), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_lbo(flat, NULL, 0, le, ne - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_lbo(NULL, lv, NV, NULL, 0), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_edge_count(NULL, &ne), ABGS_ERR_NULL);

    free(edges);
    free(le);
    CHECK_STATUS(abgs_grid_free(flat), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(g), ABGS_OK);
    return finish();
}
