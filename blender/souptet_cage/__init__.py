# souptet_cage - a Blender add-on: a coarse tetrahedral cage that provably
# encloses the active object's evaluated mesh, as a closed surface object
# NAME_cage, optionally bound to the object by a Mesh Deform modifier.
#
# The meshing is souptet's (the Python module `souptet` over libsouptet):
# the zip from `make blender-addon` carries the module and the core library
# in souptet_cage/_bundled/; without it (the add-on installed from the
# source folder) an installed `souptet` on Blender's sys.path is used.
#
# Space: the input is the object's evaluated vertices (float32, as Blender
# stores them) taken to world space in double precision; the cage object
# has the identity matrix and world-space vertices, which souptet rounds to
# float32 (float32=True) so that, as Blender stores them, they still
# enclose every input vertex. Mesh Deform relates cage and object through
# their world matrices, so the object may be rotated and scaled freely.

bl_info = {
    "name": "souptet cage",
    "author": "souptet",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar (N) > souptet",
    "description": "A closed cage that provably encloses the object (any triangle soup), "
                   "bound with Mesh Deform",
    "category": "Object",
}

import os
import sys
import threading
import time

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

MODIFIER_NAME = "souptet cage"
# Seconds the UI waits after Esc for souptet to stop before it lets go.
CANCEL_WAIT = 2.0
# Objects whose cage a modal run (invoke) is making now: name -> its thread.
RUNNING = {}


# ---- the souptet module ------------------------------------------------------

def _load_souptet():
    """The bundled module when the zip carries one, else an installed one.
    Returns (module, None) or (None, message)."""
    here = os.path.dirname(os.path.abspath(__file__))
    bundled = os.path.join(here, "_bundled")
    if os.path.isdir(os.path.join(bundled, "souptet")):
        # The core library first, by path: the extension then finds it
        # loaded (by its soname) whatever its RUNPATH says.
        lib = os.path.join(bundled, "libsouptet.so.0")
        if os.path.exists(lib):
            import ctypes
            try:
                ctypes.CDLL(lib, mode=ctypes.RTLD_GLOBAL)
            except OSError as e:
                return None, "cannot load the bundled %s: %s" % (lib, e)
        if bundled not in sys.path:
            sys.path.insert(0, bundled)
    try:
        import souptet
    except ImportError as e:
        return None, ("cannot import souptet (%s): install the add-on from the zip "
                      "`make blender-addon` builds, or put the module on Blender's "
                      "Python path" % e)
    return souptet, None


souptet, _SOUPTET_ERROR = _load_souptet()


class CageError(Exception):
    """An object this add-on refuses: reported, nothing made."""


class Cancelled(Exception):
    """Raised from the progress callback to stop souptet.mesh()."""


# ---- the input: the evaluated mesh in world space ---------------------------

def soup_of(context, obj):
    """The evaluated mesh of obj (modifiers applied) in world space:
    (V float64 (n,3), F int64 (m,3)). Vertices in no face (loose ones, and
    those of loose edges) become degenerate triangles (v, v, v) so they are
    enclosed too. Refuses what cannot be caged."""
    if obj is None:
        raise CageError("no active object")
    if obj.type != 'MESH':
        raise CageError("%s is a %s, not a mesh" % (obj.name, obj.type.lower()))
    # Our own Mesh Deform (from an earlier run) must not shape its new cage.
    ours = [m for m in obj.modifiers
            if m.type == 'MESH_DEFORM' and m.name.startswith(MODIFIER_NAME) and m.show_viewport]
    for m in ours:
        m.show_viewport = False
    try:
        depsgraph = context.evaluated_depsgraph_get()
        ev = obj.evaluated_get(depsgraph)
        me = ev.to_mesh()
        try:
            n = len(me.vertices)
            co = np.empty(3 * n, dtype=np.float32)
            me.vertices.foreach_get("co", co)
            me.calc_loop_triangles()
            t = np.empty(3 * len(me.loop_triangles), dtype=np.int32)
            me.loop_triangles.foreach_get("vertices", t)
            mw = np.array(ev.matrix_world, dtype=np.float64)
        finally:
            ev.to_mesh_clear()
    finally:
        for m in ours:
            m.show_viewport = True
    if n == 0:
        raise CageError("%s has no vertices" % obj.name)
    if len(t) == 0:
        raise CageError("%s has no faces (only vertices or edges): nothing to cage" % obj.name)
    co = co.reshape(-1, 3).astype(np.float64)
    V = co @ mw[:3, :3].T + mw[:3, 3]
    F = t.reshape(-1, 3).astype(np.int64)
    used = np.zeros(n, dtype=bool)
    used[F.ravel()] = True
    loose = np.flatnonzero(~used)
    if len(loose):
        F = np.vstack([F, np.repeat(loose[:, None], 3, axis=1)])
    if not np.all(np.isfinite(V)):
        raise CageError("%s has non-finite vertices in world space" % obj.name)
    return V, F


