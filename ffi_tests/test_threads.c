/* Eight threads querying one grid at once get exactly the single-thread answers. */
#include <math.h>
#include <pthread.h>
#include <stdlib.h>
#include "check.h"

enum { N = 40, NV = (N + 1) * (N + 1), NT = 2 * N * N, M = 20000, THREADS = 8 };
static double xyz[3 * NV], sizes[NV], pts[3 * M], reference[M], results[THREADS][M];
static uint32_t tris[3 * NT];
static abgs_grid *grid;
static int errors[THREADS];

static void *worker(void *arg) {
    int id = (int)(size_t)arg;
    uint32_t hint = ABGS_NO_HINT;
    for (int k = 0; k < M; k++) {
        /* Alternate the three query kinds. */
        abgs_status st;
        if (k % 3 == 0) st = abgs_query_size(grid, &pts[3 * k], &results[id][k]);
        else if (k % 3 == 1) st = abgs_query_size_hinted(grid, &pts[3 * k], &hint, &results[id][k]);
        else st = abgs_query_sizes(grid, &pts[3 * k], 1, &results[id][k]);
        if (st != ABGS_OK) errors[id]++;
    }
    return NULL;
}

int main(void) {
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) {
        double u = xyz[3 * i], v = xyz[3 * i + 1];
        xyz[3 * i + 2] = 0.2 * sin(6.0 * u) * cos(4.0 * v);
        sizes[i] = 0.05 + 0.5 * u * u + 0.1 * v;
    }
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &grid), ABGS_OK);
    unsigned long long s = 7;
    for (int k = 0; k < 3 * M; k++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        pts[k] = 1.4 * (double)(s >> 11) / 9007199254740992.0 - 0.2;
    }
    for (int k = 0; k < M; k++) CHECK(abgs_query_size(grid, &pts[3 * k], &reference[k]) == ABGS_OK);

    pthread_t th[THREADS];
    for (int t = 0; t < THREADS; t++) CHECK(pthread_create(&th[t], NULL, worker, (void *)(size_t)t) == 0);
    for (int t = 0; t < THREADS; t++) pthread_join(th[t], NULL);
    for (int t = 0; t < THREADS; t++) {
        CHECK(errors[t] == 0);
        CHECK(memcmp(results[t], reference, sizeof reference) == 0);
    }
    /* The parallel batch equals the reference too. */
    static double batch[M];
    CHECK_STATUS(abgs_query_sizes(grid, pts, M, batch), ABGS_OK);
    CHECK(memcmp(batch, reference, sizeof reference) == 0);
    CHECK_STATUS(abgs_grid_free(grid), ABGS_OK);
    return finish();
}
