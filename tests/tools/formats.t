#!/bin/sh
# tests/tools/formats.t - the tet-mesh formats (tetformat.h) against their
# real consumers: Gmsh reads our .msh (4.1 and 2.2, ASCII and binary) and
# .mesh and saves them again, TetGen rebuilds its mesh from our .node/.ele,
# meshio reads every file and writes its own, and what they write reads
# back to the same points and tets. A consumer that is not installed gives
# "# SKIP" (scripts/setup installs gmsh, tetgen and python3-meshio).
#
# test_tetformat --write DIR writes the sample (a perturbed 3x3x3 block of
# 135 tets, coordinates that need 17 digits); --compare A B checks that two
# files hold the same mesh.
. "$(dirname "$0")/lib.sh"

TB=${SOUPTET_TESTBIN:-$ROOT/build/tests}
T=$TB/test_tetformat
cd "$WORK" || exit 1

skip() {
    TAP_N=$((TAP_N + 1))
    echo "ok $TAP_N - $1 # SKIP $2"
}

check "the sample is written in all six variants" "$T" --write "$WORK"
grep -q '^64 135$' "$WORK/.out"
ok $? "the sample has 64 points and 135 tets"

# A real mesh from the tools, when they are built (small: a few seconds).
SM="--cells 4 --voxels 32 --offset-best-effort"
have_soupmesh=0
if [ -x "$SOUPTET_BIN/soupmesh" ]; then
    check "soupmesh makes b4.vtu from the bunny" \
        soupmesh -q $SM -o b4.vtu "$ROOT/corpus/bunny.obj"
    [ -s b4.vtu ] && have_soupmesh=1
fi

# latticetet and tetsmooth take soupmesh's .msh options (tetio.h's one
# front door): each variant holds the same mesh as the tool's .vtu.
if [ -x "$SOUPTET_BIN/latticetet" ]; then
    soupdist -q -r 24 "$ROOT/corpus/bunny.obj" | soupsign -q > f24.vdb &&
        latticetet -q --density 0.5 --cells 4 -o lo.vtu f24.vdb &&
        tetsmooth -q --fair -o to.vtu lo.vtu
    ok $? "latticetet and tetsmooth write .vtu"
    for opt in "--msh-binary" "--msh-version 2" "--msh-version 2 --msh-binary"; do
        tag=$(echo "$opt" | tr -dc 'a-z0-9')
        latticetet -q --density 0.5 --cells 4 $opt -o "lo$tag.msh" f24.vdb &&
            "$T" --compare lo.vtu "lo$tag.msh" &&
            tetsmooth -q --fair $opt -o "to$tag.msh" lo.vtu &&
            "$T" --compare to.vtu "to$tag.msh"
        ok $? "latticetet and tetsmooth $opt: the same mesh as their .vtu"
    done
    head -c 200 lomshbinary.msh | grep -aq '^4.1 1 8' &&
        head -c 200 lomshversion2.msh | grep -aq '^2.2 0 8' &&
        head -c 200 lomshversion2mshbinary.msh | grep -aq '^2.2 1 8'
    ok $? "the options give msh 4.1 binary, 2.2 ASCII, 2.2 binary"
    expect_fail "tetsmooth --msh-version 3 is a usage error" 2 \
        "^tetsmooth: --msh-version is 2 or 4" tetsmooth --msh-version 3 -o x.msh lo.vtu
fi

# The boundary the .msh and .mesh files carry as triangles (physical group
# "boundary", Medit reference 2): as many as tetstat counts boundary faces,
# and outward: the cones from the origin over them sum to the mesh volume.
NB= VOL=
if [ -x "$SOUPTET_BIN/tetstat" ] && tetstat -q --json m.node >nb.json; then
    NB=$(sed -n 's/.*"boundary_faces": \([0-9]*\).*/\1/p' nb.json)
    VOL=$(sed -n 's/.*"volume": \([-0-9.e+]*\).*/\1/p' nb.json)
