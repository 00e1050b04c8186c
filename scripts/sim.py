"""scripts/sim.py - what scripts/simulate, tests/tools/sim.t and the bench's
sim stage share: reading a cage and its embedding, carrying the embedded
surface with the cage, a large-deformation solve with SfePy, and the linear
elasticity measures of a tet mesh (stable time step, stiffness matrix,
conjugate gradients).

Imported by Debian's /usr/bin/python3 (numpy, scipy, meshio, SfePy from
python3-sfepy). SfePy is imported only by read_cage_sfepy and solve_sag,
so the rest works without it.

The demo and the tests load the cage as a SfePy user would, with SfePy's
own Mesh.from_file (read_cage_sfepy): that wants the tets alone (its
FEDomain refuses "meshes with several cell kinds"), so the cage is written
with soupmesh --volume-only (.mesh or .msh). read_cage reads any file
meshio reads (the bench's peers' meshes too).

The embedding is soupmesh --embed's text sidecar (embed.h): one line per
surface vertex, "tet b0 b1 b2 b3", tets numbered from 0 in the mesh file's
order; a surface vertex follows the cage as x = sum_i b_i p[tet_i].
"""
import numpy as np

# Material of the demo and the tests, in the model's units (dimensionless:
# only the ratio of load to stiffness matters for the shape).
YOUNG = 1.0
POISSON = 0.4   # nearly incompressible flesh, far enough from 0.5 that
                # P1 tets do not lock


def lame(young=YOUNG, poisson=POISSON):
    """(lambda, mu) of Young's modulus and Poisson's ratio."""
    lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson))
    mu = young / (2 * (1 + poisson))
    return lam, mu


# ------------------------------------------------------------------ files

def read_cage(path):
    """Points (n x 3 float64) and tets (m x 4 int64, in the file's order) of
    a tet mesh meshio reads (.mesh, .msh, .vtu, ...)."""
    import meshio
    m = meshio.read(path)
    tets = [c.data for c in m.cells if c.type == "tetra"]
    if not tets:
        raise ValueError("%s: no tetrahedra" % path)
    return np.asarray(m.points, dtype=np.float64)[:, :3], \
        np.concatenate(tets).astype(np.int64)


def read_cage_sfepy(path):
    """(SfePy Mesh, points n x 3 float64, tets m x 4 int64) of a tet mesh
    file loaded by SfePy's own Mesh.from_file (.mesh, .msh, .vtk, ...), as
    a SfePy user would load it. The file must hold the tets alone
    (soupmesh --volume-only): with the boundary triangles too, SfePy loads
    two cell kinds and its FEDomain refuses them, which is raised here as
    a ValueError naming the option."""
    from sfepy.base.base import output
    from sfepy.discrete.fem import Mesh
    output.set_output(quiet=True)
    mesh = Mesh.from_file(path)
    if list(mesh.descs) != ["3_4"]:
        raise ValueError("%s: SfePy loads the cell kinds %s; its FEDomain takes one"
                         " (write the mesh with soupmesh --volume-only)"
                         % (path, list(mesh.descs)))
    return mesh, np.array(mesh.coors, dtype=np.float64)[:, :3], \
        np.asarray(mesh.get_conn("3_4"), dtype=np.int64)