# ---- the meshing ------------------------------------------------------------

class Progress:
    """The progress callable given to souptet.mesh(). Its events are opaque
    here: a dict with the library's stage and that stage's fraction done is
    used when there is one, else the count of calls. The fraction shown
    grows through each new stage (half of what is left, stage by stage) and
    never goes back. request_cancel() (from any thread) sets souptet's
    own cancel flag (a souptet.Cancel given to mesh()), which the library
    polls itself: it stops within about 0.1 s of work, not at the next
    event; the callable also raises Cancelled once cancel is set."""

    def __init__(self):
        self.calls = 0
        self.fraction = 0.0
        self.stage = ""
        self.stages = 0
        self.cancel = False
        self.handle = souptet.Cancel() if souptet is not None else None
        self.on_main = None   # called with the fraction, on the main thread only

    def request_cancel(self):
        self.cancel = True
        if self.handle is not None:
            self.handle.set()

    def __call__(self, *args, **kwargs):
        self.calls += 1
        ev = args[0] if args else kwargs
        stage, f = None, None
        if isinstance(ev, dict):
            stage, f = ev.get("stage"), ev.get("fraction")
        if isinstance(stage, str) and isinstance(f, (int, float)) and 0 <= f <= 1:
            if stage != self.stage:
                self.stage = stage
                self.stages += 1
            done = 1.0 - 0.5 ** (self.stages - 1) * (1.0 - 0.5 * f)
        else:
            done = self.calls / (self.calls + 50.0)
        self.fraction = max(self.fraction, min(1.0, done))
        if self.on_main is not None and threading.current_thread() is threading.main_thread():
            self.on_main(self.fraction)
        if self.cancel:
            raise Cancelled()


def run_mesh(V, F, cells, tets, tries, offset, progress=None, filepath=""):
    """souptet.mesh() on the soup, always with float32=True: the cage as
    Blender stores it (float32) encloses every input vertex."""
    if souptet is None:
        raise CageError(_SOUPTET_ERROR)
    kw = dict(cells=int(cells), tries=int(tries), offset=float(offset),
              float32=True, progress=progress,
              cancel=progress.handle if progress is not None else None)
    if tets > 0:
        kw["tets"] = int(tets)
    try:
        r = souptet.mesh(V, F, **kw)
    except (Cancelled, souptet.Cancelled):
        raise Cancelled()
    except souptet.Error as e:
        if progress is not None and progress.cancel:
            raise Cancelled()
        raise CageError("souptet: %s" % e)
    if progress is not None and progress.cancel:
        raise Cancelled()
    if not r.encloses:
        raise CageError("souptet's mesh does not enclose the object (try more cells or tries)")
    if filepath:
        write_tetmesh(r, filepath)
    return r


