#!/bin/sh
# badinput: every tool refuses broken or unsuitable input with exit 1 and a
# message naming the file ("tool: FILE[:LINE]: what"), and leaves no output
# (issue #8, item 5): truncated .vdb, .vti, .vtu and .msh files, the wrong
# kind of grid, tet meshes with inverted, flat or dangling tets, zero-size
# grids, voxel sizes 0 and negative, values that are not numbers, soups
# that are not; absurd option values are usage errors (exit 2) naming the
# option. Cases the per-tool .t files already cover are not repeated.
. "$(dirname "$0")/lib.sh"
BUNNY="$ROOT/corpus/bunny.obj"
cd "$WORK" || exit 1

soupdist -q -r 32 -o d.vdb "$BUNNY"
soupdist -q -r 32 -o d.vti "$BUNNY"
soupsign -q -o s.vdb d.vdb
soupsign -q -o s.vti d.vdb
latticetet -q --density 0.5 --cells 8 -o l.vtu s.vdb
latticetet -q --density 0.5 --cells 8 -o l.msh s.vdb
latticetet -q --density 0.5 --cells 8 -o l.node s.vdb
check "the inputs are made" test -s d.vdb -a -s d.vti -a -s s.vdb -a -s s.vti -a -s l.vtu -a -s l.msh -a -s l.ele

# cut FILE BYTES OUT: the first BYTES bytes of FILE (BYTES "half": half).
cut() {
    cut_n=$2
    [ "$cut_n" = half ] && cut_n=$(($(wc -c < "$1") / 2))
    head -c "$cut_n" "$1" > "$3"
}

# field_tools WHAT PATTERN DIST SIGNED: the four readers of a field refuse
# DIST (soupsign) or SIGNED (latticetet, soupwrap, tetstat --field) with
# "tool: FILE[:LINE]: PATTERN".
field_tools() {
    ft_what=$1 ft_pat=$2 ft_d=$3 ft_s=$4
    expect_fail "soupsign: $ft_what" 1 "^soupsign: $ft_d(:[0-9]+)?: $ft_pat" soupsign -o x.vdb "$ft_d"
    expect_fail "latticetet: $ft_what" 1 "^latticetet: $ft_s(:[0-9]+)?: $ft_pat" \
        latticetet --density 0.5 -o x.vtu "$ft_s"
    expect_fail "soupwrap: $ft_what" 1 "^soupwrap: $ft_s(:[0-9]+)?: $ft_pat" soupwrap -o x.obj "$ft_s"
    expect_fail "tetstat --field: $ft_what" 1 "^tetstat: $ft_s(:[0-9]+)?: $ft_pat" \
        tetstat --field "$ft_s" l.vtu
}

# ---- truncated fields --------------------------------------------------
cut d.vdb half d-half.vdb
cut s.vdb half s-half.vdb
cut d.vdb 200 d-200.vdb
cut s.vdb 200 s-200.vdb
field_tools "a .vdb cut at half" "" d-half.vdb s-half.vdb
field_tools "a .vdb cut at 200 bytes" "" d-200.vdb s-200.vdb
expect_fail "soupsign: a VDB stream cut at half on stdin" 1 "^soupsign: <stdin>: " \
    sh -c "soupdist -q -r 32 '$BUNNY' | head -c 20000 | soupsign -o x.vdb"
expect_fail "latticetet: a VDB stream cut at 200 bytes on stdin" 1 "^latticetet: <stdin>: " \
    sh -c "head -c 200 s.vdb | latticetet --density 0.5 -o x.vtu"
cut d.vti half d-half.vti
cut s.vti half s-half.vti
cut d.vti 200 d-200.vti
cut s.vti 200 s-200.vti
field_tools "a .vti cut at half" "" d-half.vti s-half.vti
field_tools "a .vti cut at 200 bytes" "" d-200.vti s-200.vti