def read_obj(path):
    """Vertices and triangles (faces fanned) of an OBJ, read as they are."""
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if not t:
                continue
            if t[0] == "v":
                v.append([float(x) for x in t[1:4]])
            elif t[0] == "f":
                idx = [int(x.split("/")[0]) for x in t[1:]]
                idx = [i - 1 if i > 0 else len(v) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    f.append([idx[0], idx[k], idx[k + 1]])
    return np.array(v, dtype=np.float64), np.array(f, dtype=np.int64).reshape(-1, 3)


def write_obj(path, verts, tris, comment=None):
    with open(path, "w") as fh:
        if comment:
            fh.write("# %s\n" % comment)
        for p in verts:
            fh.write("v %.17g %.17g %.17g\n" % tuple(p))
        for t in tris:
            fh.write("f %d %d %d\n" % tuple(t + 1))


def read_embed(path):
    """(tet index per vertex, n x 4 barycentric coordinates) of soupmesh
    --embed's text file."""
    rows = np.loadtxt(path, comments="#", ndmin=2)
    return rows[:, 0].astype(np.int64), rows[:, 1:5].copy()


# ------------------------------------------------------------------ embedding

def carry(points, tets, tet_of, bary):
    """Where the embedded vertices are when the cage's points are `points`:
    x = sum_i b_i p[tets[t, i]]. Vertices with tet -1 (outside) raise."""
    if np.any(tet_of < 0):
        raise ValueError("%d vertices are outside the cage" % int(np.sum(tet_of < 0)))
    corners = points[tets[tet_of]]                 # n x 4 x 3
    return np.einsum("ni,nij->nj", bary, corners)


def locate(points, tets, xyz, k=24, slack=1e-12):
    """Barycentric embedding of xyz in a tet mesh that was not made with
    --embed (the bench's peers): for each point the tet whose smallest
    coordinate is largest (>= 0 for a tet that contains it; a point a
    rounding error outside keeps its nearest tet with a coordinate slightly
    below 0), first among the k tets whose centroids are nearest, then,
    for the points none of those contains (a long sliver's centroid can be
    far from the points inside it), among all tets. Floating point, for
    measuring only: souptet's own embedding (embed.h) is exact. Returns
    (tet, coordinates, smallest coordinate) per point."""
    from scipy.spatial import cKDTree
    cent = points[tets].mean(axis=1)
    k = min(k, len(tets))
    _, cand = cKDTree(cent).query(xyz, k=k)
    cand = cand.reshape(len(xyz), k)
    best_t = np.full(len(xyz), -1, dtype=np.int64)
    best_b = np.zeros((len(xyz), 4))
    best_min = np.full(len(xyz), -np.inf)
    for j in range(k):
        t = cand[:, j]
        b = barycentric(points[tets[t]], xyz)
        mn = b.min(axis=1)
        better = mn > best_min
        best_t[better], best_b[better], best_min[better] = t[better], b[better], mn[better]
    lost = np.nonzero(best_min < -slack)[0]
    if len(lost):
        p = points[tets]
        a = p[:, 0]
        inv = np.linalg.inv(np.stack([p[:, 1] - a, p[:, 2] - a, p[:, 3] - a], axis=2))
        for c in range(0, len(lost), 16):
            idx = lost[c:c + 16]
            l123 = np.einsum("mij,nmj->nmi", inv, xyz[idx][:, None, :] - a[None])
            b = np.concatenate([1 - l123.sum(axis=2, keepdims=True), l123], axis=2)
            mn = b.min(axis=2)
            j = mn.argmax(axis=1)
            r = np.arange(len(idx))
            better = mn[r, j] > best_min[idx]
            best_t[idx[better]] = j[better]
            best_b[idx[better]] = b[r, j][better]
            best_min[idx[better]] = mn[r, j][better]
    return best_t, best_b, best_min


def barycentric(corners, x):
    """Barycentric coordinates of points x (n x 3) in tets corners (n x 4 x 3)."""
    a = corners[:, 0]
    m = np.stack([corners[:, 1] - a, corners[:, 2] - a, corners[:, 3] - a], axis=2)
    l123 = np.linalg.solve(m, (x - a)[:, :, None])[:, :, 0]
    return np.column_stack([1 - l123.sum(axis=1), l123])


def rotation(axis, angle):
    axis = np.asarray(axis, dtype=np.float64)
    axis = axis / np.linalg.norm(axis)
    x, y, z = axis
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c + x * x * (1 - c), x * y * (1 - c) - z * s, x * z * (1 - c) + y * s],
                     [y * x * (1 - c) + z * s, c + y * y * (1 - c), y * z * (1 - c) - x * s],
                     [z * x * (1 - c) - y * s, z * y * (1 - c) + x * s, c + z * z * (1 - c)]])


