#!/bin/sh
# tetstat end to end: hand-made meshes with known answers (written by VTK's
# own Python writer, so foreign .vtu files are read too), surfaces that are
# and are not enclosed, a field, stdin, VTK reading what souptet writes,
# bad input, usage errors, thread-count independence.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

check "--help exits 0" sh -c 'tetstat --help | grep -q "Usage: tetstat"'
check "--version names the project" sh -c 'tetstat --version | grep -q "(souptet)"'
check "man page exists and renders" sh -c "man -l '$ROOT/man/man1/tetstat.1' >/dev/null 2>&1 || test -s '$ROOT/man/man1/tetstat.1'"

# mk.py: meshes (lattices of 5-tet cubes, mirrored on alternating cubes),
# box surfaces (outward OFF), a signed field (.vti), a non-tet mesh.
cat > mk.py <<'PY'
import sys, vtk

def det(a, b, c, d):
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    w = [d[i] - a[i] for i in range(3)]
    return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
            + u[2] * (v[0] * w[1] - v[1] * w[0]))

def lattice(n, o=(0, 0, 0), s=1.0):
    nx, ny, nz = n
    pts = [(o[0] + s * i, o[1] + s * j, o[2] + s * k)
           for k in range(nz + 1) for j in range(ny + 1) for i in range(nx + 1)]
    V = lambda i, j, k: i + (nx + 1) * (j + (ny + 1) * k)
    tets = []
    for k in range(nz):
        for j in range(ny):
            for i in range(nx):
                c = [V(i + (q & 1), j + (q >> 1 & 1), k + (q >> 2 & 1)) for q in range(8)]
                odd = (i + j + k) & 1
                mid = [[1, 2, 4, 7], [0, 3, 5, 6]][odd]
                cor = [[0, 3, 5, 6], [1, 2, 4, 7]][odd]
                ts = [[c[q] for q in mid]] + [[c[a], c[a ^ 1], c[a ^ 2], c[a ^ 4]] for a in cor]
                for t in ts:
                    if det(*[pts[q] for q in t]) < 0:
                        t[2], t[3] = t[3], t[2]
                    tets.append(t)
    return pts, tets

def write_vtu(path, pts, tets, meta={}, ascii=False, celltype=vtk.VTK_TETRA):
    ug = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    for q in pts:
        p.InsertNextPoint(q)
    ug.SetPoints(p)
    for t in tets:
        ids = vtk.vtkIdList()
        for q in t:
            ids.InsertNextId(q)
        ug.InsertNextCell(celltype, ids)
    for k, v in meta.items():
        a = vtk.vtkStringArray()
        a.SetName(k)
        a.InsertNextValue(v)
        ug.GetFieldData().AddArray(a)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(ug)
    if ascii:
        w.SetDataModeToAscii()
    assert w.Write() == 1

def write_box_off(path, lo, hi):
    v = [(hi[0] if q & 1 else lo[0], hi[1] if q & 2 else lo[1], hi[2] if q & 4 else lo[2])
         for q in range(8)]
    quads = [(0, 4, 6, 2), (1, 3, 7, 5), (0, 1, 5, 4), (2, 6, 7, 3), (0, 2, 3, 1), (4, 5, 7, 6)]
    with open(path, "w") as f:
        f.write("OFF\n8 12 0\n")
        for q in v:
            f.write("%r %r %r\n" % q)
        for a, b, c, d in quads:
            f.write("3 %d %d %d\n3 %d %d %d\n" % (a, b, c, a, c, d))

write_vtu("regular.vtu", [(1, 1, 1), (1, -1, -1), (-1, -1, 1), (-1, 1, -1)], [[0, 1, 2, 3]])
pts, tets = lattice((1, 1, 1))
write_vtu("cube.vtu", pts, tets, {"h": "1", "lattice": "cubic5"}, ascii=True)
tets[2][2], tets[2][3] = tets[2][3], tets[2][2]
write_vtu("inverted.vtu", pts, tets)
write_vtu("twocubes.vtu", *lattice((2, 1, 1)))
write_vtu("big.vtu", *lattice((2, 2, 2)))
write_vtu("big-h.vtu", *lattice((2, 2, 2)), {"h": "1"})
pts, tets = lattice((2, 2, 2))
tets[0][2], tets[0][3] = tets[0][3], tets[0][2]
write_vtu("big-inverted.vtu", pts, tets)
write_vtu("hex.vtu", [(i & 1, i >> 1 & 1, i >> 2 & 1) for i in range(8)],
          [[0, 1, 3, 2, 4, 5, 7, 6]], celltype=vtk.VTK_HEXAHEDRON)