# ---- the wrong kind of grid --------------------------------------------
# An int32 grid: the float tree's type name patched (same length, same
# value size), so OpenVDB reads a valid Int32Grid and no float grid.
/usr/bin/python3 -c "
import sys
for a, b in (('d.vdb', 'd-int.vdb'), ('s.vdb', 's-int.vdb')):
    d = open(a, 'rb').read()
    assert d.count(b'Tree_float_5_4_3') == 1
    open(b, 'wb').write(d.replace(b'Tree_float_5_4_3', b'Tree_int32_5_4_3'))
"
field_tools "a .vdb whose only grid is int32" "no float grid" d-int.vdb s-int.vdb
expect_fail "soupsign: a signed .vti is not a distance field" 1 "^soupsign: s.vti: .*signed" soupsign -o x.vdb s.vti
expect_fail "latticetet: an unsigned .vti" 1 "^latticetet: d.vti: .*not signed" latticetet --density 0.5 -o x.vtu d.vti
expect_fail "soupwrap: an unsigned .vti" 1 "^soupwrap: d.vti: .*sign it first" soupwrap -o x.obj d.vti
expect_fail "tetstat --field: an unsigned field (its IoU would be a silent 0)" 1 \
    "^tetstat: d.vdb: .*not signed" tetstat --field d.vdb l.vtu
cp l.vtu mesh.vdb
cp s.vdb field.vtu
cp s.vdb field.vti
cp s.vti field2.vdb
expect_fail "soupsign: a tet mesh named .vdb" 1 "^soupsign: mesh.vdb(:[0-9]+)?: " soupsign -o x.vdb mesh.vdb
expect_fail "soupsign: a .vdb named .vti" 1 "^soupsign: field.vti(:[0-9]+)?: " soupsign -o x.vdb field.vti
expect_fail "latticetet: a .vti named .vdb" 1 "^latticetet: field2.vdb(:[0-9]+)?: " latticetet --density 0.5 -o x.vtu field2.vdb
expect_fail "tetstat: a field named .vtu" 1 "^tetstat: field.vtu(:[0-9]+)?: " tetstat field.vtu
expect_fail "tetsmooth: a field named .vtu" 1 "^tetsmooth: field.vtu(:[0-9]+)?: " tetsmooth --fair -o x.vtu field.vtu
expect_fail "soupmesh: a field as the soup" 1 "^soupmesh: s.vdb(:[0-9]+)?: " soupmesh -o x.vtu s.vdb

# A .vdb whose transform has voxel size 0, and one with a negative voxel
# size: every copy of the voxel size in the file (the map's scale and voxel
# size, the souptet metadata) patched.
/usr/bin/python3 -c "
import struct
d = open('d.vdb', 'rb').read()
i = d.index(b'UniformScaleTranslateMap') + len(b'UniformScaleTranslateMap')
v = d[i + 24:i + 32]          # after the translation: the scale's x
assert struct.unpack('<d', v)[0] > 0 and d.count(v) >= 6
open('d-vox0.vdb', 'wb').write(d.replace(v, struct.pack('<d', 0.0)))
open('d-voxneg.vdb', 'wb').write(d.replace(v, struct.pack('<d', -struct.unpack('<d', v)[0])))
"
for f in d-vox0.vdb d-voxneg.vdb; do
    expect_fail "soupsign: $f" 1 "^soupsign: $f: .*transform" soupsign -o x.vdb "$f"
done

