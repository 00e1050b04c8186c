"""bench/peer_mesh.py - what the mesh and lattice bench stages share: reading
and writing surfaces and tet meshes in the peers' formats, and the mesh
metrics computed in Python (numpy, python3-vtk9) for when tetstat is not
built (or cannot read a peer's output).

Formats: surfaces .off .obj .ply .stl (read as they are: no welding; polygons
fanned into triangles); tet meshes TetGen .node/.ele, Gmsh .msh (version 2
ASCII, as written by `gmsh -format msh2`), Medit .mesh (Vertices,
Tetrahedra), VTK .vtu (VTK_TETRA cells).

Orientation: souptet's positive tet (a, b, c, d) has (b-a).((c-a)x(d-a)) > 0
(include/souptet/tetmesh.h), as VTK's tetra does. TetGen, Gmsh and Medit
files may use the other convention for all their tets; orient() flips the
whole mesh when most of its tets are negative (a convention, not a repair)
and counts the tets still not positive as inverted.

The Python metrics are measurements, not decisions: enclosure here is VTK's
point location (a tolerance, not exact predicates) and the distance from the
surface to the boundary is sampled at the surface's vertices; tetstat is
exact and is used whenever it exists. Rows say which one measured them.
"""
import os
import struct
import subprocess

import numpy as np


# ---------------------------------------------------------------- surfaces

def _fan(polys):
    tris = []
    for p in polys:
        for k in range(1, len(p) - 1):
            tris.append((p[0], p[k], p[k + 1]))
    return tris


def _read_off(path):
    """OFF: header, counts, points, then one face per line (extra values on a
    face line, such as colours, are ignored)."""
    with open(path) as f:
        lines = [l.split("#", 1)[0].split() for l in f]
    lines = [l for l in lines if l]
    if not lines or not lines[0][0].endswith("OFF"):
        raise ValueError("%s: not an OFF file" % path)
    head = lines[0][1:] if len(lines[0]) > 1 else lines[1]
    start = 1 if len(lines[0]) > 1 else 2
    nv, nf = int(head[0]), int(head[1])
    V = np.array([l[:3] for l in lines[start:start + nv]], dtype=np.float64).reshape(nv, 3)
    polys = []
    for l in lines[start + nv:start + nv + nf]:
        k = int(l[0])
        polys.append([int(x) for x in l[1:1 + k]])
    return V, np.array(_fan(polys), dtype=np.int64).reshape(-1, 3)


def _read_obj(path):
    V, polys = [], []
    with open(path) as f:
        for line in f:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                V.append([float(x) for x in t[1:4]])
            elif t[0] == "f":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                polys.append([i - 1 if i > 0 else len(V) + i for i in idx])
    return np.array(V, dtype=np.float64), np.array(_fan(polys), dtype=np.int64).reshape(-1, 3)


def _read_stl(path):
    with open(path, "rb") as f:
        data = f.read()
    if len(data) >= 84:
        n = struct.unpack("<I", data[80:84])[0]
        if 84 + 50 * n == len(data):
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)),
                                                      ("a", "<u2")]), count=n, offset=84)
            V = rec["v"].reshape(-1, 3).astype(np.float64)
            return V, np.arange(3 * n, dtype=np.int64).reshape(-1, 3)
    V = [[float(x) for x in l.split()[1:4]] for l in data.decode("latin-1").splitlines()
         if l.strip().startswith("vertex")]
    V = np.array(V, dtype=np.float64)
    return V, np.arange(len(V), dtype=np.int64).reshape(-1, 3)