write_box_off("inner.off", (0.5, 0.5, 0.5), (1.5, 1.5, 1.5))
write_box_off("out.off", (1.25, 0.5, 0.5), (2.25, 1.5, 1.5))
# A signed field over [-0.5, 2]^3, voxel 0.5: negative where every
# coordinate is 0.5, 1 or 1.5 (27 centers); 125 centers lie in big.vtu.
img = vtk.vtkImageData()
img.SetDimensions(6, 6, 6)
img.SetOrigin(-0.5, -0.5, -0.5)
img.SetSpacing(0.5, 0.5, 0.5)
a = vtk.vtkFloatArray()
a.SetName("sdf")
for k in range(6):
    for j in range(6):
        for i in range(6):
            p = [-0.5 + 0.5 * q for q in (i, j, k)]
            a.InsertNextValue(max(abs(p[0] - 1), abs(p[1] - 1), abs(p[2] - 1)) - 0.6)
img.GetPointData().SetScalars(a)
w = vtk.vtkXMLImageDataWriter()
w.SetFileName("f.vti")
w.SetInputData(img)
assert w.Write() == 1
# Around the bundled bunny: a 6x6x6 block of cubes over its padded box.
lo = [1e300] * 3
hi = [-1e300] * 3
for line in open(sys.argv[1]):
    if line.startswith("v "):
        x = [float(t) for t in line.split()[1:4]]
        lo = [min(lo[i], x[i]) for i in range(3)]
        hi = [max(hi[i], x[i]) for i in range(3)]
s = max(hi[i] - lo[i] for i in range(3)) * 1.1 / 6
o = [0.5 * (lo[i] + hi[i]) - 3 * s for i in range(3)]
write_vtu("bunnybox.vtu", *lattice((6, 6, 6), o, s))
PY
check "make the test meshes with VTK's Python writer" $PYVTK mk.py "$BUNNY"

# want.py FILE KEY=VALUE...: the JSON report has these values (numbers
# compared to 1e-4, so 54.7356 matches acos(1/sqrt 3)); a/b for nested keys.
cat > want.py <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
for kv in sys.argv[2:]:
    k, v = kv.split("=")
    got = r
    for part in k.split("/"):
        got = got[part]
    want = {"true": True, "false": False, "null": None}.get(v, v)
    if isinstance(got, bool) or got is None or isinstance(want, bool) or want is None:
        ok = got == want
    elif isinstance(got, str):
        ok = got == want
    else:
        ok = abs(got - float(want)) <= 1e-4 * max(1, abs(float(want)))
    if not ok:
        sys.exit("%s: %s is %r, wanted %s" % (sys.argv[1], k, got, v))
PY

check "regular tet: table says 70.5288 both ways" sh -c "tetstat regular.vtu > reg.txt && grep -Eq '^  min dihedral +70.5288$' reg.txt && grep -Eq '^  max dihedral +70.5288$' reg.txt"
check "regular tet: JSON" sh -c "tetstat --json regular.vtu > reg.json && python3 want.py reg.json tets=1 points=4 min_dihedral=70.52878 max_dihedral=70.52878 inverted=0 boundary_faces=4"
check "cube (ASCII .vtu): 54.74..90, volume 1, one component, conforming, h" \
    sh -c "tetstat --json cube.vtu > cube.json && python3 want.py cube.json tets=5 points=8 min_dihedral=54.73561 max_dihedral=90 volume=1 components=1 conforming=true nonmanifold_faces=0 interior_faces=4 boundary_faces=12 h=1 inverted=0 degenerate=0"
check "cube: histogram 4 tets in 50..60, 1 in 70..80" \
    python3 -c "import json; c=json.load(open('cube.json'))['min_dihedral_histogram']['counts']; assert c==[0,0,0,0,0,4,0,1,0], c"
