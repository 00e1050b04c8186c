# tests/blender/test_modal.py - the add-on's interactive path: the panel's
# button invokes the operator, which meshes in a thread under a modal
# timer; Esc cancels. Needs a window (xvfb-run) and Blender's event
# simulation:
#
#   xvfb-run -a blender --factory-startup --enable-event-simulate \
#       --python test_modal.py -- ADDON BUNNY.obj
# ADDON as in test_cage.py (the zip, installed into BLENDER_USER_SCRIPTS,
# or the folder). TAP lines on stdout, numbered from 1; the last line is
# the plan. Blender quits itself when done (or after 120 s).
import os
import sys
import time

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
ADDON, BUNNY = argv[0], argv[1]

N = 0
FAILED = 0


def ok(cond, name, diag=None):
    global N, FAILED
    N += 1
    print("%sok %d - %s" % ("" if cond else "not ", N, name), flush=True)
    if not cond:
        FAILED += 1
        if diag:
            print("#   %s" % diag, flush=True)


if ADDON.endswith(".zip"):
    bpy.ops.preferences.addon_install(filepath=ADDON, overwrite=True)
else:
    sys.path.insert(0, os.path.dirname(os.path.abspath(ADDON)))
bpy.ops.preferences.addon_enable(module="souptet_cage")
import souptet_cage  # noqa: E402

V, F = [], []
for line in open(BUNNY):
    p = line.split()
    if p and p[0] == "v":
        V.append([float(x) for x in p[1:4]])
    elif p and p[0] == "f":
        F.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
me = bpy.data.meshes.new("bunny")
me.from_pydata(V, [], F)
ob = bpy.data.objects.new("bunny", me)
bpy.context.scene.collection.objects.link(ob)
ob.rotation_euler = (0.5, 0.2, -0.8)
ob.scale = (1.3, 0.7, 1.0)
bpy.context.view_layer.objects.active = ob
ob.select_set(True)


def snapshot():
    return (set(bpy.data.objects.keys()), set(bpy.data.meshes.keys()),
            [m.name for m in ob.modifiers])


def invoke(**kw):
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=win, area=area, region=region):
        return bpy.ops.object.souptet_cage('INVOKE_DEFAULT', **kw)


def finish():
    print("1..%d" % N, flush=True)
    bpy.ops.wm.quit_blender()


# A sequence of steps run from an application timer, each returning the
# seconds to wait before the next, or None when it moves on.
st = {"t0": time.monotonic()}


# The sidebar panel: the same panel in the sidebar's first tab (Item; 3.4
# cannot switch tabs from Python), drawn once the sidebar shows.
drawn = []


class PanelInItem(souptet_cage.VIEW3D_PT_souptet_cage):
    bl_idname = "VIEW3D_PT_souptet_cage_item"
    bl_category = "Item"

    def draw(self, context):
        super().draw(context)
        drawn.append(1)


bpy.utils.register_class(PanelInItem)


def steps():
    win = bpy.context.window_manager.windows[0]
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    area.spaces[0].show_region_ui = True
    area.tag_redraw()
    yield 1.0
    ok(len(drawn) > 0, "the sidebar panel draws (its settings and Make cage)")
    bpy.utils.unregister_class(PanelInItem)
    # 1. a small cage made through invoke: the modal run ends with the cage
    #    bound, and the status bar is left clean.
    r = invoke(cells=6, tries=1)
    ok(r == {'RUNNING_MODAL'}, "invoke starts a modal run", r)
    t = time.monotonic()
    while "bunny" in souptet_cage.RUNNING and time.monotonic() - t < 60:
        yield 0.2
    cage = bpy.data.objects.get("bunny_cage")
    mod = ob.modifiers.get(souptet_cage.MODIFIER_NAME)
    ok(cage is not None and mod is not None and mod.is_bound,
       "the modal run makes the cage and binds it (%.1f s)" % (time.monotonic() - t))
    # 2. a large one, cancelled with Esc: the run ends within the wait the
    #    operator allows, nothing new is left behind.
    if cage is not None:
        bpy.data.objects.remove(cage)
    if mod is not None:
        ob.modifiers.remove(mod)
    before = snapshot()
    r = invoke(cells=40, tries=1)
    ok(r == {'RUNNING_MODAL'}, "a large run starts", r)
    yield 1.0
    th = souptet_cage.RUNNING.get("bunny")
    ok(th is not None and th.is_alive(), "it is still running after 1 s")
    win = bpy.context.window_manager.windows[0]
    win.event_simulate(type='ESC', value='PRESS')
    win.event_simulate(type='ESC', value='RELEASE')
    t = time.monotonic()
    while "bunny" in souptet_cage.RUNNING and time.monotonic() - t < 30:
        yield 0.2
    waited = time.monotonic() - t
    ok("bunny" not in souptet_cage.RUNNING and waited < souptet_cage.CANCEL_WAIT + 8,
       "Esc ends the run (%.1f s)" % waited)
    ok(snapshot() == before, "a cancelled run leaves nothing behind", snapshot())
    # souptet itself stopped (the library looks at the cancel flag), not
    # only the operator letting go of it.
    t = time.monotonic()
    while th is not None and th.is_alive() and time.monotonic() - t < 5:
        yield 0.2
    ok(th is not None and not th.is_alive(),
       "souptet stopped: its thread ended %.1f s after the operator" % (time.monotonic() - t))
    yield None


gen = steps()


def tick():
    try:
        d = next(gen)
    except StopIteration:
        d = None
    except Exception as e:   # a failed step fails the test
        ok(False, "the steps ran", repr(e))
        d = None
    if d is None or time.monotonic() - st["t0"] > 120:
        finish()
        return None
    return d


bpy.app.timers.register(tick, first_interval=1.0)