fi
[ -n "$NB" ] && [ "$NB" -gt 0 ] && [ -n "$VOL" ]
ok $? "tetstat counts the sample's boundary faces ($NB) and volume ($VOL)"
for f in m41.msh m41b.msh m22.msh m22b.msh; do
    sed -n '/^\$PhysicalNames/,/^\$EndPhysicalNames/p' "$f" >pn.txt
    grep -q '^2 2 "boundary"$' pn.txt && grep -q '^3 1 "volume"$' pn.txt
    ok $? "$f names its physical groups: 3-D 1 \"volume\", 2-D 2 \"boundary\""
done
grep -q '^Triangles$' m.mesh && [ "$(sed -n '/^Triangles$/{n;p;q}' m.mesh)" = "$NB" ]
ok $? "m.mesh has a Triangles section of the $NB boundary faces"

# ---- Gmsh -------------------------------------------------------------------
if command -v gmsh >/dev/null 2>&1; then
    NE=$((135 + ${NB:-0}))
    for f in m41.msh m41b.msh m22.msh m22b.msh m.mesh; do
        timeout 60 gmsh -check "$f" >gmsh.log 2>&1
        rc=$?
        if [ $rc -eq 0 ] && grep -q 'Info *: 64 nodes' gmsh.log &&
           { grep -Eq "Info *: $NE elements\$" gmsh.log ||
             { grep -q 'Info *: 135 tetrahedra$' gmsh.log &&
               grep -q "Info *: $NB triangles\$" gmsh.log; }; } &&
           ! grep -q '^Error' gmsh.log; then
            ok 0 "gmsh -check reads $f: 64 nodes, $NE elements (135 tets, $NB triangles), no error"
        else
            ok 1 "gmsh -check reads $f: 64 nodes, $NE elements (135 tets, $NB triangles), no error"
            grep -E 'Error|Warning|nodes|elements' gmsh.log | head -5 |
                sed 's/^/#   /'
        fi
    done
    # Gmsh re-saves each file; we read its output back. Gmsh numbers the
    # nodes it saves by entity (boundary nodes on the surface first) in
    # 2.2 and from .mesh: those are matched by coordinates.
    for f in m41b.msh m22.msh m.mesh; do
        for fmt in msh22 msh41; do
            out="g-${f%.*}-$fmt.msh"
            how=--renumbered
            [ "$f" = m41b.msh ] && how=
            timeout 60 gmsh "$f" -save -format "$fmt" -o "$out" >gmsh.log 2>&1
            check "gmsh saves $f as $fmt and we read back the same mesh" \
                "$T" --compare m.node "$out" $how
        done
    done
    for f in m41.msh m22b.msh; do
        timeout 60 gmsh "$f" -0 -o "g0-$f" >gmsh.log 2>&1
        grep -q '^2 2 "boundary"$' "g0-$f" && grep -q '^3 1 "volume"$' "g0-$f"
        ok $? "gmsh keeps the physical groups of $f (gmsh $f -0)"
    done
    timeout 60 gmsh m41.msh -save -format msh41 -bin -o g-bin.msh >gmsh.log 2>&1
    check "gmsh's own 4.1 binary reads back to the same mesh" \
        "$T" --compare m.node g-bin.msh
else
    skip "gmsh reads our .msh and .mesh" "gmsh is not installed"
fi

# ---- TetGen -----------------------------------------------------------------
if command -v tetgen >/dev/null 2>&1; then
    cp m.node t.node && cp m.ele t.ele
    timeout 60 tetgen -rV t >tetgen.log 2>&1
    rc=$?
    [ $rc -eq 0 ] && grep -q 'Input tetrahedra: 135' tetgen.log &&
        grep -q 'Mesh tetrahedra: 135' tetgen.log
    ok $? "tetgen -r rebuilds our .node/.ele: 135 tetrahedra in and out"
    check "tetgen's t.1.node/t.1.ele read back to the same mesh" \
        "$T" --compare m.node t.1.node --sets
else
    skip "tetgen -r reads our .node/.ele" "tetgen is not installed"
fi

# ---- meshio -----------------------------------------------------------------
PY=/usr/bin/python3
if [ -x "$PY" ] && "$PY" -c 'import meshio' 2>/dev/null; then
    cat >meshio_check.py <<'EOF'
