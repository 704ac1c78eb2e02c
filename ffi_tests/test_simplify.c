/* Simplification through the C ABI: defaults, LBO-ABGS on a plate with a
   size ramp, the report and per-iteration records, the progress callback and
   cancelling from it, per-edge scores, and every error path. */
#include <math.h>
#include <stdlib.h>
#include "check.h"

#define N 40
#define NV ((N + 1) * (N + 1))
#define NT (2 * N * N)

struct progress_state {
    int calls;
    int stop_after;
    uint64_t last_faces;
    abgs_grid *input; /* the grid being simplified, read-held by the call */
    const double *sizes;
    int busy_checked;
};

static int32_t on_progress(const abgs_iteration_record *r, void *user) {
    struct progress_state *s = (struct progress_state *)user;
    s->calls++;
    CHECK(r != NULL && r->iteration == (uint64_t)s->calls);
    CHECK(r->faces < NT && r->accepted > 0 && r->element_count > 0.0);
    s->last_faces = r->faces;
    CHECK(r->struct_size == sizeof *r);
    if (s->input != NULL) {
        /* The call holds its input: mutating it or freeing it is BUSY (and
           frees nothing), reading it still works. */
        CHECK_STATUS(abgs_grid_set_sizes(s->input, s->sizes, NV), ABGS_ERR_BUSY);
        CHECK(strstr(abgs_last_error_message(), "in use") != NULL);
        CHECK_STATUS(abgs_grid_free(s->input), ABGS_ERR_BUSY);
        double q = 0.0, mid[3] = {0.5, 0.5, 0.0};
        CHECK_STATUS(abgs_query_size(s->input, mid, &q), ABGS_OK);
        s->busy_checked++;
    }
    return s->stop_after > 0 && s->calls >= s->stop_after;
}

