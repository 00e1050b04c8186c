"""The symmetries of the corpus's symmetric parts, as ground truth, and
what the 'symholes' damage (scripts/damage-corpus) measures with them.

A symmetry is a dict, in the coordinates of the model's source file (the
OFF that every damage starts from):
  {"kind": "mirror", "through": [x, y, z], "normal": [x, y, z]}
  {"kind": "rotation", "through": [x, y, z], "axis": [x, y, z],
   "order": N}           N >= 2 turns of 360/N degrees; 0: continuous
  {"kind": "helix", "through": [x, y, z], "axis": [x, y, z], "pitch": P}
                         a screw thread: a turn by t with a move of P t / 360
                         along the axis (P > 0: right-handed)
and "min_support" where the symmetry holds on a part of the model only
(a screw's thread, its head). Each is checked on the clean model
(support(): the least share of its area that a map puts within TOL_VOXELS
voxels of the surface) before a damage is made from it, so a wrong entry
fails the corpus, not a later bench.

Needs numpy and scipy (Debian's python3-numpy, python3-scipy).
"""
import math

import numpy as np
from scipy.spatial import cKDTree

# The symmetric parts of the corpus and their symmetries (found by
# soupsign -v's detector on the clean model and by hand from the shape,
# then measured by support(); the supports measured are in the manifest).
SYMMETRIES = {
    # PrusaSlicer's M3x10 socket-head screw, axis z: the head (z 0-3) is
    # turned (continuous rotation; its hexagon socket is a small share), the
    # shank a right-handed M3 thread, pitch 0.5. The rotation holds on the
    # head (about half the area; the thread rotated by more than a few
    # degrees is off by more than half a voxel), the helix on the thread.
    # Measured: every turn of either maps at least 96% of the area onto the
    # surface.
    "screw": [{"kind": "rotation", "through": [0, 0, 0], "axis": [0, 0, 1], "order": 0,
               "min_support": 0.5},
              {"kind": "helix", "through": [0, 0, 0], "axis": [0, 0, 1], "pitch": 0.5,
               "min_support": 0.65}],
    # PrusaSlicer's M3 hex nut: D6h, six turns about z, the mid-plane, and
    # the planes through the axis.
    "nut": [{"kind": "rotation", "through": [0, 0, 0.9], "axis": [0, 0, 1], "order": 6},
            {"kind": "mirror", "through": [0, 0, 0.9], "normal": [0, 0, 1]},
            {"kind": "mirror", "through": [0, 0, 0], "normal": [1, 0, 0]}],
    # CGAL's pinion: a spur gear of 10 teeth, D10h: ten turns about its
    # (tilted) axis, the mid-plane, the planes through the axis.
    "pinion": [{"kind": "rotation", "through": [0, 0, 0],
                "axis": [0.8279, 0.3139, -0.4648], "order": 10},
               {"kind": "mirror", "through": [0, 0, 0], "normal": [0.8279, 0.3139, -0.4648]},
               {"kind": "mirror", "through": [0, 0, 0], "normal": [0.2518, 0.5325, 0.8081]}],
    # CGAL's spool: a turned part, continuous rotation about x, and the
    # planes through that axis.
    "spool": [{"kind": "rotation", "through": [0, 0, 0], "axis": [1, 0, 0], "order": 0},
              {"kind": "mirror", "through": [0, 0, 0], "normal": [0, 1, 0]}],
    # CGAL's anchor: a bracket with one mirror plane, y = 0.
    "anchor": [{"kind": "mirror", "through": [0, 0, 0], "normal": [0, 1, 0]}],
}
TOL_VOXELS = 0.5        # a point maps onto the surface within half a voxel...
VOXELS = 128            # ...of a 128-voxel grid along the longest side
CONTINUOUS_STEPS = 24   # a continuous rotation is tried at every 15 degrees
SAMPLES = 20000         # surface samples (area-uniform, fixed seed)
SUPPORT_MIN = 0.95      # a listed symmetry holds on this share of the area at least
CANDIDATES = 8          # triangles of the nearest samples tried per point


def read_off(path):
    """Vertices (n x 3) and triangles (m x 3) of a plain OFF file."""
    with open(path) as f:
        tok = [t for line in f for t in line.split("#", 1)[0].split()]
    if not tok or tok[0] != "OFF":
        raise ValueError("%s: not a plain OFF file" % path)
    nv, nf = int(tok[1]), int(tok[2])
    V = np.array(tok[4:4 + 3 * nv], float).reshape(nv, 3)
    F = np.array(tok[4 + 3 * nv:4 + 3 * nv + 4 * nf], int).reshape(nf, 4)
    if nf and (F[:, 0] != 3).any():
        raise ValueError("%s: a face that is not a triangle" % path)
    return V, F[:, 1:]


