/*
 * mpi_sizing.c: one rank builds the sizing field, every rank answers queries.
 *
 * Rank 0 loads a surface (STL, OBJ, ... or a grid that already has sizes),
 * computes the sizes (curvature, proximity, gradation; library defaults) when
 * it has none, and serialises the grid with abgs_grid_serialize. The byte
 * count, then the bytes, are broadcast (MPI_Bcast); every rank rebuilds the
 * grid with abgs_grid_deserialize and answers its share of a deterministic
 * point set (every rank can make any point from its index) with
 * abgs_query_sizes. Rank 0 gathers the answers and checks them bit for bit
 * against its own answers on the grid it built.
 *
 * Build with CMake (examples_c/CMakeLists.txt, when MPI is found), or:
 *   mpicc -std=c11 -O2 examples_c/mpi_sizing.c $(pkg-config --cflags --libs abgs) -o mpi_sizing
 * Run:
 *   mpirun -np 4 ./mpi_sizing MODEL [N_POINTS]
 *   MODEL     a surface file (sizes are computed) or a grid with a `size` array
 *   N_POINTS  query points in all (default 100000), in the model's bounding box
 *             grown by 10 % on each side
 * Exit status (the same on every rank): 0 when every answer matches, 1 on a
 * mismatch or an error, 2 on bad usage.
 */
#include <limits.h>
#include <math.h>
#include <mpi.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "abgs.h"

/* Prints the failure of an abgs call; returns 1 on success, 0 on failure. */
static int ok(abgs_status st, const char *what, int rank) {
    if (st == ABGS_OK) return 1;
    fprintf(stderr, "rank %d: %s failed: %s (%s)\n", rank, what, abgs_status_name((int)st),
            abgs_last_error_message());
    return 0;
}

/* A number in [0, 1) from (index, axis): SplitMix64, so any rank makes the
 * same point i without making the others. */
static double unit(uint64_t i, uint64_t axis) {
    uint64_t z = i * 3 + axis + 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    z ^= z >> 31;
    return (double)(z >> 11) / 9007199254740992.0;
}

/* Point i of the set, in `box` (min xyz, max xyz) grown by 10 % each side. */
static void point(uint64_t i, const double box[6], double p[3]) {
    for (int k = 0; k < 3; k++) {
        double lo = box[k], hi = box[3 + k], pad = 0.1 * (hi - lo);
        p[k] = lo - pad + unit(i, (uint64_t)k) * (hi - lo + 2.0 * pad);
    }
}

/* Broadcasts `n` bytes from rank 0 in pieces of at most INT_MAX. */
static void bcast_bytes(unsigned char *buf, uint64_t n) {
    for (uint64_t at = 0; at < n;) {
        int piece = n - at > (uint64_t)INT_MAX ? INT_MAX : (int)(n - at);
        MPI_Bcast(buf + at, piece, MPI_UNSIGNED_CHAR, 0, MPI_COMM_WORLD);
        at += (uint64_t)piece;
    }
}

/* Rank 0: the grid (loaded, sized when it has no sizes) and its bytes in
 * *out_buf (malloc'd); returns the byte count, 0 on failure. */
static uint64_t build_and_serialise(const char *path, abgs_grid **grid, unsigned char **out_buf) {
    double t0 = MPI_Wtime();
    if (!ok(abgs_grid_load(path, grid), "abgs_grid_load", 0)) return 0;
    abgs_grid_stats st = {.struct_size = sizeof st};
    if (!ok(abgs_grid_get_stats(*grid, &st), "abgs_grid_get_stats", 0)) return 0;
    if (!st.has_sizes) {
        abgs_size_params sp = {.struct_size = sizeof sp};
        abgs_size_report sr = {.struct_size = sizeof sr};
        if (!ok(abgs_size_params_default(&sp), "abgs_size_params_default", 0)) return 0;
        if (!ok(abgs_compute_size(*grid, &sp, &sr), "abgs_compute_size", 0)) return 0;
        printf("rank 0: sizes computed on %llu triangles, h in [%g, %g]\n",
               (unsigned long long)st.triangles, sr.hmin, sr.hmax);
    }
    double t1 = MPI_Wtime();
    size_t n = 0;
    if (!ok(abgs_grid_serialize(*grid, NULL, 0, &n), "abgs_grid_serialize (size)", 0)) return 0;
    *out_buf = malloc(n);
    if (*out_buf == NULL) {
        fprintf(stderr, "rank 0: out of memory (%zu bytes)\n", n);
        return 0;
    }
    if (!ok(abgs_grid_serialize(*grid, *out_buf, n, &n), "abgs_grid_serialize", 0)) return 0;
    printf("rank 0: %s: %llu vertices, %llu triangles; built in %.3f s, serialised to %zu bytes in %.4f s\n",
           path, (unsigned long long)st.vertices, (unsigned long long)st.triangles, t1 - t0, n,
           MPI_Wtime() - t1);
    return (uint64_t)n;
}