# ---- grids that hold nothing, or not numbers ----------------------------
# vti FILE EXTENT SPACING VALUES: a hand-made ASCII .vti.
vti() {
    cat > "$1" <<EOF
<?xml version="1.0"?>
<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <ImageData WholeExtent="$2" Origin="0 0 0" Spacing="$3">
    <Piece Extent="$2">
      <PointData Scalars="sdf">
        <DataArray type="Float32" Name="sdf" format="ascii">$4</DataArray>
      </PointData>
    </Piece>
  </ImageData>
</VTKFile>
EOF
}
V27="1 1 1 1 1 1 1 1 1 1 1 1 1 -1 1 1 1 1 1 1 1 1 1 1 1 1 1"
vti zero.vti "0 -1 0 -1 0 -1" "1 1 1" ""
vti sp0.vti "0 2 0 2 0 2" "0 0 0" "$V27"
vti spneg.vti "0 2 0 2 0 2" "-1 -1 -1" "$V27"
vti nan.vti "0 2 0 2 0 2" "1 1 1" "1 1 1 1 1 1 1 1 1 1 1 1 1 nan 1 1 1 1 1 1 1 1 1 1 1 1 1"
vti inf.vti "0 2 0 2 0 2" "1 1 1" "1 1 1 1 1 1 1 1 1 1 1 1 1 -inf 1 1 1 1 1 1 1 1 1 1 1 1 1"
field_tools "a zero-size .vti (extent 0 -1)" "" zero.vti zero.vti
field_tools "voxel size 0" "" sp0.vti sp0.vti
field_tools "a negative voxel size" "" spneg.vti spneg.vti
for f in nan.vti inf.vti; do
    expect_fail "latticetet: a field with a value that is not finite ($f)" 1 \
        "^latticetet: $f(:[0-9]+)?: .*not finite" latticetet --density 0.5 -o x.vtu "$f"
    expect_fail "soupwrap: a field with a value that is not finite ($f)" 1 \
        "^soupwrap: $f(:[0-9]+)?: .*not finite" soupwrap -o x.obj "$f"
    expect_fail "tetstat --field: a field with a value that is not finite ($f)" 1 \
        "^tetstat: $f(:[0-9]+)?: .*not finite" tetstat --field "$f" l.vtu
done

# ---- truncated tet meshes ----------------------------------------------
cut l.vtu half l-half.vtu
cut l.vtu 200 l-200.vtu
cut l.msh half l-half.msh
for f in l-half.vtu l-200.vtu l-half.msh; do
    expect_fail "tetstat: $f" 1 "^tetstat: $f(:[0-9]+)?: " tetstat "$f"
    expect_fail "tetsmooth: $f" 1 "^tetsmooth: $f(:[0-9]+)?: " tetsmooth --fair -o x.vtu "$f"
done
mkdir cutpair
cp l.node cutpair/l.node
cut l.ele half cutpair/l.ele
expect_fail "tetstat: a .node whose .ele is cut at half" 1 "^tetstat: cutpair/l\.(node|ele)(:[0-9]+)?: " \
    tetstat cutpair/l.node
expect_fail "tetstat: a truncated .vtu on stdin" 1 "^tetstat: <stdin>(:[0-9]+)?: " sh -c "tetstat < l-half.vtu"

# ---- tet meshes with bad tets ------------------------------------------
# vtu FILE NPOINTS POINTS NCELLS CONNECTIVITY OFFSETS TYPES: an ASCII .vtu.
vtu() {
    cat > "$1" <<EOF
<?xml version="1.0"?>
<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" header_type="UInt64">
  <UnstructuredGrid>
    <Piece NumberOfPoints="$2" NumberOfCells="$4">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">$3</DataArray>
      </Points>
      <Cells>
        <DataArray type="Int64" Name="connectivity" format="ascii">$5</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">$6</DataArray>
        <DataArray type="UInt8" Name="types" format="ascii">$7</DataArray>
      </Cells>
    </Piece>
  </UnstructuredGrid>
</VTKFile>
EOF
}
# Two positive tets on the five points of a unit corner and (1,1,1).
P5="0 0 0 1 0 0 0 1 0 0 0 1 1 1 1"
vtu good.vtu 5 "$P5" 2 "0 1 2 3 1 2 3 4" "4 8" "10 10"
vtu inverted.vtu 5 "$P5" 2 "0 1 2 3 1 3 2 4" "4 8" "10 10"
vtu flat.vtu 5 "$P5" 2 "0 1 2 3 0 1 2 2" "4 8" "10 10"
vtu range.vtu 5 "$P5" 2 "0 1 2 3 1 2 3 9" "4 8" "10 10"
vtu negidx.vtu 5 "$P5" 2 "0 1 2 3 1 2 3 -1" "4 8" "10 10"
vtu unused.vtu 6 "$P5 5 5 5" 2 "0 1 2 3 1 2 3 4" "4 8" "10 10"
vtu nanpt.vtu 5 "0 0 0 1 0 0 0 1 0 0 0 1 1 nan 1" 2 "0 1 2 3 1 2 3 4" "4 8" "10 10"
vtu notets.vtu 0 "" 0 "" "" ""
vtu badoff.vtu 5 "$P5" 2 "0 1 2 3 1 2 3 4" "4 9" "10 10"
cat > want.py <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
for kv in sys.argv[2:]:
    k, v = kv.split("=")
    if r[k] != int(v):
        sys.exit("%s: %s is %r, wanted %s" % (sys.argv[1], k, r[k], v))
