# tests/blender/test_cage.py - the Blender add-on (blender/souptet_cage) on
# three soups made from the bunny, each object rotated and non-uniformly
# scaled: clean (with a twist modifier, so the evaluated mesh is what
# counts), half its faces flipped at random, and a one-sided scan (faces
# facing down deleted, a loose vertex and a loose edge added). TAP lines on
# stdout, numbered from 1 (tests/tools/blender.t renumbers them).
#
#   blender -b --factory-startup --python-exit-code 1 --python test_cage.py -- \
#       ADDON BUNNY.obj WORKDIR
# ADDON: the zip make blender-addon builds (installed into the user
# scripts directory, which the caller points at a temporary one with
# BLENDER_USER_SCRIPTS) or the add-on's folder (imported from its parent;
# then souptet must be on sys.path).
#
# The enclosure is checked here, independently of souptet: the generalized
# winding number of the closed cage (its float32 vertices as Blender stores
# them) at every world-space vertex of the object (its float32 vertices
# taken through matrix_world in double), by van Oosterom and Strackee's
# solid angles in numpy: 1 inside, 0 outside, so > 0.5 means inside.
import os
import sys
import time

import bpy
import numpy as np

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ADDON, BUNNY, WORK = argv[0], argv[1], argv[2]

N = 0
FAILED = 0


def ok(cond, name, diag=None):
    global N, FAILED
    N += 1
    print("%sok %d - %s" % ("" if cond else "not ", N, name), flush=True)
    if not cond:
        FAILED += 1
        if diag:
            for line in str(diag).splitlines():
                print("#   " + line, flush=True)
    return cond


def note(msg):
    print("# " + msg, flush=True)


# ---- the add-on ---------------------------------------------------------------

if ADDON.endswith(".zip"):
    bpy.ops.preferences.addon_install(filepath=ADDON, overwrite=True)
    where = bpy.utils.user_resource('SCRIPTS', path="addons")
    note("installed into %s" % where)
else:
    sys.path.insert(0, os.path.dirname(os.path.abspath(ADDON)))
bpy.ops.preferences.addon_enable(module="souptet_cage")
import souptet_cage  # noqa: E402

ok(souptet_cage.souptet is not None, "the add-on imports souptet",
   souptet_cage._SOUPTET_ERROR)
if souptet_cage.souptet is None:
    print("1..%d" % N)
    sys.exit(1)
note("souptet from %s" % souptet_cage.souptet.__file__)
if ADDON.endswith(".zip"):
    # The extension links libsouptet.so.0: the zip's copy is the one loaded.
    libs = {l.split()[-1] for l in open("/proc/self/maps") if "libsouptet" in l}
    here = os.path.dirname(souptet_cage.__file__)
    ok(souptet_cage.souptet.__file__.startswith(here)
       and all(x.startswith(here) for x in libs),
       "the module and libsouptet come from the zip (%s)"
       % (", ".join(sorted(os.path.basename(x) for x in libs)) or "the library linked in"),
       sorted(libs))
ok(hasattr(bpy.ops.object, "souptet_cage") and hasattr(bpy.types, "VIEW3D_PT_souptet_cage"),
   "the operator and the sidebar panel are registered")

# ---- the scene ------------------------------------------------------------------


def read_obj(path):
    V, F = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                V.append([float(x) for x in p[1:4]])
            elif p[0] == "f":
                F.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
    return np.array(V), np.array(F)


BV, BF = read_obj(BUNNY)
rng = np.random.default_rng(7)


def new_object(name, V, F, edges=()):
    me = bpy.data.meshes.new(name)
    me.from_pydata(np.asarray(V).tolist(), list(edges), np.asarray(F).tolist())
    me.update()
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def make_active(ob):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    ob.select_set(True)
    bpy.context.view_layer.objects.active = ob


def world_vertices(ob):
    """The evaluated vertices (float32 as stored) in world space, in double."""
    dg = bpy.context.evaluated_depsgraph_get()
    ev = ob.evaluated_get(dg)
    me = ev.to_mesh()
    co = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", co)
    mw = np.array(ev.matrix_world, dtype=np.float64)
    ev.to_mesh_clear()
    co = co.reshape(-1, 3).astype(np.float64)
    return co @ mw[:3, :3].T + mw[:3, 3]