def write_tetmesh(r, filepath):
    """The tet mesh (.vtu, .msh, .node, .mesh by extension) and, next to it,
    FILE.embed.txt: one line per vertex of the evaluated mesh, in Blender's
    order, 'tet b0 b1 b2 b3' (tets from 0): where each vertex lies in the
    tets, what a simulator needs to carry the surface along."""
    path = bpy.path.abspath(filepath)
    d = os.path.dirname(path)
    if d:
        os.makedirs(d, exist_ok=True)
    try:
        r.write(path)
    except Exception as e:
        # .vtu needs souptet's VTK part (souptet._io), which the zip leaves
        # out: then the points and tets as plain VTK XML.
        if not path.lower().endswith(".vtu") or isinstance(e, OSError):
            raise CageError("cannot write %s: %s" % (path, e))
        try:
            write_vtu(path, r.points, r.tets)
        except OSError as e2:
            raise CageError("cannot write %s: %s" % (path, e2))
    tet = np.asarray(r.embed_tet)
    bary = np.asarray(r.embed_bary, dtype=np.float64)
    epath = os.path.splitext(path)[0] + ".embed.txt"
    with open(epath, "w") as f:
        for t, b in zip(tet.tolist(), bary.tolist()):
            f.write("%d %r %r %r %r\n" % (t, b[0], b[1], b[2], b[3]))


def write_vtu(path, points, tets):
    """An unstructured grid of tets in VTK's XML format (ASCII, coordinates
    to 17 digits, so exact), what ParaView and meshio read."""
    import io
    P = np.asarray(points, dtype=np.float64)
    T = np.asarray(tets, dtype=np.int64)

    def arr(a, fmt):
        b = io.StringIO()
        np.savetxt(b, a, fmt=fmt)
        return b.getvalue()

    with open(path, "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="UnstructuredGrid" version="1.0" '
                'byte_order="LittleEndian" header_type="UInt64">\n<UnstructuredGrid>\n'
                '<Piece NumberOfPoints="%d" NumberOfCells="%d">\n<Points>\n'
                '<DataArray type="Float64" NumberOfComponents="3" format="ascii">\n'
                % (len(P), len(T)))
        f.write(arr(P, "%.17g"))
        f.write('</DataArray>\n</Points>\n<Cells>\n'
                '<DataArray type="Int64" Name="connectivity" format="ascii">\n')
        f.write(arr(T, "%d"))
        f.write('</DataArray>\n<DataArray type="Int64" Name="offsets" format="ascii">\n')
        f.write(arr(4 * np.arange(1, len(T) + 1), "%d"))
        f.write('</DataArray>\n<DataArray type="UInt8" Name="types" format="ascii">\n')
        f.write(arr(np.full(len(T), 10), "%d"))
        f.write('</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n')


# ---- the cage and the modifier ------------------------------------------------

def _cage_arrays(r):
    """The boundary on the points it uses: (float32 (n,3), int (k,3))."""
    B = np.asarray(r.boundary, dtype=np.int64)
    P = np.asarray(r.points, dtype=np.float64)
    used, inv = np.unique(B.ravel(), return_inverse=True)
    return P[used].astype(np.float32), inv.reshape(-1, 3)


def build_cage(context, obj, r, bind):
    """Make (or remake) object NAME_cage from r's boundary, identity matrix,
    world-space vertices; with bind, a Mesh Deform modifier on obj bound to
    it. On failure everything made here is removed again."""
    P, T = _cage_arrays(r)
    name = obj.name + "_cage"
    mesh = bpy.data.meshes.new(name)
    made_obj = None
    old_mesh = None
    made_mod = None
    cage = bpy.data.objects.get(name)
    try:
        mesh.from_pydata(P.tolist(), [], T.tolist())
        mesh.update()
        if cage is not None and cage.type == 'MESH' and cage is not obj:
            old_mesh = cage.data
            cage.data = mesh
        else:
            cage = made_obj = bpy.data.objects.new(name, mesh)
            colls = list(obj.users_collection) or [context.scene.collection]
            for c in colls:
                c.objects.link(cage)
        cage.matrix_world.identity()
        cage.display_type = 'WIRE'
        cage.hide_render = True
        if bind:
            mod = obj.modifiers.get(MODIFIER_NAME)
            if mod is not None and mod.type != 'MESH_DEFORM':
                raise CageError("%s has a modifier named %r that is not a Mesh Deform"
                                % (obj.name, MODIFIER_NAME))
            if mod is None:
                mod = made_mod = obj.modifiers.new(MODIFIER_NAME, 'MESH_DEFORM')
            mod.object = cage
            mod.show_viewport = True
            with context.temp_override(object=obj, active_object=obj):
                if mod.is_bound:       # the operator toggles: unbind first
                    bpy.ops.object.meshdeform_bind(modifier=mod.name)
                bpy.ops.object.meshdeform_bind(modifier=mod.name)
            if not mod.is_bound:
                raise CageError("the Mesh Deform modifier did not bind")
    except BaseException:
        if made_mod is not None:
            obj.modifiers.remove(made_mod)
        if made_obj is not None:
            bpy.data.objects.remove(made_obj)
        elif old_mesh is not None:
            cage.data = old_mesh
        bpy.data.meshes.remove(mesh)
        raise
    if old_mesh is not None and old_mesh.users == 0:
        bpy.data.meshes.remove(old_mesh)
    return cage


