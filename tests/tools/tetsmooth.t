#!/bin/sh
# tetsmooth end to end: fit on the bunny's sculpted lattice (encloses, in the
# band, angles raised), fair on a density lattice (volume kept), pipes,
# determinism, refusals, no partial output.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

check "--help exits 0" sh -c 'tetsmooth --help | grep -q "Usage: tetsmooth"'
check "man page exists" test -s "$ROOT/man/man1/tetsmooth.1"

soupdist -r 48 "$BUNNY" | soupsign -o s.vdb
check "a sculpted lattice to fit (6 cells)" latticetet --sculpt --surface "$BUNNY" --cells 6 -o b6.vtu s.vdb
check "a density lattice to fair (8 cells)" latticetet --density 0.5 --cells 8 -o d8.vtu s.vdb

check "fit: file in, -o out, -v" sh -c "tetsmooth -v --fit --surface '$BUNNY' -o f6.vtu b6.vtu 2> fit.log"
check "fit: -v prints per-iteration statistics" grep -Eq "fit +1: [0-9]+/[0-9]+ boundary vertices within offset" fit.log
check "fit: the mesh still encloses the bunny (exact count, 0 -> 0)" \
    grep -q "enclosure: S vertices outside 0 -> 0, S triangles crossing 0 -> 0" fit.log

tetstat --json --surface "$BUNNY" f6.vtu > f6.json 2>/dev/null
cat > q.py <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["inverted"] == 0 and r["degenerate"] == 0, r
# the BCC lattice starts at 60..90; the fit and quality pass must end
# near [30, 140] on this closed model at R = 0.4. On this lattice (seed 1,
# soupmesh's) the fit's rescue reaches the stopping condition; the quality
# pass then ended at 29.96..132.9 degrees (its candidates along the score
# gradients stalled on a plateau of equally bad tets); with a last pass
# along the 26 cube directions too it ends at 34.13..131.4 (issue 18).
assert r["min_dihedral"] >= 33.5 and r["max_dihedral"] <= 140.0, (r["min_dihedral"], r["max_dihedral"])
s = r["surface"]
# Cetra's stopping condition: every boundary vertex within 0.4 h
assert s["dist_max_h"] <= 0.4, (s["dist_max_h"], r["h"])
assert s["encloses"] is True and s["enclosure"] == "yes", s
print(r["min_dihedral"], r["max_dihedral"])
PY
check "fit: no inverted tets, angles in [30, 140], boundary near the surface (tetstat)" \
    /usr/bin/python3 q.py f6.json

# A surface 1.4 times the bunny's size sticks out of the 6-cell lattice:
# the fit cannot enclose it. The mesh is written, the exit status is 3 and
# the error is on stderr even with -q.
awk '/^v /{printf "v %.9g %.9g %.9g\n", $2 * 1.4, $3 * 1.4, $4 * 1.4; next} {print}' \
    "$BUNNY" > big.obj
expect_fail "fit to a surface it cannot enclose: exit 3, said even with -q" 3 \
    '^tetsmooth: b6\.vtu: error: the mesh written to nb\.vtu does not enclose big\.obj: [0-9]+ of its vertices outside' \
    tetsmooth -q --fit --surface big.obj -o nb.vtu b6.vtu
check "... and the mesh was written whole" sh -c "tetstat --json nb.vtu > nb.json"

check "fit through pipes" sh -c "tetsmooth --fit --surface '$BUNNY' < b6.vtu | cat > p6.vtu && test -s p6.vtu"
mkdir t1 t2
(cd t1 && OMP_NUM_THREADS=1 tetsmooth --fit --surface "$BUNNY" -o f.vtu ../b6.vtu 2>/dev/null)
(cd t2 && OMP_NUM_THREADS=2 tetsmooth --fit --surface "$BUNNY" -o f.vtu ../b6.vtu 2>/dev/null)
check "fit: 1 and 2 threads write identical files" cmp t1/f.vtu t2/f.vtu
check "fit --no-quality --max-iters 3" tetsmooth --offset-best-effort --fit --surface "$BUNNY" --no-quality --max-iters 3 -o n6.vtu b6.vtu

# Cetra's stopping condition as soupmesh says it: --offset 0.05 cannot be
# met on 6 cells. The mesh is written, the count and the farthest distance
# in h are said even with -q, and the exit status is 4;
# --offset-best-effort makes it 0 and a warning (silent under -q).
check "--offset 0.05: exit 4, written, said under -q" \
    sh -c "tetsmooth -q --fit --surface '$BUNNY' --offset 0.05 -o o5.vtu b6.vtu 2> o5.err; test \$? -eq 4 && tetstat --json o5.vtu > o5.json && grep -Eq '^tetsmooth: b6.vtu: error: [0-9]+ of [0-9]+ boundary vertices stay farther than 0.05 h from the input, the farthest [0-9.]+ h' o5.err"
