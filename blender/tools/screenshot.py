"""The picture of docs/BLENDER.md: Blender's window with the Sprig panel beside a tree rebuilt
with changed values. Needs a display; headless, under Xvfb:

    xvfb-run -s "-screen 0 1280x760x24" blender --factory-startup --window-geometry 0 0 1280 760 \
        --enable-event-simulate \
        --python blender/tools/screenshot.py -- build/python docs/images/blender_addon.png

It keeps the 3D view with its sidebar, scaled to 80%."""

import math
import os
import sys

import addon_utils
import bpy
import numpy as np
from mathutils import Euler

SOURCE = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
module_folder, out = sys.argv[sys.argv.index("--") + 1:][:2]
os.environ["SPRIG_PYTHONPATH"] = module_folder
sys.path.insert(0, os.path.join(SOURCE, "blender"))
addon_utils.enable("sprig_addon", default_set=True)
bpy.context.preferences.view.show_splash = False
for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
bpy.ops.sprig.import_species(filepath=os.path.join(SOURCE, "species", "abop_2_6.yaml"), root="/", cell=0.02)
tree = bpy.context.view_layer.objects.active
tree.sprig.steps = 8
next(d for d in tree.sprig.defines if d.name == "a0").value = 60.0  # wider branching than the file's 45


def arrange():
    for area in bpy.context.screen.areas:
        if area.type == "VIEW_3D":
            space = area.spaces.active
            space.show_region_ui = True
            space.shading.type = "MATERIAL"
            space.overlay.show_floor = True
            r3d = space.region_3d
            r3d.view_perspective = "PERSP"
            r3d.view_location = (0.4, 0.0, 1.45)
            r3d.view_rotation = Euler((math.radians(80), 0, math.radians(25))).to_quaternion()
            r3d.view_distance = 6.2
    return None


def click_sprig_tab():
    """Blender 3.4 cannot choose a sidebar tab from Python: click the "Sprig" tab (simulated
    events, hence --enable-event-simulate)."""
    window = bpy.context.window_manager.windows[0]
    for area in window.screen.areas:
        if area.type == "VIEW_3D":
            ui = next(r for r in area.regions if r.type == "UI")
            x, y = ui.x + ui.width - 10, ui.y + ui.height - 175
            window.event_simulate(type="MOUSEMOVE", value="NOTHING", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="PRESS", x=x, y=y)
            window.event_simulate(type="LEFTMOUSE", value="RELEASE", x=x, y=y)
    return None


def shoot():
    full = out + ".full.png"
    with bpy.context.temp_override(window=bpy.context.window_manager.windows[0]):
        bpy.ops.screen.screenshot(filepath=full)
    shrink(full, out)
    os.remove(full)
    bpy.ops.wm.quit_blender()
    return None


def shrink(path, out, width=1060, height=700, scale=0.8):
    """The top-left width x height of the screenshot (the 3D view and its sidebar), scaled, as RGB PNG."""
    image = bpy.data.images.load(path)
    w, h = image.size
    pixels = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(pixels)
    crop = pixels.reshape(h, w, 4)[h - height:, :width]  # Blender's rows run bottom to top
    small = bpy.data.images.new("shot", width, height)
    small.pixels.foreach_set(np.ascontiguousarray(crop).ravel())
    small.scale(int(width * scale), int(height * scale))
    settings = bpy.context.scene.render.image_settings
    settings.file_format, settings.color_mode, settings.compression = "PNG", "RGB", 100
    small.save_render(out)


bpy.app.timers.register(arrange, first_interval=0.5)
bpy.app.timers.register(click_sprig_tab, first_interval=2.0)
bpy.app.timers.register(shoot, first_interval=20.0)