def _read_ply(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkPLYReader()
    r.SetFileName(path)
    r.Update()
    pd = r.GetOutput()
    V = vtk_to_numpy(pd.GetPoints().GetData()).astype(np.float64)
    polys = []
    ids = vtk.vtkIdList()
    cells = pd.GetPolys()
    cells.InitTraversal()
    while cells.GetNextCell(ids):
        polys.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    return V, np.array(_fan(polys), dtype=np.int64).reshape(-1, 3)


def read_surface(path):
    """(V, F): points (n, 3) float64 and triangles (m, 3) int64, as in the file."""
    ext = os.path.splitext(path)[1].lower()
    if ext == ".off":
        return _read_off(path)
    if ext == ".obj":
        return _read_obj(path)
    if ext == ".stl":
        return _read_stl(path)
    if ext == ".ply":
        return _read_ply(path)
    raise ValueError("%s: unknown surface format" % path)


def write_off(path, V, F):
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(V), len(F)))
        f.write("".join("%.17g %.17g %.17g\n" % tuple(v) for v in V))
        f.write("".join("3 %d %d %d\n" % tuple(t) for t in F))


def write_stl(path, V, F):
    """ASCII STL with 17 digits, so a reader that parses doubles gets the
    points exactly (Gmsh does)."""
    out = ["solid souptet\n"]
    for t in F:
        out.append(" facet normal 0 0 0\n  outer loop\n")
        for i in t:
            out.append("   vertex %.17g %.17g %.17g\n" % tuple(V[i]))
        out.append("  endloop\n endfacet\n")
    out.append("endsolid souptet\n")
    with open(path, "w") as f:
        f.write("".join(out))


def bbox_diag(V):
    return float(np.linalg.norm(V.max(axis=0) - V.min(axis=0))) if len(V) else 0.0


# --------------------------------------------------------------- tet meshes

def read_tetgen(prefix):
    """prefix.node / prefix.ele (TetGen 1.5; first index 0 or 1)."""
    with open(prefix + ".node") as f:
        rows = [l.split("#", 1)[0].split() for l in f]
    rows = [r for r in rows if r]
    n = int(rows[0][0])
    ids = np.array([int(r[0]) for r in rows[1:1 + n]])
    P = np.array([[float(x) for x in r[1:4]] for r in rows[1:1 + n]], dtype=np.float64)
    with open(prefix + ".ele") as f:
        rows = [l.split("#", 1)[0].split() for l in f]
    rows = [r for r in rows if r]
    m = int(rows[0][0])
    T = np.array([[int(x) for x in r[1:5]] for r in rows[1:1 + m]], dtype=np.int64)
    return P, T - ids.min()


