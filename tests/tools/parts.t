#!/bin/sh
# soupmesh --parts: each tet's part (issue 38). Nested boxes named in an OBJ
# (a bone inside flesh), two glTF mesh nodes side by side, a 25-piece OFF,
# the outputs' tags read by meshio and gmsh, the default output without
# parts, and the bad inputs (duplicate, unnamed, empty and non-UTF-8
# names, one part, too many parts).
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1
PY=/usr/bin/python3

check "--help names --parts" sh -c 'soupmesh --help | grep -q -- "--parts MODE"'

# ---- nested boxes ------------------------------------------------------------
# flesh [0,4]x[0,2]x[0,2], bone [0.5,3.5]x[0.7,1.3]x[0.7,1.3] (volume 1.08).
cat >boxes.py <<'PY'
import sys
def box(f, name, lo, hi, voff, head="o"):
    if name is not None:
        f.write("%s %s\n" % (head, name))
    for z in (lo[2], hi[2]):
        for y in (lo[1], hi[1]):
            for x in (lo[0], hi[0]):
                f.write("v %r %r %r\n" % (x, y, z))
    for q in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
        f.write("f " + " ".join(str(voff + i + 1) for i in q) + "\n")
    return voff + 8
FLESH, BONE = ((0, 0, 0), (4, 2, 2)), ((0.5, 0.7, 0.7), (3.5, 1.3, 1.3))
with open("nested.obj", "w") as f:
    n = box(f, "flesh", *FLESH, 0)
    box(f, "bone", *BONE, n)
# bad names: a duplicate, an object without faces, an unnamed run before
# the first object, a name that is not UTF-8
with open("bad.obj", "wb") as f:
    import io
    t = io.StringIO()
    n = box(t, None, (10, 0, 0), (11, 1, 1), 0)
    n = box(t, "a", (0, 0, 0), (1, 1, 1), n)
    t.write("o empty\n")
    n = box(t, "a", (2, 0, 0), (3, 1, 1), n)
    n = box(t, "NONUTF8", (4, 0, 0), (5, 1, 1), n)
    f.write(t.getvalue().encode().replace(b"NONUTF8", b"caf\xe9"))
# groups only (no o): parts by g
with open("groups.obj", "w") as f:
    n = box(f, "left", (0, 0, 0), (1, 1, 1), 0, "g")
    box(f, "right", (2, 0, 0), (3, 1, 1), n, "g")
# 25 separate cubes, no names: pieces
with open("cubes.off", "w") as f:
    V, F = [], []
    for i in range(5):
        for j in range(5):
            lo = (1.5 * i, 1.5 * j, 0)
            b = len(V)
            for z in (0, 1):
                for y in (0, 1):
                    for x in (0, 1):
                        V.append((lo[0] + x, lo[1] + y, z))
            for q in ((0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)):
                F.append([b + k for k in q])
    f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
    for v in V:
        f.write("%r %r %r\n" % v)
    for q in F:
        f.write("4 %d %d %d %d\n" % tuple(q))
# 65536 separate triangles: more pieces than parts may be
with open("many.off", "w") as f:
    n = 65536
    f.write("OFF\n%d %d 0\n" % (3 * n, n))
    for k in range(n):
        x = 2.0 * (k % 256)
        y = 2.0 * (k // 256)
        f.write("%r %r 0\n%r %r 0\n%r %r 1\n" % (x, y, x + 1, y, x, y))
    for k in range(n):
        f.write("3 %d %d %d\n" % (3 * k, 3 * k + 1, 3 * k + 2))
PY
$PY boxes.py
check "nested boxes: soupmesh --parts names --cells 12 (encloses: exit 0)" \
    soupmesh -q --parts names --cells 12 -o nested.vtu nested.obj
cat >nested_check.py <<'PY'
import sys
import meshio
import numpy as np
m = meshio.read(sys.argv[1])
tets = m.cells_dict["tetra"]
part = m.cell_data["part"][0]
share = m.cell_data["part_share"][0]
assert part.dtype == np.int32, part.dtype
assert share.dtype == np.float64, share.dtype
names = [bytes(m.field_data["part_name_%d" % k]).decode() for k in range(int(m.field_data["parts"][0]))]
assert names == ["flesh", "bone"], names
bone = names.index("bone")
p = m.points[tets]
c = p.mean(axis=1)
vol = np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0], np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))) / 6
inb = np.all((c > [0.5, 0.7, 0.7]) & (c < [3.5, 1.3, 1.3]), axis=1)
fb = np.mean(part[inb] == bone)
ff = np.mean(part[~inb] != bone)
vb = vol[part == bone].sum()
print("# %d tets: centroid in bone %d (%.1f%% bone), others %d (%.1f%% flesh); bone volume %.4f of 1.08"
      % (len(tets), inb.sum(), 100 * fb, (~inb).sum(), 100 * ff, vb))