def cage_arrays(cage):
    me = cage.data
    co = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", co)
    faces = [tuple(p.vertices) for p in me.polygons]
    return co.reshape(-1, 3).astype(np.float64), faces


def winding_numbers(P, C, T):
    """Generalized winding number of the closed triangle surface (C, T) at
    each point of P: sum of signed solid angles / 4 pi (van Oosterom and
    Strackee, 1983), in chunks of points."""
    A, B, Cc = C[T[:, 0]], C[T[:, 1]], C[T[:, 2]]
    out = np.empty(len(P))
    step = max(1, 2000000 // max(1, len(T)))
    for s in range(0, len(P), step):
        p = P[s:s + step, None, :]
        a, b, c = A[None] - p, B[None] - p, Cc[None] - p
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ijk,ijk->ij", a, b) * lc
               + np.einsum("ijk,ijk->ij", b, c) * la + np.einsum("ijk,ijk->ij", c, a) * lb)
        out[s:s + step] = 2.0 * np.arctan2(det, den).sum(axis=1) / (4.0 * np.pi)
    return out


def snapshot():
    return (set(bpy.data.objects.keys()), set(bpy.data.meshes.keys()),
            {o.name: [m.name for m in o.modifiers] for o in bpy.data.objects})


# The three soups, each rotated and non-uniformly scaled.
cases = []

clean = new_object("clean", BV, BF)
clean.rotation_euler = (0.4, -0.7, 1.2)
clean.scale = (1.6, 0.6, 1.1)
clean.location = (3.0, -1.0, 0.5)
tw = clean.modifiers.new("twist", 'SIMPLE_DEFORM')
tw.deform_method = 'TWIST'
tw.angle = 1.2
tw.deform_axis = 'Y'
cases.append(clean)

Fflip = BF.copy()
flip = rng.random(len(BF)) < 0.5
Fflip[flip] = Fflip[flip][:, ::-1]
flipped = new_object("flipped", BV, Fflip)
flipped.rotation_euler = (-1.0, 0.3, 2.5)
flipped.scale = (0.5, 1.4, 0.9)
flipped.location = (-2.0, 4.0, 1.0)
note("flipped %d of %d faces" % (flip.sum(), len(BF)))
cases.append(flipped)

# One-sided: the faces whose normal points down (the bunny's up is +y) go;
# a loose vertex above the ears and a loose edge beside it must be caged too.
n = np.cross(BV[BF[:, 1]] - BV[BF[:, 0]], BV[BF[:, 2]] - BV[BF[:, 0]])
keep = n[:, 1] >= 0
top = BV[:, 1].max()
Vscan = np.vstack([BV, [[0.0, top + 1.0, 0.0], [1.0, top + 0.5, 0.5], [1.5, top + 0.2, 0.8]]])
nv = len(BV)
scan = new_object("scan", Vscan, BF[keep], edges=[(nv + 1, nv + 2)])
scan.rotation_euler = (0.9, 1.9, -0.6)
scan.scale = (1.2, 0.8, 0.5)
scan.location = (0.0, 0.0, -3.0)
note("scan keeps %d of %d faces, plus a loose vertex and a loose edge" % (keep.sum(), len(BF)))
cases.append(scan)

CELLS, TRIES = 6, 1

