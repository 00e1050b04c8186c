#!/bin/sh
# tests/tools/conventions.t - what a TetGen, Gmsh or fTetWild user expects
# of every tool (issue 40, item 5): -h is help, -V and --version print the
# version and the commit, one option name means one thing (a field's
# voxels are -r/--voxels everywhere, the old spellings still work with a
# note), a surface format or a .msh option on a tet mesh output is a usage
# error, and soupmesh --json says what tetstat --json reads back.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1
BUNNY="$ROOT/corpus/bunny.obj"
TB=${SOUPTET_TESTBIN:-$ROOT/build/tests}
TOOLS="soupdist soupsign soupinfo soupwrap latticetet tetsmooth tetstat soupmesh"

for t in $TOOLS; do
    "$t" --help >long.txt 2>long.err; rc_long=$?
    "$t" -h >short.txt 2>short.err; rc_short=$?
    [ $rc_long -eq 0 ] && [ $rc_short -eq 0 ] && [ -s short.txt ] && cmp -s long.txt short.txt &&
        ! [ -s short.err ]
    ok $? "$t -h: the help of --help, exit 0 (exit $rc_short)"
    grep -Eq '^  -h, --help ' short.txt && grep -Eq '^  -V, --version ' short.txt
    ok $? "$t --help lists -h, --help and -V, --version"
    "$t" -V >v.txt 2>v.err; rc=$?
    "$t" --version >vl.txt 2>&1
    [ $rc -eq 0 ] && cmp -s v.txt vl.txt &&
        grep -Eq "^$t \\(souptet\\) [0-9]+\\.[0-9]+\\.[0-9]+\$" v.txt &&
        grep -Eq '^commit ([0-9a-f]{7,}|v?[0-9][^ ]*-g[0-9a-f]+)(-dirty)?$|^commit unknown$' v.txt
    ok $? "$t -V and --version: version and commit ($(tr '\n' ' ' <v.txt))"
done

# In a clone, the commit is one of its own (HEAD's after make; an earlier
# one when the tools were built before the last commit).
if git -C "$ROOT" rev-parse HEAD >/dev/null 2>&1; then
    c=$(soupmesh -V | sed -n 's/^commit \(.*-g\)\{0,1\}\([0-9a-f]\{7,\}\)\(-dirty\)\{0,1\}$/\2/p')
    [ -n "$c" ] && git -C "$ROOT" merge-base --is-ancestor "$c" HEAD
    ok $? "--version names a commit of this clone's history (${c:-none}; HEAD $(git -C "$ROOT" rev-parse --short=12 HEAD))"
fi

# One name, one meaning: -r/--voxels is the field's resolution. Fields
# are compared by their grid and values (the history differs).
cat >same_grid.py <<'EOF'
import sys, numpy as np
from vtk.util.numpy_support import vtk_to_numpy
import vtk
def load(f):
    r = vtk.vtkXMLImageDataReader(); r.SetFileName(f); r.Update()
    g = r.GetOutput()
    return g.GetDimensions(), g.GetSpacing(), vtk_to_numpy(g.GetPointData().GetArray(0))
a, b = load(sys.argv[1]), load(sys.argv[2])
sys.exit(0 if a[0] == b[0] and a[1] == b[1] and np.array_equal(a[2], b[2]) else 1)
EOF
same_grid() { "$PYVTK" same_grid.py "$1" "$2"; }
soupdist -q -r 24 -o r.vti "$BUNNY" && soupdist -q --voxels 24 -o v.vti "$BUNNY" &&
    same_grid r.vti v.vti
ok $? "soupdist --voxels is -r"
soupdist --cells 24 -o c.vti "$BUNNY" 2>c.err && same_grid r.vti c.vti &&
    grep -q '^soupdist: --cells is now --voxels (-r)' c.err
ok $? "soupdist --cells still works, with a note"
soupdist -q --cells 24 -o cq.vti "$BUNNY" 2>cq.err && ! [ -s cq.err ]
ok $? "... which -q silences"
soupdist -q -s 0.5 -o s.vti "$BUNNY" && soupdist --voxel 0.5 -o s2.vti "$BUNNY" 2>s.err &&
    same_grid s.vti s2.vti && grep -q 'voxel is now --voxel-size' s.err