def read_msh2(path):
    """Tets (element type 4) of a Gmsh ASCII .msh version 2."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = lines.index("$Nodes")
    n = int(lines[i + 1])
    node = {}
    P = np.empty((n, 3))
    for k in range(n):
        t = lines[i + 2 + k].split()
        node[int(t[0])] = k
        P[k] = [float(x) for x in t[1:4]]
    i = lines.index("$Elements")
    m = int(lines[i + 1])
    T = []
    for k in range(m):
        t = lines[i + 2 + k].split()
        if t[1] == "4":
            ntags = int(t[2])
            T.append([node[int(x)] for x in t[3 + ntags:7 + ntags]])
    return P, np.array(T, dtype=np.int64).reshape(-1, 4)


def read_medit(path):
    """Vertices and Tetrahedra of a Medit .mesh (ASCII, 1-based)."""
    with open(path) as f:
        toks = f.read().split()
    P = np.empty((0, 3))
    T = np.empty((0, 4), dtype=np.int64)
    i = 0
    while i < len(toks):
        w = toks[i]
        if w == "Vertices":
            n = int(toks[i + 1])
            P = np.array(toks[i + 2:i + 2 + 4 * n], dtype=np.float64).reshape(n, 4)[:, :3]
            i += 2 + 4 * n
        elif w == "Tetrahedra":
            m = int(toks[i + 1])
            T = np.array(toks[i + 2:i + 2 + 5 * m], dtype=np.int64).reshape(m, 5)[:, :4] - 1
            i += 2 + 5 * m
        else:
            i += 1
    return P, T


def read_vtu(path):
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    P = vtk_to_numpy(g.GetPoints().GetData()).astype(np.float64)
    conn = vtk_to_numpy(g.GetCells().GetConnectivityArray()).astype(np.int64)
    return P, conn.reshape(-1, 4)


def vtu_field_data(path):
    """The string field data of a .vtu (souptet stores h, history, ...)."""
    import vtk
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    fd = r.GetOutput().GetFieldData()
    out = {}
    for k in range(fd.GetNumberOfArrays()):
        a = fd.GetAbstractArray(k)
        if a is None:
            continue
        if a.IsA("vtkStringArray") and a.GetNumberOfValues() > 0:
            out[a.GetName()] = a.GetValue(0)
        elif a.IsA("vtkUnsignedCharArray"):   # souptet's text meta
            out[a.GetName()] = bytes(int(a.GetValue(i)) for i in
                                     range(a.GetNumberOfTuples())).decode()
        elif a.IsA("vtkDataArray") and a.GetNumberOfTuples() > 0:
            out[a.GetName()] = a.GetTuple1(0)
    return out


def write_vtu(path, P, T):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(P, dtype=np.float64), deep=True))
    cells = vtk.vtkCellArray()
    offsets = numpy_to_vtkIdTypeArray(np.arange(0, 4 * len(T) + 1, 4, dtype=np.int64), deep=True)
    conn = numpy_to_vtkIdTypeArray(np.ascontiguousarray(T.reshape(-1), dtype=np.int64), deep=True)
    cells.SetData(offsets, conn)
    g = vtk.vtkUnstructuredGrid()
    g.SetPoints(pts)
    g.SetCells(vtk.VTK_TETRA, cells)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetFileName(path)
    w.SetInputData(g)
    w.SetDataModeToBinary()
    w.SetCompressorTypeToZLib()
    if not w.Write():
        raise RuntimeError("cannot write %s" % path)


def signed_volumes(P, T):
    a, b, c, d = (P[T[:, k]] for k in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0


def orient(P, T):
    """(T, inverted): T flipped as a whole if most tets are negative; the
    number of tets that are then not positive."""
    v = signed_volumes(P, T)
    if np.count_nonzero(v < 0) > np.count_nonzero(v > 0):
        T = T[:, [0, 1, 3, 2]]
        v = -v
    return T, int(np.count_nonzero(v <= 0))


def dihedrals(P, T):
    """Per-tet (min, max) dihedral angle in degrees."""
    X = P[T]                               # (m, 4, 3)
    # outward normal of the face opposite corner i
    faces = ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1))
    N = np.empty((len(T), 4, 3))
    for i, (a, b, c) in enumerate(faces):
        n = np.cross(X[:, b] - X[:, a], X[:, c] - X[:, a])
        # point away from corner i whatever the tet's orientation
        s = np.sign(np.einsum("ij,ij->i", n, X[:, a] - X[:, i]))
        s[s == 0] = 1.0
        n *= s[:, None]
        ln = np.linalg.norm(n, axis=1)
        ln[ln == 0] = 1.0
        N[:, i] = n / ln[:, None]
    ang = []
    for i in range(4):
        for j in range(i + 1, 4):
            cosv = np.clip(-np.einsum("ij,ij->i", N[:, i], N[:, j]), -1.0, 1.0)
            ang.append(np.degrees(np.arccos(cosv)))
    A = np.stack(ang, axis=1)
    return A.min(axis=1), A.max(axis=1)


def boundary_faces(T):
    F = np.concatenate([T[:, [1, 2, 3]], T[:, [0, 3, 2]], T[:, [0, 1, 3]], T[:, [0, 2, 1]]])
    key = np.sort(F, axis=1)
    _, idx, cnt = np.unique(key, axis=0, return_index=True, return_counts=True)
    return F[idx[cnt == 1]]


def mesh_metrics(P, T):
    """tets, points, min/max dihedral, inverted, volume (numpy)."""
    T, inverted = orient(P, T)
    used = np.unique(T)
    mn, mx = dihedrals(P, T) if len(T) else (np.array([0.0]), np.array([0.0]))
    return {"tets": int(len(T)), "points": int(len(used)), "min_dihedral": float(mn.min()),
            "max_dihedral": float(mx.max()), "inverted": inverted,
            "volume": float(signed_volumes(P, T).sum()), "measured_by": "python"}


def surface_metrics(P, T, V, F):
    """Enclosure and distances of a tet mesh against a surface, by VTK
    (approximate: see the module comment)."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray

    def polydata(X, tris):
        pts = vtk.vtkPoints()
        pts.SetData(numpy_to_vtk(np.ascontiguousarray(X, dtype=np.float64), deep=True))
        ca = vtk.vtkCellArray()
        ca.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(tris) + 1, 3, dtype=np.int64), deep=True),
                   numpy_to_vtkIdTypeArray(np.ascontiguousarray(tris.reshape(-1), dtype=np.int64), deep=True))
        pd = vtk.vtkPolyData()
        pd.SetPoints(pts)
        pd.SetPolys(ca)
        return pd

    T, _ = orient(P, T)
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(P, dtype=np.float64), deep=True))
    cells = vtk.vtkCellArray()
    cells.SetData(numpy_to_vtkIdTypeArray(np.arange(0, 4 * len(T) + 1, 4, dtype=np.int64), deep=True),
                  numpy_to_vtkIdTypeArray(np.ascontiguousarray(T.reshape(-1), dtype=np.int64), deep=True))
    g = vtk.vtkUnstructuredGrid()
    g.SetPoints(pts)
    g.SetCells(vtk.VTK_TETRA, cells)
    loc = vtk.vtkStaticCellLocator()
    loc.SetDataSet(g)
    loc.BuildLocator()
    diag = bbox_diag(V)
    tol2 = (1e-9 * diag) ** 2        # point location only: on the boundary counts as inside
    gc = vtk.vtkGenericCell()
    pc = [0.0, 0.0, 0.0]
    w = [0.0] * 4
    inside = sum(1 for v in V if loc.FindCell(tuple(v), tol2, gc, pc, w) >= 0)
    B = boundary_faces(T)
    bverts = np.unique(B)
    # boundary vertices -> S
    sl = vtk.vtkStaticCellLocator()
    S = polydata(V, F)
    sl.SetDataSet(S)
    sl.BuildLocator()
    cp = [0.0, 0.0, 0.0]
    cid, sid, d2 = vtk.reference(0), vtk.reference(0), vtk.reference(0.0)
    dv = []
    for p in P[bverts]:
        sl.FindClosestPoint(tuple(p), cp, cid, sid, d2)
        dv.append(float(d2) ** 0.5)
    # S (its vertices) -> boundary
    bl = vtk.vtkStaticCellLocator()
    Bpd = polydata(P, B)
    bl.SetDataSet(Bpd)
    bl.BuildLocator()
    ds = 0.0
    for v in V[np.unique(F)]:
        bl.FindClosestPoint(tuple(v), cp, cid, sid, d2)
        ds = max(ds, float(d2) ** 0.5)
    return {"enclosed_fraction": inside / float(len(V)) if len(V) else 1.0,
            "crossing_triangles": None,
            "dist_boundary_to_surface_max": max(dv) if dv else 0.0,
            "dist_boundary_to_surface_mean": float(np.mean(dv)) if dv else 0.0,
            "dist_surface_to_boundary_max": ds, "measured_by": "python"}


def timed(cmd, timeout, **kw):
    """(CompletedProcess or None on timeout, wall seconds)."""
    import time
    t0 = time.time()
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)
    except subprocess.TimeoutExpired:
        return None, time.time() - t0
    return r, time.time() - t0


def last_error(text, default="exit status"):
    """The most telling line of a peer's stderr/stdout."""
    lines = [l.strip() for l in (text or "").splitlines() if l.strip()]
    for l in reversed(lines):
        low = l.lower()
        if "error" in low or "fail" in low or "not" in low or "cannot" in low or "invalid" in low \
                or "intersect" in low or "abort" in low or "terminate" in low:
            return l[:160]
    return lines[-1][:160] if lines else default
