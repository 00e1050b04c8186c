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
SM="--cells 4 --field-cells 32"
have_soupmesh=0
if [ -x "$SOUPTET_BIN/soupmesh" ]; then
    check "soupmesh makes b4.vtu from the bunny" \
        soupmesh -q $SM -o b4.vtu "$ROOT/corpus/bunny.obj"
    [ -s b4.vtu ] && have_soupmesh=1
fi

# ---- Gmsh -------------------------------------------------------------------
if command -v gmsh >/dev/null 2>&1; then
    for f in m41.msh m41b.msh m22.msh m22b.msh m.mesh; do
        timeout 60 gmsh -check "$f" >gmsh.log 2>&1
        rc=$?
        if [ $rc -eq 0 ] && grep -q 'Info *: 64 nodes' gmsh.log &&
           grep -Eq 'Info *: 135 (elements|tetrahedra)$' gmsh.log &&
           ! grep -q '^Error' gmsh.log; then
            ok 0 "gmsh -check reads $f: 64 nodes, 135 elements, no error"
        else
            ok 1 "gmsh -check reads $f: 64 nodes, 135 elements, no error"
            grep -E 'Error|Warning|nodes|elements' gmsh.log | head -5 |
                sed 's/^/#   /'
        fi
    done
    # Gmsh re-saves each file; we read its output back.
    for f in m41b.msh m22.msh m.mesh; do
        for fmt in msh22 msh41; do
            out="g-${f%.*}-$fmt.msh"
            timeout 60 gmsh "$f" -save -format "$fmt" -o "$out" >gmsh.log 2>&1
            check "gmsh saves $f as $fmt and we read back the same mesh" \
                "$T" --compare m.node "$out"
        done
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
    for f in mio41.msh mio22.msh mio.mesh mio.node; do
        check "meshio's $f reads back to the same mesh" "$T" --compare m.node "$f"
    done
    # .vtu (tetio.h's writer) through meshio, when a tool can make one.
    if [ $have_soupmesh -eq 1 ]; then
        if "$PY" -c 'import meshio
m = meshio.read("b4.vtu")
meshio.write("b.msh", m, file_format="gmsh")' >vtu.log 2>&1; then
            check "meshio reads soupmesh's .vtu; its .msh is the same mesh" \
                "$T" --compare b4.vtu b.msh
        elif grep -q '_parse_raw_binary' vtu.log; then
            # Known: meshio 5.0.0's vtu reader asserts on the <Array
            # type="String"> elements VTK writes for string FieldData (our
            # meta); VTK and ParaView read the file.
            TAP_N=$((TAP_N + 1))
            echo "not ok $TAP_N - meshio reads soupmesh's .vtu # TODO meshio 5.0 cannot parse VTK string FieldData"
        else
            ok 1 "meshio reads soupmesh's .vtu"
            tail -3 vtu.log | sed 's/^/#   /'
        fi
    else
        skip "meshio reads a .vtu" "soupmesh is not built"
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