for ob in cases:
    t0 = time.time()
    make_active(ob)
    P = world_vertices(ob)
    size = np.linalg.norm(P.max(axis=0) - P.min(axis=0))
    try:
        res = bpy.ops.object.souptet_cage(cells=CELLS, tries=TRIES, offset=0.4, bind=True)
    except RuntimeError as e:
        res = {"error: %s" % e}
    if not ok(res == {'FINISHED'}, "%s: the operator finishes" % ob.name, res):
        continue
    cage = bpy.data.objects.get(ob.name + "_cage")
    if not ok(cage is not None and cage.type == 'MESH', "%s: the cage object %s_cage exists"
              % (ob.name, ob.name)):
        continue
    ok(np.allclose(np.array(cage.matrix_world), np.eye(4), atol=0, rtol=0),
       "%s: the cage's matrix is the identity (world-space vertices)" % ob.name)
    C, faces = cage_arrays(cage)
    T = np.array(faces)
    edges = {}
    for f in faces:
        for i in range(len(f)):
            e = tuple(sorted((f[i], f[(i + 1) % len(f)])))
            edges[e] = edges.get(e, 0) + 1
    counts = np.array(list(edges.values()))
    ok(T.ndim == 2 and T.shape[1] == 3 and len(T) > 0 and np.all(counts == 2),
       "%s: the cage is closed (%d triangles, every one of %d edges in two)"
       % (ob.name, len(T), len(edges)),
       "edge counts: %s" % np.unique(counts, return_counts=True).__repr__())
    vol = np.einsum("ij,ij->i", C[T[:, 0]], np.cross(C[T[:, 1]], C[T[:, 2]])).sum() / 6.0
    ok(vol > 0, "%s: the cage is outward (signed volume %.4g > 0)" % (ob.name, vol))
    w = winding_numbers(P, C, T)
    bad = np.flatnonzero(w <= 0.5)
    ok(len(bad) == 0,
       "%s: every one of %d world-space vertices is inside the cage (winding numbers %.6f..%.6f)"
       % (ob.name, len(P), w.min(), w.max()),
       "outside: %s" % bad[:10].tolist())
    # Not a closed surface around one point only: the winding number of a
    # point far off is 0.
    far = winding_numbers(P.max(axis=0)[None] + size, C, T)[0]
    ok(abs(far) < 1e-6, "%s: a point far off has winding number 0 (%.2g)" % (ob.name, far))
    mod = ob.modifiers.get(souptet_cage.MODIFIER_NAME)
    ok(mod is not None and mod.type == 'MESH_DEFORM' and mod.object == cage and mod.is_bound,
       "%s: a Mesh Deform modifier targets the cage and is bound" % ob.name)
    ok(ob.modifiers[-1] == mod, "%s: it is last in the stack" % ob.name)
    before = world_vertices(ob)
    ok(np.abs(before - P).max() <= 1e-4 * size,
       "%s: binding leaves the mesh in place (%.2g of its size)"
       % (ob.name, np.abs(before - P).max() / size))
    d = np.array([0.3, -0.2, 0.5]) * size
    co = np.empty(3 * len(cage.data.vertices), dtype=np.float32)
    cage.data.vertices.foreach_get("co", co)
    cage.data.vertices.foreach_set("co", (co.reshape(-1, 3) + d).astype(np.float32).ravel())
    cage.data.update()
    bpy.context.view_layer.update()
    after = world_vertices(ob)
    err = np.abs(after - before - d).max()
    ok(err <= 1e-3 * size,
       "%s: moving the cage by a vector moves the deformed mesh by it (%.2g of its size)"
       % (ob.name, err / size))
    cage.data.vertices.foreach_set("co", co)
    cage.data.update()
    note("%s: %d vertices, cage %d triangles, %.1f s" % (ob.name, len(P), len(T), time.time() - t0))

# Running again replaces the cage and rebinds (no NAME_cage.001, one modifier).
make_active(clean)
ntri = len(bpy.data.objects["clean_cage"].data.polygons)
res = bpy.ops.object.souptet_cage(cells=5, tets=600, tries=1, bind=True)
mods = [m for m in clean.modifiers if m.type == 'MESH_DEFORM']
ok(res == {'FINISHED'} and "clean_cage.001" not in bpy.data.objects and len(mods) == 1
   and mods[0].is_bound and mods[0].object == bpy.data.objects["clean_cage"]
   and len(bpy.data.objects["clean_cage"].data.polygons) != ntri,
   "running again (tets=600) replaces the cage and rebinds its one modifier")
w = winding_numbers(world_vertices(clean), *[np.array(x) if i else x for i, x in
                                             enumerate(cage_arrays(bpy.data.objects["clean_cage"]))])
