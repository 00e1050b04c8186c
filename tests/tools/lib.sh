# tests/tools/lib.sh - TAP helpers for the tool tests (sourced, not run).
#
#   ok COND-EXIT-STATUS "name"    after running a command
#   check "name" CMD...           runs CMD, ok when it exits 0
#   done_testing                  prints the plan, exits non-zero on failure
# SOUPTET_BIN points at build/bin; every test works in its own temp dir.

: "${SOUPTET_BIN:=$(cd "$(dirname "$0")/../.." && pwd)/build/bin}"
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
PATH="$SOUPTET_BIN:$PATH"
export PATH
TAP_N=0
TAP_FAILED=0
WORK=$(mktemp -d "${TMPDIR:-/tmp}/souptet-test.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

ok() {
    TAP_N=$((TAP_N + 1))
    if [ "$1" -eq 0 ]; then
        echo "ok $TAP_N - $2"
    else
        echo "not ok $TAP_N - $2"
        TAP_FAILED=$((TAP_FAILED + 1))
    fi
}

check() {
    name=$1
    shift
    if "$@" >"$WORK/.out" 2>"$WORK/.err"; then
        ok 0 "$name"
    else
        ok 1 "$name"
        sed 's/^/#   /' "$WORK/.err" | head -20
    fi
}

# expect_fail NAME EXIT PATTERN CMD...: CMD exits EXIT and stderr matches
# the extended regular expression PATTERN (one line, the tool's message).
expect_fail() {
    name=$1 want=$2 pat=$3
    shift 3
    "$@" >"$WORK/.out" 2>"$WORK/.err"
    rc=$?
    if [ "$rc" -eq "$want" ] && grep -Eq -- "$pat" "$WORK/.err"; then
        ok 0 "$name"
    else
        ok 1 "$name"
        echo "#   exit $rc (wanted $want); stderr:"
        sed 's/^/#   /' "$WORK/.err" | head -5
    fi
}

done_testing() {
    echo "1..$TAP_N"
    [ "$TAP_FAILED" -eq 0 ]
}

# The Python with Debian's vtk module (a python3 earlier on PATH may lack it).
PYVTK=/usr/bin/python3

# holed_bunny: the bundled bunny with three holes cut (every face whose
# centre is within 0.09 of the diagonal of vertex 100, 1500 or 900), as
# OBJ on stdout: a soup whose fill the pseudo volume must guess.
holed_bunny() {
    "$PYVTK" - "$ROOT/corpus/bunny.obj" <<'EOF'
import math, sys
lines = open(sys.argv[1]).read().splitlines()
v = [l for l in lines if l.startswith("v ")]
f = [l for l in lines if l.startswith("f ")]
P = [tuple(map(float, l.split()[1:4])) for l in v]
d = math.dist([min(p[k] for p in P) for k in range(3)], [max(p[k] for p in P) for k in range(3)])
def centre(l):
    ids = [int(t.split("/")[0]) - 1 for t in l.split()[1:4]]
    return [sum(P[i][k] for i in ids) / 3 for k in range(3)]
keep = [l for l in f if all(math.dist(centre(l), P[q]) > 0.09 * d for q in (100, 1500, 900))]
print("\n".join(v + keep))
EOF
}
