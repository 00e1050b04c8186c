#!/usr/bin/python3
"""tests/tools/sim_check.py CAGE EMBED SURFACE [--sfepy [MSH...] [--default DMSH]]
- the checks of sim.t on a cage soupmesh made with --embed and
--volume-only (scripts/sim.py does the work). Prints TAP lines without a
plan (sim.t numbers them); exits 0. With --sfepy the cage is loaded by
SfePy's own Mesh.from_file (as a SfePy user loads it), else by meshio.

  embed      every surface vertex has a tet, coordinates >= 0 summing to 1,
             and the rest cage carries the surface onto itself (rounding)
  rigid      a rotated and shifted cage carries the surface to the rotated
             and shifted surface, to rounding (<= 1e-14 of its size)
  locate     the bench's floating-point point location finds every point
  linear     sim.stiffness against a hand-made one-tet matrix; CG+Jacobi
             reaches the direct solution; eigsh's extreme eigenvalues agree
             with a dense solver's
  sfepy      (with --sfepy) SfePy's Mesh.from_file loads the cage and
             each MSH (soupmesh --volume-only .msh) into one cell kind its
             FEDomain takes, the same points and tets as meshio reads;
             DMSH (soupmesh's default .msh) keeps its "boundary" group of
             triangles for gmsh and meshio; the
             Neo-Hookean sag (on the mesh as SfePy loaded it) converges, keeps the base
             fixed, goes down; under a small load it matches linear
             elasticity (sim.stiffness) to 1%
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts"))
import numpy as np  # noqa: E402
import sim  # noqa: E402

N = 0


def ok(cond, name, diag=""):
    global N
    N += 1
    print("%s %d - %s" % ("ok" if cond else "not ok", N, name))
    if not cond and diag:
        print("#   " + diag)
    sys.stdout.flush()


def main():
    cage, embed, surface = sys.argv[1:4]
    rest = sys.argv[4:]
    with_sfepy = "--sfepy" in rest
    dmsh = rest[rest.index("--default") + 1] if "--default" in rest else None
    mshs = [a for a in rest if a.endswith(".msh") and a != dmsh]
    print("# numbering continues from sim.t", file=sys.stderr)
    smesh = None
    if with_sfepy:
        smesh, points, tets = sim.read_cage_sfepy(cage)
    else:
        points, tets = sim.read_cage(cage)
    tet_of, bary = sim.read_embed(embed)
    surf, _ = sim.read_obj(surface)
    diag = float(np.linalg.norm(surf.max(axis=0) - surf.min(axis=0)))

    ok(len(tet_of) == len(surf) and np.all(tet_of >= 0) and np.all(tet_of < len(tets)),
       "every surface vertex has a tet of the cage (%d vertices, %d tets)" % (len(surf), len(tets)))
    s = np.abs(bary.sum(axis=1) - 1).max()
    ok(np.all(bary >= 0) and s <= 4e-16, "barycentric coordinates >= 0, summing to 1 within 4e-16",
       "min %g, largest |sum-1| %g" % (bary.min(), s))
    e = np.linalg.norm(sim.carry(points, tets, tet_of, bary) - surf, axis=1).max() / diag
    ok(e <= 1e-14, "the rest cage carries the surface onto itself (%.1e of its size)" % e)
    worst = 0.0
    for axis, angle, shift in (((1, 2, 3), 0.7, (0.3, -0.2, 0.1)), ((0, 0, 1), np.pi / 2, (0, 0, 0)),
                               ((-2, 1, 0.5), 2.9, (10.0, 20.0, -5.0))):
        worst = max(worst, sim.rigid_error(points, tets, tet_of, bary, surf, axis, angle, shift))
    ok(worst <= 4e-15, "a rigidly moved cage moves the surface rigidly, to rounding"
       " (%.1e of its size, at most 4e-15; 3 motions)" % worst)
    # Not every map is reproduced: a smooth non-affine one shows a real error.
    emax, _ = sim.smooth_error(points, tets, tet_of, bary, surf)
    ok(1e-8 < emax < 0.05, "a smooth bend and twist is interpolated with an error above rounding"
       " and below 5%% of the size (%.1e)" % emax)

    # locate (the bench's embedding of peers' meshes) with too few
    # candidates (k = 2) must still find every point's tet by its fallback.
    from scipy.spatial import Delaunay
    rng = np.random.default_rng(20)
    dp = rng.random((300, 3))
    dt = Delaunay(dp).simplices.astype(np.int64)
    q = 0.2 + 0.6 * rng.random((500, 3))
    lt, lb, lmin = sim.locate(dp, dt, q, k=2)
    back = np.abs(sim.carry(dp, dt, lt, lb) - q).max()
    ok(lmin.min() >= 0 and back < 1e-14, "locate finds a containing tet for every point"
       " (smallest coordinate %.1e, back %.1e)" % (lmin.min(), back))

    # One tet, by hand: the unit corner tet under a uniaxial strain
    # eps_xx = 0.01 has stress diag(lam + 2 mu, lam, lam) 0.01, and corner a
    # gets the force V sigma grad(N_a) (V = 1/6, grad N = (-1,-1,-1), e_x,
    # e_y, e_z).
    p1 = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    t1 = np.array([[0, 1, 2, 3]])
    k1 = sim.stiffness(p1, t1).toarray()
    lam, mu = sim.lame()
    u = np.zeros(12)
    u[0::3] = p1[:, 0] * 0.01
    sigma = np.diag([lam + 2 * mu, lam, lam]) * 0.01
    grads = np.array([[-1.0, -1, -1], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    want = (grads @ sigma / 6).ravel()
    ok(np.allclose(k1, k1.T, rtol=0, atol=1e-15) and np.abs(k1 @ u - want).max() < 1e-15,
       "one tet's stiffness: symmetric, the corner forces of a uniaxial strain",
       "K u %s, want %s" % (k1 @ u, want))
    rigid = np.tile([1.0, -2.0, 0.5], 4)
    ok(np.abs(k1 @ rigid).max() < 1e-15, "a translation costs no force")

    k, rhs, free = sim.fixed_system(points, tets)
    from scipy.sparse.linalg import spsolve
    direct = spsolve(k, rhs)
    it, x = sim.pcg_jacobi(k, rhs, 1e-8)
    err = np.linalg.norm(x - direct) / np.linalg.norm(direct)
    ok(it < len(rhs) and err < 1e-6, "CG+Jacobi reaches the direct solution (%d iterations,"
       " relative error %.1e)" % (it, err))
    lmax, lmin, cond = sim.condition(k)
    ev = np.linalg.eigvalsh(k.toarray()) if k.shape[0] <= 4000 else None
    ok(ev is not None and abs(lmax / ev[-1] - 1) < 1e-5 and abs(lmin / ev[0] - 1) < 1e-5,
       "eigsh's extreme eigenvalues of the fixed-base stiffness match a dense solver's"
       " (condition %.3g)" % cond, "eigsh %g %g, dense %s" % (lmax, lmin,
                                                              ev[[0, -1]] if ev is not None else "-"))

    if not with_sfepy:
        return 0
    from sfepy.discrete.fem import FEDomain
    mp, mt = sim.read_cage(cage)
    FEDomain("domain", smesh)
    ok(np.array_equal(points, mp) and np.array_equal(tets, mt),
       "SfePy's Mesh.from_file loads the --volume-only Medit cage into tets alone, which"
       " its FEDomain takes: the points and tets meshio reads, in order (so the"
       " embedding's tet numbers hold there)")
    for f in mshs:
        try:
            sm, sp, st = sim.read_cage_sfepy(f)
            FEDomain("domain", sm)
            good = np.array_equal(sp, points) and np.array_equal(st, tets)
            why = "points or tets differ from the cage's"
        except Exception as e:  # noqa: BLE001 - the message is the diagnostic
            good, why = False, repr(e)
        ok(good, "SfePy's Mesh.from_file and FEDomain take the --volume-only %s: the"
           " cage's points and tets" % f, why)
    if dmsh:
        import meshio
        d = meshio.read(dmsh)
        kinds = {c.type: len(c.data) for c in d.cells}
        phys = d.cell_data.get("gmsh:physical")
        tri_groups = set()
        if phys is not None:
            for c, g in zip(d.cells, phys):
                if c.type == "triangle":
                    tri_groups |= set(np.unique(g).tolist())
        ok(kinds.get("tetra") == len(tets) and kinds.get("triangle", 0) > 0
           and tri_groups == {2} and d.field_data.get("boundary", [0])[0] == 2,
           "the default %s keeps its boundary triangles in physical group 2 \"boundary\""
           " for gmsh and meshio (%s)" % (dmsh, kinds))
        try:
            from sfepy.discrete.fem import Mesh
            FEDomain("domain", Mesh.from_file(dmsh))
            print("# SfePy %s takes the default .msh too" % __import__("sfepy").__version__)
        except Exception as e:  # noqa: BLE001
            print("# SfePy refuses the default .msh, as --volume-only is for: %s" % e)
    height = np.ptp(points[:, 1])
    base = sim.base_nodes(points)
    load = 0.015
    disp, iters, conv = sim.solve_sag(points, tets, load, steps=3, mesh=smesh)
    ok(conv, "SfePy: the Neo-Hookean sag converges in 3 load steps (Newton iterations %s)" % iters)
    ok(np.abs(disp[base]).max() == 0.0, "SfePy: the %d base nodes stay where they are" % len(base))
    down = disp[:, 1].min() / height
    ok(down < -0.01 and disp[:, 1].max() < 0.1 * -disp[:, 1].min(),
       "SfePy: the body sags (lowest displacement %.3f of the height, hardly any up)" % down)
    small = 1e-5
    dsmall, _, conv2 = sim.solve_sag(points, tets, small, steps=1, mesh=smesh)
    lin = np.zeros(3 * len(points))
    lin[free] = spsolve(k, rhs * small)
    lin = lin.reshape(-1, 3)
    rel = np.linalg.norm(dsmall - lin) / np.linalg.norm(lin)
    ok(conv2 and rel < 0.01, "SfePy under a small load agrees with linear elasticity"
       " (relative difference %.1e)" % rel)
    big = np.linalg.norm(disp) / (np.linalg.norm(lin) * load / small)
    ok(abs(big - 1) > 0.01, "under the full load it does not (large deformation: %.3f of the"
       " linear answer)" % big)
    return 0


if __name__ == "__main__":
    sys.exit(main())
