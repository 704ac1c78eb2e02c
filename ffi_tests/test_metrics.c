/* Metrics through the C ABI: defaults, abgs_evaluate, abgs_hausdorff and
   abgs_hausdorff_directed on tiny plates with known answers, and every error
   path. */
#include <math.h>
#include "check.h"

enum { NF = 8, NVF = (NF + 1) * (NF + 1), NTF = 2 * NF * NF };
enum { NC = 2, NVC = (NC + 1) * (NC + 1), NTC = 2 * NC * NC };

static int near(double a, double b, double tol) { return fabs(a - b) <= tol; }

/* Sizes linear in x: h = 0.1 + 0.1 x (reproduced exactly by any triangulation). */
static void linear_sizes(const double *xyz, int nv, double *h) {
    for (int i = 0; i < nv; i++) h[i] = 0.1 + 0.1 * xyz[3 * i];
}

int main(void) {
    static double xf[3 * NVF], hf[NVF], xc[3 * NVC], hc[NVC], xs[3 * NVF], h2[NVF];
    static uint32_t tf[3 * NTF], tc[3 * NTC];
    make_plate(NF, xf, tf);
    make_plate(NC, xc, tc);
    linear_sizes(xf, NVF, hf);
    linear_sizes(xc, NVC, hc);
    for (int i = 0; i < NVF; i++) h2[i] = 2.0 * hf[i];

    abgs_eval_params p = {.struct_size = sizeof p};
    CHECK_STATUS(abgs_eval_params_default(&p), ABGS_OK);
    CHECK(p.samples == 100000 && p.hausdorff_samples == 100000 && p.seed == 1);
    CHECK_STATUS(abgs_eval_params_default(NULL), ABGS_ERR_NULL);
    p.samples = 20000;
    p.hausdorff_samples = 20000;

    abgs_grid *fine = NULL, *coarse = NULL, *doubled = NULL, *bare = NULL, *lifted = NULL, *patch = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xf, NVF, tf, NTF, hf, &fine), ABGS_OK);
    CHECK_STATUS(abgs_grid_from_arrays(xc, NVC, tc, NTC, hc, &coarse), ABGS_OK);
    CHECK_STATUS(abgs_grid_from_arrays(xf, NVF, tf, NTF, h2, &doubled), ABGS_OK);
    CHECK_STATUS(abgs_grid_from_arrays(xf, NVF, tf, NTF, NULL, &bare), ABGS_OK);
    /* The fine plate lifted to z = 0.25, and its lower-left quarter [0, 0.5]^2. */
    for (int i = 0; i < NVF; i++) {
        xs[3 * i] = xf[3 * i];
        xs[3 * i + 1] = xf[3 * i + 1];
        xs[3 * i + 2] = 0.25;
    }
    CHECK_STATUS(abgs_grid_from_arrays(xs, NVF, tf, NTF, hf, &lifted), ABGS_OK);
    for (int i = 0; i < NVF; i++) {
        xs[3 * i] = 0.5 * xf[3 * i];
        xs[3 * i + 1] = 0.5 * xf[3 * i + 1];
        xs[3 * i + 2] = 0.0;
    }
    CHECK_STATUS(abgs_grid_from_arrays(xs, NVF, tf, NTF, NULL, &patch), ABGS_OK);

    /* A grid against itself: nothing changes. */
    abgs_evaluation e = {.struct_size = sizeof e};
    CHECK_STATUS(abgs_evaluate(fine, fine, &p, &e), ABGS_OK);
    CHECK(e.faces_reference == NTF && e.faces_candidate == NTF);
    CHECK(e.vertices_reference == NVF && e.vertices_candidate == NVF);
    CHECK(e.reduction == 0.0);
    CHECK(near(e.size_deviation_mean, 1.0, 1e-14) && near(e.size_deviation_max, 1.0, 1e-14));
    CHECK(near(e.size_deviation_p95, 1.0, 1e-14) && near(e.size_deviation_p99, 1.0, 1e-14));
    CHECK(e.size_deviation_samples == 20000);
    CHECK(e.wrong_sheet == 0.0);
    CHECK(e.contact_reference.samples == 0 && e.contact_reference.share == 0.0);
    CHECK(e.contact_candidate.samples == 0 && e.contact_candidate.max == 0.0);
    CHECK(e.hausdorff < 1e-15 && e.hausdorff_relative < 1e-15);
    CHECK(near(e.diagonal, sqrt(2.0), 1e-15));
    CHECK(fabs(e.element_count_change) < 1e-12);
    /* (4/√3) ∫ (0.1 + 0.1x)^-2 dx dy over [0,1]^2 = (4/√3) · 100 · (1 - 1/2);
       the degree-5 rule on 1/h² over 8 columns is within 1e-6 of it. */
    double expected = 4.0 / sqrt(3.0) * 50.0;
    CHECK(near(e.element_count_reference, expected, 1e-6 * expected));
    CHECK(near(e.elements_per_cell, e.element_count_candidate / NTF, 1e-15 * expected));
    CHECK(near(e.elements_per_cell, e.elements_per_cell_reference, 1e-12 * expected));
    if (!near(e.element_count_reference, expected, 1e-6 * expected))
        fprintf(stderr, "element count %.12g, expected %.12g\n", e.element_count_reference, expected);
    CHECK(near(e.angles_reference.min, 45.0, 1e-9) && near(e.angles_reference.max, 90.0, 1e-9));
    CHECK(near(e.angles_candidate.mean_min, 45.0, 1e-9) && e.angles_candidate.max_p99 >= 89.999);
    CHECK(e.seconds >= 0.0);

    /* The coarse plate reproduces the linear field: deviation 1, Hausdorff 0. */
    CHECK_STATUS(abgs_evaluate(fine, coarse, &p, &e), ABGS_OK);
    CHECK(e.faces_candidate == NTC && near(e.reduction, 1.0 - (double)NTC / NTF, 1e-15));
    CHECK(near(e.size_deviation_max, 1.0, 1e-12) && near(e.size_deviation_mean, 1.0, 1e-12));
    CHECK(e.hausdorff < 1e-12);
    CHECK(near(e.element_count_candidate, expected, 1e-6 * expected));
    /* Fewer cells for the same elements. */
    CHECK(near(e.elements_per_cell, e.element_count_candidate / NTC, 1e-12 * expected));
    CHECK(e.elements_per_cell > e.elements_per_cell_reference);
    CHECK(fabs(e.element_count_change) < 1e-9);

    /* Doubled sizes: the ratio is 2 everywhere, a quarter of the elements. */
    CHECK_STATUS(abgs_evaluate(fine, doubled, &p, &e), ABGS_OK);
    CHECK(near(e.size_deviation_mean, 2.0, 1e-12) && near(e.size_deviation_p95, 2.0, 1e-12));
    CHECK(near(e.size_deviation_max, 2.0, 1e-12));
    CHECK(near(e.element_count_change, -0.75, 1e-12));

    /* Deterministic: the same call gives the same bits. */
    abgs_evaluation e2 = {.struct_size = sizeof e2};
    CHECK_STATUS(abgs_evaluate(fine, doubled, &p, &e2), ABGS_OK);
    CHECK(e2.size_deviation_mean == e.size_deviation_mean && e2.element_count_candidate == e.element_count_candidate);

    /* Two coincident plates as two bodies, one with twice the other's sizes:
       every point lies on both, and their sizes differ by 100 % everywhere;
       a query there reads the smaller (the tie rule). */
    {
        static double x2[6 * NVF], hh[2 * NVF];
        static uint32_t t2[6 * NTF];
        for (int i = 0; i < 3 * NVF; i++) x2[i] = x2[3 * NVF + i] = xf[i];
        for (int i = 0; i < 3 * NTF; i++) {
            t2[i] = tf[i];
            t2[3 * NTF + i] = tf[i] + NVF;
        }
        for (int i = 0; i < NVF; i++) {
            hh[i] = hf[i];
            hh[NVF + i] = h2[i];
        }
        abgs_grid *pair = NULL;
        CHECK_STATUS(abgs_grid_from_arrays(x2, 2 * NVF, t2, 2 * NTF, hh, &pair), ABGS_OK);
        CHECK_STATUS(abgs_evaluate(pair, pair, &p, &e), ABGS_OK);
        CHECK(e.contact_reference.share == 1.0 && e.contact_reference.samples == p.samples);
        CHECK(near(e.contact_reference.p50, 1.0, 1e-12) && near(e.contact_reference.max, 1.0, 1e-12));
        CHECK(e.contact_reference.over_10 == 1.0);
        CHECK(e.contact_candidate.p95 == e.contact_reference.p95);
        double q[3] = {0.3, 0.6, 0.0}, hq = 0.0;
        CHECK_STATUS(abgs_query_size(pair, q, &hq), ABGS_OK);
        CHECK(near(hq, 0.1 + 0.1 * 0.3, 1e-15));
        CHECK_STATUS(abgs_grid_free(pair), ABGS_OK);
    }

    /* Hausdorff: the plate lifted by 0.25 is 0.25 away either way. */
    double d = -1.0, d1 = -1.0, d2 = -1.0;
    CHECK_STATUS(abgs_hausdorff(fine, lifted, 1000, 7, &d), ABGS_OK);
    CHECK(near(d, 0.25, 1e-15));
    CHECK_STATUS(abgs_evaluate(fine, lifted, &p, &e), ABGS_OK);
    CHECK(near(e.hausdorff, 0.25, 1e-15) && near(e.hausdorff_relative, 0.25 / sqrt(2.0), 1e-15));
    /* One-sided: the quarter lies on the plate (0); the plate's far corner
       (1, 1) is sqrt(0.5) from the quarter's corner (0.5, 0.5). */
    CHECK_STATUS(abgs_hausdorff_directed(patch, fine, 1000, 7, &d1), ABGS_OK);
    CHECK(d1 < 1e-15);
    CHECK_STATUS(abgs_hausdorff_directed(fine, patch, 1000, 7, &d2), ABGS_OK);
    CHECK(near(d2, sqrt(0.5), 1e-15));
    CHECK_STATUS(abgs_hausdorff(patch, fine, 1000, 7, &d), ABGS_OK);
    CHECK(d == d2);
    /* Sizes are not needed for the Hausdorff distance. */
    CHECK_STATUS(abgs_hausdorff(bare, patch, 10, 1, &d), ABGS_OK);

    /* Errors. */
    CHECK_STATUS(abgs_evaluate(NULL, fine, &p, &e), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_evaluate(fine, NULL, &p, &e), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_evaluate(fine, fine, NULL, &e), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_evaluate(fine, fine, &p, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_evaluate(fine, bare, &p, &e), ABGS_ERR_NO_SIZES);
    CHECK_STATUS(abgs_evaluate(bare, fine, &p, &e), ABGS_ERR_NO_SIZES);
    abgs_eval_params bad = p;
    bad.samples = 0;
    CHECK_STATUS(abgs_evaluate(fine, fine, &bad, &e), ABGS_ERR_INVALID_ARGUMENT);
    bad = p;
    bad.hausdorff_samples = 0;
    CHECK_STATUS(abgs_evaluate(fine, fine, &bad, &e), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_hausdorff(NULL, fine, 10, 1, &d), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff(fine, NULL, 10, 1, &d), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff(fine, fine, 10, 1, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff(fine, fine, 0, 1, &d), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_hausdorff_directed(NULL, fine, 10, 1, &d), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff_directed(fine, NULL, 10, 1, &d), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff_directed(fine, fine, 10, 1, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_hausdorff_directed(fine, fine, 0, 1, &d), ABGS_ERR_INVALID_ARGUMENT);

    abgs_grid *all[] = {fine, coarse, doubled, bare, lifted, patch};
    for (int i = 0; i < 6; i++) CHECK_STATUS(abgs_grid_free(all[i]), ABGS_OK);
    return finish();
}
