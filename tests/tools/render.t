#!/bin/sh
# tests/tools/render.t - scripts/render's pictures, as a newcomer makes
# them: the mesh picture has its three panels (the mesh, the cut-away with
# a fair share of the mesh's pixels, and the colour bar in a strip of its
# own) on the bunny as it is and lying on its side; the field picture has
# a colour bar beside it (it had none). That the cut's plane faces the
# camera is by construction (its normal is the view direction), not
# measured here.
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

# The bunny as it is, and turned so its up axis lies along x (a fixed z
# cut plane used to be seen nearly edge-on on such models).
"$PYVTK" - "$ROOT/corpus/bunny.obj" > lying.obj <<'EOF'
import sys
for line in open(sys.argv[1]):
    if line.startswith("v "):
        x, y, z = map(float, line.split()[1:4])
        print("v %r %r %r" % (y, z, x))
    else:
        sys.stdout.write(line)
EOF
cat > panels.py <<'EOF'
# Non-white pixels in each panel of a mesh picture: left [0, 0.5), cut
# [0.5, 0.9), bar [0.9, 1.0) of the width.
import sys
import vtk
from vtk.util.numpy_support import vtk_to_numpy
r = vtk.vtkPNGReader()
r.SetFileName(sys.argv[1])
r.Update()
img = r.GetOutput()
w, h, _ = img.GetDimensions()
a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
ink = (a < 235).any(axis=2)
c1, c2 = int(0.5 * w), int(0.9 * w)
print(w, h, int(ink[:, :c1].sum()), int(ink[:, c1:c2].sum()), int(ink[:, c2:].sum()))
EOF
for m in bunny lying; do
    src="$ROOT/corpus/bunny.obj"
    [ $m = lying ] && src=lying.obj
    soupmesh -q --cells 6 -o $m.vtu "$src" &&
        "$ROOT/scripts/render" $m.vtu $m.png "$src" 2> $m.err
    ok $? "$m: scripts/render draws the mesh"
    sed 's/^/#   /' $m.err | head -3
    set -- $("$PYVTK" panels.py $m.png 2>/dev/null)
    echo "# $m: ${1}x$2, ink: whole $3, cut-away $4, colour bar $5"
    [ "${1:-0}" -eq 1600 ] && [ "${4:-0}" -ge $(( ${3:-1} / 4 )) ]
    ok $? "$m: the cut-away panel has at least a quarter of the whole mesh's ink"
    [ "${5:-0}" -gt 1000 ]
    ok $? "$m: the colour bar has a strip of its own"
done

soupdist -q -r 48 "$ROOT/corpus/bunny.obj" | soupsign -q -o f.vti &&
    "$ROOT/scripts/render" f.vti f.png 2> f.err
ok $? "scripts/render draws the field"
"$PYVTK" - f.png <<'EOF'
import sys
import vtk
from vtk.util.numpy_support import vtk_to_numpy
r = vtk.vtkPNGReader()
r.SetFileName(sys.argv[1])
r.Update()
img = r.GetOutput()
w, h, _ = img.GetDimensions()
a = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3]
strip = a[:, int(0.85 * w):]
# the bar's colours: saturated red and blue both present in the strip
red = ((strip[:, :, 0] > 200) & (strip[:, :, 1] < 60) & (strip[:, :, 2] < 60)).sum()
blue = ((strip[:, :, 2] > 200) & (strip[:, :, 0] < 60) & (strip[:, :, 1] < 60)).sum()
sys.exit(0 if red > 100 and blue > 100 else 1)
EOF
ok $? "the field picture has a colour bar beside it"

done_testing
