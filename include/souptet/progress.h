/*
 * progress.h - how long-running library calls report progress.
 *
 * Units: fractions in [0, 1].
 * Ownership: the caller owns the callback's context and the cancel flag,
 * which must outlive the call.
 * Threads: the callback is called from one thread; the flag may be set from
 * any thread or a signal handler.
 * Errors: a cancelled call returns ST_ECANCELLED and frees what it made.
 *
 * The library never prints: a caller that wants a progress line passes a
 * callback. It is called from one thread only, with a stage name and the
 * fraction done in [0, 1], often enough for a display (a few times per
 * second at most is the caller's business).
 *
 * Cancelling: a caller that may want to stop a long call points cancel at
 * an int it owns and sets it to nonzero (from any thread, or a signal
 * handler: st_progress_cancel). The long calls (the distance field, the
 * signs and the pseudo volume, the pipeline, the fit, the wrap) look at it
 * often enough to stop within about 0.1 s of work; they then free what
 * they made and return ST_ECANCELLED, with nothing written.
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
    volatile int *cancel;   /* NULL, or nonzero once the caller wants the
                               call to stop */
} st_progress;

/* Nonzero once p's caller asked to stop (p may be NULL). Cheap: a relaxed
 * atomic load, callable from any thread, in parallel loops. */
static inline int st_progress_cancelled(const st_progress *p)
{
    return p && p->cancel && __atomic_load_n(p->cancel, __ATOMIC_RELAXED) != 0;
}

/* Ask the call that was given flag to stop; async-signal-safe. */
static inline void st_progress_cancel(volatile int *flag)
{
    __atomic_store_n(flag, 1, __ATOMIC_RELAXED);
}

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
