#!/bin/sh
# soupwrap end to end: a pipe from soupdist | soupsign, --surface, every
# output format checked by soupinfo (closed, manifold, oriented, no
# degenerate or self-intersecting triangles), history, refusals.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

check "--help exits 0" sh -c 'soupwrap --help | grep -q "Usage: soupwrap"'
check "--version names the project" sh -c 'soupwrap --version | grep -q "(souptet)"'
check "man page exists" test -s "$ROOT/man/man1/soupwrap.1"

cat > good.py <<'PY'
import json, sys
# good.py REPORT.json [PIECES]: every report is a closed 2-manifold,
# consistently oriented, without degenerate, collinear, duplicated or
# self-intersecting triangles; with PIECES, that many pieces.
for r in json.load(open(sys.argv[1])):
    bad = {k: r[k] for k in ("boundary_edges", "nonmanifold_edges", "nonmanifold_vertices",
                             "inconsistent_edges", "degenerate_triangles", "collinear_triangles",
                             "duplicated_triangles", "self_intersecting_pairs") if r[k] != 0}
    if not r["closed"] or bad:
        sys.exit("%s: closed %s, %s" % (r["file"], r["closed"], bad))
    # STL repeats each triangle's vertices; the others index them once
    if not r["file"].endswith(".stl") and r["welded_vertices"] != r["vertices"]:
        sys.exit("%s: vertices share points" % r["file"])
    if len(sys.argv) > 2 and r["pieces"] != int(sys.argv[2]):
        sys.exit("%s: %d pieces" % (r["file"], r["pieces"]))
PY

check "soupdist | soupsign | soupwrap -o .obj" sh -c "soupdist -r 40 '$BUNNY' | soupsign | soupwrap -o b.obj"
check "the same field from a file, -o .off .ply .stl" sh -c \
    "soupdist -r 40 '$BUNNY' | soupsign -o s.vdb && soupwrap -o b.off s.vdb && soupwrap -o b.ply s.vdb && soupwrap -o b.stl s.vdb"
check "every format: closed, manifold, oriented, no self-intersections (soupinfo)" sh -c \
    "soupinfo --json b.obj b.off b.ply b.stl > r.json && python3 good.py r.json 1"
check "obj, off, ply hold the same vertices and faces" sh -c \
    "soupinfo --json b.obj b.off b.ply | python3 -c 'import json,sys; d=json.load(sys.stdin); assert len(set((r[\"vertices\"], r[\"triangles\"]) for r in d)) == 1, d'"
check "history: soupwrap's command line in the file" grep -q "soupwrap -o b.off s.vdb" b.off
check "history: soupsign's and soupdist's too" sh -c "grep -q '^# soupsign' b.off && grep -q '^# soupdist' b.off"
check "stdout is OBJ, the same surface" sh -c "soupwrap s.vdb > out.obj && grep -v '^#' out.obj > a.txt && grep -v '^#' b.obj > b.txt && cmp a.txt b.txt"

# An exact cube soup (every triangle its own vertices, every other one flipped)
cat > cube.off <<'END'
OFF
36 12 0
0 0 0
1 1 0
1 0 0
0 0 0
0 1 0
1 1 0
0 0 1
1 0 1
1 1 1
0 0 1
1 1 1
0 1 1
0 0 0
1 0 0
1 0 1
0 0 0
1 0 1
0 0 1
0 1 0
0 1 1
1 1 1
0 1 0
1 1 1
1 1 0
0 0 0
0 0 1
0 1 1
0 0 0
0 1 1
0 1 0
1 0 0
1 1 0
1 1 1
1 0 0
1 1 1
1 0 1
3 0 1 2
3 3 5 4
3 6 7 8
3 9 11 10
3 12 13 14
3 15 17 16
3 18 19 20
3 21 23 22
3 24 25 26
3 27 29 28
3 30 31 32
3 33 35 34
END
check "--surface: a flipped cube soup becomes one closed shell" sh -c \
    "soupwrap --surface cube.off -r 24 -o c.ply && soupinfo --json c.ply > c.json && python3 good.py c.json 1"
# The same cube without its last face: its hole is capped (default) or not.
awk 'NR == 2 { print "36 10 0"; next } NR <= 2 + 36 + 10 { print }' cube.off > holed.off
check "--surface: a cube with a face missing becomes one closed shell (hole capped)" sh -c \
    "soupwrap --surface holed.off -r 24 -o h1.ply && soupinfo --json h1.ply > h1.json && python3 good.py h1.json 1"
check "--fill-holes off: one closed shell too" sh -c \
    "soupwrap --surface holed.off --fill-holes off -r 24 -o h2.ply && soupinfo --json h2.ply > h2.json && python3 good.py h2.json 1"
