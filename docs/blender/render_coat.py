"""Renders a `pelt export ... -o coat.usda` in Blender with Cycles on the CPU: the strands as hair
curves coloured by their displayColor, the mesh plain. For README pictures only (PyPI `bpy`):
python render_coat.py COAT.usda OUT.png [azimuth_deg elevation_deg]."""

import math
import sys

import bpy
from mathutils import Vector

coat, out = sys.argv[1], sys.argv[2]
azimuth = math.radians(float(sys.argv[3]) if len(sys.argv) > 3 else 30.0)
elevation = math.radians(float(sys.argv[4]) if len(sys.argv) > 4 else 15.0)

bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.wm.usd_import(filepath=coat)
scene = bpy.context.scene

hair = bpy.data.materials.new("strands")
hair.use_nodes = True
nodes, links = hair.node_tree.nodes, hair.node_tree.links
shader = nodes["Principled BSDF"]
attribute = nodes.new("ShaderNodeAttribute")
attribute.attribute_name = "displayColor"
links.new(attribute.outputs["Color"], shader.inputs["Base Color"])
shader.inputs["Roughness"].default_value = 0.5
skin = bpy.data.materials.new("skin")
skin.use_nodes = True
skin.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.62, 0.46, 0.38, 1.0)

low, high = Vector((1e9, 1e9, 1e9)), Vector((-1e9, -1e9, -1e9))
for obj in scene.objects:
    if obj.type == "CURVES":
        obj.data.materials.append(hair)
        if "displayColor" not in obj.data.attributes:
            # No colours in the file: Pelt's default fur colour (#8a5a36, linear).
            links.remove(shader.inputs["Base Color"].links[0])
            shader.inputs["Base Color"].default_value = (0.254, 0.102, 0.036, 1.0)
    elif obj.type == "MESH":
        obj.data.materials.append(skin)
        for corner in obj.bound_box:
            p = obj.matrix_world @ Vector(corner)
            low = Vector(map(min, low, p))
            high = Vector(map(max, high, p))
centre, radius = (low + high) / 2, (high - low).length / 2

camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(camera)
scene.camera = camera
camera.data.lens = 50
distance = radius * 2.8
# Blender is Z up; azimuth about Z from the front (-Y looking at +Y, as pelt's default framing).
camera.location = centre + distance * Vector(
    (math.sin(azimuth) * math.cos(elevation), -math.cos(azimuth) * math.cos(elevation), math.sin(elevation))
)
camera.rotation_euler = (centre - camera.location).to_track_quat("-Z", "Y").to_euler()

sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 3.0
sun.rotation_euler = (math.radians(40), 0, math.radians(30))
scene.collection.objects.link(sun)
world = bpy.data.worlds.new("world")
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.6, 0.65, 0.7, 1.0)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 24
scene.cycles.use_denoising = False
scene.render.resolution_x, scene.render.resolution_y = 480, 360
scene.render.filepath = out
bpy.ops.render.render(write_still=True)
print(f"{out}: rendered {coat}")
