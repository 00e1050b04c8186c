#!/bin/sh
# soupdist end to end: formats, pipes, VTK's reader, bad input, atomic output.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

check "--help exits 0" sh -c 'soupdist --help | grep -q "Usage: soupdist"'
check "--version names the project" sh -c 'soupdist --version | grep -q "(souptet)"'
check "man page exists and renders" sh -c "man -l '$ROOT/man/man1/soupdist.1' >/dev/null 2>&1 || test -s '$ROOT/man/man1/soupdist.1'"

check "bunny to .vdb" soupdist -r 48 -o b.vdb "$BUNNY"
check "bunny to .vti" soupdist -r 48 -o b.vti "$BUNNY"
# The .vdb reader's walk of OpenVDB's delayed-load metadata (the leaves'
# mask: raw under 48 bytes, else blosc, padded to 128 bytes when shorter)
# lets every real field through: 25, 78, 165 and 637 leaves.
for r in 16 32 48 96; do
    soupdist -r $r -o r$r.vdb "$BUNNY" && soupsign -o r$r-s.vdb r$r.vdb 2>r$r.err && ! [ -s r$r.err ]
    ok $? "soupdist -r $r .vdb reads back (soupsign)"
done
check "bunny to a stream on a pipe" sh -c "soupdist -r 48 '$BUNNY' | cat > s.vdb && test -s s.vdb"
check "stdin in, stream out" sh -c "soupdist -r 48 - < '$BUNNY' | cat > s2.vdb && test -s s2.vdb"

# VTK's own reader opens the .vti: dims, spacing, the scalars, band values
cat > readvti.py <<'PY'
import sys, vtk
r = vtk.vtkXMLImageDataReader(); r.SetFileName(sys.argv[1]); r.Update()
img = r.GetOutput(); a = img.GetPointData().GetScalars()
lo, hi = a.GetRange()
dims = img.GetDimensions()
assert a.GetName() == "distance", a.GetName()
assert dims[0] > 48 and a.GetNumberOfTuples() == dims[0] * dims[1] * dims[2]
assert lo >= 0 and abs(hi - 3 * img.GetSpacing()[0]) < 1e-6 * hi, (lo, hi)
print("ok", dims, lo, hi)
PY
check "VTK's reader opens the .vti (python3-vtk9)" $PYVTK readvti.py b.vti

# Determinism: the same field for 1 and 2 threads (the .vti has no volatile bytes)
# (same output name in two folders: the history records the command line)
mkdir t1 t2
(cd t1 && OMP_NUM_THREADS=1 soupdist -r 40 -o t.vti "$BUNNY")
(cd t2 && OMP_NUM_THREADS=2 soupdist -r 40 -o t.vti "$BUNNY")
check "1 and 2 threads write identical files" cmp t1/t.vti t2/t.vti

# Bad input: exit 1, "soupdist: FILE:LINE: what", no output file
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n' > range.obj
expect_fail "index out of range: file and line" 1 "^soupdist: range.obj:4: " soupdist -o x.vdb range.obj
printf 'v 0 0 0\nv 1 0 nan\nv 0 1 0\nf 1 2 3\n' > nan.obj
expect_fail "NaN coordinate: file and line" 1 "^soupdist: nan.obj:2: " soupdist -o x.vdb nan.obj
printf 'OFF\n1000000000000 1 0\n0 0 0\n' > huge.off
expect_fail "absurd header count" 1 "^soupdist: huge.off:" soupdist -o x.vdb huge.off
: > empty.stl
expect_fail "empty file" 1 "^soupdist: empty.stl" soupdist -o x.vdb empty.stl
printf 'v 0 0 0\nv 1 0 0\n' > notri.obj
expect_fail "no triangles" 1 "^soupdist: notri.obj" soupdist -o x.vdb notri.obj
head -c 500 "$BUNNY" > trunc.obj; printf 'f 1 2\n' >> trunc.obj
expect_fail "truncated face" 1 "^soupdist: trunc.obj:[0-9]+: " soupdist -o x.vdb trunc.obj
mkdir adir.obj
expect_fail "a directory" 1 "^soupdist: adir.obj" soupdist -o x.vdb adir.obj
expect_fail "a missing file" 1 "^soupdist: missing.obj" soupdist -o x.vdb missing.obj
check "no partial output after failures" test ! -e x.vdb

# Output errors: unwritable place, nothing left behind
expect_fail "unwritable output directory" 1 "^soupdist: nodir/x.vdb" soupdist -r 16 -o nodir/x.vdb "$BUNNY"
expect_fail "unknown output format" 2 "format" soupdist -o x.txt "$BUNNY"
check "no temporary files left" sh -c '! ls -a | grep -q "^\.x\."'

# Usage errors: exit 2
expect_fail "unknown option" 2 "unknown option" soupdist --bogus "$BUNNY"
expect_fail "-r 0" 2 "-r wants" soupdist -r 0 "$BUNNY"
expect_fail "absurd -r" 2 "-r wants" soupdist -r 99999999999 "$BUNNY"
expect_fail "band below 3" 2 "--band wants" soupdist --band 1 "$BUNNY"
expect_fail "-r and -s together" 2 "not both" soupdist -r 8 -s 0.1 "$BUNNY"
expect_fail "memory limit names the fix" 1 "max-memory" soupdist -r 2000 --max-memory 64M -o x.vdb "$BUNNY"
expect_fail "negative voxel size" 2 "-s wants" soupdist -s -1 "$BUNNY"

done_testing
