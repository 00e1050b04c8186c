/*
 * stream26 - the memory floor for sign voting, a peer for `make bench`.
 *
 *   stream26 FIELD [--threads T] [--repeat R]
 *
 * Reads a field and streams it 26 times the plainest way that does the
 * same traffic as voting: each pass reads every value and adds a byte vote
 * (value below a threshold) into a vote array, in storage order, in
 * parallel. Prints JSON: the best time of R runs. soupsign's voting should
 * stay within a small factor of it.
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

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: stream26 FIELD [--threads T] [--repeat R]\n");
        return 2;
    }
    int repeat = 3;
    for (int i = 2; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--repeat") == 0)
            repeat = atoi(argv[i + 1]);
#ifdef _OPENMP
        else if (strcmp(argv[i], "--threads") == 0)
            omp_set_num_threads(atoi(argv[i + 1]));
#endif
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
    double best = INFINITY;
    unsigned long check = 0;
    for (int r = 0; r < repeat; r++) {
        memset(votes, 0, n);
        double t0 = now();
        for (int pass = 0; pass < 26; pass++) {
            #pragma omp parallel for schedule(static)
            for (size_t i = 0; i < n; i++)
                votes[i] = (uint8_t)(votes[i] + (fabsf(g->data[i]) < t));
        }
        double dt = now() - t0;
        if (dt < best)
            best = dt;
        for (size_t i = 0; i < n; i += 4099)
            check += votes[i];
    }
    printf("{\"peer\": \"stream26\", \"voxels\": %zu, \"best_s\": %.6f, \"check\": %lu}\n",
           n, best, check);
    free(votes);
    st_grid_free(g);
    return 0;
}
