/*
 * fpenv.h - refuse to compile where IEEE double semantics are not what the
 * code was proven under (private; included by every library file whose
 * results depend on them).
 *
 * The predicates' error bounds and expansion arithmetic (pred.c), the
 * exact segment/triangle tests (isect.c), the order-independent distance
 * minimum (dist.c), the rounding arguments of the quality scores
 * (smooth_mesh.c), the correctly rounded number parser (lexer.c) and every
 * isfinite()/isnan() that rejects bad input assume: round to nearest even,
 * each operation rounded once to double, no reassociation, no reciprocal
 * or contraction rewrites, and NaN and infinity that exist. -ffast-math
 * (or -Ofast) breaks all of it: test_pred then finds thousands of
 * near-degenerate orientations wrong. FLT_EVAL_METHOD != 0 (x87 extended
 * precision, e.g. -m32 -mfpmath=387) rounds twice and breaks the
 * two-sum and two-product identities.
 *
 * The Makefile puts -fno-fast-math -ffp-contract=off after the user's
 * CFLAGS, so a plain `make CFLAGS=-ffast-math` still builds correct code;
 * this header catches every other way in (another build system, a
 * compiler driver that appends its own flags). -ffp-contract=fast has no
 * predefined macro and is the Makefile's job alone.
 */
#ifndef SOUPTET_FPENV_H
#define SOUPTET_FPENV_H

#include <float.h>

#if defined(__FAST_MATH__)
#error "souptet: compiled with -ffast-math (or -Ofast): the exact predicates and error bounds need IEEE double arithmetic; remove it or add -fno-fast-math after it"
#endif
#if defined(__FINITE_MATH_ONLY__) && __FINITE_MATH_ONLY__
#error "souptet: compiled with -ffinite-math-only: NaN and infinity checks on the input would be compiled away; add -fno-finite-math-only"
#endif
#if !defined(FLT_EVAL_METHOD) || FLT_EVAL_METHOD != 0
#error "souptet: FLT_EVAL_METHOD is not 0 (extended-precision evaluation, e.g. x87): double rounding breaks the exact predicates; build with SSE2 (-msse2 -mfpmath=sse) or for x86-64"
#endif

#endif