assert inb.sum() > 0 and fb >= 0.9 and ff >= 0.9, (fb, ff)
assert 0.54 <= vb <= 2.16, vb
assert np.all((share >= 0) & (share <= 1))
PY
check "nested boxes: >= 90% of tets in the bone tagged bone, >= 90% of the others flesh, bone volume 0.5-2x" \
    $PY nested_check.py nested.vtu
sed 's/^/#   /' "$WORK/.out"

check "tetstat: tets and volume per part, and the pseudo volume" sh -c \
    "tetstat nested.vtu | grep -Eq '^  1 +bone +[0-9]+ tets, volume [0-9.]+, its pseudo volume [0-9.]+ \(ratio 0\.[89]|^  1 +bone .*\(ratio 1\.[01]'"
check "tetstat --json: the parts" sh -c "tetstat --json nested.vtu | $PY -c '
import json, sys
d = json.load(sys.stdin)
p = d[\"parts\"]
assert [x[\"name\"] for x in p] == [\"flesh\", \"bone\"], p
assert sum(x[\"tets\"] for x in p) == d[\"tets\"], p
assert 0.5 < p[1][\"volume_ratio\"] < 2, p'"
check "tetstat: no parts section without parts" sh -c \
    "soupmesh -q --cells 6 -o p6.vtu nested.obj && ! tetstat p6.vtu | grep -q '^parts'"

# ---- the formats -------------------------------------------------------------
check "nested boxes: .msh" soupmesh -q --parts names --cells 12 -o nested.msh nested.obj
cat >msh_check.py <<'PY'
import sys
import meshio
import numpy as np
# msh_check.py FILE NAME... : one volume group per name, the boundary group
m = meshio.read(sys.argv[1])
want = sys.argv[2:]
vol = {k: v for k, v in m.field_data.items() if v[1] == 3}
assert sorted(vol) == sorted(want), (sorted(vol), want)
assert m.field_data["boundary"][1] == 2
tags = np.concatenate([d for c, d in zip(m.cells, m.cell_data["gmsh:physical"]) if c.type == "tetra"])
for n in want:
    assert np.sum(tags == vol[n][0]) > 0, n
PY
check "meshio reads the .msh groups by name (flesh, bone, boundary)" $PY msh_check.py nested.msh flesh bone
check ".msh 2.2 binary too" sh -c "soupmesh -q --parts names --cells 12 --msh-version 2 --msh-binary \
    -o n22.msh nested.obj && $PY msh_check.py n22.msh flesh bone"
if command -v gmsh >/dev/null 2>&1; then
    # gmsh reads the file and writes its groups back: they survive by name
    check "gmsh reads the .msh groups (re-saved by gmsh, read by meshio)" sh -c \
        "timeout 60 gmsh -0 nested.msh -format msh22 -o regmsh.msh >gmsh.log 2>&1 &&
         ! grep -q '^Error' gmsh.log && $PY msh_check.py regmsh.msh flesh bone"
else
    echo "ok - # SKIP gmsh not installed"
fi
check "nested boxes: .mesh, tet references 1 and 2" sh -c "soupmesh -q --parts names --cells 12 \
    -o nested.mesh nested.obj && awk '/^Tetrahedra/{n=1;next} n==1{n=2;next} n==2&&NF==5{r[\$5]++} n==2&&NF!=5{n=0}
    END{exit !(r[1]>0 && r[2]>0 && length(r)==2)}' nested.mesh"
check "nested boxes: .ele, one attribute, parts 0 and 1" sh -c "soupmesh -q --parts names --cells 12 \
    -o nested.node nested.obj && head -1 nested.ele | grep -Eq '^[0-9]+ 4 1\$' &&
    awk 'NR>1&&NF==6{a[\$6]++} END{exit !(a[0]>0 && a[1]>0 && length(a)==2)}' nested.ele"
check "nested boxes: --embed .vtu gives each input vertex's part" sh -c "soupmesh -q --parts names \
    --cells 12 --embed emb.vtu -o e.vtu nested.obj && $PY -c '
import meshio, numpy as np
m = meshio.read(\"emb.vtu\")
assert list(m.point_data[\"part\"]) == [0] * 8 + [1] * 8, m.point_data[\"part\"]'"

check "latticetet --sculpt --parts: the pipe of tools tags the tets too" sh -c \
    "soupdist nested.obj | soupsign --surface nested.obj |
     latticetet --sculpt --surface nested.obj --parts names --cells 8 |
     tetsmooth --fit --surface nested.obj -o lt.vtu && tetstat lt.vtu | grep -Eq '^  1 +bone +[0-9]+ tets'"
expect_fail "latticetet --parts without --sculpt: usage" 2 "--parts goes with --sculpt" \
    latticetet --density 0.5 --parts names -o x.vtu nested.obj

# ---- glTF nodes, groups, pieces ---------------------------------------------
cat >gltf2.py <<'PY'
import base64, json, struct
V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
I = [0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5]
vb = b"".join(struct.pack("<3f", *v) for v in V)
ib = struct.pack("<36H", *I)
buf = vb + ib
doc = {"asset": {"version": "2.0"},
       "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(buf).decode()}],
       "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(vb)},
                       {"buffer": 0, "byteOffset": len(vb), "byteLength": len(ib)}],
       "accessors": [{"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                     {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"}],
       "meshes": [{"name": "cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
       "nodes": [{"name": "tyre", "mesh": 0}, {"name": "body", "mesh": 0, "translation": [2, 0, 0]}],
       "scenes": [{"nodes": [0, 1]}], "scene": 0}
json.dump(doc, open("two.gltf", "w"))
PY
$PY gltf2.py
check "glTF: two mesh nodes side by side give two groups by node name" sh -c \
    "soupmesh -q --parts auto --cells 10 -o two.msh two.gltf && $PY msh_check.py two.msh tyre body"
check "OBJ groups (no objects) give the parts" sh -c \
    "soupmesh -q --parts names --cells 10 -o groups.msh groups.obj && $PY msh_check.py groups.msh left right"
check "OFF without names, --parts auto: 25 pieces, 25 groups" sh -c \
    "soupmesh -q --parts auto --cells 10 -o cubes.msh cubes.off &&
     $PY msh_check.py cubes.msh $(seq -f 'piece_%g' 0 24 | tr '\n' ' ')"

check "the tags do not depend on the thread count (1 and 2 threads)" sh -c \
    "soupmesh -q --threads 1 --parts auto --cells 10 -o t1.vtu cubes.off &&
     soupmesh -q --threads 2 --parts auto --cells 10 -o t2.vtu cubes.off && $PY -c '
import meshio, numpy as np
a, b = meshio.read(\"t1.vtu\"), meshio.read(\"t2.vtu\")
assert np.array_equal(a.points, b.points)
for k in (\"part\", \"part_share\"):
    assert np.array_equal(a.cell_data[k][0], b.cell_data[k][0]), k'"

# ---- bad input ---------------------------------------------------------------
check "bad names: meshed" sh -c "soupmesh --parts names --cells 8 -o bad.msh bad.obj 2>bad.err"
check "an object without faces is skipped, said" grep -q "bad.obj: warning: 1 named part without faces skipped (first: 'empty')" bad.err
check "an unnamed part is said" grep -q "bad.obj: warning: 1 part without a name" bad.err
check "a name that is not UTF-8 is said" grep -q "bad.obj: warning: 1 part name not UTF-8" bad.err
check "a duplicate name is said" grep -q "bad.obj: warning: 1 part name given twice, suffixed" bad.err
check "bad names: groups part_0, a, a_2, part_3" $PY msh_check.py bad.msh part_0 a a_2 part_3
check "-v lists the parts" sh -c "soupmesh -v --parts names --cells 8 -o bad2.msh bad.obj 2>&1 |
    grep -q \"part 2 'a_2': 12 triangles\""
check "--parts on one part: one group, no error" sh -c \
    "soupmesh -q --parts pieces --cells 8 -o one.msh '$ROOT/corpus/bunny.obj' && $PY msh_check.py one.msh piece_0"
expect_fail "more than 65535 pieces: said, exit 1" 1 "65536 pieces, more than 65535 parts" \
    soupmesh --parts pieces --cells 8 -o many.vtu many.off
check "... and no output left" test ! -e many.vtu
expect_fail "--parts with another word: usage, exit 2" 2 "--parts is auto, names, pieces or none" \
    soupmesh --parts colour -o x.vtu nested.obj

# ---- without --parts ---------------------------------------------------------
check "default: no part arrays or names" sh -c "soupmesh -q --cells 8 -o plain.vtu nested.obj && $PY -c '
import meshio
m = meshio.read(\"plain.vtu\")
assert \"part\" not in m.cell_data and \"parts\" not in m.field_data'"
check "default .msh keeps the one volume group" sh -c "soupmesh -q --cells 8 -o plain.msh nested.obj &&
    grep -q '^3 1 \"volume\"' plain.msh"
# --parts none is the default: the same bytes but the history line
soupmesh -q --cells 8 -o none.msh --parts none nested.obj
check "--parts none writes what no --parts writes (but the history)" sh -c \
    "grep -v 'souptet history' plain.msh > a && grep -v 'souptet history' none.msh > b && cmp a b"

done_testing