def _closest_on_triangles(P, A, B, C):
    """Distance from each point P[i] to the triangle A[i] B[i] C[i]
    (Ericson, Real-Time Collision Detection, 5.1.5), vectorised."""
    ab, ac, ap = B - A, C - A, P - A
    d1, d2 = (ab * ap).sum(1), (ac * ap).sum(1)
    bp, cp = P - B, P - C
    d3, d4 = (ab * bp).sum(1), (ac * bp).sum(1)
    d5, d6 = (ab * cp).sum(1), (ac * cp).sum(1)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    safe = lambda x: np.where(x == 0, 1.0, x)
    den = safe(va + vb + vc)
    Q = A + ab * (vb / den)[:, None] + ac * (vc / den)[:, None]
    t = d1 / safe(d1 - d3)
    m = (vc <= 0) & (d1 >= 0) & (d3 <= 0)
    Q[m] = (A + ab * t[:, None])[m]
    t = d2 / safe(d2 - d6)
    m = (vb <= 0) & (d2 >= 0) & (d6 <= 0)
    Q[m] = (A + ac * t[:, None])[m]
    t = (d4 - d3) / safe((d4 - d3) + (d5 - d6))
    m = (va <= 0) & (d4 - d3 >= 0) & (d5 - d6 >= 0)
    Q[m] = (B + (C - B) * t[:, None])[m]
    m = (d1 <= 0) & (d2 <= 0)
    Q[m] = A[m]
    m = (d3 >= 0) & (d4 <= d3)
    Q[m] = B[m]
    m = (d6 >= 0) & (d5 <= d6)
    Q[m] = C[m]
    return np.linalg.norm(P - Q, axis=1)


class Surface:
    """Area-uniform samples of the triangles F of V (fixed seed), and the
    distance from points to the triangles: exact to each of the triangles
    that hold the point's CANDIDATES nearest samples (so never below the
    true distance; within a sample spacing of it)."""

    def __init__(self, V, F, samples=SAMPLES, seed=1):
        self.V, self.F = V, F
        T = V[F]
        self.area = 0.5 * np.linalg.norm(np.cross(T[:, 1] - T[:, 0], T[:, 2] - T[:, 0]), axis=1)
        rng = np.random.default_rng(seed)
        fi = rng.choice(len(F), samples, p=self.area / self.area.sum())
        u, v = rng.random(samples), rng.random(samples)
        flip = u + v > 1
        u[flip], v[flip] = 1 - u[flip], 1 - v[flip]
        self.face = fi
        self.points = T[fi, 0] + (T[fi, 1] - T[fi, 0]) * u[:, None] + (T[fi, 2] - T[fi, 0]) * v[:, None]
        self.tree = cKDTree(self.points)

    def distance(self, Q):
        k = min(CANDIDATES, len(self.points))
        _, idx = self.tree.query(Q, k=k)
        idx = idx.reshape(len(Q), k)
        best = np.full(len(Q), np.inf)
        for j in range(k):
            f = self.F[self.face[idx[:, j]]]
            best = np.minimum(best, _closest_on_triangles(Q, self.V[f[:, 0]], self.V[f[:, 1]],
                                                          self.V[f[:, 2]]))
        return best


def _rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * (K @ K)


def maps(sym):
    """The group elements other than the identity a symmetry stands for,
    as (matrix, through, shift): a mirror; every turn of a rotation of
    order N; CONTINUOUS_STEPS turns of a continuous one or of a helix."""
    o = np.asarray(sym["through"], float)
    zero = np.zeros(3)
    if sym["kind"] == "mirror":
        n = np.asarray(sym["normal"], float) / np.linalg.norm(sym["normal"])
        return [(np.eye(3) - 2 * np.outer(n, n), o, zero)]
    a = np.asarray(sym["axis"], float) / np.linalg.norm(sym["axis"])
    if sym["kind"] == "helix":
        n = CONTINUOUS_STEPS
        return [(_rotation(a, 2 * math.pi * k / n), o, a * sym["pitch"] * k / n)
                for k in range(1, n)]
    n = sym["order"] or CONTINUOUS_STEPS
    return [(_rotation(a, 2 * math.pi * k / n), o, zero) for k in range(1, n)]


def apply(m, P):
    M, o, shift = m
    return (P - o) @ M.T + o + shift


def tolerance(V):
    return TOL_VOXELS * float((V.max(0) - V.min(0)).max()) / VOXELS


def support(surface, sym, tol):
    """The least, over the symmetry's maps, share of the surface's samples
    that the map puts within tol of the surface."""
    return min(float((surface.distance(apply(m, surface.points)) < tol).mean())
               for m in maps(sym))


def recoverable(V, F, removed, syms, tol, samples=SAMPLES):
    """The share of the removed area (faces whose index is in removed) that
    some map of the symmetries puts back within tol of the kept surface:
    what the surviving surface says of the lost one."""
    removed = np.asarray(sorted(removed), int)
    keep = np.ones(len(F), bool)
    keep[removed] = False
    if not keep.any() or not len(removed):
        return 0.0 if len(removed) else 1.0
    lost = Surface(V, F[removed], samples)
    kept = Surface(V, F[keep], samples)
    found = np.zeros(len(lost.points), bool)
    for s in syms:
        for m in maps(s):
            todo = ~found
            if not todo.any():
                break
            found[todo] = kept.distance(apply(m, lost.points[todo])) < tol
    return float(found.mean())