ok(w.min() > 0.5, "the new cage encloses the mesh (min winding number %.6f)" % w.min())

# filepath: the tet mesh and the embedding of every vertex.
make_active(flipped)
path = os.path.join(WORK, "flipped.vtu")
res = bpy.ops.object.souptet_cage(cells=CELLS, tries=TRIES, bind=False, filepath=path)
emb = os.path.join(WORK, "flipped.embed.txt")
ok(res == {'FINISHED'} and os.path.getsize(path) > 0 and os.path.exists(emb),
   "filepath writes the tet mesh and FILE.embed.txt")
try:
    import meshio
    m = meshio.read(path)
    pts = m.points
    tets = m.cells_dict["tetra"]
    e = np.loadtxt(emb)
    P = world_vertices(flipped)
    back = np.einsum("ij,ijk->ik", e[:, 1:], pts[tets[e[:, 0].astype(int)]])
    size = np.linalg.norm(P.max(axis=0) - P.min(axis=0))
    ok(len(e) == len(P) and np.abs(back - P).max() <= 1e-9 * size,
       "the embedding gives back every world-space vertex (%.2g of the size)"
       % (np.abs(back - P).max() / size))
except ImportError:
    print("ok %d - the embedding gives back every vertex # SKIP no meshio" % (N + 1))
    N += 1

# Refusals leave nothing behind.
verts_only = new_object("verts_only", BV[:50], [], edges=[(0, 1), (2, 3)])
make_active(verts_only)
before = snapshot()
try:
    res = bpy.ops.object.souptet_cage(cells=CELLS, tries=TRIES)
    msg = ""
except RuntimeError as e:
    res, msg = {'CANCELLED'}, str(e)
ok(res == {'CANCELLED'} and "no faces" in msg and snapshot() == before,
   "a vertices-and-edges-only object is refused with an error, nothing left behind", msg)

empty = bpy.data.objects.new("an_empty", None)
bpy.context.scene.collection.objects.link(empty)
make_active(empty)
before = snapshot()
try:
    res = bpy.ops.object.souptet_cage(cells=CELLS, tries=TRIES)
    msg = ""
except RuntimeError as e:
    res, msg = {'CANCELLED'}, str(e)
ok(res == {'CANCELLED'} and "not a mesh" in msg and snapshot() == before,
   "a non-mesh object (an empty) is refused, nothing left behind", msg)

# souptet refusing the parameters (cells past its 4096): its message, and
# nothing left behind.
make_active(flipped)
before = snapshot()
try:
    res = bpy.ops.object.souptet_cage(cells=5000, tries=TRIES)
    msg = ""
except RuntimeError as e:
    res, msg = {'CANCELLED'}, str(e)
ok(res == {'CANCELLED'} and "souptet:" in msg and snapshot() == before,
   "souptet.Error is reported, nothing left behind", msg)

# Cancelling, two ways; souptet stops and nothing is made: the callback
# raises once cancel is set (at its first call), and request_cancel() (what
# Esc calls) sets the run's souptet.Cancel, which the library polls itself
# (set before the run: it stops before any event).
make_active(clean)
V, F = souptet_cage.soup_of(bpy.context, clean)
for way in ("callback", "souptet.Cancel"):
    prog = souptet_cage.Progress()
    if way == "callback":
        prog.cancel = True
    else:
        prog.request_cancel()
    try:
        souptet_cage.run_mesh(V, F, CELLS, 0, TRIES, 0.4, progress=prog)
        cancelled = False
    except souptet_cage.Cancelled:
        cancelled = True
    ok(cancelled and (prog.calls >= 1 if way == "callback" else prog.handle.is_set()),
       "a cancel through the %s stops souptet (%d call)" % (way, prog.calls))

prog = souptet_cage.Progress()
souptet_cage.run_mesh(V, F, CELLS, 0, TRIES, 0.4, progress=prog)
ok(prog.calls > 0 and 0 < prog.fraction <= 1,
   "the progress callback is called (%d calls, fraction %.2f)" % (prog.calls, prog.fraction))

print("1..%d" % N, flush=True)
sys.exit(1 if FAILED else 0)