check "cube: the table shows h" sh -c "tetstat cube.vtu | grep -Eq '^  lattice h +1$'"
check "two cubes sharing a face: 20 boundary, 10 interior faces, volume 2" \
    sh -c "tetstat --json twocubes.vtu > two.json && python3 want.py two.json tets=10 boundary_faces=20 interior_faces=10 volume=2 components=1 conforming=true"
check "inverted tet: exit 0, counted, flagged in the table and on stderr" \
    sh -c "tetstat inverted.vtu > inv.txt 2> inv.err && grep -Eq '^  inverted tets +1 .*INVERTED' inv.txt && grep -q 'warning: 1 inverted tet' inv.err"
check "inverted tet: -q keeps stderr quiet" sh -c "tetstat -q inverted.vtu > /dev/null 2> q.err && test ! -s q.err"
check "stdin" sh -c "tetstat --json < cube.vtu > in.json && python3 want.py in.json file='<stdin>' tets=5"
check "'-' is stdin" sh -c "cat cube.vtu | tetstat --json - | python3 -c 'import json,sys; assert abs(json.load(sys.stdin)[\"volume\"] - 1) < 1e-12'"

# Against surfaces: the inner box [0.5,1.5]^3 of the mesh [0,2]^3.
check "inner box: distances, volume ratio 8" \
    sh -c "tetstat --json --surface inner.off big.vtu > inner.json && python3 want.py inner.json surface/vertices=8 surface/triangles=12 surface/boundary_vertices=26 surface/dist_min=0.5 surface/dist_max=0.8660254 surface/surface_dist_max=0.5 surface/closed=true surface/surface_volume=1 surface/volume_ratio=8"
# The enclosure test is always built: a null "encloses" is a failure here.
check "inner box: enclosed (every vertex inside, nothing crossing)" \
    python3 want.py inner.json surface/encloses=true surface/enclosure=yes surface/vertices_inside=8 surface/fraction_inside=1 surface/crossing_triangles=0
# Both distances in h (h = 1) and relative to the inner box's diagonal
# (sqrt 3); the stopping condition: 8 corners at 0.866 h, 12 edge
# midpoints at 0.707 h, 6 face centres at 0.5 h.
check "inner box: both distances in h and per diagonal" \
    sh -c "tetstat --json --surface inner.off big-h.vtu > innerh.json && python3 want.py innerh.json surface/diagonal=1.7320508 surface/dist_max_h=0.8660254 surface/dist_max_diag=0.5 surface/surface_dist_max_h=0.5 surface/surface_dist_max_diag=0.2886751 surface/offset_ratio=null"
check "--offset 0.9: condition met" \
    sh -c "tetstat --json --offset 0.9 --surface inner.off big-h.vtu > o9.json && python3 want.py o9.json surface/offset_ratio=0.9 surface/beyond_offset=0 surface/offset_met=true"
check "--offset 0.75: the 8 corners beyond, a warning" \
    sh -c "tetstat --json --offset 0.75 --surface inner.off big-h.vtu > o75.json 2> o75.err && python3 want.py o75.json surface/beyond_offset=8 surface/offset_met=false && grep -q '8 boundary vertices farther than 0.75 h' o75.err"
check "--offset 0.6: corners and edge midpoints beyond, in the table" \
    sh -c "tetstat --offset 0.6 --surface inner.off big-h.vtu 2>/dev/null | grep -q 'beyond 0.6 h (offset) *20 *<- OFFSET NOT MET'"
expect_fail "--offset without --surface" 2 "needs --surface" tetstat --offset 0.4 big.vtu
check "--offset on a mesh without h: not reported, said on stderr" \
    sh -c "tetstat --json --offset 0.6 --surface inner.off big.vtu > noh.json 2> noh.err && python3 want.py noh.json surface/beyond_offset=null surface/dist_max_h=null && grep -q 'no cell width' noh.err"
check "box sticking out: not enclosed, said on stderr" \
    sh -c "tetstat --json --surface out.off big.vtu > out.json 2> out.err && python3 want.py out.json surface/encloses=false surface/enclosure=no surface/vertices_inside=4 surface/fraction_inside=0.5 && grep -q 'does not enclose out.off' out.err"
