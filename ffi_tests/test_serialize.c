/* abgs_grid_serialize / abgs_grid_deserialize: the size first (NULL, 0),
   BUFFER_TOO_SMALL writes nothing, the round trip answers bit for bit, an
   `.abgs` file holds the same bytes, and every truncation, changed header
   byte, NULL and foreign buffer is an error with a message. */
#include <math.h>
#include <stdlib.h>
#include "check.h"

/* Deterministic pseudo-random numbers in [0, 1). */
static double rnd(unsigned long long *s) {
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*s >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv) {
    const char *tmpdir = argc > 1 ? argv[1] : ".";
    enum { N = 12, NV = (N + 1) * (N + 1), NT = 2 * N * N, M = 3000 };
    static double xyz[3 * NV], sizes[NV];
    static uint32_t tris[3 * NT];
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) {
        xyz[3 * i + 2] = 0.2 * sin(3.0 * xyz[3 * i]) * xyz[3 * i + 1];
        sizes[i] = 0.05 + 0.1 * xyz[3 * i] * xyz[3 * i + 1];
    }
    abgs_grid *g = NULL, *back = NULL;
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &g), ABGS_OK);

    /* The size first, then the bytes. */
    size_t need = 0, len = 0;
    CHECK_STATUS(abgs_grid_serialize(g, NULL, 0, &need), ABGS_OK);
    CHECK(need > 128);
    unsigned char *buf = malloc(need + 16);
    CHECK(buf != NULL);
    if (buf == NULL) return finish();
    memset(buf, 0xAB, need + 16);
    CHECK_STATUS(abgs_grid_serialize(g, buf, need - 1, &len), ABGS_ERR_BUFFER_TOO_SMALL);
    CHECK(len == need);
    int untouched = 1;
    for (size_t i = 0; i < need + 16; i++) untouched &= buf[i] == 0xAB;
    CHECK(untouched);
    CHECK_STATUS(abgs_grid_serialize(g, buf, need + 16, &len), ABGS_OK);
    CHECK(len == need);
    CHECK(memcmp(buf, "\x89" "ABGS\r\n\x1a", 8) == 0);
    CHECK(buf[need] == 0xAB); /* nothing past the grid */
    CHECK_STATUS(abgs_grid_serialize(NULL, buf, need, &len), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_serialize(g, buf, need, NULL), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_serialize(g, NULL, need, &len), ABGS_ERR_NULL);

    /* Round trip: same arrays, same answers bit for bit. */
    CHECK_STATUS(abgs_grid_deserialize(buf, need, &back), ABGS_OK);
    CHECK(back != NULL);
    static double v2[3 * NV], s2[NV];
    static uint32_t t2[3 * NT];
    size_t nt = 0;
    CHECK_STATUS(abgs_grid_triangle_count(back, &nt), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_vertices(back, v2, 3 * NV), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_triangles(back, t2, 3 * nt), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_sizes(back, s2, NV), ABGS_OK);
    static double v1[3 * NV];
    static uint32_t t1[3 * NT];
    CHECK_STATUS(abgs_grid_copy_vertices(g, v1, 3 * NV), ABGS_OK);
    CHECK_STATUS(abgs_grid_copy_triangles(g, t1, 3 * NT), ABGS_OK);
    CHECK(nt == NT && memcmp(v1, v2, sizeof v1) == 0 && memcmp(t1, t2, sizeof t1) == 0);
    CHECK(memcmp(sizes, s2, sizeof sizes) == 0);
    unsigned long long seed = 9;
    static double pts[3 * M], h1[M], h2[M];
    for (int k = 0; k < 3 * M; k++) pts[k] = 1.6 * rnd(&seed) - 0.3;
    CHECK_STATUS(abgs_query_sizes(g, pts, M, h1), ABGS_OK);
    CHECK_STATUS(abgs_query_sizes(back, pts, M, h2), ABGS_OK);
    CHECK(memcmp(h1, h2, sizeof h1) == 0);
    int same = 1;
    for (int k = 0; k < M; k += 10) {
        double a = 0, b = 0;
        CHECK(abgs_query_size_volume(g, &pts[3 * k], 1.2, &a) == ABGS_OK);
        CHECK(abgs_query_size_volume(back, &pts[3 * k], 1.2, &b) == ABGS_OK);
        same &= memcmp(&a, &b, sizeof a) == 0;
    }
    CHECK(same);
    /* A deserialised grid serialises to the same bytes. */
    unsigned char *again = malloc(need);
    CHECK(again != NULL);
    if (again != NULL) {
        CHECK_STATUS(abgs_grid_serialize(back, again, need, &len), ABGS_OK);
        CHECK(len == need && memcmp(buf, again, need) == 0);
    }
    CHECK_STATUS(abgs_grid_free(back), ABGS_OK);

    /* abgs_grid_save to .abgs writes the same bytes; abgs_grid_load reads them. */
    char path[1024];
    snprintf(path, sizeof path, "%s/serialize_test.abgs", tmpdir);
    CHECK_STATUS(abgs_grid_save(g, path), ABGS_OK);
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL);
    if (f != NULL && again != NULL) {
        size_t got = fread(again, 1, need, f);
        CHECK(got == need && fgetc(f) == EOF && memcmp(buf, again, need) == 0);
        fclose(f);
    }
    back = NULL;
    CHECK_STATUS(abgs_grid_load(path, &back), ABGS_OK);
    CHECK_STATUS(abgs_query_sizes(back, pts, M, h2), ABGS_OK);
    CHECK(memcmp(h1, h2, sizeof h1) == 0);
    CHECK_STATUS(abgs_grid_free(back), ABGS_OK);
    remove(path);

    /* Every truncation is PARSE; out_grid is NULL after a failure. */
    int all_parse = 1;
    for (size_t n = 0; n < need; n++) {
        back = (abgs_grid *)buf; /* garbage the call must overwrite */
        abgs_status st = abgs_grid_deserialize(buf, n, &back);
        all_parse &= st == ABGS_ERR_PARSE && back == NULL;
    }
    CHECK(all_parse);
    CHECK_STATUS(abgs_grid_deserialize(buf, need - 1, &back), ABGS_ERR_PARSE);
    /* Every header byte changed: an error (PARSE or UNSUPPORTED_FORMAT). */
    int all_refused = 1;
    for (size_t i = 0; i < 128; i++) {
        buf[i] ^= 0x5A;
        abgs_status st = abgs_grid_deserialize(buf, need, &back);
        all_refused &= (st == ABGS_ERR_PARSE || st == ABGS_ERR_UNSUPPORTED_FORMAT) && back == NULL;
        buf[i] ^= 0x5A;
    }
    CHECK(all_refused);
    /* Another version: UNSUPPORTED_FORMAT, named in the message. */
    buf[8] = 2;
    CHECK_STATUS(abgs_grid_deserialize(buf, need, &back), ABGS_ERR_UNSUPPORTED_FORMAT);
    CHECK(strstr(abgs_last_error_message(), "version 2") != NULL);
    buf[8] = 1;
    CHECK_STATUS(abgs_grid_deserialize(buf, need, &back), ABGS_OK);
    CHECK_STATUS(abgs_grid_free(back), ABGS_OK);
    /* A text file, NULLs. */
    const char text[] = "solid x\n facet normal 0 0 1\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n";
    CHECK_STATUS(abgs_grid_deserialize(text, sizeof text, &back), ABGS_ERR_PARSE);
    CHECK(strstr(abgs_last_error_message(), "not an abgs grid") != NULL);
    CHECK_STATUS(abgs_grid_deserialize(NULL, need, &back), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_deserialize(NULL, 0, &back), ABGS_ERR_NULL);
    CHECK_STATUS(abgs_grid_deserialize(buf, need, NULL), ABGS_ERR_NULL);

    free(again);
    free(buf);
    CHECK_STATUS(abgs_grid_free(g), ABGS_OK);
    return finish();
}