import sys, warnings
import numpy as np
import meshio
warnings.simplefilter("ignore")
files = sys.argv[1:]
ref = None
bad = 0
for f in files:
    m = meshio.read(f)
    tets = [c.data for c in m.cells if c.type == "tetra"]
    if len(tets) != 1:
        print("#   %s: no single tetra block" % f); bad = 1; continue
    t = tets[0]
    p = m.points
    if ref is None:
        ref = (p, t)
    elif not (np.array_equal(p, ref[0]) and np.array_equal(t, ref[1])):
        print("#   %s: differs from %s" % (f, files[0])); bad = 1
    # meshio's tetra corner order: positive volume (as Gmsh's).
    a, b, c, d = (p[t[:, k]] for k in range(4))
    vol = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))
    if not (vol > 0).all():
        print("#   %s: %d tets with volume <= 0" % (f, (vol <= 0).sum())); bad = 1
print("%d %d" % (len(ref[0]), len(ref[1])))
# meshio writes every format; tetformat reads them back.
meshio.write("mio41.msh", meshio.Mesh(ref[0], [("tetra", ref[1])]), file_format="gmsh")
meshio.write("mio22.msh", meshio.Mesh(ref[0], [("tetra", ref[1])]), file_format="gmsh22", binary=False)
meshio.write("mio.mesh", meshio.Mesh(ref[0], [("tetra", ref[1])]))
meshio.write("mio.node", meshio.Mesh(ref[0], [("tetra", ref[1])]))
sys.exit(bad)
EOF
    "$PY" meshio_check.py m41.msh m41b.msh m22.msh m22b.msh m.node m.mesh \
        >meshio.log 2>&1
    rc=$?
    [ $rc -eq 0 ] && grep -q '^64 135$' meshio.log
    ok $? "meshio reads all six variants: identical points and tets, all positive"
    [ $rc -eq 0 ] || grep '^#' meshio.log | head -5
    cat >meshio_bnd.py <<'EOF'
import sys, warnings
import numpy as np
import meshio
warnings.simplefilter("ignore")
nb, vol = int(sys.argv[1]), float(sys.argv[2])
bad = 0
for f in sys.argv[3:]:
    m = meshio.read(f)
    tri = [(i, c.data) for i, c in enumerate(m.cells) if c.type == "triangle"]
    tet = [(i, c.data) for i, c in enumerate(m.cells) if c.type == "tetra"]
    if len(tri) != 1 or len(tet) != 1 or len(tri[0][1]) != nb:
        print("#   %s: %s, want one tetra and one triangle block of %d"
              % (f, [(c.type, len(c.data)) for c in m.cells], nb)); bad = 1; continue
    key = "medit:ref" if f.endswith(".mesh") else "gmsh:physical"
    cd = m.cell_data.get(key)
    if cd is None or set(cd[tet[0][0]]) != {1} or set(cd[tri[0][0]]) != {2}:
        print("#   %s: %s is not 1 on tets and 2 on triangles" % (f, key)); bad = 1
    if not f.endswith(".mesh"):
        fd = {k: list(v) for k, v in m.field_data.items()}
        if fd.get("volume") != [1, 3] or fd.get("boundary") != [2, 2]:
            print("#   %s: field_data %s" % (f, fd)); bad = 1
    if "41" in f:   # meshio makes cell_sets from 4.1 files only
        cs = m.cell_sets
        if "volume" not in cs or "boundary" not in cs or \
           len(cs["boundary"][tri[0][0]]) != nb or len(cs["volume"][tet[0][0]]) != len(tet[0][1]):
            print("#   %s: cell_sets %s" % (f, sorted(cs))); bad = 1
    p, t = m.points, tri[0][1]
    s = np.einsum("ij,ij->i", p[t[:, 0]], np.cross(p[t[:, 1]], p[t[:, 2]])).sum() / 6
    if not abs(s - vol) <= 1e-9 * abs(vol):
        print("#   %s: boundary cones sum to %.17g, the mesh volume is %.17g" % (f, s, vol)); bad = 1
    print("%s %d %.17g" % (f, len(t), s))