check "box sticking out: the table says so" sh -c "tetstat --surface out.off big.vtu 2>/dev/null | grep -q 'DOES NOT ENCLOSE'"
# One inverted tet: the counts are clean but prove nothing (enclose.h).
check "an inverted tet: clean counts, enclosure unverified, not 'encloses'" \
    sh -c "tetstat --json --surface inner.off big-inverted.vtu > inv.json 2> inv.err && python3 want.py inv.json surface/encloses=false surface/enclosure=unverified surface/vertices_inside=8 surface/crossing_triangles=0 && grep -q 'enclosure of inner.off unverified' inv.err"
check "an inverted tet: the table says unverified" \
    sh -c "tetstat --surface inner.off big-inverted.vtu 2>/dev/null | grep -Eq '^  encloses S +unverified'"
check "box sticking out: S -> boundary max 0.75" \
    sh -c "tetstat --json --surface out.off big.vtu 2>/dev/null > out2.json && python3 want.py out2.json surface/surface_dist_max=0.75"
check "a soup that is not oriented: volume n/a in the table" \
    sh -c "awk 'NR>3+8 {print \$1, \$2, \$4, \$3; next} {print}' inner.off > flip.off && tetstat --surface flip.off big.vtu | grep -Eq '^  volume ratio +n/a$'"

# Against a field: 125 voxel centers in the closed mesh, 27 negative.
check "field: IoU 27/125" \
    sh -c "tetstat --json --field f.vti big.vtu > f.json && python3 want.py f.json field/mesh_inside=125 field/field_inside=27 field/both=27 field/iou=0.216"

# What souptet writes opens in VTK's own reader, with the quality arrays.
check "souptet writes a sample .vtu" "$SOUPTET_TESTBIN/test_tetio" --write s.vtu
cat > vtkread.py <<'PY'
import sys, vtk
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1])
r.Update()
g = r.GetOutput()
assert g.GetNumberOfCells() == 2 and g.GetNumberOfPoints() == 5, (g.GetNumberOfCells(), g.GetNumberOfPoints())
assert all(g.GetCellType(i) == vtk.VTK_TETRA for i in range(2))
cd = g.GetCellData()
for n in ("min_dihedral", "max_dihedral", "volume", "region"):
    assert cd.GetArray(n) is not None, n
assert cd.GetScalars().GetName() == "min_dihedral"
assert cd.GetArray("region").GetNumberOfComponents() == 3
assert g.GetPointData().GetArray("temperature") is not None
fd = g.GetFieldData()
# Numbers as numbers, text as UInt8 bytes (tetio_vtu.cpp, for meshio).
assert fd.GetAbstractArray("h").GetDataType() == vtk.VTK_DOUBLE
assert fd.GetAbstractArray("h").GetTuple1(0) == 0.0625
ha = fd.GetAbstractArray("history")
assert ha.GetDataType() == vtk.VTK_UNSIGNED_CHAR
hist = bytes(int(ha.GetValue(i)) for i in range(ha.GetNumberOfTuples())).decode()
assert hist.endswith("latticetet --density 0.5"), hist
# The sample's first tet is negatively oriented: -1/210 (to rounding).
v = [cd.GetArray("volume").GetValue(i) for i in range(2)]
assert abs(v[0] + 1 / 210) < 1e-6 and v[1] > 0, v
PY
check "VTK's reader opens it: tets, quality arrays, mesh arrays, field data" $PYVTK vtkread.py s.vtu
check "tetstat reads it" sh -c "tetstat --json s.vtu > s.json && python3 want.py s.json tets=2 h=0.0625 interior_faces=1 inverted=1"

# The bunny in a 6x6x6 block of cubes: enclosed, and 1 or 2 threads agree.
check "bunny in a block: report" sh -c "tetstat --json --surface '$BUNNY' bunnybox.vtu > b2.json && python3 want.py b2.json tets=1080 components=1 conforming=true surface/vertices=1839 surface/closed=true"
if python3 -c "import json,sys; sys.exit(json.load(open('b2.json'))['surface']['encloses'] is None)"; then
    check "bunny in a block: enclosed" python3 want.py b2.json surface/encloses=true surface/crossing_triangles=0
fi
check "1 and 2 threads give the same report" sh -c "tetstat --threads 1 --json --surface '$BUNNY' bunnybox.vtu > b1.json && cmp b1.json b2.json"