def rigid_error(points, tets, tet_of, bary, surface, axis=(1.0, 2.0, 3.0), angle=0.7,
                shift=(0.3, -0.2, 0.1)):
    """Largest distance between the surface carried by a rigidly moved cage
    (rotation about `axis` by `angle`, then a shift of `shift` box
    diagonals) and the surface moved by the same motion, relative to the
    larger of the surface's box diagonal and its largest moved coordinate
    (what rounding is relative to). Barycentric interpolation reproduces
    affine maps, so this is rounding: a few units of 1e-16."""
    diag = float(np.linalg.norm(surface.max(axis=0) - surface.min(axis=0)))
    r = rotation(axis, angle)
    t = np.asarray(shift) * diag
    want = surface @ r.T + t
    moved = carry(points @ r.T + t, tets, tet_of, bary)
    scale = max(diag, float(np.abs(want).max()))
    return float(np.max(np.linalg.norm(moved - want, axis=1))) / scale


def smooth_map(x, lo, hi):
    """A smooth analytic deformation of the box [lo, hi]: a bend of the up
    axis (y) towards x, and a twist about y, each growing with height; of
    the order of a tenth of the box. The same map for every mesh of a model."""
    ext = hi - lo
    s = (x - lo) / ext                          # 0..1 in the box
    ang = 0.6 * s[:, 1] ** 2                    # twist about the up axis
    cx, cz = lo[0] + 0.5 * ext[0], lo[2] + 0.5 * ext[2]
    dx, dz = x[:, 0] - cx, x[:, 2] - cz
    out = x.copy()
    out[:, 0] = cx + np.cos(ang) * dx - np.sin(ang) * dz
    out[:, 2] = cz + np.sin(ang) * dx + np.cos(ang) * dz
    out[:, 0] += 0.15 * ext[1] * np.sin(np.pi * s[:, 1] / 2) ** 2
    return out


def smooth_error(points, tets, tet_of, bary, surface):
    """(max, mean) distance, relative to the surface's box diagonal, between
    the surface carried by the cage under smooth_map and smooth_map of the
    surface itself: the interpolation error of the cage's linear tets."""
    lo, hi = surface.min(axis=0), surface.max(axis=0)
    diag = float(np.linalg.norm(hi - lo))
    d = np.linalg.norm(carry(smooth_map(points, lo, hi), tets, tet_of, bary)
                       - smooth_map(surface, lo, hi), axis=1) / diag
    return float(d.max()), float(d.mean())


# ------------------------------------------------------------------ linear elasticity

def base_nodes(points, up=1, fraction=0.08, span=None):
    """The nodes held fixed: those within `fraction` of the height above the
    lowest point along axis `up`; with span = (lo, hi), of that height above
    lo instead (the input surface's range along `up`, so that meshes of one
    model made by different meshers hold the same slab)."""
    y = points[:, up]
    lo, hi = span if span is not None else (y.min(), y.max())
    return np.nonzero(y <= lo + fraction * (hi - lo))[0]


def altitudes(points, tets):
    """Each tet's shortest altitude: 3 V / (largest face area)."""
    p = points[tets]
    vol = np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0],
                           np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))) / 6
    faces = ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))
    amax = np.zeros(len(tets))
    for a, b, c in faces:
        amax = np.maximum(amax, 0.5 * np.linalg.norm(
            np.cross(p[:, b] - p[:, a], p[:, c] - p[:, a]), axis=1))
    return 3 * vol / amax


def dihedral_range(points, tets):
    """(min, max) dihedral angle in degrees over all tets: at each edge,
    the angle between the other two corners seen across the edge."""
    p = points[tets]
    lo, hi = 180.0, 0.0
    for i, j, k, l in ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2),
                       (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1)):
        e = p[:, j] - p[:, i]
        e /= np.linalg.norm(e, axis=1)[:, None]
        a = p[:, k] - p[:, i]
        b = p[:, l] - p[:, i]
        a -= np.einsum("ij,ij->i", a, e)[:, None] * e
        b -= np.einsum("ij,ij->i", b, e)[:, None] * e
        c = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        ang = np.degrees(np.arccos(np.clip(c, -1, 1)))
        lo, hi = min(lo, float(ang.min())), max(hi, float(ang.max()))
    return lo, hi