PY
check "the good two-tet mesh: tetstat says 2 tets, nothing wrong; tetsmooth fairs it" sh -c \
    "tetstat -q --json good.vtu > good.json && /usr/bin/python3 want.py good.json tets=2 inverted=0 degenerate=0 unused_points=0 && tetsmooth -q --fair -o g.vtu good.vtu"
expect_fail "tetsmooth --fair: an inverted tet is refused" 1 "^tetsmooth: inverted.vtu: .*inverted or flat" \
    tetsmooth --fair -o x.vtu inverted.vtu
expect_fail "tetsmooth --fit: an inverted tet is refused" 1 "^tetsmooth: inverted.vtu: .*inverted or flat" \
    tetsmooth --fit --surface "$BUNNY" --cell-width 1 -o x.vtu inverted.vtu
check "tetstat: a flat tet (a corner twice) is reported, exit 0: degenerate 1" sh -c \
    "tetstat -q --json flat.vtu > flat.json && /usr/bin/python3 want.py flat.json tets=2 degenerate=1 inverted=0"
expect_fail "tetstat: a flat tet is said on stderr" 0 "^tetstat: flat.vtu: warning: 1 degenerate" tetstat flat.vtu
expect_fail "tetsmooth: a flat tet is refused" 1 "^tetsmooth: flat.vtu: .*inverted or flat" \
    tetsmooth --fair -o x.vtu flat.vtu
for f in range.vtu negidx.vtu; do
    expect_fail "tetstat: a tet with a corner out of range ($f)" 1 "^tetstat: $f(:[0-9]+)?: .*point -?[0-9]+ of 5" tetstat "$f"
    expect_fail "tetsmooth: a tet with a corner out of range ($f)" 1 "^tetsmooth: $f(:[0-9]+)?: .*point -?[0-9]+ of 5" \
        tetsmooth --fair -o x.vtu "$f"
done
check "tetstat: a point no tet uses is reported, exit 0: unused_points 1" sh -c \
    "tetstat -q --json unused.vtu > unused.json && /usr/bin/python3 want.py unused.json tets=2 points=6 unused_points=1"
check "tetsmooth: a point no tet uses is kept and stays unused" sh -c \
    "tetsmooth -q --fair -o u.vtu unused.vtu && tetstat -q --json u.vtu > u.json && /usr/bin/python3 want.py u.json tets=2 points=6 unused_points=1 inverted=0"
expect_fail "tetstat: a point that is not a number" 1 "^tetstat: nanpt.vtu(:[0-9]+)?: .*not finite" tetstat nanpt.vtu
expect_fail "tetsmooth: a point that is not a number" 1 "^tetsmooth: nanpt.vtu(:[0-9]+)?: .*not finite" \
    tetsmooth --fair -o x.vtu nanpt.vtu
check "tetstat: a mesh without tets is a report of 0 tets" sh -c \
    "tetstat -q --json notets.vtu > nt.json && /usr/bin/python3 want.py nt.json tets=0 points=0"
expect_fail "tetsmooth: a mesh without tets is refused" 1 "^tetsmooth: notets.vtu: .*no tets" \
    tetsmooth --fair -o x.vtu notets.vtu