# Bad input, usage.
expect_fail "a hexahedron is refused" 1 "^tetstat: hex.vtu: .*not a tetrahedron" tetstat hex.vtu
expect_fail "a missing mesh" 1 "^tetstat: missing.vtu: cannot open" tetstat missing.vtu
printf '<VTKFile garbage' > junk.vtu
expect_fail "a garbled mesh" 1 "^tetstat: junk.vtu:[0-9:]* " tetstat junk.vtu
head -c 600 s.vtu > trunc.vtu
expect_fail "a truncated mesh" 1 "^tetstat: trunc.vtu:[0-9:]* " tetstat trunc.vtu
expect_fail "empty stdin" 1 "^tetstat: <stdin>: empty" sh -c "tetstat < /dev/null"
expect_fail "a missing surface" 1 "^tetstat: nope.obj" tetstat --surface nope.obj cube.vtu
# Well-formed (it passes the pre-flight check of src/io/vtkxml.h), but its
# zlib block is not zlib: VTK itself fails and says so.
printf '<VTKFile type="ImageData" version="1.0" compressor="vtkZLibDataCompressor"><ImageData WholeExtent="0 1 0 0 0 0"><Piece Extent="0 1 0 0 0 0"><PointData><DataArray type="Float32" Name="f" format="binary">AQAAAGAAAAAAAAAABAAAAA==AAAAAA==</DataArray></PointData></Piece></ImageData></VTKFile>' > junk.vti
expect_fail "a garbled field: VTK's message reaches the field reader" 1 "^tetstat: junk.vti: .*Zlib error" tetstat --field junk.vti cube.vtu
printf '<VTKFile type="ImageData" junk' > junk2.vti
expect_fail "a malformed field is refused at its line" 1 "^tetstat: junk2.vti:1: " tetstat --field junk2.vti cube.vtu
expect_fail "a missing field" 1 "^tetstat: nope.vdb" tetstat --field nope.vdb cube.vtu
check "a failed read prints no report" sh -c "! tetstat missing.vtu 2>/dev/null | grep -q ."
expect_fail "two meshes" 2 "one mesh at a time" tetstat cube.vtu big.vtu
# One truth: on a bunny with three holes (the largest caps 0.09 of the
# diagonal), soupmesh's fit meets its condition against the soup and its
# fill, and tetstat --surface alone rebuilds that fill from the mesh's
# meta: the same count (0), no OFFSET NOT MET, no warning (it said 19
# vertices beyond, up to 1.14 h, and NOT MET).
holed_bunny > holed.obj
soupmesh -q -o holed.vtu holed.obj 2> holed.err
ok $? "soupmesh meshes the holed bunny and says nothing is amiss (exit 0: its offset condition holds)"
sed 's/^/#   /' holed.err | head -3
tetstat --surface holed.obj holed.vtu > holed.txt 2> holed.warn
grep -Eq 'beyond 0.4 h \(S\|fill\) +0 +\(met\)' holed.txt && ! grep -q 'NOT MET' holed.txt &&
    [ ! -s holed.warn ]
ok $? "tetstat --surface alone agrees: 0 beyond 0.4 h against the soup and its fill, no NOT MET, no warning"
sed 's/^/#   /' holed.warn | head -3
grep -E 'beyond 0.4 h' holed.txt | sed 's/^/#   /'
tetstat --json --surface holed.obj holed.vtu 2>/dev/null | grep -q '"offset_met": true'
ok $? "tetstat --json: offset_met true"
soupmesh -q --offset-fill off -o holed-s.vtu holed.obj 2>/dev/null
rc=$?
tetstat --surface holed.obj holed-s.vtu > holed-s.txt 2>/dev/null
if [ $rc -eq 0 ]; then
    ! grep -q 'NOT MET' holed-s.txt && ! grep -q 'S|fill' holed-s.txt
else
    [ $rc -eq 4 ] && grep -q 'beyond 0.4 h (offset) .*NOT MET' holed-s.txt
fi
ok $? "soupmesh --offset-fill off (exit $rc) and tetstat measure against the soup alone, agreeing"

expect_fail "unknown option" 2 "unknown option" tetstat --frobnicate cube.vtu
expect_fail "stdin twice" 2 "standard input" tetstat --surface - -
expect_fail "bad --threads" 2 "threads" tetstat --threads 0 cube.vtu

done_testing
