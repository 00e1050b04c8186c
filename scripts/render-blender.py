# scripts/render-blender.py - the README's picture of the Blender add-on:
# the bunny (rotated and non-uniformly scaled, like a user's object) inside
# the cage the add-on makes, as Blender renders it (Workbench), and the
# same bunny after the cage's top was pulled up and twisted: Mesh Deform
# carries the mesh along.
#
#   blender -b --factory-startup --python scripts/render-blender.py -- \
#       ADDON BUNNY.obj OUT.png
# ADDON: the zip make blender-addon builds (installed into the user
# scripts directory: point BLENDER_USER_SCRIPTS at a scratch one), or the
# add-on's folder (souptet must then be on Blender's Python path).
# Workbench needs an OpenGL context: Blender 3.4 falls back to surfaceless
# EGL without a display; where that fails, run it under xvfb-run -a.
import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

ADDON, BUNNY, OUT = sys.argv[sys.argv.index("--") + 1:][:3]
if ADDON.endswith(".zip"):
    bpy.ops.preferences.addon_install(filepath=ADDON, overwrite=True)
else:
    sys.path.insert(0, os.path.dirname(os.path.abspath(ADDON)))
bpy.ops.preferences.addon_enable(module="souptet_cage")

for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)

V, F = [], []
for line in open(BUNNY):
    p = line.split()
    if p and p[0] == "v":
        V.append([float(x) for x in p[1:4]])
    elif p and p[0] == "f":
        F.append([int(x.split("/")[0]) - 1 for x in p[1:4]])
V = np.array(V)
V -= (V.min(axis=0) + V.max(axis=0)) / 2
V /= np.abs(V).max()


def bunny(name, x):
    me = bpy.data.meshes.new(name)
    me.from_pydata(V.tolist(), [], F)
    for p in me.polygons:
        p.use_smooth = True
    ob = bpy.data.objects.new(name, me)
    bpy.context.scene.collection.objects.link(ob)
    # the bunny's up is +y: stand it on z, turn it, squash it a little
    ob.rotation_euler = (math.pi / 2, 0, math.radians(-25))
    ob.scale = (1.0, 0.85, 1.15)
    ob.location = (x, 0, 0)
    ob.color = (0.85, 0.62, 0.45, 1)
    bpy.context.view_layer.objects.active = ob
    ob.select_set(True)
    return ob


def wire(cage, color):
    """Render the cage's edges: a second object on the cage's mesh with a
    thin Wireframe modifier (not on the cage itself: Mesh Deform reads the
    cage's evaluated mesh, and the modifier changes its vertex count)."""
    ob = bpy.data.objects.new(cage.name + "_edges", cage.data)
    bpy.context.scene.collection.objects.link(ob)
    w = ob.modifiers.new("edges", 'WIREFRAME')
    w.thickness = 0.012
    w.use_relative_offset = False
    ob.color = color


rest = bunny("bunny", -1.25)
r = bpy.ops.object.souptet_cage(cells=8, tries=2, bind=False)
assert r == {'FINISHED'}, r
wire(bpy.data.objects["bunny_cage"], (0.1, 0.25, 0.6, 1))

moved = bunny("moved", 1.25)
r = bpy.ops.object.souptet_cage(cells=8, tries=2, bind=True)
assert r == {'FINISHED'}, r
cage = bpy.data.objects["moved_cage"]
# pull the cage's upper part up and twist it about the vertical
me = cage.data
co = np.empty(3 * len(me.vertices), dtype=np.float32)
me.vertices.foreach_get("co", co)
co = co.reshape(-1, 3).astype(np.float64)
c = co.mean(axis=0)
z0, z1 = co[:, 2].min(), co[:, 2].max()
t = np.clip((co[:, 2] - z0) / (z1 - z0), 0, 1) ** 2
a = 0.8 * t
x, y = co[:, 0] - c[0], co[:, 1] - c[1]
co[:, 0] = c[0] + x * np.cos(a) - y * np.sin(a)
co[:, 1] = c[1] + x * np.sin(a) + y * np.cos(a)
co[:, 2] += 0.45 * t
me.vertices.foreach_set("co", co.astype(np.float32).ravel())
me.update()
wire(cage, (0.55, 0.1, 0.1, 1))

scene = bpy.context.scene
scene.render.engine = 'BLENDER_WORKBENCH'
scene.display.shading.light = 'STUDIO'
scene.display.shading.color_type = 'OBJECT'
scene.display.shading.show_cavity = False
scene.render.resolution_x, scene.render.resolution_y = 800, 500
scene.render.resolution_percentage = 100
scene.render.film_transparent = False
scene.world = scene.world or bpy.data.worlds.new("w")
scene.display.shading.background_type = 'VIEWPORT' if hasattr(scene.display.shading, "background_type") else None
scene.render.image_settings.file_format = 'PNG'
scene.render.image_settings.color_mode = 'RGB'
scene.render.image_settings.compression = 100

cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
scene.collection.objects.link(cam)
scene.camera = cam
cam.data.type = 'ORTHO'
cam.data.ortho_scale = 5.0
target = Vector((0, 0, 0.1))
cam.location = Vector((0.6, -8.0, 2.2))
cam.rotation_euler = (target - cam.location).to_track_quat('-Z', 'Y').to_euler()
scene.render.filepath = os.path.abspath(OUT)
bpy.ops.render.render(write_still=True)
# 128 colours: a third of the bytes, no visible change (python3-pil, when
# Blender's Python has it).
try:
    from PIL import Image
    im = Image.open(OUT).convert("RGB")
    im.quantize(colors=128, method=Image.Quantize.MEDIANCUT,
                dither=Image.Dither.NONE).save(OUT, optimize=True)
except ImportError:
    pass
print("wrote", OUT, os.path.getsize(OUT), "bytes")