def stable_dt(points, tets, density=1.0, young=YOUNG, poisson=POISSON):
    """The explicit (central difference) stable time step of linear
    elasticity on the mesh, the usual per-element estimate: the smallest
    over tets of the shortest altitude over the dilatational wave speed
    sqrt((lambda + 2 mu) / rho)."""
    lam, mu = lame(young, poisson)
    return float(altitudes(points, tets).min() / np.sqrt((lam + 2 * mu) / density))


def stiffness(points, tets, young=YOUNG, poisson=POISSON):
    """The global stiffness matrix of linear elasticity with linear tets
    (scipy CSR, 3 n x 3 n, dofs x0 y0 z0 x1 ...)."""
    import scipy.sparse as sp
    lam, mu = lame(young, poisson)
    p = points[tets]
    m = len(tets)
    jac = np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]], axis=2)
    det = np.linalg.det(jac)
    inv = np.linalg.inv(jac)                            # rows: gradients of l1..l3
    g = np.concatenate([-inv.sum(axis=1, keepdims=True), inv], axis=1)   # m x 4 x 3
    vol = np.abs(det) / 6
    # B (6 x 12) per tet, Voigt order xx yy zz yz xz xy.
    b = np.zeros((m, 6, 12))
    for a in range(4):
        gx, gy, gz = g[:, a, 0], g[:, a, 1], g[:, a, 2]
        b[:, 0, 3 * a] = gx
        b[:, 1, 3 * a + 1] = gy
        b[:, 2, 3 * a + 2] = gz
        b[:, 3, 3 * a + 1], b[:, 3, 3 * a + 2] = gz, gy
        b[:, 4, 3 * a], b[:, 4, 3 * a + 2] = gz, gx
        b[:, 5, 3 * a], b[:, 5, 3 * a + 1] = gy, gx
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    ke = np.einsum("mki,kl,mlj->mij", b, d, b) * vol[:, None, None]
    dof = (3 * tets[:, :, None] + np.arange(3)).reshape(m, 12)
    rows = np.repeat(dof, 12, axis=1).ravel()
    cols = np.tile(dof, (1, 12)).ravel()
    n = 3 * len(points)
    return sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(n, n))


def gravity_load(points, tets, up=1, rho_g=1.0):
    """The consistent load of a uniform body force -rho_g along `up`: each
    tet's weight split equally among its corners."""
    p = points[tets]
    vol = np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0],
                           np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))) / 6
    f = np.zeros(3 * len(points))
    np.add.at(f, 3 * tets.ravel() + up, -np.repeat(rho_g * vol / 4, 4))
    return f


def fixed_system(points, tets, up=1, fraction=0.08, span=None):
    """The stiffness matrix and gravity load with the base nodes' dofs
    removed (what is solved; base_nodes(points, up, fraction, span)), and
    the kept dofs."""
    k = stiffness(points, tets)
    f = gravity_load(points, tets, up)
    fixed = np.zeros(3 * len(points), dtype=bool)
    base = base_nodes(points, up, fraction, span)
    for c in range(3):
        fixed[3 * base + c] = True
    used = np.zeros(len(points), dtype=bool)
    used[tets.ravel()] = True
    free = np.nonzero(~fixed & np.repeat(used, 3))[0]
    return k[free][:, free].tocsc(), f[free], free


def condition(k):
    """(lambda_max, lambda_min, condition number) of a symmetric positive
    definite sparse matrix: scipy's eigsh, the smallest by shift-invert
    about 0."""
    from scipy.sparse.linalg import eigsh
    lmax = eigsh(k, k=1, which="LA", return_eigenvectors=False, tol=1e-6)[0]
    lmin = eigsh(k, k=1, sigma=0, which="LM", return_eigenvectors=False, tol=1e-8)[0]
    return float(lmax), float(lmin), float(lmax / lmin)


def pcg_jacobi(k, f, tol=1e-8, maxit=100000):
    """Iterations of conjugate gradients with a Jacobi (diagonal)
    preconditioner until ||r|| <= tol ||f||, from x = 0."""
    k = k.tocsr()
    dinv = 1.0 / k.diagonal()
    x = np.zeros_like(f)
    r = f.copy()
    z = dinv * r
    p = z.copy()
    rz = r @ z
    stop = tol * np.linalg.norm(f)
    for it in range(1, maxit + 1):
        kp = k @ p
        alpha = rz / (p @ kp)
        x += alpha * p
        r -= alpha * kp
        if np.linalg.norm(r) <= stop:
            return it, x
        z = dinv * r
        rz_new = r @ z
        p = z + (rz_new / rz) * p
        rz = rz_new
    return maxit, x