int main(int argc, char **argv) {
    MPI_Init(&argc, &argv);
    int rank = 0, size = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    long long n_arg = argc > 2 ? atoll(argv[2]) : 100000;
    if (argc < 2 || argc > 3 || n_arg <= 0 || n_arg > INT_MAX) {
        if (rank == 0) fprintf(stderr, "usage: %s MODEL [N_POINTS]\n", argv[0]);
        MPI_Finalize();
        return 2;
    }
    const uint64_t n_points = (uint64_t)n_arg;

    /* Rank 0 builds and serialises; a byte count of 0 tells the others it failed. */
    abgs_grid *built = NULL, *grid = NULL;
    unsigned char *bytes = NULL;
    uint64_t n_bytes = 0;
    if (rank == 0) n_bytes = build_and_serialise(argv[1], &built, &bytes);
    double t0 = MPI_Wtime();
    MPI_Bcast(&n_bytes, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    if (n_bytes == 0) {
        abgs_grid_free(built);
        free(bytes);
        MPI_Finalize();
        return 1;
    }
    if (rank != 0) bytes = malloc(n_bytes);
    int have = bytes != NULL, all_have = 0;
    MPI_Allreduce(&have, &all_have, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
    if (!all_have) {
        if (!have) fprintf(stderr, "rank %d: out of memory (%llu bytes)\n", rank, (unsigned long long)n_bytes);
        abgs_grid_free(built);
        free(bytes);
        MPI_Finalize();
        return 1;
    }
    bcast_bytes(bytes, n_bytes);
    double t1 = MPI_Wtime();

    /* Every rank, rank 0 included, works on the deserialised grid. */
    int good = ok(abgs_grid_deserialize(bytes, (size_t)n_bytes, &grid), "abgs_grid_deserialize", rank);
    double t2 = MPI_Wtime();
    free(bytes);
    abgs_grid_stats st = {.struct_size = sizeof st};
    good = good && ok(abgs_grid_get_stats(grid, &st), "abgs_grid_get_stats", rank);
    double box[6] = {0};
    if (good) {
        memcpy(box, st.bbox_min, sizeof st.bbox_min);
        memcpy(box + 3, st.bbox_max, sizeof st.bbox_max);
    }

    /* This rank's share: points [first, first + count). */
    const uint64_t first = n_points * (uint64_t)rank / (uint64_t)size;
    const uint64_t count = n_points * (uint64_t)(rank + 1) / (uint64_t)size - first;
    double *pts = malloc(3 * (count ? count : 1) * sizeof *pts);
    double *mine = malloc((count ? count : 1) * sizeof *mine);
    good = good && pts != NULL && mine != NULL;
    double t3 = MPI_Wtime();
    if (good) {
        for (uint64_t i = 0; i < count; i++) point(first + i, box, &pts[3 * i]);
        good = ok(abgs_query_sizes(grid, pts, (size_t)count, mine), "abgs_query_sizes", rank);
    }
    double t4 = MPI_Wtime();
    int all_good = 0;
    MPI_Allreduce(&good, &all_good, 1, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
    int rc = all_good ? 0 : 1;

    /* Rank 0 gathers every answer and checks it against its own grid's. */
    double times[2] = {t2 - t1, t4 - t3}, worst[2] = {0, 0};
    MPI_Reduce(times, worst, 2, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD);
    if (all_good) {
        int *counts = NULL, *offsets = NULL;
        double *all = NULL;
        if (rank == 0) {
            counts = malloc((size_t)size * sizeof *counts);
            offsets = malloc((size_t)size * sizeof *offsets);
            all = malloc(n_points * sizeof *all);
            if (counts == NULL || offsets == NULL || all == NULL) {
                fprintf(stderr, "rank 0: out of memory\n");
                MPI_Abort(MPI_COMM_WORLD, 1);
            }
            for (int r = 0; r < size; r++) {
                uint64_t f = n_points * (uint64_t)r / (uint64_t)size;
                offsets[r] = (int)f;
                counts[r] = (int)(n_points * (uint64_t)(r + 1) / (uint64_t)size - f);
            }
        }
        MPI_Gatherv(mine, (int)count, MPI_DOUBLE, all, counts, offsets, MPI_DOUBLE, 0, MPI_COMM_WORLD);
        if (rank == 0) {
            /* The reference: every point queried on the grid rank 0 built. */
            double *ref = malloc(n_points * sizeof *ref), *p = malloc(3 * n_points * sizeof *p);
            uint64_t mismatches = 0;
            if (ref == NULL || p == NULL) {
                fprintf(stderr, "rank 0: out of memory\n");
                rc = 1;
            } else {
                for (uint64_t i = 0; i < n_points; i++) point(i, box, &p[3 * i]);
                if (!ok(abgs_query_sizes(built, p, (size_t)n_points, ref), "abgs_query_sizes", 0)) rc = 1;
                for (uint64_t i = 0; rc == 0 && i < n_points; i++) {
                    if (memcmp(&ref[i], &all[i], sizeof ref[i]) != 0) {
                        if (mismatches < 5)
                            fprintf(stderr, "point %llu: %.17g on its rank, %.17g on rank 0\n",
                                    (unsigned long long)i, all[i], ref[i]);
                        mismatches++;
                    }
                }
                if (mismatches) rc = 1;
            }
            printf("%d ranks: broadcast %llu bytes in %.4f s, deserialised in %.4f s (slowest rank)\n",
                   size, (unsigned long long)n_bytes, t1 - t0, worst[0]);
            printf("%llu points, %.0f queries/s per rank (slowest rank %.4f s); %llu mismatches: %s\n",
                   (unsigned long long)n_points, worst[1] > 0 ? (double)n_points / size / worst[1] : 0.0,
                   worst[1], (unsigned long long)mismatches, rc == 0 ? "bit-identical" : "FAILED");
            free(ref);
            free(p);
        }
        free(counts);
        free(offsets);
        free(all);
    }
    MPI_Bcast(&rc, 1, MPI_INT, 0, MPI_COMM_WORLD);
    free(pts);
    free(mine);
    abgs_grid_free(grid);
    abgs_grid_free(built);
    MPI_Finalize();
    return rc;
}
