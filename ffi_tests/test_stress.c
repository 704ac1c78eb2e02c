/* Stress: 16 threads query one grid (plain, hinted, batch, volume, volume
   batch) while other threads call abgs_grid_set_sizes and abgs_grid_free on
   it. Every answer that comes back OK is bit-identical to the single-thread
   answer; every other status is ABGS_ERR_BUSY.

   Phase 1 races set_sizes (same values, so any interleaving is correct)
   against the queries: either may win, each loser gets BUSY.
   Phase 2 pins the grid in use (an abgs_simplify whose progress callback
   waits until the phase ends), so every set_sizes and free must be BUSY,
   whatever the timing, while the queries keep running and keep agreeing. */
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <time.h>
#include "check.h"

enum { N = 40, NV = (N + 1) * (N + 1), NT = 2 * N * N, M = 600, QUERY_THREADS = 16, MUTATORS = 2 };
enum { PLAIN, HINTED, BATCH, VOLUME, VOLUME_BATCH, KINDS };
static const double BETA = 1.2;
static double xyz[3 * NV], sizes[NV], pts[3 * M], reference[KINDS][M];
static uint32_t tris[3 * NT];
static abgs_grid *grid;
static atomic_int stop_queries, stop_mutators, pinned, release_pin;

struct tally {
    long ok, busy, wrong, other;
};
static struct tally q_tally[QUERY_THREADS], m_tally[MUTATORS];

static void count(struct tally *t, abgs_status st) {
    if (st == ABGS_OK) t->ok++;
    else if (st == ABGS_ERR_BUSY) t->busy++;
    else t->other++;
}

static void *query_worker(void *arg) {
    struct tally *t = &q_tally[(size_t)arg];
    uint32_t hint = ABGS_NO_HINT;
    double out[8];
    int k = (int)(size_t)arg * 37;
    while (!atomic_load(&stop_queries)) {
        k = (k + 1) % M;
        int kind = k % KINDS;
        const double *p = &pts[3 * k];
        abgs_status st;
        switch (kind) {
        case PLAIN: st = abgs_query_size(grid, p, &out[0]); break;
        case HINTED: st = abgs_query_size_hinted(grid, p, &hint, &out[0]); break;
        case BATCH: st = abgs_query_sizes(grid, p, 1, &out[0]); break;
        case VOLUME: st = abgs_query_size_volume(grid, p, BETA, &out[0]); break;
        default: st = abgs_query_sizes_volume(grid, p, 1, BETA, &out[0]); break;
        }
        count(t, st);
        if (st == ABGS_OK && memcmp(&out[0], &reference[kind][k], sizeof out[0]) != 0) t->wrong++;
        if (k % 8 == 0) { /* leave the lock free now and then, so writers can win too */
            struct timespec d = {0, 20 * 1000};
            nanosleep(&d, NULL);
        }
    }
    return NULL;
}

static void *mutator(void *arg) {
    size_t id = (size_t)arg;
    struct tally *t = &m_tally[id];
    while (!atomic_load(&stop_mutators)) {
        abgs_status st = (id % 2 == 0 || !atomic_load(&pinned)) ? abgs_grid_set_sizes(grid, sizes, NV)
                                                                  : abgs_grid_free(grid);
        count(t, st);
    }
    return NULL;
}

/* Holds the grid (read side) from inside abgs_simplify until released. */
static int32_t hold(const abgs_iteration_record *r, void *user) {
    (void)r;
    (void)user;
    atomic_store(&pinned, 1);
    while (!atomic_load(&release_pin)) sched_yield();
    atomic_store(&pinned, 0);
    return 1; /* stop the simplification after this iteration */
}

static void *pin_worker(void *arg) {
    abgs_grid **out = (abgs_grid **)arg;
    abgs_simplify_params p = {.struct_size = sizeof p};
    abgs_simplify_params_default(&p);
    p.progress = hold;
    abgs_status st = abgs_simplify(grid, &p, out, NULL);
    return (void *)(size_t)st;
}