def _settings():
    """The operator's settings, also the panel's (scene.souptet_cage)."""
    return {
        "cells": IntProperty(name="Cells", default=10, min=1, soft_max=100,
                             description="Lattice cells along the object's longest side"),
        "tets": IntProperty(name="Tets", default=0, min=0,
                            description="About this many tets (0: from cells)"),
        "tries": IntProperty(name="Tries", default=4, min=1, soft_max=16,
                             description="Candidate lattices; the best is kept"),
        "offset": FloatProperty(name="Offset", default=0.4, min=0.001, max=10.0, soft_max=1.0,
                                description="How far the cage may stay from the surface, "
                                            "in cells"),
        "bind": BoolProperty(name="Bind", default=True,
                             description="Add a Mesh Deform modifier targeting the cage "
                                         "and bind it"),
        "filepath": StringProperty(name="Tet mesh", default="", subtype='FILE_PATH',
                                   description="Also write the tet mesh (.vtu, .msh, .node, "
                                               ".mesh) and its embedding (FILE.embed.txt)"),
    }


# ---- the operator -------------------------------------------------------------

class OBJECT_OT_souptet_cage(bpy.types.Operator):
    """Make a closed cage that encloses the active object's evaluated mesh
    (every vertex, in world space, as Blender stores it) and bind it with
    Mesh Deform"""
    bl_idname = "object.souptet_cage"
    bl_label = "Make cage"
    bl_options = {'REGISTER', 'UNDO'}

    __annotations__ = _settings()

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.mode == 'OBJECT'

    def _params(self):
        return dict(cells=self.cells, tets=self.tets, tries=self.tries, offset=self.offset)

    def _done(self, context, obj, r):
        try:
            cage = build_cage(context, obj, r, self.bind)
        except CageError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        msg = "%s: %d tets, cage of %d faces" % (cage.name, len(r.tets), len(r.boundary))
        if self.filepath:
            msg += ", tet mesh in %s" % bpy.path.abspath(self.filepath)
        self.report({'INFO'}, msg)
        return {'FINISHED'}

    # Scripts (and -b): blocking; the progress shows on the cursor when the
    # callback comes on this thread.
    def execute(self, context):
        obj = context.active_object
        wm = context.window_manager
        prog = Progress()
        try:
            V, F = soup_of(context, obj)
            wm.progress_begin(0, 100)
            prog.on_main = lambda f: wm.progress_update(int(100 * f))
            try:
                r = run_mesh(V, F, progress=prog, filepath=self.filepath, **self._params())
            finally:
                wm.progress_end()
        except CageError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        except Cancelled:
            self.report({'WARNING'}, "cancelled")
            return {'CANCELLED'}
        return self._done(context, obj, r)

    # The UI: souptet works in a thread (the module lets go of the GIL), a
    # timer updates the status bar, Esc cancels through the progress callback.
    def invoke(self, context, event):
        obj = context.active_object
        try:
            V, F = soup_of(context, obj)
            if souptet is None:
                raise CageError(_SOUPTET_ERROR)
        except CageError as e:
            self.report({'ERROR'}, str(e))
            return {'CANCELLED'}
        if obj.name in RUNNING:
            self.report({'ERROR'}, "the cage of %s is being made" % obj.name)
            return {'CANCELLED'}
        self._obj_name = obj.name
        self._progress = Progress()
        self._result = None
        self._error = None
        params = self._params()
        filepath = self.filepath

        def work():
            try:
                self._result = run_mesh(V, F, progress=self._progress,
                                        filepath=filepath, **params)
            except BaseException as e:   # handed to the main thread
                self._error = e

        self._cancel_time = 0.0
        self._thread = threading.Thread(target=work, name="souptet", daemon=True)
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        if context.workspace is not None:
            context.workspace.status_text_set("souptet: making the cage of %s (Esc cancels)"
                                              % obj.name)
        self._thread.start()
        RUNNING[obj.name] = self._thread
        return {'RUNNING_MODAL'}

    def _finish(self, context):
        RUNNING.pop(self._obj_name, None)
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def modal(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            if not self._progress.cancel:
                self._progress.request_cancel()
                self._cancel_time = time.monotonic()
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            # Input waits for the cage (views may still move); TIMER events
            # pass on below: others' timers must reach them.
            if event.type in {'MOUSEMOVE', 'INBETWEEN_MOUSEMOVE', 'MIDDLEMOUSE',
                              'WHEELUPMOUSE', 'WHEELDOWNMOUSE', 'TRACKPADPAN',
                              'TRACKPADZOOM'}:
                return {'PASS_THROUGH'}
            return {'RUNNING_MODAL'}
        context.window_manager.progress_update(int(100 * self._progress.fraction))
        if context.workspace is not None:
            context.workspace.status_text_set(
                "souptet: the cage of %s, %s %d%% (%s)"
                % (self._obj_name, self._progress.stage or "starting",
                   int(100 * self._progress.fraction),
                   "cancelling" if self._progress.cancel else "Esc cancels"))
        if self._thread.is_alive():
            if not (self._progress.cancel and
                    time.monotonic() - self._cancel_time > CANCEL_WAIT):
                return {'PASS_THROUGH'}
            # souptet has not stopped yet (a stage that does not look at
            # the cancel flag): let the thread run out on its own; what it
            # makes is dropped (run_mesh sees the flag and raises).
            self._finish(context)
            self.report({'WARNING'}, "cancelled (souptet finishes its current stage "
                                     "in the background; its result is dropped)")
            return {'CANCELLED'}
        self._finish(context)
        err = self._error
        if isinstance(err, Cancelled) or (err is not None and self._progress.cancel):
            self.report({'WARNING'}, "cancelled")
            return {'CANCELLED'}
        if isinstance(err, CageError):
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        if err is not None:
            self.report({'ERROR'}, "souptet failed: %s: %s" % (type(err).__name__, err))
            return {'CANCELLED'}
        obj = bpy.data.objects.get(self._obj_name)
        if obj is None:
            self.report({'ERROR'}, "the object went away while its cage was made")
            return {'CANCELLED'}
        return self._done(context, obj, self._result)


# ---- the panel ----------------------------------------------------------------

class SouptetCageSettings(bpy.types.PropertyGroup):
    __annotations__ = _settings()


class VIEW3D_PT_souptet_cage(bpy.types.Panel):
    bl_label = "souptet cage"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "souptet"

    def draw(self, context):
        layout = self.layout
        s = context.scene.souptet_cage
        if souptet is None:
            layout.label(text="souptet module missing", icon='ERROR')
        col = layout.column(align=True)
        col.prop(s, "cells")
        col.prop(s, "tets")
        col.prop(s, "tries")
        col.prop(s, "offset")
        layout.prop(s, "bind")
        layout.label(text="Tet mesh to write (optional):")
        layout.prop(s, "filepath", text="")
        obj = context.active_object
        row = layout.row()
        row.enabled = obj is not None and obj.type == 'MESH'
        op = row.operator(OBJECT_OT_souptet_cage.bl_idname, text="Make cage", icon='MOD_MESHDEFORM')
        for k in ("cells", "tets", "tries", "offset", "bind", "filepath"):
            setattr(op, k, getattr(s, k))


_classes = (OBJECT_OT_souptet_cage, SouptetCageSettings, VIEW3D_PT_souptet_cage)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.souptet_cage = PointerProperty(type=SouptetCageSettings)


def unregister():
    del bpy.types.Scene.souptet_cage
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
