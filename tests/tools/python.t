#!/bin/sh
# The Python module (python/souptet): the pytest suite in tests/python,
# one TAP line per pytest test. The module is built into the build's
# python/ beside SOUPTET_BIN's bin/ (release and debug builds only: under
# config=sanitize the library is ASan-built and a plain python3 cannot
# load it, so this skips).
. "$(dirname "$0")/lib.sh"
BUILD_DIR=$(dirname "$SOUPTET_BIN")
PYDIR="$BUILD_DIR/python"
PY=/usr/bin/python3

case "$(basename "$BUILD_DIR")" in
    build-sanitize|build-fuzz|build-tsan)
        echo "1..0 # SKIP the Python module is not built in $(basename "$BUILD_DIR") (a sanitizer-built library needs its runtime preloaded into python3)"
        exit 0 ;;
esac
if ! ls "$PYDIR"/souptet/_core.*so >/dev/null 2>&1; then
    echo "1..0 # SKIP no Python module in $PYDIR (make builds it when python3-dev and python3-numpy are installed)"
    exit 0
fi
if ! "$PY" -c 'import pytest, numpy' 2>/dev/null; then
    echo "1..0 # SKIP $PY has no pytest or numpy (python3-pytest, python3-numpy)"
    exit 0
fi

SOUPTET_TAP="$WORK/tap" SOUPTET_PYTHON="$PYDIR" SOUPTET_BIN="$SOUPTET_BIN" \
  PYTHONDONTWRITEBYTECODE=1 \
  "$PY" -m pytest -q -p no:cacheprovider --basetemp="$WORK/pytest" "$ROOT/tests/python" \
  >"$WORK/log" 2>&1
rc=$?
touch "$WORK/tap"
cat "$WORK/tap"
n=$(grep -Ec '^(not )?ok ' "$WORK/tap")
if [ "$rc" -ne 0 ] && ! grep -q '^not ok ' "$WORK/tap"; then
    # pytest failed outside a test (collection, import): say where
    n=$((n + 1))
    echo "not ok $n - pytest exited $rc"
    tail -30 "$WORK/log" | sed 's/^/#   /'
fi
tail -1 "$WORK/log" | sed 's/^/# /'
echo "1..$n"
[ "$rc" -eq 0 ]
