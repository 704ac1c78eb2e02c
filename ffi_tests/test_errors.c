/* Every error path returns its status and leaves a message; nothing crashes. */
#include <math.h>
#include "check.h"

int main(int argc, char **argv) {
    const char *tmpdir = argc > 1 ? argv[1] : ".";
    enum { N = 4, NV = (N + 1) * (N + 1), NT = 2 * N * N };
    double xyz[3 * NV], sizes[NV];
    uint32_t tris[3 * NT];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) sizes[i] = 1.0;
    abgs_grid *g = NULL;

    /* NULL pointers. */
    CHECK_STATUS(abgs_grid_from_arrays(NULL, NV, tris, NT, NULL, &g), ABGS_ERR_NULL);
    CHECK(g == NULL);
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, NULL, NT, NULL, &g), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_load(NULL, &g), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_query_size(NULL, xyz, sizes), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_get_stats(NULL, NULL), ABGS_ERR_NULL);

    /* Empty input, out-of-range index. */
    CHECK_STATUS(abgs_grid_from_arrays(xyz, 0, tris, NT, NULL, &g), ABGS_ERR_EMPTY);
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, 0, NULL, &g), ABGS_ERR_EMPTY);
    tris[5] = NV; /* one past the end */
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_ERR_OUT_OF_RANGE);
    tris[5] = 0xFFFFFFFFu;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_ERR_OUT_OF_RANGE);
    make_plate(N, xyz, tris);

    /* NaN / inf coordinates. */
    xyz[7] = NAN;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_ERR_NON_FINITE);
    xyz[7] = INFINITY;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_ERR_NON_FINITE);
    make_plate(N, xyz, tris);

    /* Sizes <= 0 or NaN. */
    sizes[3] = 0.0;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_ERR_INVALID_SIZE);
    sizes[3] = -1.0;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_ERR_INVALID_SIZE);
    sizes[3] = NAN;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_ERR_INVALID_SIZE);
    sizes[3] = 1.0;
    CHECK(g == NULL);

    /* A grid without sizes answers geometry but not sizes. */
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &g), ABGS_OK);
    double p[3] = {0.5, 0.5, 0.5}, s = -1.0;
    CHECK_STATUS(abgs_query_size(g, p, &s), ABGS_ERR_NO_SIZES);
    CHECK(s == -1.0);
    abgs_hit hit = {.struct_size = sizeof hit};
    CHECK_STATUS(abgs_query_closest(g, p, ABGS_NO_HINT, &hit), ABGS_OK);
    CHECK(hit.distance == 0.5 && isnan(hit.size));
    double sc[NV];
    CHECK_STATUS(abgs_grid_copy_sizes(g, sc, NV), ABGS_ERR_NO_SIZES);

    /* Wrong array lengths and bad sizes on set_sizes: the grid is unchanged. */
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV - 1), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV + 1), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_grid_set_sizes(g, NULL, NV), ABGS_ERR_NULL);
    sizes[0] = -2.0;
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV), ABGS_ERR_INVALID_SIZE);
    CHECK_STATUS(abgs_query_size(g, p, &s), ABGS_ERR_NO_SIZES);
    sizes[0] = 1.0;
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV), ABGS_OK);

    /* Buffers too small. */
    double v[3 * NV];
    uint32_t t[3 * NT];
    CHECK_STATUS(abgs_grid_copy_vertices(g, v, 3 * NV - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_grid_copy_triangles(g, t, 3 * NT - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_grid_copy_sizes(g, sc, NV - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_grid_copy_vertices(g, NULL, 3 * NV), ABGS_ERR_NULL);

    /* Query arguments. */
    double bad[3] = {0.0, NAN, 0.0};
    CHECK_STATUS(abgs_query_size(g, bad, &s), ABGS_ERR_NON_FINITE);
    CHECK_STATUS(abgs_query_size(g, NULL, &s), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_query_size(g, p, NULL), ABGS_ERR_NULL);
    uint32_t hint = 123456789u; /* out of range: ignored, then replaced */
    CHECK_STATUS(abgs_query_size_hinted(g, p, &hint, &s), ABGS_OK);
    CHECK(hint < NT && s == 1.0);
    CHECK_STATUS(abgs_query_size_hinted(g, p, NULL, &s), ABGS_ERR_NULL);
    double pts[6] = {0.1, 0.1, 0.0, 0.2, NAN, 0.0}, outs[2] = {-1.0, -1.0};
    CHECK_STATUS(abgs_query_sizes(g, pts, 2, outs), ABGS_ERR_NON_FINITE);
    CHECK(outs[0] == -1.0 && outs[1] == -1.0);
    CHECK_STATUS(abgs_query_sizes(g, NULL, 2, outs), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_query_sizes(g, pts, 0, NULL), ABGS_OK);
    CHECK_STATUS(abgs_query_size_volume(g, p, 1.0, &s), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_query_size_volume(g, p, 0.5, &s), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_query_size_volume(g, p, NAN, &s), ABGS_ERR_NON_FINITE);
    CHECK_STATUS(abgs_query_sizes_volume(g, pts, 2, INFINITY, outs), ABGS_ERR_NON_FINITE);

    /* Files: unreadable, unknown extension, garbage content, unwritable. */
    abgs_grid *h = NULL;
    CHECK_STATUS(abgs_grid_load("/nonexistent/dir/none.stl", &h), ABGS_ERR_IO);
    CHECK(h == NULL);
    CHECK_STATUS(abgs_grid_load("grid.xyz", &h), ABGS_ERR_UNSUPPORTED_FORMAT);
    char path[1024];
    snprintf(path, sizeof path, "%s/garbage.off", tmpdir);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("OFF\n3 1 0\n0 0 0\n1 0 0\n", f); /* truncated */
        fclose(f);
        CHECK_STATUS(abgs_grid_load(path, &h), ABGS_ERR_PARSE);
        CHECK(h == NULL);
    }
    snprintf(path, sizeof path, "%s/badindex.off", tmpdir);
    f = fopen(path, "w");
    if (f) {
        fputs("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", f);
        fclose(f);
        abgs_status st = abgs_grid_load(path, &h);
        CHECK(st == ABGS_ERR_PARSE || st == ABGS_ERR_OUT_OF_RANGE);
    }
    CHECK_STATUS(abgs_grid_save(g, "/nonexistent/dir/out.vtk"), ABGS_ERR_IO);
    CHECK_STATUS(abgs_grid_save(g, "out.unknown"), ABGS_ERR_UNSUPPORTED_FORMAT);

    /* Status names are stable. */
    CHECK(strcmp(abgs_status_name(ABGS_ERR_BUSY), "ABGS_ERR_BUSY") == 0);
    CHECK(strcmp(abgs_status_name(12345), "ABGS_UNKNOWN_STATUS") == 0);

    CHECK_STATUS(abgs_grid_free(g), ABGS_OK);
    return finish();
}