sys.exit(bad)
EOF
    "$PY" meshio_bnd.py "${NB:-0}" "${VOL:-0}" m41.msh m41b.msh m22.msh m22b.msh \
        m.mesh >mbnd.log 2>&1
    rc=$?
    ok $rc "meshio: $NB outward boundary triangles in every .msh (physical 2, \"boundary\") and .mesh (ref 2)"
    [ $rc -eq 0 ] || grep '^#' mbnd.log | head -5
    for f in mio41.msh mio22.msh mio.mesh mio.node; do
        check "meshio's $f reads back to the same mesh" "$T" --compare m.node "$f"
    done
    # Every .vtu souptet writes (tetio.h's writer) through meshio: a mesh
    # from soupmesh, from latticetet and from tetsmooth, the --embed point
    # cloud, and the test sample (meta of every kind). meshio 5-7 refused
    # them all (VTK's String field data) before the meta became numbers
    # and bytes.
    if [ $have_soupmesh -eq 1 ]; then
        soupmesh -q $SM --embed e4.vtu -o be.vtu "$ROOT/corpus/bunny.obj" &&
        soupdist -q -r 24 "$ROOT/corpus/bunny.obj" | soupsign -q |
            latticetet -q --density 0.5 --cells 4 -o lt.vtu &&
        tetsmooth -q --fair -o ts.vtu lt.vtu &&
        "$TB/test_tetio" --write sample.vtu
        ok $? "soupmesh, --embed, latticetet, tetsmooth and the library write their .vtu"
        cat >meshio_vtu.py <<'EOF'
import sys, warnings
import numpy as np
import meshio
warnings.simplefilter("ignore")
bad = 0
for f in sys.argv[1:]:
    try:
        m = meshio.read(f)
    except Exception as e:
        print("#   %s: meshio: %s: %s" % (f, type(e).__name__, e)); bad = 1; continue
    types = sorted(c.type for c in m.cells)
    n = sum(len(c.data) for c in m.cells)
    fd = m.field_data
    # Numbers are numbers; text is bytes that decode as UTF-8.
    text = {k: bytes(v.astype(np.uint8)).decode() for k, v in fd.items()
            if v.dtype == np.uint8}
    nums = {k: float(v[0]) for k, v in fd.items() if v.dtype in (np.float64, np.uint64)}
    if "seed" in fd and fd["seed"].dtype != np.uint64:
        print("#   %s: seed is %s, not uint64" % (f, fd["seed"].dtype)); bad = 1
    print("%s %s %d %s %s" % (f, ",".join(types), n,
          "history" in text, ",".join(sorted(nums))))
    for k, v in m.cell_data.items():
        if any(len(x) == 0 for x in v):
            print("#   %s: empty cell array %s" % (f, k)); bad = 1
sys.exit(bad)
EOF
        "$PY" meshio_vtu.py b4.vtu be.vtu e4.vtu lt.vtu ts.vtu sample.vtu >mvtu.log 2>&1
        rc=$?
        ok $rc "meshio reads every .vtu souptet writes"
        [ $rc -eq 0 ] || grep '^#' mvtu.log | head -5
        grep -Eq '^b4.vtu tetra [1-9][0-9]* True (.*,)?h,' mvtu.log &&
            grep -q '^b4.vtu .*seed' mvtu.log
        ok $? "meshio: the mesh's history is text, h and seed are numbers"
        n=$(grep -c '^v ' "$ROOT/corpus/bunny.obj")
        grep -q "^e4.vtu vertex $n " mvtu.log
        ok $? "meshio: the --embed .vtu is $n vertex cells (one per input vertex)"
        grep -q '^sample.vtu tetra 2 True .*offset_ratio' mvtu.log
        ok $? "meshio: the sample's field data (text and numbers)"
        if "$PY" -c 'import meshio
m = meshio.read("b4.vtu")
meshio.write("b.msh", m, file_format="gmsh")' >vtu.log 2>&1; then
            check "meshio's .msh of soupmesh's .vtu is the same mesh" \
                "$T" --compare b4.vtu b.msh
        else
            ok 1 "meshio writes soupmesh's .vtu as .msh"
            tail -3 vtu.log | sed 's/^/#   /'
        fi
        # VTK (what ParaView reads with) sees the same metadata, typed.
        if "$PYVTK" -c 'import vtk' 2>/dev/null; then
            cat >vtk_meta.py <<'EOF'
