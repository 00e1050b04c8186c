#!/bin/sh
# Exactness cannot be compiled away: the predicates refuse to compile under
# -ffast-math, -Ofast, -ffinite-math-only and extended-precision
# evaluation (src/base/fpenv.h), every library source that uses floating point
# includes that check, and the Makefile's own flags win over a user's
# CFLAGS=-ffast-math (pred.c and test_pred built that way still pass).
. "$(dirname "$0")/lib.sh"
cd "$ROOT" || exit 1
CC=${CC:-cc}
# pred.c in its layer's folder (src/MODULES), or in a flat src/.
PRED=$(find src -name pred.c | head -1)
PRED_O=${PRED#src/}
PRED_O=${PRED_O%.c}.o

# refused NAME FLAGS...: compiling pred.c with FLAGS fails with a
# message from fpenv.h that names the problem.
refused() {
    name=$1 pat=$2
    shift 2
    if "$CC" -std=c11 -D_POSIX_C_SOURCE=200809L -Iinclude "$@" -fsyntax-only "$PRED" \
            >"$WORK/.out" 2>"$WORK/.err"; then
        ok 1 "$name"
        echo "#   compiled without a word"
    elif grep -q "fpenv.h.*error: #error \"souptet: .*$pat" "$WORK/.err"; then
        ok 0 "$name"
    else
        ok 1 "$name"
        sed 's/^/#   /' "$WORK/.err" | head -5
    fi
}
refused "pred.c refuses -ffast-math" "-ffast-math" -ffast-math
refused "pred.c refuses -Ofast" "-ffast-math" -Ofast
refused "pred.c refuses -ffinite-math-only" "finite-math-only" -ffinite-math-only
refused "pred.c refuses FLT_EVAL_METHOD 2 (x87)" "FLT_EVAL_METHOD" \
    -Wno-builtin-macro-redefined -U__FLT_EVAL_METHOD__ -D__FLT_EVAL_METHOD__=2
check "pred.c compiles with -ffast-math undone after it" \
    "$CC" -std=c11 -Iinclude -ffast-math -fno-fast-math -fsyntax-only "$PRED"

# Every source file of the library (and the tools' common code) that uses floating point
# includes the check (a new file cannot skip it unnoticed).
missing=
for f in src/*.c src/*/*.c src/adapters/*.cpp; do
    [ -f "$f" ] || continue
    case $f in src/tools/*) continue;; esac
    if grep -Eq '\<(double|float)\>|isfinite|isnan' "$f" &&
            ! grep -Eq '^#include "([a-z./]*/)?fpenv\.h"' "$f"; then
        missing="$missing $f"
    fi
done
[ -z "$missing" ]
ok $? "every floating-point source includes fpenv.h"
[ -z "$missing" ] || echo "#   missing in:$missing"

# The Makefile's flags come after the user's: make CFLAGS='-O2 -ffast-math'
# builds pred.c and test_pred with IEEE semantics, and test_pred passes.
B="$WORK/b"
if env -u MAKEFLAGS -u MFLAGS -u MAKELEVEL make -s --no-print-directory config=release \
        BUILD="$B" CFLAGS="-O2 -ffast-math" "$B/obj/$PRED_O" "$B/obj/tests/test_pred.o" \
        >"$WORK/.out" 2>"$WORK/.err"; then
    ok 0 "make CFLAGS='-O2 -ffast-math' builds pred.o (the mandatory flags win)"
    if "$CC" -fopenmp "$B/obj/tests/test_pred.o" "$B/obj/$PRED_O" -lm -o "$B/test_pred" \
            2>"$WORK/.err" && "$B/test_pred" >"$WORK/.out" 2>&1; then
        ok 0 "test_pred built with CFLAGS='-O2 -ffast-math' passes"
    else
        ok 1 "test_pred built with CFLAGS='-O2 -ffast-math' passes"
        grep '^not ok' "$WORK/.out" | head -5 | sed 's/^/#   /'
    fi
else
    ok 1 "make CFLAGS='-O2 -ffast-math' builds pred.o (the mandatory flags win)"
    sed 's/^/#   /' "$WORK/.err" | head -5
    ok 1 "test_pred built with CFLAGS='-O2 -ffast-math' passes # not built"
fi

done_testing
