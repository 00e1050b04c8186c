/*
 * stream26 - the memory floor for sign voting, a peer for `make bench`.
 *
 *   stream26 FIELD [--threads T] [--repeat R] [--simd]
 *
 * Reads a field and streams it 26 times the plainest way that does the
 * same traffic as voting: each pass reads every value and adds a byte vote
 * (value below a threshold) into a vote array, in storage order, in
 * parallel. Prints JSON: the best wall time of R runs and the CPU time
 * (all threads) of that run. soupsign's voting should stay within a small
 * factor of it.
 *
 * --simd: the same passes written so the compiler vectorises them (the
 * pointers hoisted and restrict, `omp simd`): far fewer instructions per
 * voxel, so nearer the memory bandwidth; the default loop is the plain one
 * (the compiler reloads g->data every voxel and does not vectorise it).
 */
#include "souptet/gridio.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_now(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The vectorised passes (--simd). */
static void passes_simd(uint8_t *restrict votes, const float *restrict data, size_t n, float t)
{
    for (int pass = 0; pass < 26; pass++) {
        #pragma omp parallel for simd schedule(static)
        for (size_t i = 0; i < n; i++)
            votes[i] = (uint8_t)(votes[i] + (fabsf(data[i]) < t));
    }
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: stream26 FIELD [--threads T] [--repeat R] [--simd]\n");
        return 2;
    }
    int repeat = 3, simd = 0;
    for (int i = 2; i < argc; i++) {
        if (strcmp(argv[i], "--simd") == 0)
            simd = 1;
        else if (strcmp(argv[i], "--repeat") == 0 && i + 1 < argc)
            repeat = atoi(argv[++i]);
#ifdef _OPENMP
        else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc)
            omp_set_num_threads(atoi(argv[++i]));
#endif
        else {
            fprintf(stderr, "stream26: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    st_grid *g;
    st_error err;
    if (st_grid_read(&g, argv[1], 0, &err)) {
        fprintf(stderr, "stream26: %s: %s\n", argv[1], err.msg);
        return 1;
    }
    size_t n = st_grid_count(g);
    uint8_t *votes = calloc(n, 1);
    const float t = (float)(0.6 * g->voxel);
    double best = INFINITY, best_cpu = 0.0;
    unsigned long check = 0;
    for (int r = 0; r < repeat; r++) {
        memset(votes, 0, n);
        double t0 = now(), c0 = cpu_now();
        if (simd)
            passes_simd(votes, g->data, n, t);
        else
            for (int pass = 0; pass < 26; pass++) {
                #pragma omp parallel for schedule(static)
                for (size_t i = 0; i < n; i++)
                    votes[i] = (uint8_t)(votes[i] + (fabsf(g->data[i]) < t));
            }
        double dt = now() - t0, dc = cpu_now() - c0;
        if (dt < best) {
            best = dt;
            best_cpu = dc;
        }
        for (size_t i = 0; i < n; i += 4099)
            check += votes[i];
    }
    printf("{\"peer\": \"stream26\", \"mode\": \"%s\", \"voxels\": %zu, \"best_s\": %.6f, "
           "\"cpu_s\": %.6f, \"check\": %lu}\n",
           simd ? "simd" : "plain", n, best, best_cpu, check);
    free(votes);
    st_grid_free(g);
    return 0;
}
