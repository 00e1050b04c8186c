/*
 * tap.h - a few macros that print the Test Anything Protocol, run by prove.
 *
 *   TAP_CHECK(cond, "name %d", x);   prints "ok N - name" or "not ok N - name"
 *   TAP_NEAR(a, b, tol, "name");     |a - b| <= tol, printing both on failure
 *   return tap_done();               prints the plan "1..N", exit status
 */
#ifndef SOUPTET_TESTS_TAP_H
#define SOUPTET_TESTS_TAP_H

#include <math.h>
#include <stdio.h>

static int tap_count, tap_failed;

static inline int tap_result(int ok, const char *file, int line)
{
    tap_count++;
    if (!ok)
        tap_failed++;
    printf("%s %d - ", ok ? "ok" : "not ok", tap_count);
    (void)file;
    (void)line;
    return ok;
}

#define TAP_CHECK(cond, ...)                                              \
    do {                                                                  \
        int tap_ok_ = (cond) ? 1 : 0;                                     \
        tap_result(tap_ok_, __FILE__, __LINE__);                          \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
        if (!tap_ok_)                                                     \
            printf("#   failed at %s:%d: %s\n", __FILE__, __LINE__, #cond); \
    } while (0)

#define TAP_NEAR(a, b, tol, ...)                                          \
    do {                                                                  \
        double tap_a_ = (double)(a), tap_b_ = (double)(b);                \
        int tap_ok_ = fabs(tap_a_ - tap_b_) <= (double)(tol);             \
        tap_result(tap_ok_, __FILE__, __LINE__);                          \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
        if (!tap_ok_)                                                     \
            printf("#   failed at %s:%d: %.17g vs %.17g (tol %g)\n",      \
                   __FILE__, __LINE__, tap_a_, tap_b_, (double)(tol));    \
    } while (0)

#define TAP_NOTE(...)                                                     \
    do {                                                                  \
        printf("# ");                                                     \
        printf(__VA_ARGS__);                                              \
        printf("\n");                                                     \
    } while (0)

static inline int tap_done(void)
{
    printf("1..%d\n", tap_count);
    return tap_failed ? 1 : 0;
}

#endif
