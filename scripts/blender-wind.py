"""Checks that Blender imports a tree's wind (docs/MESHES.md "Wind") and renders frames of it.

    blender -b --python scripts/blender-wind.py -- TREE.glb [OUT_PREFIX [SECONDS ...]]

Imports TREE.glb with Blender's own glTF importer (import_shading='SMOOTH', which Debian's
Blender 3.4 needs), asserts that every part with morph targets has its shape keys (`static`,
`gust`, `sway_M_sin`, ...) driven by an action from the animation 'wind', prints them, and,
given OUT_PREFIX, renders the scene at each of SECONDS (default 0, 2.5, 5, 7.5) with
Workbench, 320 x 320, from a camera looking along glTF's -Z, to OUT_PREFIX_<seconds>.png,
and the still tree (every shape key at 0) to OUT_PREFIX_still.png.
Exits 1 when there is no shape key or no action."""
import math
import os
import sys

import bpy

args = sys.argv[sys.argv.index("--") + 1:]
glb = os.path.abspath(args[0])
prefix = os.path.abspath(args[1]) if len(args) > 1 else None
times = [float(t) for t in args[2:]] or [0.0, 2.5, 5.0, 7.5]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=glb, import_shading='SMOOTH')
scene = bpy.context.scene
fps = scene.render.fps

swaying = 0
for obj in scene.objects:
    keys = obj.data.shape_keys if obj.type == "MESH" else None
    if not keys:
        continue
    action = keys.animation_data.action if keys.animation_data else None
    names = [k.name for k in keys.key_blocks]
    print(f"wind: {obj.name}: {len(names) - 1} shape keys {names[1:]}, action {action.name if action else None}, "
          f"frames {tuple(action.frame_range) if action else None}")
    if action is None or len(names) < 2:
        sys.exit(1)
    swaying += 1
if swaying == 0:
    print("wind: no part has shape keys")
    sys.exit(1)

if prefix:
    lo = [min(v[k] for o in scene.objects if o.type == "MESH" for v in o.bound_box) for k in range(3)]
    hi = [max(v[k] for o in scene.objects if o.type == "MESH" for v in o.bound_box) for k in range(3)]
    size = max(hi[k] - lo[k] for k in range(3))
    centre = [(lo[k] + hi[k]) / 2 for k in range(3)]
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = size * 1.15
    camera.location = (centre[0], centre[1] - 4 * size, centre[2])  # Blender's -Y: glTF's +Z
    camera.rotation_euler = (math.radians(90), 0, 0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.display.shading.color_type = "MATERIAL"
    scene.render.resolution_x = scene.render.resolution_y = 320
    for t in times:
        scene.frame_set(round(t * fps))  # the importer keys glTF time t at frame t * fps
        scene.render.filepath = f"{prefix}_{t:g}.png"
        bpy.ops.render.render(write_still=True)
    # The still tree: the actions unlinked, every shape key at 0.
    for obj in scene.objects:
        keys = obj.data.shape_keys if obj.type == "MESH" else None
        if keys:
            keys.animation_data.action = None
            for k in keys.key_blocks:
                k.value = 0.0
    scene.render.filepath = f"{prefix}_still.png"
    bpy.ops.render.render(write_still=True)
