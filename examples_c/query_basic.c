/*
 * query_basic.c: load a background grid with sizes and query it from C.
 *
 * Build from the repository root, after `cargo build --release --lib`:
 *   cc -std=c11 -O2 -Iinclude examples_c/query_basic.c -Ltarget/release -labgs -Wl,-rpath,$PWD/target/release -o query_basic
 * or with CMake (examples_c/CMakeLists.txt) or pkg-config (`pkg-config --cflags --libs abgs`).
 *
 * Usage: query_basic GRID_FILE [x y z ...]
 *   GRID_FILE  a surface grid with a per-vertex `size` array (vtk, vtu, msh, ply, ...)
 *   x y z      query points; without any, the bounding-box centre and 4 other
 *              points inside the bounding box are queried.
 * Each point is queried with abgs_query_size, then again with
 * abgs_query_size_hinted (one hint carried from point to point, as a mesher
 * walking its front would do), printing `x y z size` per point.
 * Exit status: 0 on success, 1 on any error, 2 on bad usage.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abgs.h"

/* Prints `what` and the library's description of the last failure when
 * `status` is not ABGS_OK; returns 1 on success, 0 on failure. */
static int check(abgs_status status, const char *what) {
    if (status == ABGS_OK) {
        return 1;
    }
    fprintf(stderr, "error: %s failed: %s: %s\n", what, abgs_status_name((int)status),
            abgs_last_error_message());
    return 0;
}

/* Parses one coordinate; returns 1 on success. */
static int parse_coordinate(const char *text, double *out) {
    char *end = NULL;
    *out = strtod(text, &end);
    return end != text && *end == '\0';
}

int main(int argc, char **argv) {
    if (argc < 2 || (argc - 2) % 3 != 0) {
        fprintf(stderr, "usage: %s GRID_FILE [x y z ...]\n", argc > 0 ? argv[0] : "query_basic");
        return 2;
    }

    /* The header and the library must come from the same release. */
    const uint32_t header_version =
        ABGS_VERSION_MAJOR * 10000u + ABGS_VERSION_MINOR * 100u + ABGS_VERSION_PATCH;
    if (abgs_version_number() != header_version) {
        fprintf(stderr, "warning: abgs.h is version %d.%d.%d but the library is %s\n",
                ABGS_VERSION_MAJOR, ABGS_VERSION_MINOR, ABGS_VERSION_PATCH, abgs_version());
    }

    abgs_grid *grid = NULL;
    if (!check(abgs_grid_load(argv[1], &grid), "abgs_grid_load")) {
        return 1;
    }

    int ok = 0;
    double *points = NULL;
    size_t n_points = 0;

    abgs_grid_stats stats = {.struct_size = sizeof stats};
    if (!check(abgs_grid_get_stats(grid, &stats), "abgs_grid_get_stats")) {
        goto done;
    }
    printf("abgs %s, grid %s\n", abgs_version(), argv[1]);
    printf("  vertices %llu, triangles %llu, bodies %llu\n",
           (unsigned long long)stats.vertices, (unsigned long long)stats.triangles,
           (unsigned long long)stats.bodies);
    printf("  bbox [%g %g %g] - [%g %g %g]\n", stats.bbox_min[0], stats.bbox_min[1],
           stats.bbox_min[2], stats.bbox_max[0], stats.bbox_max[1], stats.bbox_max[2]);
    if (!stats.has_sizes) {
        fprintf(stderr, "error: %s has no `size` point array\n", argv[1]);
        goto done;
    }
    printf("  sizes %g to %g\n", stats.size_min, stats.size_max);

    if (argc > 2) {
        n_points = (size_t)(argc - 2) / 3;
        points = malloc(3 * n_points * sizeof *points);
        if (points == NULL) {
            fprintf(stderr, "error: out of memory\n");
            goto done;
        }
        for (size_t i = 0; i < 3 * n_points; ++i) {
            if (!parse_coordinate(argv[2 + i], &points[i])) {
                fprintf(stderr, "error: `%s` is not a number\n", argv[2 + i]);
                goto done;
            }
        }
    } else {
        /* The bbox centre, then 4 points at 1/4 and 3/4 of the box. */
        static const double fractions[5][3] = {
            {0.50, 0.50, 0.50}, {0.25, 0.25, 0.25}, {0.75, 0.25, 0.50},
            {0.25, 0.75, 0.50}, {0.75, 0.75, 0.75},
        };
        n_points = 5;
        points = malloc(3 * n_points * sizeof *points);
        if (points == NULL) {
            fprintf(stderr, "error: out of memory\n");
            goto done;
        }
        for (size_t i = 0; i < n_points; ++i) {
            for (int k = 0; k < 3; ++k) {
                points[3 * i + k] = stats.bbox_min[k] +
                                    fractions[i][k] * (stats.bbox_max[k] - stats.bbox_min[k]);
            }
        }
    }

    printf("sizes (abgs_query_size): x y z size\n");
    for (size_t i = 0; i < n_points; ++i) {
        const double *p = &points[3 * i];
        double size = 0.0;
        if (!check(abgs_query_size(grid, p, &size), "abgs_query_size")) {
            goto done;
        }
        printf("%g %g %g %.10g\n", p[0], p[1], p[2], size);
    }

    /* Same answers, found faster when consecutive points are close. */
    printf("sizes (abgs_query_size_hinted): x y z size\n");
    uint32_t hint = ABGS_NO_HINT;
    for (size_t i = 0; i < n_points; ++i) {
        const double *p = &points[3 * i];
        double size = 0.0;
        if (!check(abgs_query_size_hinted(grid, p, &hint, &size), "abgs_query_size_hinted")) {
            goto done;
        }
        printf("%g %g %g %.10g\n", p[0], p[1], p[2], size);
    }
    ok = 1;

done:
    free(points);
    if (!check(abgs_grid_free(grid), "abgs_grid_free")) {
        ok = 0;
    }
    return ok ? 0 : 1;
}