static void run_phase(int pin, struct tally *q_sum, struct tally *m_sum) {
    memset(q_tally, 0, sizeof q_tally);
    memset(m_tally, 0, sizeof m_tally);
    atomic_store(&stop_queries, 0);
    atomic_store(&stop_mutators, 0);
    atomic_store(&release_pin, 0);
    pthread_t pin_th, q[QUERY_THREADS], m[MUTATORS];
    abgs_grid *pin_out = NULL;
    if (pin) {
        CHECK(pthread_create(&pin_th, NULL, pin_worker, &pin_out) == 0);
        while (!atomic_load(&pinned)) sched_yield();
    }
    for (size_t t = 0; t < QUERY_THREADS; t++) CHECK(pthread_create(&q[t], NULL, query_worker, (void *)t) == 0);
    for (size_t t = 0; t < MUTATORS; t++) CHECK(pthread_create(&m[t], NULL, mutator, (void *)t) == 0);
    struct timespec d = {0, 300 * 1000 * 1000};
    nanosleep(&d, NULL);
    atomic_store(&stop_mutators, 1);
    for (size_t t = 0; t < MUTATORS; t++) pthread_join(m[t], NULL);
    atomic_store(&stop_queries, 1);
    for (size_t t = 0; t < QUERY_THREADS; t++) pthread_join(q[t], NULL);
    if (pin) {
        atomic_store(&release_pin, 1);
        void *st = NULL;
        pthread_join(pin_th, &st);
        CHECK((abgs_status)(size_t)st == ABGS_OK && pin_out != NULL);
        CHECK_STATUS(abgs_grid_free(pin_out), ABGS_OK);
    }
    memset(q_sum, 0, sizeof *q_sum);
    memset(m_sum, 0, sizeof *m_sum);
    for (int t = 0; t < QUERY_THREADS; t++) {
        q_sum->ok += q_tally[t].ok, q_sum->busy += q_tally[t].busy;
        q_sum->wrong += q_tally[t].wrong, q_sum->other += q_tally[t].other;
    }
    for (int t = 0; t < MUTATORS; t++) {
        m_sum->ok += m_tally[t].ok, m_sum->busy += m_tally[t].busy;
        m_sum->other += m_tally[t].other;
    }
}

int main(void) {
    make_plate(N, xyz, tris);
    for (int i = 0; i < NV; i++) {
        double u = xyz[3 * i], v = xyz[3 * i + 1];
        xyz[3 * i + 2] = 0.2 * sin(6.0 * u) * cos(4.0 * v);
        sizes[i] = 0.02 + 0.2 * u + 0.05 * v;
    }
    CHECK_STATUS(abgs_grid_from_arrays(xyz, NV, tris, NT, sizes, &grid), ABGS_OK);
    unsigned long long s = 11;
    for (int k = 0; k < 3 * M; k++) {
        s = s * 6364136223846793005ULL + 1442695040888963407ULL;
        pts[k] = 1.4 * (double)(s >> 11) / 9007199254740992.0 - 0.2;
    }
    /* Single-thread answers of every kind. */
    for (int k = 0; k < M; k++) {
        uint32_t hint = ABGS_NO_HINT;
        const double *p = &pts[3 * k];
        CHECK(abgs_query_size(grid, p, &reference[PLAIN][k]) == ABGS_OK);
        CHECK(abgs_query_size_hinted(grid, p, &hint, &reference[HINTED][k]) == ABGS_OK);
        CHECK(abgs_query_sizes(grid, p, 1, &reference[BATCH][k]) == ABGS_OK);
        CHECK(abgs_query_size_volume(grid, p, BETA, &reference[VOLUME][k]) == ABGS_OK);
        CHECK(abgs_query_sizes_volume(grid, p, 1, BETA, &reference[VOLUME_BATCH][k]) == ABGS_OK);
    }
    CHECK(memcmp(reference[PLAIN], reference[HINTED], sizeof reference[0]) == 0);
    CHECK(memcmp(reference[PLAIN], reference[BATCH], sizeof reference[0]) == 0);
    CHECK(memcmp(reference[VOLUME], reference[VOLUME_BATCH], sizeof reference[0]) == 0);

    struct tally q, m;
    run_phase(0, &q, &m);
    printf("race:   queries ok %ld busy %ld wrong %ld other %ld; set_sizes ok %ld busy %ld other %ld\n",
           q.ok, q.busy, q.wrong, q.other, m.ok, m.busy, m.other);
    CHECK(q.ok > 0 && q.wrong == 0 && q.other == 0);
    CHECK(m.ok + m.busy > 0 && m.other == 0);

    run_phase(1, &q, &m);
    printf("pinned: queries ok %ld busy %ld wrong %ld other %ld; set_sizes/free ok %ld busy %ld other %ld\n",
           q.ok, q.busy, q.wrong, q.other, m.ok, m.busy, m.other);
    CHECK(q.ok > 0 && q.busy == 0 && q.wrong == 0 && q.other == 0);
    CHECK(m.busy > 0 && m.ok == 0 && m.other == 0);

    /* Unpinned and idle, the grid frees. */
    CHECK_STATUS(abgs_grid_free(grid), ABGS_OK);
    return finish();
}
