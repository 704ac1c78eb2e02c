/* Lifecycle: version, build from arrays, stats, copy-out, save/load, free. */
#include <math.h>
#include <stdlib.h>
#include "check.h"

int main(int argc, char **argv) {
    const char *tmpdir = argc > 1 ? argv[1] : ".";
    CHECK(abgs_version_number() == ABGS_VERSION_MAJOR * 10000 + ABGS_VERSION_MINOR * 100 + ABGS_VERSION_PATCH);
    char expect[32];
    snprintf(expect, sizeof expect, "%d.%d.%d", ABGS_VERSION_MAJOR, ABGS_VERSION_MINOR, ABGS_VERSION_PATCH);
    CHECK(strcmp(abgs_version(), expect) == 0);

    enum { N = 8, NV = (N + 1) * (N + 1), NT = 2 * N * N };
    double xyz[3 * NV], sizes[NV];
    uint32_t tris[3 * NT];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) sizes[i] = 0.1 + xyz[3 * i];

    abgs_grid *g = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_OK);
    CHECK(g != NULL);
    abgs_grid_stats st = {.struct_size = sizeof st};
    CHECK_STATUS(abgs_grid_get_stats(g, &st), ABGS_OK);
    CHECK(st.vertices == NV && st.triangles == NT && st.bodies == 1);
    CHECK(st.boundary_edges == 4 * N && st.non_manifold_edges == 0);
    CHECK(st.has_sizes == 1 && st.size_min == 0.1 && st.size_max == 1.1);
    CHECK(fabs(st.diagonal - sqrt(2.0)) < 1e-15);
    CHECK(st.memory_bytes > 0);

    size_t nv = 0, nt = 0;
    CHECK_STATUS(abgs_grid_vertex_count(g, &nv), ABGS_OK);
    CHECK_STATUS(abgs_grid_triangle_count(g, &nt), ABGS_OK);
    CHECK(nv == NV && nt == NT);
    double vcopy[3 * NV], scopy[NV];
    uint32_t tcopy[3 * NT];
    CHECK_STATUS(abgs_grid_copy_vertices(g, vcopy, 3 * nv), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_triangles(g, tcopy, 3 * nt), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_sizes(g, scopy, nv), ABGS_OK);
    CHECK(memcmp(vcopy, xyz, sizeof xyz) == 0);
    CHECK(memcmp(tcopy, tris, sizeof tris) == 0);
    CHECK(memcmp(scopy, sizes, sizeof sizes) == 0);

    /* Save in every writable format that keeps sizes, load back, compare. */
    const char *exts[] = {"vtk", "vtu", "msh", "ply", "mesh"};
    for (size_t e = 0; e < sizeof exts / sizeof exts[0]; e++) {
        char path[1024];
        snprintf(path, sizeof path, "%s/lifecycle.%s", tmpdir, exts[e]);
        CHECK_STATUS(abgs_grid_save(g, path), ABGS_OK);
        abgs_grid *h = NULL;
        CHECK_STATUS(abgs_grid_load(path, &h), ABGS_OK);
        if (!h) continue;
        double v2[3 * NV], s2[NV];
        CHECK_STATUS(abgs_grid_copy_vertices(h, v2, 3 * NV), ABGS_OK);
        CHECK_STATUS(abgs_grid_copy_sizes(h, s2, NV), ABGS_OK);
        CHECK(memcmp(v2, xyz, sizeof xyz) == 0);
        CHECK(memcmp(s2, sizes, sizeof sizes) == 0);
        CHECK_STATUS(abgs_grid_free(h), ABGS_OK);
    }

    /* New sizes replace the old ones. */
    for (int i = 0; i < NV; i++) sizes[i] = 2.0;
    CHECK_STATUS(abgs_grid_set_sizes(g, sizes, NV), ABGS_OK);
    double p[3] = {0.3, 0.3, 1.0}, s = 0;
    CHECK_STATUS(abgs_query_size(g, p, &s), ABGS_OK);
    CHECK(s == 2.0);

    CHECK_STATUS(abgs_grid_free(g), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(NULL), ABGS_OK);
    return finish();
}
