/* Tiny assertion helpers shared by the C tests (run by tests/ffi_c.rs). */
#ifndef ABGS_FFI_CHECK_H
#define ABGS_FFI_CHECK_H
#include <stdio.h>
#include <string.h>
#include "abgs.h"

static int g_passed = 0, g_failed = 0;

#define CHECK(cond)                                                              \
    do {                                                                         \
        if (cond) {                                                              \
            g_passed++;                                                          \
        } else {                                                                 \
            g_failed++;                                                          \
            fprintf(stderr, "%s:%d: CHECK failed: %s\n", __FILE__, __LINE__, #cond); \
        }                                                                        \
    } while (0)

/* The call returns `expected` and, when it is an error, leaves a message
   naming the function. */
#define CHECK_STATUS(call, expected)                                                       \
    do {                                                                                   \
        abgs_status st_ = (call);                                                          \
        if (st_ == (expected)) {                                                           \
            g_passed++;                                                                    \
            if (st_ != ABGS_OK) {                                                          \
                const char *m_ = abgs_last_error_message();                                \
                CHECK(m_ != NULL && strncmp(m_, "abgs_", 5) == 0 && strlen(m_) > 10);      \
            }                                                                              \
        } else {                                                                           \
            g_failed++;                                                                    \
            fprintf(stderr, "%s:%d: %s returned %s, expected %s (%s)\n", __FILE__, __LINE__, \
                    #call, abgs_status_name((int)st_), abgs_status_name((int)(expected)),   \
                    abgs_last_error_message());                                            \
        }                                                                                  \
    } while (0)

static int finish(void) {
    printf("%d passed, %d failed\n", g_passed, g_failed);
    return g_failed == 0 ? 0 : 1;
}

/* A (n+1) x (n+1) vertex plate in z = 0 over [0,1]^2, triangulated. */
static void make_plate(int n, double *xyz, uint32_t *tris) {
    int k = 0;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            xyz[3 * k + 0] = (double)i / n;
            xyz[3 * k + 1] = (double)j / n;
            xyz[3 * k + 2] = 0.0;
            k++;
        }
    int t = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)n + 2, d = a + (uint32_t)n + 1;
            tris[3 * t + 0] = a; tris[3 * t + 1] = b; tris[3 * t + 2] = c; t++;
            tris[3 * t + 0] = a; tris[3 * t + 1] = c; tris[3 * t + 2] = d; t++;
        }
}
#endif