expect_fail "bad --fill-holes" 2 "--fill-holes is on or off" soupwrap --surface holed.off --fill-holes 1
check "--smooth 2 and --adaptivity 0.5 stay valid" sh -c \
    "soupwrap --smooth 2 -o sm.obj s.vdb && soupwrap --adaptivity 0.5 -o ad.obj s.vdb && soupinfo --json sm.obj ad.obj > sa.json && python3 good.py sa.json 1"
check "adaptivity makes fewer faces" sh -c \
    "[ \$(grep -c '^f ' ad.obj) -lt \$(grep -c '^f ' b.obj) ]"

mkdir t1 t2
(cd t1 && OMP_NUM_THREADS=1 soupwrap -o w.ply ../s.vdb)
(cd t2 && OMP_NUM_THREADS=2 soupwrap -o w.ply ../s.vdb)
check "1 and 2 threads write identical files" cmp t1/w.ply t2/w.ply

soupdist -r 24 -o d.vdb cube.off
expect_fail "an unsigned distance field is refused" 1 "^soupwrap: .*sign it first" soupwrap -o x.obj d.vdb
expect_fail "a missing file" 1 "^soupwrap: missing.vdb" soupwrap -o x.obj missing.vdb
expect_fail "a missing surface" 1 "^soupwrap: missing.obj" soupwrap --surface missing.obj -o x.obj
check "no partial output" test ! -e x.obj
expect_fail "unknown output format" 2 "cannot tell the format" soupwrap -o x.xyz s.vdb
# A screw-like CAD part with large holes (issue 37): a hex head on a shank
# whose thread is rings of two radii with flat steps between them, all at
# multiples of 1/8, so at -r 48 and 128 the steps lie on voxel centers: the
# voxels there are at distance 0, the inside ones hold -FLT_MIN, and
# volumeToMesh put up to eight points on each such center. soupwrap exited
# 1 then ("the extracted surface fails its check: degenerate triangles").
cat > screw.py <<'PY'
import math, sys
seg = 24
V, F = [], []
def ring(z, r, hexa=False):
    b = len(V)
    for i in range(seg):
        a = 2 * math.pi * i / seg
        s = math.pi / 3
        rr = r * math.cos(s / 2) / math.cos((a + s / 2) % s - s / 2) if hexa else r
        V.append((rr * math.cos(a), rr * math.sin(a), z))
    return b
def strip(b0, b1):
    for i in range(seg):
        j = (i + 1) % seg
        F.append(((b0 + i, b0 + j, b1 + j), i))
        F.append(((b0 + i, b1 + j, b1 + i), i))
rings = [(ring(0.25 * k, 1.5 if k % 2 == 0 else 1.25),
          ring(0.25 * k + 0.25, 1.5 if k % 2 == 0 else 1.25)) for k in range(32)]
for a, b in rings:
    strip(a, b)
for k in range(31):
    strip(rings[k][1], rings[k + 1][0])
h0, h1 = ring(8.0, 2.75, True), ring(10.0, 2.75, True)
strip(h0, rings[-1][1])
strip(h0, h1)
c0 = len(V); V.append((0, 0, 0))
c1 = len(V); V.append((0, 0, 10.0))
for i in range(seg):
    j = (i + 1) % seg
    F.append(((c0, rings[0][0] + j, rings[0][0] + i), i))
    F.append(((c1, h1 + i, h1 + j), -1 - i))
def gone(f, i):
    zc = sum(V[v][2] for v in f) / 3
    u = (i if i >= 0 else -1 - i) / seg
    return ((0.05 < u < 0.35 and 1.0 < zc < 6.0) or (0.5 < u < 0.8 and 5.0 < zc < 9.0)
            or (i < 0 and 0.6 < u < 0.9))
keep = [f for f, i in F if not gone(f, i)]
print("OFF\n%d %d 0" % (len(V), len(keep)))
for v in V:
    print("%.17g %.17g %.17g" % v)
for f in keep:
    print("3 %d %d %d" % f)
PY
check "screw-like part with large holes: -r 48 and -r 128 give valid surfaces" sh -c \
    "python3 screw.py > screw.off && soupwrap --surface screw.off -r 48 -o sc48.off && soupwrap --surface screw.off -r 128 -o sc128.off && soupinfo --json sc48.off sc128.off > sc.json && python3 good.py sc.json 1"
check "-v: the values held off the isovalue are reported" sh -c \
    "soupwrap --surface screw.off -r 48 -v -o sc.off 2>&1 | grep -q 'isovalue margin: [1-9][0-9]* values held 0.01562 voxels off it'"

expect_fail "-r without --surface" 2 "needs --surface" soupwrap -r 32 s.vdb
expect_fail "field and --surface" 2 "not both" soupwrap --surface cube.off s.vdb
expect_fail "bad --adaptivity" 2 "adaptivity" soupwrap --adaptivity 2 s.vdb

done_testing
