"""Imports a .glb into Blender 3.4 (background) and renders it with Cycles from a camera that
frames the model, for docs/MESHES.md "Levels of detail" (looking at a level of detail).

Usage: blender -b --factory-startup --python scripts/blender-lod-render.py -- IN.glb OUT.png [SIZE] [SAMPLES] [SHADING]

SHADING is the importer's `import_shading`: SMOOTH (the default: Blender's own smooth
normals over the merged vertices; the file's normals are not read) or NORMALS (the file's
normals as custom split normals, so crease splits stay sharp; Debian's importer needs
numpy's old `np.bool` alias for it, which this script puts back). Both merge vertices
(`merge_vertices=True`): an atlas part has one vertex per corner, which unmerged would
shade flat under SMOOTH and stay in loose triangles under NORMALS.

Prints `import: S s (CPU C s, load L), N triangles, peak M MB` (the import's wall time, its
CPU time, the one-minute load average after it, the triangles Blender holds, Blender's peak
resident memory after the import): a wall time far above the CPU time means the machine
was busy, not that the file is slow (docs/BLENDER.md "Importing Sprig's glb"). The camera
looks at the bounding box's centre from the front-left and slightly above (the same for
every level of one model, since the levels share their bounds within a few per cent); a
sun and a grey sky light it.
"""
import math
import os
import resource
import sys
import time

import bpy
from mathutils import Vector

args = sys.argv[sys.argv.index("--") + 1:]
src, dst = args[0], args[1]
size = int(args[2]) if len(args) > 2 else 480
samples = int(args[3]) if len(args) > 3 else 16
shading = args[4] if len(args) > 4 else 'SMOOTH'
if shading == 'NORMALS':
    import numpy
    if 'bool' not in numpy.__dict__:
        numpy.bool = bool  # Blender 3.4's importer names np.bool, removed in numpy 1.24

bpy.ops.wm.read_factory_settings(use_empty=True)
t0, c0 = time.time(), time.process_time()
bpy.ops.import_scene.gltf(filepath=src, import_shading=shading, merge_vertices=True)
seconds, cpu = time.time() - t0, time.process_time() - c0
meshes = [o for o in bpy.context.scene.objects if o.type == 'MESH']
triangles = sum(sum(len(p.vertices) - 2 for p in o.data.polygons) for o in meshes)
peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
print("import: %.2f s (CPU %.2f s, load %.1f), %d triangles, peak %.0f MB" %
      (seconds, cpu, os.getloadavg()[0], triangles, peak))

lo = Vector((math.inf,) * 3)
hi = Vector((-math.inf,) * 3)
for o in meshes:
    for c in o.bound_box:
        w = o.matrix_world @ Vector(c)
        lo = Vector(map(min, lo, w))
        hi = Vector(map(max, hi, w))
centre = (lo + hi) / 2
radius = (hi - lo).length / 2
scene = bpy.context.scene
cam = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
scene.collection.objects.link(cam)
cam.data.lens = 50
direction = Vector((-0.6, -0.8, 0.25)).normalized()
cam.location = centre + direction * radius * 2.9
cam.rotation_euler = (centre - cam.location).to_track_quat('-Z', 'Y').to_euler()
scene.camera = cam
sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", 'SUN'))
sun.data.energy = 3.0
sun.rotation_euler = (math.radians(40), 0, math.radians(-30))
scene.collection.objects.link(sun)
world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (0.75, 0.8, 0.9, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 0.8
scene.world = world
scene.render.engine = 'CYCLES'
scene.cycles.samples = samples
scene.cycles.device = 'CPU'
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
scene.render.resolution_x = scene.render.resolution_y = size
scene.render.filepath = dst
t0 = time.time()
bpy.ops.render.render(write_still=True)
print("render: %.1f s" % (time.time() - t0))
