"""Renders the tutorial's glb as Blender's own glTF importer reads it (Cycles on the CPU).

    blender -b --python docs/tutorial/blender_render.py -- out/sapling.glb out/sapling-blender.png

A ground plane, a sun, a sky-blue world and a camera are added around the imported parts
`wood` and `leaves`; 24 samples at 480 x 480 take about 20 s on two cores. Debian's
Blender 3.4 needs import_shading='SMOOTH' (its default fails on a glb with normals) and has
no denoiser."""
import math
import os
import sys

import bpy

glb, png = (os.path.abspath(p) for p in sys.argv[sys.argv.index("--") + 1:][:2])
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb, import_shading='SMOOTH')
scene = bpy.context.scene

bpy.ops.mesh.primitive_plane_add(size=30)
ground = bpy.data.materials.new("ground")
ground.use_nodes = True
ground.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.45, 0.42, 0.37, 1)
bpy.context.active_object.data.materials.append(ground)

camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
camera.location = (7.5, -9.5, 3.4)
camera.rotation_euler = (math.radians(82), 0, math.radians(38))
scene.collection.objects.link(camera)
scene.camera = camera

sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
sun.data.energy = 4
sun.rotation_euler = (math.radians(40), 0, math.radians(-40))
scene.collection.objects.link(sun)

world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.6, 0.7, 0.85, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 0.8
scene.world = world

scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 24
scene.cycles.use_denoising = False
scene.render.resolution_x = scene.render.resolution_y = 480
scene.render.filepath = png
bpy.ops.render.render(write_still=True)