expect_fail "tetstat: offsets past the connectivity" 1 "^tetstat: badoff.vtu(:[0-9]+)?: " tetstat badoff.vtu
expect_fail "tetsmooth: offsets past the connectivity" 1 "^tetsmooth: badoff.vtu(:[0-9]+)?: " \
    tetsmooth --fair -o x.vtu badoff.vtu

# ---- soups that are not, for the tools that read one besides soupdist --
printf 'v 0 0 0\nv 1 0 0\nv 0 1 nan\nf 1 2 3\n' > nan.obj
: > empty.stl
for f in nan.obj empty.stl; do
    expect_fail "soupmesh: $f" 1 "^soupmesh: $f(:[0-9]+)?: " soupmesh -o x.vtu "$f"
    expect_fail "soupwrap --surface: $f" 1 "^soupwrap: $f(:[0-9]+)?: " soupwrap --surface "$f" -o x.obj
    expect_fail "soupsign --surface: $f" 1 "^soupsign: $f(:[0-9]+)?: " soupsign --surface "$f" -o x.vdb d.vdb
    expect_fail "latticetet --surface: $f" 1 "^latticetet: $f(:[0-9]+)?: " \
        latticetet --sculpt --surface "$f" -o x.vtu s.vdb
    expect_fail "tetsmooth --surface: $f" 1 "^tetsmooth: $f(:[0-9]+)?: " \
        tetsmooth --fit --surface "$f" -o x.vtu l.vtu
    expect_fail "tetstat --surface: $f" 1 "^tetstat: $f(:[0-9]+)?: " tetstat --surface "$f" l.vtu
done
check "no output after any refusal" sh -c "test ! -e x.vdb && test ! -e x.vtu && test ! -e x.obj && ! ls -A | grep -Eq '^\.x\.'"

# ---- absurd option values: usage errors (exit 2) naming the option -----
for r in -5 1e9 abc "" 1.5; do
    expect_fail "soupdist -r '$r'" 2 "^soupdist: -r wants" soupdist -r "$r" -o x.vdb "$BUNNY"
    expect_fail "soupwrap --surface -r '$r'" 2 "^soupwrap: -r wants" soupwrap --surface "$BUNNY" -r "$r" -o x.obj
done
for s in 0 nan inf -inf abc; do
    expect_fail "soupdist -s '$s'" 2 "^soupdist: -s wants" soupdist -s "$s" -o x.vdb "$BUNNY"
    expect_fail "latticetet --size '$s'" 2 "^latticetet: --size wants" latticetet --density 0.5 --size "$s" -o x.vtu s.vdb
done
for c in 0 -5 abc 1e9; do
    expect_fail "latticetet --cells '$c'" 2 "^latticetet: --cells wants" latticetet --density 0.5 --cells "$c" -o x.vtu s.vdb
    expect_fail "soupmesh --cells '$c'" 2 "^soupmesh: --cells wants" soupmesh --cells "$c" -o x.vtu "$BUNNY"
done
expect_fail "soupmesh --voxels 0" 2 "^soupmesh: --voxels wants" soupmesh --voxels 0 -o x.vtu "$BUNNY"
for m in 0 -1G abc 1X 1e30; do
    expect_fail "--max-memory '$m'" 2 "^soupsign: --max-memory wants" soupsign --max-memory "$m" -o x.vdb d.vdb
done
for n in 0 -1 abc; do
    expect_fail "--threads '$n'" 2 "^soupmesh: --threads wants" soupmesh --threads "$n" -o x.vtu "$BUNNY"
done

# A 3 KB .vdb whose grid metadata claims a 4 GB string: OpenVDB would
# zero-fill it before reading (4 GB touched, seconds); the walk of the
# length-prefixed parts refuses it first, fast and small.
V="$ROOT/tests/data/fuzz/vdb/timeout-d8fabcd9cee97d9b5231c03d9e917109de94238a"
expect_fail "a .vdb claiming a 4 GB metadata string: refused by the walk, naming the byte" 1 \
    "^soupsign: .*timeout-d8fabcd9[0-9a-f]*: byte [0-9]+: not a valid OpenVDB file \(truncated or corrupt\): a grid's metadata claims [0-9]+ bytes but [0-9]+ remain" \
    soupsign -o x.vdb "$V"
