#!/bin/sh
# The gate on the symmetry search (symmetry.h, st_symmetry_fill_may_act):
# a soup whose only hole is small against the voxel is not searched (no
# fill could change its cap), and says so in -v and the metadata; one
# with a larger hole is searched.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

cat > ringed.py <<'PY'
import math, sys
# ringed.py C R: a cylinder (radius 1, z in [-1, 1]) of 64 sides in 16
# rings without the side's quads in the first C columns of rings 4..4+R
cols, rings = int(sys.argv[1]), int(sys.argv[2])
n, m = 64, 16
V = [(math.cos(2 * math.pi * k / n), math.sin(2 * math.pi * k / n), -1.0 + 2.0 * r / m)
     for r in range(m + 1) for k in range(n)] + [(0, 0, -1.0), (0, 0, 1.0)]
F = []
for r in range(m):
    for k in range(n):
        a, b = r * n + k, r * n + (k + 1) % n
        if not (k < cols and 4 <= r < 4 + rings):
            F += [(a, b, b + n), (a, b + n, a + n)]
for k in range(n):
    F += [(len(V) - 2, (k + 1) % n, k), (len(V) - 1, m * n + k, m * n + (k + 1) % n)]
print("OFF\n%d %d 0" % (len(V), len(F)))
for v in V:
    print("%.17g %.17g %.17g" % v)
for f in F:
    print("3 %d %d %d" % f)
PY
cat > vti.py <<'PY'
# vti.py meta F: F's symmetry_fill metadata; vti.py same F G: exit 0 when
# the two fields hold the same values, bit for bit
import sys, vtk
from vtk.util.numpy_support import vtk_to_numpy
def read(f):
    r = vtk.vtkXMLImageDataReader(); r.SetFileName(f); r.Update()
    return r.GetOutput()
if sys.argv[1] == "meta":
    a = read(sys.argv[2]).GetFieldData().GetAbstractArray("symmetry_fill")
    print(a.GetValue(0) if a else "")
else:
    x, y = (vtk_to_numpy(read(f).GetPointData().GetScalars()) for f in sys.argv[2:4])
    sys.exit(0 if x.dtype == y.dtype and x.tobytes() == y.tobytes() else 1)
PY
# one quad gone (a hole 0.1 x 0.125) at a voxel of 0.125; 4 x 4 quads
python3 ringed.py 1 1 > small.off && python3 ringed.py 4 4 > large.off &&
    soupdist -r 16 -q small.off -o small.vdb && soupdist -r 16 -q large.off -o large.vdb &&
    soupsign -v --surface small.off -o small.vti small.vdb 2> small.txt &&
    soupsign --symmetry off --surface small.off -o small-off.vti small.vdb &&
    soupsign -v --surface large.off -o large.vti large.vdb 2> large.txt
ok $? "the cylinders with a small and a larger hole are signed"
check "a small hole: -v says the signs did not search" \
    grep -q "not searched by the signs (no fill could change any of the 1 caps" small.txt
check "and the metadata (symmetry_fill) says why" sh -c \
    "$PYVTK vti.py meta small.vti | grep -q '^not searched: no fill could change any of the 1 caps by a voxel'"
check "the signs are those of --symmetry off, bit for bit" $PYVTK vti.py same small.vti small-off.vti
check "a larger hole: searched, the symmetries found and tried" \
    grep -Eq "symmetries: [1-9][0-9]* accepted .*candidates measured\); fill: " large.txt
check "and its metadata records the fill" sh -c \
    "$PYVTK vti.py meta large.vti | grep -Eq '^[1-9][0-9]* symmetries, [0-9]+ maps'"

done_testing
