/* Remeshing through the C ABI: defaults, uniform and size-driven modes, the
   report, kept feature edges, issue texts, and every error path. */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>
#include <stdlib.h>
#include "check.h"

/* The unit cube [0,1]^3 as 8 vertices and 12 triangles, outward. */
static const double cube_xyz[3 * 8] = {
    0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1,
};
static const uint32_t cube_tris[3 * 12] = {
    0, 2, 1, 0, 3, 2, /* z = 0 */
    4, 5, 6, 4, 6, 7, /* z = 1 */
    0, 1, 5, 0, 5, 4, /* y = 0 */
    3, 7, 6, 3, 6, 2, /* y = 1 */
    0, 4, 7, 0, 7, 3, /* x = 0 */
    1, 2, 6, 1, 6, 5, /* x = 1 */
};

/* 1 when p lies on the cube's surface (inside the box, one coordinate at 0 or 1). */
static int on_cube(const double *p) {
    const double tol = 1e-9;
    int on_face = 0;
    for (int k = 0; k < 3; k++) {
        if (p[k] < -tol || p[k] > 1.0 + tol) return 0;
        if (fabs(p[k]) <= tol || fabs(p[k] - 1.0) <= tol) on_face = 1;
    }
    return on_face;
}

/* 1 when p lies on one of the cube's 12 edges (two coordinates at 0 or 1). */
static int on_cube_edge(const double *p) {
    const double tol = 1e-9;
    int n = 0;
    for (int k = 0; k < 3; k++)
        if (fabs(p[k]) <= tol || fabs(p[k] - 1.0) <= tol) n++;
    return on_cube(p) && n >= 2;
}

/* Copies out the vertices and triangles of g (caller frees). */
static void copy_out(const abgs_grid *g, size_t *nv, size_t *nt, double **xyz, uint32_t **tris) {
    CHECK_STATUS(abgs_grid_vertex_count(g, nv), ABGS_OK);
    CHECK_STATUS(abgs_grid_triangle_count(g, nt), ABGS_OK);
    *xyz = malloc(3 * *nv * sizeof **xyz);
    *tris = malloc(3 * *nt * sizeof **tris);
    CHECK_STATUS(abgs_grid_copy_vertices(g, *xyz, 3 * *nv), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_triangles(g, *tris, 3 * *nt), ABGS_OK);
}