expect_fail "the same on stdin" 1 "^soupsign: <stdin>: byte [0-9]+: not a valid OpenVDB file" \
    sh -c "soupsign -o x.vdb < '$V'"

# The walk goes on through a float grid's tree (issue 40, item 7), so
# what OpenVDB would act on unchecked is refused first: a second buffer
# (it read on with a "WARNING: multi-buffer trees" on stderr and exit 0),
# a root tile's active flag of 255 (a bool load UBSan reports in
# RootNode.h), a compressed block claiming 216 GB (allocated before it is
# read: ASan's out-of-memory in make fuzz). soupdist's .vdb file (Blosc)
# and stream (no compression), each with one defect.
cat >craft.py <<'EOF'
import struct, sys
# craft.py IN OUT KIND: a .vdb of soupdist's with one defect OpenVDB would
# act on before checking (see gridio_vdb.cpp, VdbWalk::float_grid).
d = bytearray(open(sys.argv[1], 'rb').read())
p = 0
def u(fmt):
    global p
    v = struct.unpack_from('<' + fmt, d, p); p += struct.calcsize('<' + fmt); return v[0]
def string():
    global p
    n = u('I'); s = bytes(d[p:p + n]); p += n; return s
def metamap():
    for _ in range(u('i')):
        string(); string(); string()
u('q'); u('I'); u('Q'); offsets = u('B'); p += 36
metamap()
assert u('i') == 1
string(); string(); string()
end_at = p + 16
u('q'); u('q'); u('q'); compression = u('I')
metamap()
mp = string()
p += {b'UniformScaleTranslateMap': 144, b'ScaleTranslateMap': 144}[mp]
buffers_at = p
u('i'); u('f'); tiles_at = p; u('I'); u('I')
kind = sys.argv[3]
if kind == 'buffers':
    struct.pack_into('<i', d, buffers_at, 2)
elif kind == 'tile':
    # one root tile whose active flag is 255, far from the children
    struct.pack_into('<I', d, tiles_at, 1)
    d[tiles_at + 8:tiles_at + 8] = struct.pack('<iiifB', 1 << 20, 1 << 20, 1 << 20, 1.0, 255)
    if offsets:
        struct.pack_into('<q', d, end_at, struct.unpack_from('<q', d, end_at)[0] + 17)
elif kind == 'claim':
    assert compression & 5, 'needs a compressed file'
    p += 12 + 4096 * 2           # the first child's origin and masks
    meta = d[p]; p += 1
    p += {2: 4, 4: 4, 5: 8}.get(meta, 0)
    if meta in (3, 4, 5):
        p += 4096
    struct.pack_into('<q', d, p, 0x35eaa95400)
open(sys.argv[2], 'wb').write(d)
EOF
soupdist -q -r 16 -o walk.vdb "$BUNNY" && soupdist -q -r 16 "$BUNNY" >walk-stream.vdb
for spec in "walk-stream.vdb buffers the tree has 2 buffers .OpenVDB reads one." \
            "walk.vdb buffers the tree has 2 buffers .OpenVDB reads one." \
            "walk-stream.vdb tile a root tile's active flag is 255, not 0 or 1" \
            "walk.vdb tile a root tile's active flag is 255, not 0 or 1" \
            "walk.vdb claim a compressed block claims 231570232320 bytes but [0-9]+ remain"; do
    set -- $spec
    src=$1 kind=$2
    shift 2
    "$PYVTK" craft.py "$src" "bad-$kind-$src" "$kind"
    expect_fail "$src with $kind: '$*', nothing on stderr from OpenVDB" 1 \
        "^soupsign: bad-$kind-$src: byte [0-9]+: not a valid OpenVDB file \(truncated or corrupt\): $*\$" \
        soupsign -o x.vdb "bad-$kind-$src"
    [ "$(wc -l <"$WORK/.err")" -eq 1 ]
    ok $? "... one line on stderr"
done

done_testing
