"""fem_check.py MESH - does linear elasticity solve on MESH (issue 24)?

The P1 stiffness of scripts/sim.py with the nodes of the lowest 15% of the
height fixed, gravity as the load, solved by scipy's sparse LU: exit 0 when
the solution is finite with a relative residual under 1e-8, 1 when the
matrix is singular (a piece hanging by an edge or a vertex, an island).
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import sim  # noqa: E402
from scipy.sparse.linalg import splu  # noqa: E402

points, tets = sim.read_cage(sys.argv[1])
k, f, _ = sim.fixed_system(points, tets, fraction=0.15)
try:
    u = splu(k).solve(f)
    res = float(np.linalg.norm(k @ u - f) / np.linalg.norm(f))
    ok = bool(np.isfinite(u).all()) and res < 1e-8
except RuntimeError as e:      # "Factor is exactly singular"
    ok, res = False, float("nan")
    print("fem_check: %s" % e)
print("fem_check: %d tets, relative residual %.2e: %s" % (len(tets), res,
                                                          "solved" if ok else "singular"))
sys.exit(0 if ok else 1)
