"""Makes a Blender hair groom on the bunny and exports it as USD, as a groomer would: the bunny
imported from OBJ (Blender turns it Z up), hair curves grown from points scattered on its surface,
longer on top, combed down and back, exported with Blender's USD exporter (BasisCurves,
Z up, metres). For README pictures only (PyPI `bpy`): python make_groom.py BUNNY.obj OUT.usda."""

import random
import sys

import bpy
from mathutils import Vector

source, out = sys.argv[1], sys.argv[2]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.obj_import(filepath=source)
body = next(o for o in bpy.context.scene.objects if o.type == "MESH")
mesh = body.data
mesh.calc_loop_triangles()

random.seed(7)
triangles = list(mesh.loop_triangles)
areas = [t.area for t in triangles]
hair = bpy.data.hair_curves.new("groom")
roots = []
for _ in range(40000):
    t = random.choices(triangles, weights=areas)[0]
    a, b = random.random(), random.random()
    if a + b > 1:
        a, b = 1 - a, 1 - b
    corners = [mesh.vertices[i].co for i in t.vertices]
    root = corners[0] * (1 - a - b) + corners[1] * a + corners[2] * b
    roots.append((root, t.normal.copy()))

POINTS = 6
hair.add_curves([POINTS] * len(roots))
# The mesh keeps the OBJ's own Y-up coordinates (its object turns it Z up): comb down and back.
comb = Vector((0.0, -1.0, -0.5)).normalized()
positions = hair.position_data
for k, (root, normal) in enumerate(roots):
    # Longer on the back and top, short on the belly.
    length = 0.2 + 0.5 * max(0.0, normal.y)
    along = (normal + comb * 0.8).normalized()
    for i in range(POINTS):
        t = i / (POINTS - 1)
        # Fall a little with height: the tip droops toward the comb.
        bend = (along + comb * (0.6 * t)).normalized()
        positions[k * POINTS + i].vector = root + bend * (length * t)
hair.surface = body
groom = bpy.data.objects.new("groom", hair)
bpy.context.scene.collection.objects.link(groom)
groom.parent = body
bpy.ops.wm.usd_export(filepath=out, export_hair=True, selected_objects_only=False)
print(f"{out}: {len(roots)} curves")