check "--offset 0.05 --offset-best-effort: exit 0, a warning" \
    sh -c "tetsmooth --offset-best-effort --fit --surface '$BUNNY' --offset 0.05 -o o5b.vtu b6.vtu 2> o5b.err && grep -Eq '^tetsmooth: b6.vtu: warning: [0-9]+ of [0-9]+ boundary vertices stay farther than 0.05 h' o5b.err"
check "--offset-best-effort -q: silent" \
    sh -c "tetsmooth -q --offset-best-effort --fit --surface '$BUNNY' --offset 0.05 -o o5c.vtu b6.vtu 2> o5c.err && ! test -s o5c.err"
expect_fail "--offset-best-effort with --fair" 2 "go with --fit" tetsmooth --fair --offset-best-effort -o x.vtu b6.vtu

check "fair" sh -c "tetsmooth -v --fair -o fd8.vtu d8.vtu 2> fair.log"
tetstat --json d8.vtu > d8.json 2>/dev/null
tetstat --json fd8.vtu > fd8.json 2>/dev/null
cat > v.py <<'PY'
import json, sys
a = json.load(open(sys.argv[1])); b = json.load(open(sys.argv[2]))
assert b["inverted"] == 0 and b["degenerate"] == 0, b
assert abs(b["volume"] / a["volume"] - 1) <= 0.005, (a["volume"], b["volume"])
assert b["min_dihedral"] > 0 and b["tets"] == a["tets"]
print(a["volume"], b["volume"])
PY
check "fair: volume kept within 0.5%, nothing inverted (tetstat)" /usr/bin/python3 v.py d8.json fd8.json
check "fair: the history records the command" sh -c \
    "/usr/bin/python3 -c \"
import vtk, sys
r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName('fd8.vtu'); r.Update()
fd = r.GetOutput().GetFieldData()
h = [fd.GetAbstractArray(i) for i in range(fd.GetNumberOfArrays()) if fd.GetArrayName(i) == 'history']
v = bytes(int(h[0].GetValue(i)) for i in range(h[0].GetNumberOfTuples())).decode() if h else ''
sys.exit(0 if 'tetsmooth -v --fair' in v and 'latticetet' in v else 1)
\""

cat > noh.py <<'PY'
import sys, vtk
r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(sys.argv[1]); r.Update()
g = r.GetOutput(); g.GetFieldData().RemoveArray("h")
w = vtk.vtkXMLUnstructuredGridWriter(); w.SetFileName(sys.argv[2]); w.SetInputData(g); w.Write()
PY
/usr/bin/python3 noh.py b6.vtu noh.vtu
expect_fail "a mesh without h and no --cell-width" 1 "^tetsmooth: .*cell width" \
    tetsmooth --fit --surface "$BUNNY" -o x.vtu noh.vtu
check "--cell-width stands in for h" tetsmooth --offset-best-effort --fit --surface "$BUNNY" --cell-width 2 --max-iters 2 \
    --quality-rounds 2 -o cw.vtu noh.vtu
check "fair --min-angle 25 --no-quality" sh -c "tetsmooth -v --fair --min-angle 25 --no-quality -o fa.vtu d8.vtu 2> fa.log && grep -q 'after fairing 2[5-9]' fa.log"

expect_fail "no mode" 2 "--fair or --fit" tetsmooth b6.vtu
expect_fail "--fit without --surface" 2 "needs --surface" tetsmooth --fit -o x.vtu b6.vtu
expect_fail "--field with --fair" 2 "go with --fit" tetsmooth --fair --field f.vti -o x.vtu b6.vtu
expect_fail "--field from standard input" 2 "reads a file" tetsmooth --fit --surface "$BUNNY" --field - -o x.vtu b6.vtu
expect_fail "--fair with --surface" 2 "go with --fit" tetsmooth --fair --surface "$BUNNY" -o x.vtu b6.vtu
expect_fail "--fit with --iters" 2 "go with --fair" tetsmooth --fit --surface "$BUNNY" --iters 3 -o x.vtu b6.vtu
expect_fail "bad --step" 2 "step" tetsmooth --fit --surface "$BUNNY" --step 2 -o x.vtu b6.vtu
expect_fail "a missing mesh" 1 "^tetsmooth: missing.vtu" tetsmooth --fair -o x.vtu missing.vtu
printf 'not a mesh' > junk.vtu
expect_fail "a file that is not a mesh" 1 "^tetsmooth: junk.vtu" tetsmooth --fair -o x.vtu junk.vtu
expect_fail "a missing surface" 1 "^tetsmooth: nosuch.obj" tetsmooth --fit --surface nosuch.obj -o x.vtu b6.vtu
check "no partial output" test ! -e x.vtu

done_testing
