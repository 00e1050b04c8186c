/*
 * progress.h - how long-running library calls report progress.
 *
 * The library never prints: a caller that wants a progress line passes a
 * callback. It is called from one thread only, with a stage name and the
 * fraction done in [0, 1], often enough for a display (a few times per
 * second at most is the caller's business).
 */
#ifndef SOUPTET_PROGRESS_H
#define SOUPTET_PROGRESS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef void (*st_progress_fn)(void *ctx, const char *stage, double fraction);

typedef struct st_progress {
    st_progress_fn fn;   /* NULL: no reports */
    void *ctx;
} st_progress;

static inline void st_progress_report(const st_progress *p, const char *stage,
                                      double fraction)
{
    if (p && p->fn)
        p->fn(p->ctx, stage, fraction);
}

#ifdef __cplusplus
}
#endif
#endif