# ------------------------------------------------------------------ SfePy

def solve_sag(points, tets, load, steps=4, up=1, fraction=0.08, young=YOUNG,
              poisson=POISSON, quiet=True, mesh=None):
    """A compressible Neo-Hookean body (total Lagrangian: SfePy's
    dw_tl_he_neohook + dw_tl_bulk_penalty, mu and bulk modulus K from
    Young's modulus and Poisson's ratio) sagging under its weight `load`
    (force per volume, along -up), the base nodes (base_nodes) held fixed,
    the load applied in `steps` equal increments, Newton at each. Returns
    (displacement n x 3, [Newton iterations per step], converged). Only the
    mesh's points used by tets are in the problem; the others get 0.
    mesh: the SfePy Mesh these points and tets came from (read_cage_sfepy),
    solved as loaded when every point is used; None: one is made from the
    arrays (Mesh.from_data)."""
    from sfepy.base.base import output, IndexedStruct
    from sfepy.discrete import (FieldVariable, Material, Integral, Function,
                                Equation, Equations, Problem)
    from sfepy.discrete.conditions import Conditions, EssentialBC
    from sfepy.discrete.fem import Mesh, FEDomain, Field
    from sfepy.solvers.ls import ScipyDirect
    from sfepy.solvers.nls import Newton
    from sfepy.solvers.ts_solvers import SimpleTimeSteppingSolver
    from sfepy.terms import Term
    output.set_output(quiet=quiet)

    used = np.unique(tets.ravel())
    remap = np.full(len(points), -1, dtype=np.int64)
    remap[used] = np.arange(len(used))
    coors = points[used]
    if mesh is None or len(used) != len(points):
        conn = remap[tets].astype(np.int32)
        mesh = Mesh.from_data("cage", coors, None, [conn],
                              [np.zeros(len(conn), dtype=np.int32)], ["3_4"])
    domain = FEDomain("domain", mesh)
    omega = domain.create_region("Omega", "all")
    y = coors[:, up]
    ycut = y.min() + fraction * (y.max() - y.min())
    axis = "xyz"[up]
    # The same nodes as base_nodes (y <= ycut), with room for rounding.
    base = domain.create_region("Base", "vertices in (%s < %.17g)"
                                % (axis, ycut + 1e-12 * (y.max() - y.min())), "vertex")
    field = Field.from_args("displacement", np.float64, "vector", omega, approx_order=1)
    u = FieldVariable("u", "unknown", field)
    v = FieldVariable("v", "test", field, primary_var_name="u")
    lam, mu = lame(young, poisson)
    bulk = lam + 2.0 * mu / 3.0
    solid = Material("solid", mu=mu, K=bulk)

    def body_force(ts, coors, mode=None, **kwargs):
        if mode != "qp":
            return None
        val = np.zeros((coors.shape[0], 3, 1))
        val[:, up, 0] = -load * ts.time
        return {"val": val}
    force = Material("force", function=Function("body_force", body_force))
    integral = Integral("i", order=2)
    t1 = Term.new("dw_tl_he_neohook(solid.mu, v, u)", integral, omega, solid=solid, v=v, u=u)
    t2 = Term.new("dw_tl_bulk_penalty(solid.K, v, u)", integral, omega, solid=solid, v=v, u=u)
    t3 = Term.new("dw_volume_lvf(force.val, v)", integral, omega, force=force, v=v)
    eqs = Equations([Equation("balance", t1 + t2 - t3)])
    pb = Problem("sag", equations=eqs)
    pb.set_bcs(ebcs=Conditions([EssentialBC("fix", base, {"u.all": 0.0})]))
    status = IndexedStruct()
    iters = []

    nls = Newton({"i_max": 20, "eps_a": 1e-9, "eps_r": 1e-9, "ls_on": 0.99999,
                  "ls_red": 0.5, "ls_min": 1e-4}, lin_solver=ScipyDirect({}), status=status)
    tss = SimpleTimeSteppingSolver({"t0": 0.0, "t1": 1.0, "n_step": steps + 1, "quasistatic": True,
                                    "verbose": not quiet}, nls=nls, context=pb)
    pb.set_solver(tss)
    conv = []

    def step_hook(pb_, ts, variables):
        iters.append(int(status.n_iter))
        conv.append(status.condition == 0)
    state = pb.solve(save_results=False, step_hook=step_hook)
    uv = _displacement(state, pb).reshape(-1, 3)
    disp = np.zeros((len(points), 3))
    disp[used] = uv
    return disp, iters[1:], all(conv)


