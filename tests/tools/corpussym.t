#!/bin/sh
# tests/tools/corpussym.t - scripts/corpus_symmetry.py, the ground truth of
# the symholes damage (scripts/damage-corpus): the support of a listed
# symmetry on a shape that has it and on one that does not, a helix, and
# the share of a removed patch that the kept surface's images recover; and
# damage-corpus's choice of damages per model (symholes only where a
# symmetry is listed; '(symholes only)' models get nothing else).
. "$(dirname "$0")/lib.sh"
cd "$WORK" || exit 1

if ! $PYVTK -c 'import numpy, scipy' 2>/dev/null; then
    echo "1..0 # skip numpy and scipy are needed (python3-numpy python3-scipy)"
    exit 0
fi

cat >shapes.py <<'EOF'
import math, sys
import numpy as np
sys.path.insert(0, sys.argv[1] + "/scripts")
import corpus_symmetry as cs


def prism(n, r=1.0, h=0.6, twist=0.0):
    """A closed n-gon prism along z (top turned by twist radians)."""
    V = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n), 0.0)
         for k in range(n)]
    V += [(r * math.cos(2 * math.pi * k / n + twist), r * math.sin(2 * math.pi * k / n + twist), h)
          for k in range(n)]
    V += [(0, 0, 0), (0, 0, h)]
    F = []
    for k in range(n):
        a, b = k, (k + 1) % n
        F += [(a, b, n + b), (a, n + b, n + a), (2 * n, b, a), (2 * n + 1, n + a, n + b)]
    return np.array(V, float), np.array(F, int)


def support(V, F, sym):
    return cs.support(cs.Surface(V, F, 6000), sym, cs.tolerance(V))


V, F = prism(6)
hexa = {"kind": "rotation", "through": [0, 0, 0], "axis": [0, 0, 1], "order": 6}
penta = dict(hexa, order=5)
mirror_z = {"kind": "mirror", "through": [0, 0, 0.3], "normal": [0, 0, 1]}
mirror_off = {"kind": "mirror", "through": [0, 0, 0.2], "normal": [0, 0, 1]}
test = sys.argv[2]
if test == "true":
    print(min(support(V, F, s) for s in (hexa, mirror_z)))
elif test == "false":
    print(max(support(V, F, s) for s in (penta, mirror_off)))
elif test == "helix":
    # a 48-gon prism: a helix of pitch 0 is its turns by 15 degrees (it
    # holds); with a pitch the turns rise and the caps leave the surface
    V, F = prism(48, h=0.6)
    print(support(V, F, {"kind": "helix", "through": [0, 0, 0], "axis": [0, 0, 1],
                         "pitch": 0.0}),
          support(V, F, {"kind": "helix", "through": [0, 0, 0], "axis": [0, 0, 1],
                         "pitch": 0.3}))
elif test == "recover":
    # the side faces of the x > 0 half removed: the mirror x = 0 brings
    # them back; the whole side removed: nothing maps onto a kept side
    # face (the caps are elsewhere)
    V, F = prism(24)
    mx = {"kind": "mirror", "through": [0, 0, 0], "normal": [1, 0, 0]}
    side = [i for i in range(len(F)) if i % 4 < 2]
    half = [i for i in side if V[F[i]].mean(0)[0] > 0.05]
    tol = cs.tolerance(V)
    print(cs.recoverable(V, F, half, [mx], tol, 6000), cs.recoverable(V, F, side, [mx], tol, 6000))
EOF

out=$($PYVTK shapes.py "$ROOT" true)
$PYVTK -c "import sys; sys.exit(0 if float('$out') >= 0.99 else 1)"
ok $? "a hexagonal prism's 6-fold axis and mid-plane hold on all its area ($out)"

out=$($PYVTK shapes.py "$ROOT" false)
$PYVTK -c "import sys; sys.exit(0 if float('$out') < 0.9 else 1)"
ok $? "a 5-fold axis and an off-centre plane do not hold on it (at most $out)"

set -- $($PYVTK shapes.py "$ROOT" helix)
$PYVTK -c "import sys; sys.exit(0 if float('$1') >= 0.99 and float('$2') < 0.9 else 1)"
ok $? "a round prism: a helix of pitch 0 (a turn) holds ($1), of pitch 0.3 it does not ($2)"

set -- $($PYVTK shapes.py "$ROOT" recover)
$PYVTK -c "import sys; sys.exit(0 if float('$1') >= 0.95 and float('$2') < 0.05 else 1)"
ok $? "half the side removed is recoverable by the mirror ($1); the whole side is not ($2)"

# damage-corpus's choice of damages: its wanted() on made-up models.
$PYVTK - "$ROOT" >wanted.out <<'EOF'
import importlib.machinery, importlib.util, sys
loader = importlib.machinery.SourceFileLoader("dc", sys.argv[1] + "/scripts/damage-corpus")
spec = importlib.util.spec_from_loader("dc", loader)
dc = importlib.util.module_from_spec(spec)
loader.exec_module(dc)
big = {"triangles": 5000}
for model, props in (("screw", "closed, CAD, a screw (symholes only)"),
                     ("pinion", "closed, CAD, genus 1"), ("bunny", "closed, manifold")):
    print(model, " ".join(d for d in dc.DAMAGES if dc.wanted(d, model, props, big)))
EOF
grep -qx 'screw symholes' wanted.out
ok $? "a '(symholes only)' model gets symholes alone"
grep -q '^pinion .*largeholes symholes$' wanted.out && grep -q '^pinion deleted50 holes' wanted.out
ok $? "a symmetric CAD part gets every damage, largeholes and symholes too"
grep -q '^bunny ' wanted.out && ! grep -q '^bunny .*holes$' wanted.out && grep -q '^bunny deleted50 holes' wanted.out
ok $? "a model with no symmetry listed gets neither largeholes nor symholes"
[ $TAP_FAILED -eq 0 ] || sed 's/^/#   /' wanted.out

done_testing
