/* Query semantics: a linear field is reproduced exactly; hinted == unhinted;
   batch == single; volume mode is bounded by the surface field. */
#include <math.h>
#include <stdlib.h>
#include "check.h"

static double field(const double *p) { return 0.5 + 0.25 * p[0] - 0.125 * p[1] + 2.0 * p[2]; }

/* Deterministic pseudo-random numbers in [0, 1). */
static double rnd(unsigned long long *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

int main(void) {
    /* A bent plate: z = 0.3 * x so all three coordinates vary. */
    enum { N = 20, NV = (N + 1) * (N + 1), NT = 2 * N * N, M = 2000 };
    static double xyz[3 * NV], sizes[NV];
    static uint32_t tris[3 * NT];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) {
        xyz[3 * i + 2] = 0.3 * xyz[3 * i];
        sizes[i] = field(&xyz[3 * i]);
    }
    abgs_grid *g = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_OK);

    /* On-surface points: exact to 1e-12 relative. */
    unsigned long long seed = 42;
    int exact = 1;
    for (int k = 0; k < M; k++) {
        double p[3] = {rnd(&seed), rnd(&seed), 0.0};
        p[2] = 0.3 * p[0];
        double s = 0;
        if (abgs_query_size(g, p, &s) != ABGS_OK || fabs(s - field(p)) > 1e-12 * fabs(field(p))) exact = 0;
    }
    CHECK(exact);

    /* Off-surface points along a coherent walk: hinted == unhinted, bit for bit;
       the answer equals the field at the reported closest point. */
    static double pts[3 * M], single[M], batch[M];
    uint32_t hint = ABGS_NO_HINT;
    int same = 1, at_closest = 1;
    double x = 0.1, y = 0.1;
    for (int k = 0; k < M; k++) {
        x += 0.01 * (rnd(&seed) - 0.3);
        y += 0.01 * (rnd(&seed) - 0.3);
        double *p = &pts[3 * k];
        p[0] = x; p[1] = y; p[2] = 0.3 * x + 0.2 * (rnd(&seed) - 0.5);
        double s1 = 0, s2 = 0;
        CHECK(abgs_query_size(g, p, &s1) == ABGS_OK);
        CHECK(abgs_query_size_hinted(g, p, &hint, &s2) == ABGS_OK);
        if (memcmp(&s1, &s2, sizeof s1) != 0) same = 0;
        abgs_hit h = {.struct_size = sizeof h};
        CHECK(abgs_query_closest(g, p, ABGS_NO_HINT, &h) == ABGS_OK);
        if (fabs(h.size - field(h.point)) > 1e-12 * field(h.point) || memcmp(&h.size, &s1, sizeof s1) != 0) at_closest = 0;
        single[k] = s1;
    }
    CHECK(same);
    CHECK(at_closest);

    /* Batch equals single, bit for bit. */
    CHECK_STATUS(abgs_query_sizes(g, pts, M, batch), ABGS_OK);
    CHECK(memcmp(single, batch, sizeof single) == 0);

    /* Volume mode: H(x) <= h(closest) + ln(beta) * dist, equality on the surface,
       and the batch equals single queries. */
    double beta = 1.2, vol[M];
    int bounded = 1;
    for (int k = 0; k < M; k++) {
        abgs_hit h = {.struct_size = sizeof h};
        double v = 0;
        CHECK(abgs_query_closest(g, &pts[3 * k], ABGS_NO_HINT, &h) == ABGS_OK);
        CHECK(abgs_query_size_volume(g, &pts[3 * k], beta, &v) == ABGS_OK);
        if (v > h.size + log(beta) * h.distance + 1e-12) bounded = 0;
        vol[k] = v;
    }
    CHECK(bounded);
    double vb[M];
    CHECK_STATUS(abgs_query_sizes_volume(g, pts, M, beta, vb), ABGS_OK);
    CHECK(memcmp(vol, vb, sizeof vol) == 0);

    CHECK_STATUS(abgs_grid_free(g), ABGS_OK);
    return finish();
}