def _displacement(state, pb):
    """u's values from what Problem.solve returned (a State before SfePy
    2022.1, Variables after)."""
    try:
        return np.asarray(state.get_parts()["u"])
    except AttributeError:
        return np.asarray(state["u"].data[0] if hasattr(state["u"], "data") else state["u"]())



def solve_cantilever_parts(mesh, load, young, poisson, clamp=0.6, up=1, quiet=True):
    """A two-material (or more) cantilever in linear elasticity: the SfePy
    mesh `mesh` (read by read_cage_sfepy from a .mesh whose tet references
    are soupmesh --parts' part + 1, which SfePy loads as its cell groups),
    Young's modulus young[g] and Poisson's ratio poisson[g] in cell group
    g (one dw_lin_elastic term over the body, its stiffness per cell),
    clamped where x is within `clamp` of its smallest value, under its
    weight `load` (force per volume along -up). Returns (displacement of
    the mesh's points n x 3, Newton iterations, converged)."""
    from sfepy.base.base import output, IndexedStruct
    from sfepy.discrete import (FieldVariable, Material, Integral, Function,
                                Equation, Equations, Problem)
    from sfepy.discrete.conditions import Conditions, EssentialBC
    from sfepy.discrete.fem import FEDomain, Field
    from sfepy.mechanics.matcoefs import stiffness_from_youngpoisson
    from sfepy.solvers.ls import ScipyDirect
    from sfepy.solvers.nls import Newton
    from sfepy.terms import Term
    output.set_output(quiet=quiet)
    domain = FEDomain("domain", mesh)
    omega = domain.create_region("Omega", "all")
    x = mesh.coors[:, 0]
    base = domain.create_region("Clamp", "vertices in (x < %.17g)" % (x.min() + clamp), "vertex")
    field = Field.from_args("displacement", np.float64, "vector", omega, approx_order=1)
    u = FieldVariable("u", "unknown", field)
    v = FieldVariable("v", "test", field, primary_var_name="u")
    integral = Integral("i", order=2)
    groups = np.asarray(mesh.cmesh.cell_groups)
    d_of = {g: stiffness_from_youngpoisson(3, young[g], poisson[g]) for g in young}
    d_c = np.array([d_of[g] for g in groups], dtype=np.float64)

    def params(ts, coors, mode=None, **kwargs):
        if mode != "qp":
            return None
        nqp = coors.shape[0] // len(groups)    # quadrature points by cell
        val = np.zeros((coors.shape[0], 3, 1))
        val[:, up, 0] = -load
        return {"D": np.repeat(d_c, nqp, axis=0), "val": val}
    solid = Material("solid", function=Function("params", params))
    terms = Term.new("dw_lin_elastic(solid.D, v, u)", integral, omega, solid=solid, v=v, u=u) \
        - Term.new("dw_volume_lvf(solid.val, v)", integral, omega, solid=solid, v=v)
    pb = Problem("cantilever", equations=Equations([Equation("balance", terms)]))
    pb.set_bcs(ebcs=Conditions([EssentialBC("clamp", base, {"u.all": 0.0})]))
    status = IndexedStruct()
    nls = Newton({"i_max": 1, "eps_a": 1e-10, "eps_r": 1.0}, lin_solver=ScipyDirect({}),
                 status=status)
    pb.set_solver(nls)
    state = pb.solve(save_results=False)
    return _displacement(state, pb).reshape(-1, 3), int(status.n_iter), status.condition == 0