ok $? "soupdist --voxel still works, with a note (--voxel-size)"
soupwrap --surface "$BUNNY" --cells 24 -o w.obj 2>w.err && grep -q 'cells is now --voxels' w.err &&
    soupwrap -q --surface "$BUNNY" --voxels 24 -o w2.obj &&
    [ "$(grep -v '^#' w.obj | cksum)" = "$(grep -v '^#' w2.obj | cksum)" ]
ok $? "soupwrap --cells still works, with a note; --voxels is the same"
SM="-q --offset-best-effort --cells 4"
soupmesh $SM -r 32 -o a.vtu "$BUNNY" && soupmesh $SM --voxels 32 -o b.vtu "$BUNNY" &&
    soupmesh --offset-best-effort --cells 4 --field-cells 32 -o c.vtu "$BUNNY" 2>f.err &&
    tetstat -q --json a.vtu >a.json && tetstat -q --json c.vtu >c.json &&
    grep -q '^soupmesh: --field-cells is now --voxels' f.err
ok $? "soupmesh -r, --voxels and the old --field-cells"
"$TB"/test_tetformat --compare a.vtu b.vtu 2>/dev/null || cmp -s a.json c.json
ok $? "... make the same mesh"
soupmesh -h 0.5 >h.txt 2>h.err && grep -q '^Usage: soupmesh' h.txt && ! [ -s h.err ]
ok $? "soupmesh -h takes no value: -h 0.5 is help, not the cell width"

# Outputs a tet mesh cannot go to.
expect_fail "soupmesh -o x.stl: a surface format, use --boundary" 2 \
    "^soupmesh: STL is a surface format: use --boundary x.stl for the cage's surface" \
    soupmesh -o x.stl "$BUNNY"
expect_fail "latticetet -o x.obj: a surface format" 2 "^latticetet: OBJ is a surface format" \
    latticetet --density 0.5 -o x.obj nothing.vdb
for t in "soupmesh --cells 4 $BUNNY" "tetsmooth --fair nothing.vtu" \
         "latticetet --density 0.5 nothing.vdb"; do
    expect_fail "${t%% *} --msh-version 2 -o x.vtu: usage error" 2 \
        "^${t%% *}: --msh-version shapes a .msh output, not 'x.vtu'" $t --msh-version 2 -o x.vtu
    expect_fail "${t%% *} --msh-binary on stdout: usage error" 2 \
        "^${t%% *}: --msh-binary shapes a .msh output, not '<stdout>'" sh -c "$t --msh-binary >x.out"
done
soupmesh -q --offset-best-effort --cells 4 --msh-version 2 --msh-binary -o ok.msh "$BUNNY"
ok $? "... and with a .msh output they are fine"

# soupmesh --json: one object, the numbers tetstat reads from the mesh.
soupmesh -q --cells 4 --voxels 32 --tries 2 --json -o j.vtu "$BUNNY" >j.json
rc=$?
tetstat -q --json --surface "$BUNNY" j.vtu >t.json
"$PYVTK" - j.json t.json $rc <<'EOF'
import json, sys
j = json.load(open(sys.argv[1])); t = json.load(open(sys.argv[2]))
print('#', {k: j[k] for k in ('tets', 'h', 'seed', 'encloses', 'offset_met', 'exit_status')})
m = t
assert j['tool'] == 'soupmesh' and j['exit_status'] == int(sys.argv[3])
assert j['tets'] == m['tets'], (j['tets'], m['tets'])
assert abs(j['h'] - t['h']) <= 1e-12 * j['h']
assert j['encloses'] is True and j['candidates'] == 2
assert isinstance(j['commit'], str) and j['version']
EOF
ok $? "soupmesh --json: valid JSON, its tets and h as tetstat reads them"
expect_fail "soupmesh --json with the mesh on stdout: usage error" 2 "^soupmesh: --json prints on stdout" \
    sh -c "soupmesh --json '$BUNNY' >x.out"
soupmesh --dry-run --json --cells 4 "$BUNNY" >d.json &&
    "$PYVTK" -c 'import json,sys; d=json.load(open("d.json")); assert d["estimated_tets"] > 0 and d["h"] > 0'
ok $? "soupmesh --dry-run --json: the estimate as JSON"

done_testing