int main(void) {
    abgs_simplify_params p = {.struct_size = sizeof p};
    CHECK_STATUS(abgs_simplify_params_default(&p), ABGS_OK);
    CHECK(p.method == ABGS_METHOD_LBO && p.fraction == 0.10 && p.pool_factor == 2.0);
    CHECK(p.t_size == 1.2 && p.tau_d == 0.0 && p.max_distance == 0.0);
    CHECK(p.beta == 1.2 && p.clearance_fraction == 0.25);
    CHECK(p.max_iterations == 1000 && p.repair == 1 && p.progress == NULL);
    CHECK(p.t_score == 0.5 && p.verify == 0);
    CHECK(p.selection == ABGS_SELECTION_BATCHED && p.fit_sizes == 1);
    CHECK_STATUS(abgs_simplify_params_default(NULL), ABGS_ERR_NULL);
    /* A struct whose struct_size was not set is refused, not overrun. */
    abgs_simplify_params z = {0};
    CHECK_STATUS(abgs_simplify_params_default(&z), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "struct_size") != NULL);
    CHECK(z.struct_size == 0 && z.fraction == 0.0);

    static double xyz[3 * NV];
    static uint32_t tris[3 * NT];
    static double h[NV];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) h[i] = 0.02 + 0.2 * xyz[3 * i];
    abgs_grid *dense = NULL, *out = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, NULL, &dense), ABGS_OK);

    /* No sizes yet. */
    CHECK_STATUS(abgs_simplify(dense, &p, &out, NULL), ABGS_ERR_NO_SIZES);
    CHECK(out == NULL);
    CHECK_STATUS(abgs_grid_set_sizes(dense, h, NV), ABGS_OK);

    /* Full run with a progress callback. */
    struct progress_state st = {0, 0, 0, dense, h, 0};
    p.progress = on_progress;
    p.user_data = &st;
    abgs_simplify_report r = {.struct_size = sizeof r};
    CHECK_STATUS(abgs_simplify(dense, &p, &out, &r), ABGS_OK);
    CHECK(out != NULL);
    CHECK(r.faces_in == NT && r.vertices_in == NV);
    /* a linear field on a square is exact on its two corner triangles */
    CHECK(r.faces_out < NT / 2 && r.faces_out >= 2);
    CHECK(r.stop == ABGS_STOP_CONVERGED);
    CHECK(r.iterations >= 2 && (int)r.iterations == st.calls + 1); /* the last selected nothing */
    CHECK(r.corners == 4 && r.feature_lines >= 4);
    CHECK(st.busy_checked == st.calls && r.struct_size == sizeof r);
    CHECK(r.element_count_in > 0.0 && fabs(r.element_count_out / r.element_count_in - 1.0) < 0.1);
    size_t nt = 0, nv = 0;
    CHECK_STATUS(abgs_grid_triangle_count(out, &nt), ABGS_OK);
    CHECK_STATUS(abgs_grid_vertex_count(out, &nv), ABGS_OK);
    CHECK(nt == r.faces_out && nv == r.vertices_out);
    /* Sizes come with the result and follow the ramp. */
    double q = 0.0;
    double mid[3] = {0.5, 0.5, 0.0};
    CHECK_STATUS(abgs_query_size(out, mid, &q), ABGS_OK);
    CHECK(fabs(q / 0.12 - 1.0) < 0.2);
    abgs_iteration_record rec = {.struct_size = sizeof rec};
    CHECK_STATUS(abgs_grid_simplify_iteration(out, 0, &rec), ABGS_OK);
    CHECK(rec.iteration == 1 && rec.accepted > 0 && rec.candidates >= rec.collapsible);
    CHECK_STATUS(abgs_grid_simplify_iteration(out, (size_t)r.iterations - 1, &rec), ABGS_OK);
    CHECK(rec.faces == r.faces_out && rec.accepted == 0);
    CHECK_STATUS(abgs_grid_simplify_iteration(out, (size_t)r.iterations, &rec), ABGS_ERR_OUT_OF_RANGE);
    CHECK_STATUS(abgs_grid_simplify_iteration(dense, 0, &rec), ABGS_ERR_OUT_OF_RANGE);
    CHECK_STATUS(abgs_grid_simplify_iteration(out, 0, NULL), ABGS_ERR_NULL);

    /* Cancel after two iterations: a valid, partly simplified grid. */
    abgs_grid *part = NULL;
    struct progress_state st2 = {0, 2, 0, NULL, NULL, 0};
    p.user_data = &st2;
    CHECK_STATUS(abgs_simplify(dense, &p, &part, &r), ABGS_OK);
    CHECK(part != NULL && r.stop == ABGS_STOP_CANCELLED && r.iterations == 2 && st2.calls == 2);
    CHECK(r.faces_out == st2.last_faces && r.faces_out < NT && r.faces_out > nt);
    CHECK_STATUS(abgs_query_size(part, mid, &q), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(part), ABGS_OK);
    p.progress = NULL;
    p.user_data = NULL;

    /* NULL params = defaults: the same result. */
    abgs_grid *again = NULL;
    CHECK_STATUS(abgs_simplify(dense, NULL, &again, &r), ABGS_OK);
    CHECK(r.faces_out == nt);
    CHECK_STATUS(abgs_grid_free(again), ABGS_OK);

    /* Edge scores, in the order of abgs_grid_copy_edges. */
    size_t ne = 0;
    CHECK_STATUS(abgs_grid_edge_count(dense, &ne), ABGS_OK);
    double *ds = malloc(ne * sizeof *ds), *dd = malloc(ne * sizeof *dd), *y = malloc(ne * sizeof *y);
    uint8_t *valid = malloc(ne);
    CHECK_STATUS(abgs_edge_scores(dense, &p, ds, dd, valid, y, ne), ABGS_OK);
    size_t n_valid = 0, n_coll = 0;
    for (size_t e = 0; e < ne; e++) {
        CHECK(y[e] >= 0.0 && y[e] <= 1.0);
        if (valid[e]) {
            n_valid++;
            double expect = 0.5 * fmax((ds[e] - 1.0) / 0.2, dd[e] / 0.05);
            if (expect > 1.0) expect = 1.0;
            CHECK(fabs(expect - y[e]) < 1e-12);
            CHECK(dd[e] < 1e-12); /* a plate: collapses stay on it */
            if (y[e] < 0.5) n_coll++;
        } else {
            CHECK(y[e] == 1.0 && isnan(ds[e]) && isnan(dd[e]));
        }
    }
    CHECK(n_valid > ne / 2 && n_coll > 0); /* a linear ramp on a plate: exact */
    CHECK_STATUS(abgs_edge_scores(dense, NULL, NULL, NULL, NULL, y, ne), ABGS_OK);
    CHECK_STATUS(abgs_edge_scores(dense, NULL, NULL, NULL, NULL, y, ne - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_edge_scores(NULL, NULL, NULL, NULL, NULL, y, ne), ABGS_ERR_NULL);

    /* Errors. */
    abgs_grid *none = NULL;
    CHECK_STATUS(abgs_simplify(NULL, &p, &none, NULL), ABGS_ERR_NULL);
    CHECK(none == NULL);
    CHECK_STATUS(abgs_simplify(dense, &p, NULL, NULL), ABGS_ERR_NULL);
    abgs_simplify_params bad = p;
    bad.method = ABGS_METHOD_GCN;
    bad.t_score = 1.5;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "t_score") != NULL);
    bad.t_score = NAN;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_NON_FINITE);
    bad.t_score = 0.5;
    bad.verify = 3;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "verify = 3") != NULL);
    CHECK(none == NULL);
    /* GCN-ABGS (the embedded model), with and without the exact check of its
       choices: fewer faces, sizes carried, and verify never keeps more than
       the model alone would let through. */
    for (uint32_t verify = 0; verify <= 1; verify++) {
        abgs_simplify_params g = p;
        g.method = ABGS_METHOD_GCN;
        g.verify = verify;
        abgs_grid *gout = NULL;
        abgs_simplify_report gr = {.struct_size = sizeof gr};
        CHECK_STATUS(abgs_simplify(dense, &g, &gout, &gr), ABGS_OK);
        CHECK(gout != NULL && gr.faces_in == NT && gr.faces_out < NT / 2);
        CHECK(gr.stop == ABGS_STOP_CONVERGED);
        double q = 0.0, mid[3] = {0.5, 0.5, 0.0};
        CHECK_STATUS(abgs_query_size(gout, mid, &q), ABGS_OK);
        CHECK(fabs(q - (0.02 + 0.2 * 0.5)) < 0.2 * (0.02 + 0.2 * 0.5));
        CHECK_STATUS(abgs_grid_free(gout), ABGS_OK);
    }
    bad.method = 7; /* no such method: checked, never taken as an enum */
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "method = 7") != NULL);
    bad = p;
    bad.fit_sizes = 2; /* a flag: 0 or 1 */
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "fit_sizes = 2") != NULL);
    /* Without the size fit each vertex keeps the ramp's value at its
       position; with it (the default) a linear field is fitted exactly: the
       same faces and, to the solver's tolerance, the same sizes. */
    {
        abgs_simplify_params f = p;
        f.fit_sizes = 0;
        abgs_grid *fout = NULL;
        abgs_simplify_report fr = {.struct_size = sizeof fr};
        CHECK_STATUS(abgs_simplify(dense, &f, &fout, &fr), ABGS_OK);
        CHECK(fr.faces_out == nt);
        size_t fv = 0;
        CHECK_STATUS(abgs_grid_vertex_count(fout, &fv), ABGS_OK);
        double *fx = malloc(3 * fv * sizeof *fx), *fh = malloc(fv * sizeof *fh);
        double *dh = malloc(nv * sizeof *dh), *dx = malloc(3 * nv * sizeof *dx);
        CHECK_STATUS(abgs_grid_copy_vertices(fout, fx, 3 * fv), ABGS_OK);
        CHECK_STATUS(abgs_grid_copy_sizes(fout, fh, fv), ABGS_OK);
        CHECK_STATUS(abgs_grid_copy_vertices(out, dx, 3 * nv), ABGS_OK);
        CHECK_STATUS(abgs_grid_copy_sizes(out, dh, nv), ABGS_OK);
        for (size_t i = 0; i < fv; i++) {
            double ramp = 0.02 + 0.2 * fx[3 * i];
            CHECK(fabs(fh[i] - ramp) <= 1e-12 * ramp);
        }
        for (size_t i = 0; i < nv; i++) {
            double ramp = 0.02 + 0.2 * dx[3 * i];
            CHECK(fabs(dh[i] - ramp) <= 1e-6 * ramp);
        }
        free(fx);
        free(fh);
        free(dh);
        free(dx);
        CHECK_STATUS(abgs_grid_free(fout), ABGS_OK);
    }
    bad = p;
    bad.selection = 2; /* no such selection */
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "selection = 2") != NULL);
    /* The paper's global selection: the same kind of grid. */
    {
        abgs_simplify_params g = p;
        g.selection = ABGS_SELECTION_GLOBAL;
        abgs_grid *gout = NULL;
        abgs_simplify_report gr = {.struct_size = sizeof gr};
        CHECK_STATUS(abgs_simplify(dense, &g, &gout, &gr), ABGS_OK);
        CHECK(gout != NULL && gr.faces_out < NT / 2 && gr.stop == ABGS_STOP_CONVERGED);
        double q = 0.0, mid[3] = {0.5, 0.5, 0.0};
        CHECK_STATUS(abgs_query_size(gout, mid, &q), ABGS_OK);
        CHECK(fabs(q - (0.02 + 0.2 * 0.5)) < 0.2 * (0.02 + 0.2 * 0.5));
        CHECK_STATUS(abgs_grid_free(gout), ABGS_OK);
    }
    bad = p;
    bad.struct_size = 0;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    abgs_simplify_report rz = {0};
    CHECK_STATUS(abgs_simplify(dense, &p, &none, &rz), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(none == NULL && rz.faces_out == 0);
    bad = p;
    bad.t_size = NAN;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_NON_FINITE);
    bad = p;
    bad.t_size = 1.0;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p;
    bad.fraction = 0.0;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p;
    bad.max_iterations = 0;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p;
    bad.max_distance = -1.0;
    CHECK_STATUS(abgs_simplify(dense, &bad, &none, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_edge_scores(dense, &bad, NULL, NULL, NULL, y, ne), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(none == NULL);

    free(ds);
    free(dd);
    free(y);
    free(valid);
    CHECK_STATUS(abgs_grid_free(out), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(dense), ABGS_OK);
    return finish();
}