int main(void) {
    abgs_remesh_params p = {.struct_size = sizeof p};
    CHECK_STATUS(abgs_remesh_params_default(&p), ABGS_OK);
    CHECK(p.edge_length == 0.0 && p.relative_length == 0.01 && p.feature_angle_deg == 30.0);
    CHECK(p.iterations == 10 && p.curvature_limit == 1 && p.n_circle == 24.0);
    CHECK(p.piece_faces == 50000.0);
    CHECK_STATUS(abgs_remesh_params_default(NULL), ABGS_ERR_NULL);

    abgs_grid *cube = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(cube_xyz, 8, cube_tris, 12, NULL, &cube), ABGS_OK);

    /* Uniform mode, absolute length 0.1: many more triangles, all on the cube. */
    p.edge_length = 0.1;
    abgs_remesh_report r;
    memset(&r, 0xff, sizeof r);
    r.struct_size = sizeof r;
    abgs_grid *dense = NULL;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &p, &dense, &r), ABGS_OK);
    CHECK(dense != NULL);
    CHECK(r.vertices_in == 8 && r.faces_in == 12);
    CHECK(r.faces_out > 600 && r.faces_out < 5000);
    CHECK(r.target_length == 0.1 && r.target_min > 0.0 && r.target_max <= 0.1);
    CHECK(r.feature_edges_in == 12 && r.feature_lines == 12 && r.corners == 8);
    CHECK(r.feature_edges_out >= 12 * 8);
    CHECK(r.iterations == 10 && r.seconds >= 0.0 && r.seconds < 600.0);
    CHECK(r.n_issues == 0);
    CHECK(r.pieces == 0); /* about 1,400 triangles: far below two pieces */
    size_t nv = 0, nt = 0;
    double *xyz = NULL;
    uint32_t *tris = NULL;
    copy_out(dense, &nv, &nt, &xyz, &tris);
    CHECK(nv == r.vertices_out && nt == r.faces_out);
    int all_on = 1, corners = 0;
    for (size_t i = 0; i < nv; i++) {
        if (!on_cube(&xyz[3 * i])) all_on = 0;
        int at_corner = 1;
        for (int k = 0; k < 3; k++)
            if (xyz[3 * i + k] != 0.0 && xyz[3 * i + k] != 1.0) at_corner = 0;
        corners += at_corner;
    }
    CHECK(all_on);
    CHECK(corners == 8); /* corners never move and are never removed */
    abgs_grid_stats st = {.struct_size = sizeof st};
    CHECK_STATUS(abgs_grid_get_stats(dense, &st), ABGS_OK);
    CHECK(st.bodies == 1 && st.boundary_edges == 0 && st.non_manifold_edges == 0);
    CHECK(st.has_sizes == 0);

    /* Pieces of about 200 triangles: the cube (about 1,400) is cut along its
       edges, and the pieces merge back into one closed body. */
    {
        abgs_remesh_params pp = p;
        pp.piece_faces = 200.0;
        abgs_remesh_report rp = {.struct_size = sizeof rp};
        abgs_grid *cut = NULL;
        CHECK_STATUS(abgs_grid_remesh(cube, NULL, &pp, &cut, &rp), ABGS_OK);
        CHECK(rp.pieces >= 2 && rp.n_issues == 0);
        CHECK(rp.faces_out > 600 && rp.faces_out < 5000);
        abgs_grid_stats sc = {.struct_size = sizeof sc};
        CHECK_STATUS(abgs_grid_get_stats(cut, &sc), ABGS_OK);
        CHECK(sc.bodies == 1 && sc.boundary_edges == 0 && sc.non_manifold_edges == 0);
        CHECK_STATUS(abgs_grid_free(cut), ABGS_OK);
        /* 0 = never cut. */
        pp.piece_faces = 0.0;
        CHECK_STATUS(abgs_grid_remesh(cube, NULL, &pp, &cut, &rp), ABGS_OK);
        CHECK(rp.pieces == 0 && rp.faces_out == r.faces_out);
        CHECK_STATUS(abgs_grid_free(cut), ABGS_OK);
    }

    /* A caller built against the first released header (before piece_faces
       and pieces were appended): its structs end where those fields begin.
       The library reads and writes only those bytes, and the missing
       parameter takes its default (a read of the -7 beyond them would be an
       error). */
    {
        abgs_remesh_params old_p;
        memset(&old_p, 0, sizeof old_p);
        old_p.struct_size = offsetof(abgs_remesh_params, piece_faces);
        CHECK(old_p.struct_size == 48);
        old_p.piece_faces = -7.0;
        CHECK_STATUS(abgs_remesh_params_default(&old_p), ABGS_OK);
        CHECK(old_p.relative_length == 0.01 && old_p.n_circle == 24.0);
        CHECK(old_p.piece_faces == -7.0); /* not written */
        old_p.edge_length = 0.1;
        abgs_remesh_report old_r;
        memset(&old_r, 0xff, sizeof old_r);
        old_r.struct_size = offsetof(abgs_remesh_report, pieces);
        CHECK(old_r.struct_size == 120);
        abgs_grid *og = NULL;
        CHECK_STATUS(abgs_grid_remesh(cube, NULL, &old_p, &og, &old_r), ABGS_OK);
        CHECK(old_r.struct_size == 120 && old_r.faces_out == r.faces_out);
        CHECK(old_r.pieces == UINT64_MAX); /* not written */
        CHECK_STATUS(abgs_grid_free(og), ABGS_OK);
        /* One byte short of the first released size is refused. */
        old_p.struct_size = 47;
        CHECK_STATUS(abgs_grid_remesh(cube, NULL, &old_p, &og, NULL), ABGS_ERR_INVALID_ARGUMENT);
        CHECK(strstr(abgs_last_error_message(), "struct_size") != NULL);
    }

    /* The kept feature edges run along the cube's edges. */
    size_t nfe = 0;
    CHECK_STATUS(abgs_grid_remesh_feature_edge_count(dense, &nfe), ABGS_OK);
    CHECK(nfe == r.feature_edges_out);
    uint32_t *fe = malloc(2 * nfe * sizeof *fe);
    CHECK_STATUS(abgs_grid_remesh_copy_feature_edges(dense, fe, 2 * nfe - 1), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK_STATUS(abgs_grid_remesh_copy_feature_edges(dense, NULL, 2 * nfe), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_remesh_copy_feature_edges(dense, fe, 2 * nfe), ABGS_OK);
    int along = 1;
    for (size_t e = 0; e < 2 * nfe; e++)
        if (fe[e] >= nv || !on_cube_edge(&xyz[3 * fe[e]])) along = 0;
    CHECK(along);
    free(fe);
    CHECK_STATUS(abgs_grid_remesh_feature_edge_count(NULL, &nfe), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_remesh_feature_edge_count(dense, NULL), ABGS_ERR_NULL);
    /* Grids not made by the remesher have no such record. */
    CHECK_STATUS(abgs_grid_remesh_feature_edge_count(cube, &nfe), ABGS_ERR_INVALID_ARGUMENT);
    uint32_t two[2];
    CHECK_STATUS(abgs_grid_remesh_copy_feature_edges(cube, two, 2), ABGS_ERR_INVALID_ARGUMENT);
    char text[256];
    CHECK_STATUS(abgs_grid_remesh_issue(cube, 0, text, sizeof text, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK_STATUS(abgs_grid_remesh_issue(dense, 0, text, sizeof text, NULL), ABGS_ERR_OUT_OF_RANGE);

    /* The output is an ordinary grid: sizes can be set and queried. */
    double *hs = malloc(nv * sizeof *hs);
    for (size_t i = 0; i < nv; i++) hs[i] = 0.1 + 0.2 * xyz[3 * i];
    CHECK_STATUS(abgs_grid_set_sizes(dense, hs, nv), ABGS_OK);
    double q[3] = {0.5, 0.5, 2.0}, h = 0.0;
    CHECK_STATUS(abgs_query_size(dense, q, &h), ABGS_OK);
    CHECK(fabs(h - 0.2) < 1e-12); /* the field is linear in x, the closest point is on z = 1 */
    free(hs);
    free(xyz);
    free(tris);

    /* Defaults (params NULL): diagonal / 100 and the curvature cap (no effect on a cube). */
    abgs_grid *fine = NULL;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, NULL, &fine, &r), ABGS_OK);
    CHECK(fabs(r.target_length - sqrt(3.0) / 100.0) < 1e-15);
    CHECK(r.faces_out > 20000);
    CHECK_STATUS(abgs_grid_free(fine), ABGS_OK);

    /* Size-driven mode: sizes 0.05 .. 0.2 growing with x on a separate sizing grid. */
    abgs_grid *sizing = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(cube_xyz, 8, cube_tris, 12, NULL, &sizing), ABGS_OK);
    abgs_grid *sized = NULL;
    CHECK_STATUS(abgs_grid_remesh(cube, sizing, &p, &sized, &r), ABGS_ERR_NO_SIZES);
    CHECK(sized == NULL);
    double cube_h[8];
    for (int i = 0; i < 8; i++) cube_h[i] = 0.05 + 0.15 * cube_xyz[3 * i];
    CHECK_STATUS(abgs_grid_set_sizes(sizing, cube_h, 8), ABGS_OK);
    p.edge_length = 0.0; /* ignored in size-driven mode (but still checked) */
    CHECK_STATUS(abgs_grid_remesh(cube, sizing, &p, &sized, &r), ABGS_OK);
    CHECK(sized != NULL && isnan(r.target_length));
    CHECK(r.target_min >= 0.05 - 1e-12 && r.target_max <= 0.2 + 1e-12);
    copy_out(sized, &nv, &nt, &xyz, &tris);
    /* Edge length / h(midpoint) near 1 on average; fine near x = 0, coarse near x = 1. */
    double sum = 0.0;
    size_t n = 0, left = 0, right = 0;
    all_on = 1;
    for (size_t t = 0; t < nt; t++) {
        for (int k = 0; k < 3; k++) {
            const double *a = &xyz[3 * tris[3 * t + k]], *b = &xyz[3 * tris[3 * t + (k + 1) % 3]];
            double m[3], len = 0.0, hm = 0.0;
            for (int c = 0; c < 3; c++) {
                m[c] = 0.5 * (a[c] + b[c]);
                len += (a[c] - b[c]) * (a[c] - b[c]);
            }
            CHECK(abgs_query_size(sizing, m, &hm) == ABGS_OK);
            sum += sqrt(len) / hm;
            n++;
        }
        double cx = (xyz[3 * tris[3 * t]] + xyz[3 * tris[3 * t + 1]] + xyz[3 * tris[3 * t + 2]]) / 3.0;
        if (cx < 0.25) left++;
        if (cx > 0.75) right++;
    }
    for (size_t i = 0; i < nv; i++)
        if (!on_cube(&xyz[3 * i])) all_on = 0;
    CHECK(all_on);
    double mean = sum / (double)n;
    CHECK(mean > 0.75 && mean < 1.25);
    CHECK(left > 3 * right);
    free(xyz);
    free(tris);
    CHECK_STATUS(abgs_grid_free(sized), ABGS_OK);
    /* The input may be its own sizing grid once it has sizes. */
    sized = NULL;
    CHECK_STATUS(abgs_grid_remesh(cube, cube, &p, &sized, NULL), ABGS_ERR_NO_SIZES);
    CHECK(sized == NULL);
    CHECK_STATUS(abgs_grid_set_sizes(cube, cube_h, 8), ABGS_OK);
    CHECK_STATUS(abgs_grid_remesh(cube, cube, &p, &sized, NULL), ABGS_OK);
    CHECK(sized != NULL);
    CHECK_STATUS(abgs_grid_free(sized), ABGS_OK);

    /* An open plate keeps its boundary and stays in its square. */
    enum { N = 4, NV = (N + 1) * (N + 1), NT = 2 * N * N };
    double plate_xyz[3 * NV];
    uint32_t plate_tris[3 * NT];
    make_plate(N, plate_xyz, plate_tris);
    abgs_grid *plate = NULL, *plate2 = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(plate_xyz, NV, plate_tris, NT, NULL, &plate), ABGS_OK);
    p.edge_length = 0.1;
    CHECK_STATUS(abgs_grid_remesh(plate, NULL, &p, &plate2, &r), ABGS_OK);
    CHECK(r.faces_out > 100 && r.corners == 4);
    CHECK_STATUS(abgs_grid_get_stats(plate2, &st), ABGS_OK);
    /* 4 sides of length 1 cut into pieces of 0.1 · [4/5, 4/3]. */
    CHECK(st.boundary_edges >= 4 * 8 && st.boundary_edges <= 4 * 12 && st.bodies == 1);
    CHECK(st.bbox_min[0] == 0.0 && st.bbox_min[1] == 0.0 && st.bbox_max[0] == 1.0 && st.bbox_max[1] == 1.0);
    CHECK(st.bbox_min[2] == 0.0 && st.bbox_max[2] == 0.0);
    CHECK_STATUS(abgs_grid_free(plate2), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(plate), ABGS_OK);

    /* Three pages meeting along one edge: the non-manifold edge is locked and
       reported as an issue, with its text. */
    const double book_xyz[3 * 8] = {
        0, 0, 0, 1, 0, 0, /* the spine */
        0, 1, 0, 1, 1, 0, 0, -1, 0, 1, -1, 0, 0, 0, 1, 1, 0, 1,
    };
    const uint32_t book_tris[3 * 6] = {0, 1, 3, 0, 3, 2, 1, 0, 4, 1, 4, 5, 0, 1, 7, 0, 7, 6};
    abgs_grid *book = NULL, *book2 = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(book_xyz, 8, book_tris, 6, NULL, &book), ABGS_OK);
    CHECK_STATUS(abgs_grid_remesh(book, NULL, &p, &book2, &r), ABGS_OK);
    CHECK(r.n_issues >= 1);
    CHECK_STATUS(abgs_grid_get_stats(book2, &st), ABGS_OK);
    CHECK(st.non_manifold_edges >= 1);
    size_t len = 0;
    CHECK_STATUS(abgs_grid_remesh_issue(book2, 0, NULL, 0, &len), ABGS_OK);
    CHECK(len > 10);
    size_t len2 = 0;
    CHECK_STATUS(abgs_grid_remesh_issue(book2, 0, text, 4, &len2), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK(len2 == len);
    CHECK_STATUS(abgs_grid_remesh_issue(book2, 0, NULL, 4, NULL), ABGS_ERR_NULL);
    char *issue = malloc(len);
    CHECK_STATUS(abgs_grid_remesh_issue(book2, 0, issue, len, NULL), ABGS_OK);
    CHECK(strlen(issue) + 1 == len);
    int any_locked = 0;
    for (uint64_t i = 0; i < r.n_issues; i++) {
        CHECK_STATUS(abgs_grid_remesh_issue(book2, (size_t)i, text, sizeof text, NULL), ABGS_OK);
        if (strstr(text, "locked") != NULL) any_locked = 1;
    }
    CHECK(any_locked);
    CHECK_STATUS(abgs_grid_remesh_issue(book2, (size_t)r.n_issues, text, sizeof text, NULL), ABGS_ERR_OUT_OF_RANGE);
    CHECK_STATUS(abgs_grid_remesh_issue(NULL, 0, text, sizeof text, NULL), ABGS_ERR_NULL);
    free(issue);
    CHECK_STATUS(abgs_grid_free(book2), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(book), ABGS_OK);

    /* Error paths: *out_grid is NULL after every failure. */
    abgs_grid *o = dense;
    CHECK_STATUS(abgs_grid_remesh(NULL, NULL, &p, &o, NULL), ABGS_ERR_NULL);
    CHECK(o == NULL);
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &p, NULL, NULL), ABGS_ERR_NULL);
    abgs_remesh_params bad = p;
    bad.edge_length = -1.0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "edge_length") != NULL);
    bad = p; bad.edge_length = NAN;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.edge_length = INFINITY;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.edge_length = 0.0; bad.relative_length = 0.0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "relative_length") != NULL);
    bad = p; bad.edge_length = 0.0; bad.relative_length = -0.01;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.relative_length = NAN;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.feature_angle_deg = 181.0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "feature_angle_deg") != NULL);
    bad = p; bad.feature_angle_deg = -1.0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.feature_angle_deg = NAN;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_NON_FINITE);
    bad = p; bad.iterations = 0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(strstr(abgs_last_error_message(), "iterations") != NULL);
    bad = p; bad.n_circle = 0.0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    bad = p; bad.n_circle = -INFINITY;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), ABGS_ERR_NON_FINITE);
    /* piece_faces: 0 (never cut) or finite and >= 1. */
    const double bad_pieces[4] = {-1.0, 0.5, NAN, INFINITY};
    const abgs_status bad_pieces_status[4] = {ABGS_ERR_INVALID_ARGUMENT, ABGS_ERR_INVALID_ARGUMENT,
                                              ABGS_ERR_NON_FINITE, ABGS_ERR_NON_FINITE};
    for (int i = 0; i < 4; i++) {
        bad = p;
        bad.piece_faces = bad_pieces[i];
        CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, NULL), bad_pieces_status[i]);
        CHECK(strstr(abgs_last_error_message(), "piece_faces") != NULL && o == NULL);
    }
    /* Bad parameters are errors in size-driven mode too. */
    bad = p; bad.edge_length = -1.0;
    CHECK_STATUS(abgs_grid_remesh(cube, sizing, &bad, &o, NULL), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(o == NULL);
    /* A failed call leaves the report untouched. */
    memset(&r, 0, sizeof r);
    r.struct_size = sizeof r;
    bad = p; bad.iterations = 0;
    CHECK_STATUS(abgs_grid_remesh(cube, NULL, &bad, &o, &r), ABGS_ERR_INVALID_ARGUMENT);
    CHECK(r.faces_out == 0 && r.n_issues == 0);

    /* A remeshed grid can be remeshed again. */
    abgs_grid *again = NULL;
    p.edge_length = 0.2;
    CHECK_STATUS(abgs_grid_remesh(dense, NULL, &p, &again, &r), ABGS_OK);
    CHECK(r.faces_out > 12 && r.faces_out < r.faces_in);
    CHECK_STATUS(abgs_grid_free(again), ABGS_OK);

    CHECK_STATUS(abgs_grid_free(sizing), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(dense), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(cube), ABGS_OK);
    return finish();
}