import sys, vtk
r = vtk.vtkXMLUnstructuredGridReader()
r.SetFileName(sys.argv[1]); r.Update()
g = r.GetOutput(); fd = g.GetFieldData()
out = []
for i in range(fd.GetNumberOfArrays()):
    a = fd.GetAbstractArray(i)
    if a.GetDataType() == vtk.VTK_UNSIGNED_CHAR:
        v = bytes(int(a.GetValue(k)) for k in range(a.GetNumberOfTuples())).decode()
        out.append("%s text %s" % (a.GetName(), v.split("\n")[0]))
    else:
        out.append("%s %s %r" % (a.GetName(), a.GetDataTypeAsString(), a.GetTuple1(0)))
types = set(g.GetCellType(c) for c in range(g.GetNumberOfCells()))
print("\n".join(out)); print("celltypes", sorted(types))
EOF
            "$PYVTK" vtk_meta.py b4.vtu >vmeta.log 2>&1
            grep -q '^h double [0-9.]*$' vmeta.log && grep -q '^history text .*soupmesh' vmeta.log &&
                grep -q '^source text .*bunny.obj' vmeta.log && grep -q '^celltypes \[10\]$' vmeta.log
            rc=$?
            ok $rc "VTK reads the metadata: h a double, history and source text"
            [ $rc -eq 0 ] || sed 's/^/#   /' vmeta.log | head -8
            "$PYVTK" vtk_meta.py e4.vtu >vmeta.log 2>&1
            grep -q '^celltypes \[1\]$' vmeta.log
            ok $? "VTK reads the --embed .vtu as vertex cells"
            # The tools read it all back: tetsmooth keeps the typed meta.
            tetsmooth -q --fair -o ts2.vtu b4.vtu && "$PYVTK" vtk_meta.py ts2.vtu >vmeta2.log 2>&1
            grep -q '^h double' vmeta2.log && grep -q '^history text .*soupmesh' vmeta2.log &&
                grep -q '^offset_ratio double 0.4$' vmeta2.log
            ok $? "tetsmooth reads the typed meta back and writes it again"
        else
            skip "VTK reads the metadata" "python3-vtk9 is not installed"
        fi
    else
        skip "meshio reads every .vtu" "soupmesh is not built"
    fi
else
    skip "meshio reads our files" "python3-meshio is not installed"
fi

# ---- the tools, once tetio.c dispatches to tetformat -----------------------
if [ -x "$SOUPTET_BIN/tetstat" ]; then
    # tetio.c dispatches to tetformat: an 'unknown tet mesh format' here
    # is a regression, and fails.
    for f in m41.msh m41b.msh m22.msh m22b.msh m.node m.ele m.mesh; do
        tetstat -q --json "$f" >ts.json 2>ts.err
        rc=$?
        [ $rc -eq 0 ] && grep -q '"tets": 135' ts.json
        ok $? "tetstat reads $f: 135 tets"
        [ $rc -eq 0 ] || sed 's/^/#   /' ts.err | head -3
    done
    expect_fail "tetstat refuses a truncated .msh with its line" 1 \
        'm-cut\.msh:[0-9]+: ' sh -c 'head -c 3000 m22.msh >m-cut.msh && tetstat m-cut.msh'
else
    skip "tetstat reads every format" "tetstat is not built"
fi
if [ $have_soupmesh -eq 1 ]; then
    for f in b4.msh b4.node b4.mesh; do
        check "soupmesh -o $f writes the same mesh as its .vtu" sh -c \
            "soupmesh -q $SM -o $f '$ROOT/corpus/bunny.obj' && '$T' --compare b4.vtu $f"
    done
    [ -s b4.ele ] && ! ls .b4* >/dev/null 2>&1
    ok $? "soupmesh -o b4.node also wrote b4.ele, and no temporary file is left"
    grep -q '^souptet history: .*soupmesh.* -o b4.msh' b4.msh
    ok $? "the .msh records soupmesh's command line in \$Comments"
    soupmesh -q $SM --msh-version 2 -o b22.msh "$ROOT/corpus/bunny.obj"
    sed -n 2p b22.msh | grep -q '^2\.2 0 8$'
    ok $? "soupmesh --msh-version 2 writes msh 2.2"
    tetstat --json - < b4.msh > stdin.json && grep -q '"tets": [1-9]' stdin.json
    ok $? "tetstat reads a .msh on stdin (sniffed)"
else
    skip "soupmesh writes .msh .node .mesh by -o extension" "soupmesh is not built"
fi

done_testing
