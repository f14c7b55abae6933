"""Sprig species in Blender (docs/BLENDER.md): imports a species as mesh objects built from the
`sprig` Python module's arrays, shows its grammar's #defines and its steps in a sidebar panel
(changing one rebuilds the meshes), sways a tree in its wind (shape keys and a looping action
'wind', the .glb's morph targets and animation), and renders it with Sprig's own renderer
into an image."""

bl_info = {
    "name": "Sprig",
    "author": "Sprig",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "File > Import > Sprig species; View3D > Sidebar > Sprig",
    "description": "Import procedural plants, shells, organisms and solids made by Sprig",
    "category": "Import-Export",
}

import importlib
import os
import sys

import bpy
import numpy as np
from bpy.props import (BoolProperty, CollectionProperty, FloatProperty, IntProperty, PointerProperty,
                       StringProperty)
from bpy_extras.io_utils import ImportHelper

# ---- The sprig module ------------------------------------------------------------------------


def _module_folders():
    """Where the `sprig` package may lie: the add-on preference, $SPRIG_PYTHONPATH, and the
    build folder of the checkout the add-on was enabled from (blender/sprig_addon/ -> build/python)."""
    folders = []
    addon = bpy.context.preferences.addons.get(__name__)
    if addon and addon.preferences and addon.preferences.module_folder:
        folders.append(bpy.path.abspath(addon.preferences.module_folder))
    if os.environ.get("SPRIG_PYTHONPATH"):
        folders.append(os.environ["SPRIG_PYTHONPATH"])
    folders.append(os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))),
                                "build", "python"))
    return folders


def sprig_module():
    """The `sprig` module, imported on first use from sys.path or _module_folders()."""
    try:
        return importlib.import_module("sprig")
    except ImportError:
        pass
    for folder in _module_folders():
        if os.path.isfile(os.path.join(folder, "sprig", "__init__.py")):
            sys.path.insert(0, folder)
            return importlib.import_module("sprig")
    raise ImportError("the sprig Python module is not found: set its folder (build/python) in the add-on's "
                      "preferences, or SPRIG_PYTHONPATH (docs/BLENDER.md)")


# ---- Meshes and materials --------------------------------------------------------------------


def z_up(a):
    """Sprig's Y-up (x, y, z) as Blender's Z-up (x, -z, y)."""
    return np.ascontiguousarray(np.stack([a[:, 0], -a[:, 2], a[:, 1]], axis=1), dtype=np.float32)


def build_mesh(name, part):
    """A Blender mesh of one part of Species.mesh(): Z-up positions, triangles, smooth custom
    normals, the vertex colours as colour attribute "Col", the UVs (per corner for atlases)."""
    positions, triangles = part["positions"], part["triangles"].astype(np.int32)
    nv, nt = len(positions), len(triangles)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(nv)
    mesh.vertices.foreach_set("co", z_up(positions).ravel())
    mesh.loops.add(3 * nt)
    mesh.loops.foreach_set("vertex_index", triangles.ravel())
    mesh.polygons.add(nt)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * nt, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(nt, 3, dtype=np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(nt, dtype=bool))
    if part["colors"] is not None:
        rgba = np.concatenate([part["colors"], np.ones((nv, 1), np.float32)], axis=1)
        mesh.color_attributes.new("Col", "FLOAT_COLOR", "POINT").data.foreach_set("color", rgba.ravel())
    corner_uvs = part["texture_corner_uvs"]
    if corner_uvs is None and part["uvs"] is not None:
        corner_uvs = part["uvs"][triangles]
    if corner_uvs is not None:
        mesh.uv_layers.new(name="UVMap").data.foreach_set("uv", np.ascontiguousarray(corner_uvs, np.float32).ravel())
    mesh.update()
    mesh.validate(clean_customdata=False)
    if part["normals"] is not None and len(mesh.vertices) == nv:
        mesh.use_auto_smooth = True
        mesh.normals_split_custom_set_from_vertices(z_up(part["normals"]))
    return mesh


def texture_image(name, texture):
    """A Blender image of a part's texture (H, W, 4 linear floats, top row first)."""
    height, width = texture.shape[:2]
    image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    image.pixels.foreach_set(np.ascontiguousarray(texture[::-1], np.float32).ravel())
    image.pack()
    return image


def build_material(name, part):
    """A Principled BSDF material as Sprig's glTF export makes it: roughness from the part's
    material; base colour from its texture (an Image Texture: the image holds the absolute
    colours), else from its vertex colours (an Attribute node reading "Col"), else its base colour."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    bsdf = nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*part["base_color"], 1.0)
    bsdf.inputs["Roughness"].default_value = part["roughness"]
    mat.use_backface_culling = not part["double_sided"]
    if part["texture"] is not None:
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = texture_image(name, part["texture"])
        tex.location = (-500, 0)
        links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        if part["alpha_cutoff"] is not None:
            links.new(tex.outputs["Alpha"], bsdf.inputs["Alpha"])
            mat.blend_method = "CLIP"
            mat.alpha_threshold = part["alpha_cutoff"]
    elif part["colors"] is not None:
        attribute = nodes.new("ShaderNodeAttribute")
        attribute.attribute_name = "Col"
        attribute.location = (-500, 300)
        links.new(attribute.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


# ---- Wind -----------------------------------------------------------------------------------

# Blender's keyframe interpolation enum value of 'LINEAR' (foreach_set takes the numbers).
_LINEAR = 1


def add_wind_keys(obj, part):
    """Shape keys on obj's mesh from the part's wind (Species.mesh(wind=...)): 'Basis', then one
    key per morph target with the .glb's name, each the Basis moved by its displacement, its
    slider range opened to the animation's weights. Returns whether keys were added."""
    wind = part["wind"]
    if wind is None or len(obj.data.vertices) != len(part["positions"]):
        return False
    basis = z_up(part["positions"])
    obj.shape_key_add(name="Basis", from_mix=False)
    for name, delta, weights in zip(wind["names"], wind["targets"], wind["weights"]):
        key = obj.shape_key_add(name=name, from_mix=False)
        key.slider_max = min(10.0, max(1.0, float(weights.max())))
        key.slider_min = max(-10.0, min(0.0, float(weights.min())))
        key.data.foreach_set("co", (basis + z_up(delta)).ravel())
    return True


def wind_action_of(empty):
    """The action driving the shape keys of the species' parts, or None."""
    for obj in empty.children:
        keys = obj.data.shape_keys if obj.type == "MESH" else None
        if keys and keys.animation_data and keys.animation_data.action:
            return keys.animation_data.action
    return None


def set_wind_action(scene, keyed, action):
    """The action 'wind' (action, emptied, or a new one) driving the shape keys of the objects
    keyed (object, part) pairs: one fcurve per target name, the .glb's keyframes (times, weights)
    at frame 1 + time x the scene's fps, LINEAR, repeated by a Cycles modifier so the 20 s loop
    plays forever. Without keyed objects the action is removed. Returns the action or None."""
    if not keyed:
        if action is not None and action.users == 0:
            bpy.data.actions.remove(action)
        return None
    if action is None:
        action = bpy.data.actions.new("wind")
        action.id_root = "KEY"
    for fcurve in list(action.fcurves):
        action.fcurves.remove(fcurve)
    fps = scene.render.fps / scene.render.fps_base
    curves = {}  # every part's weights of a name are the same (one rig per tree)
    for _, part in keyed:
        wind = part["wind"]
        for name, weights in zip(wind["names"], wind["weights"]):
            curves.setdefault(name, (wind["times"], weights))
    for name, (times, weights) in curves.items():
        fcurve = action.fcurves.new('key_blocks["%s"].value' % name, action_group="wind")
        fcurve.keyframe_points.add(len(times))
        co = np.stack([1.0 + times.astype(np.float64) * fps, weights], axis=1).astype(np.float32)
        fcurve.keyframe_points.foreach_set("co", co.ravel())
        fcurve.keyframe_points.foreach_set("interpolation", np.full(len(times), _LINEAR, np.int32))
        fcurve.modifiers.new("CYCLES")
        fcurve.update()
    for obj, _ in keyed:
        obj.data.shape_keys.animation_data_create().action = action
    return action


def wind_option(settings):
    """Species.mesh's wind= for the panel's values: (speed, direction), or False (no wind)."""
    if settings.has_wind and settings.wind_speed > 0:
        return (settings.wind_speed, settings.wind_direction)
    return False


# ---- Species settings and (re)building -------------------------------------------------------


class SprigDefine(bpy.types.PropertyGroup):
    """One #define of the grammar: its value (the file's at import) and the file's value."""
    value: FloatProperty(name="Value", update=lambda self, context: regenerate_owner(self.id_data))
    default: FloatProperty(name="File value")


class SprigSpecies(bpy.types.PropertyGroup):
    """What the empty of an imported species remembers: where its file is, and its parameters."""
    file: StringProperty(name="File", subtype="FILE_PATH")
    root: StringProperty(name="Root", subtype="DIR_PATH")
    kind: StringProperty(name="Kind")
    defines: CollectionProperty(type=SprigDefine)
    steps: IntProperty(name="Steps", min=0, update=lambda self, context: regenerate_owner(self.id_data))
    max_steps: IntProperty(name="File steps", min=0)
    cell: FloatProperty(name="Cell", min=0.0, default=0.0, precision=3,
                        description="Polygonization cell size (0: the species' own)",
                        update=lambda self, context: regenerate_owner(self.id_data))
    has_wind: BoolProperty(name="Has wind", default=False)
    wind_speed: FloatProperty(name="Wind", min=0.0, max=60.0, default=0.0, precision=1, unit="VELOCITY",
                              description="Wind speed in m/s (the species' own at import; 0: no wind animation)",
                              update=lambda self, context: regenerate_owner(self.id_data))
    wind_direction: FloatProperty(name="Direction", min=-360.0, max=360.0, default=0.0, precision=0,
                                  description="Azimuth the wind blows toward, degrees (0: toward Sprig's +Z, "
                                              "Blender's -Y; 90: toward +X)",
                                  update=lambda self, context: regenerate_owner(self.id_data))
    live: BoolProperty(name="Live", default=True, description="Rebuild the meshes when a parameter changes")
    building: BoolProperty(default=False)


def load_species(settings):
    """sprig.load with the panel's values: the #defines and, for trees, the steps."""
    sprig = sprig_module()
    overrides = {d.name: d.value for d in settings.defines}
    steps = settings.steps if settings.max_steps > 0 else None
    return sprig.load(settings.file, overrides=overrides, steps=steps, root=settings.root or "/")


def part_objects(empty):
    """The children of a species' empty by part name."""
    return {o["sprig_part"]: o for o in empty.children if "sprig_part" in o}


def rebuild_parts(empty, species):
    """Meshes the species and gives each part's object (made on first use) the new mesh;
    objects of parts the species no longer has are removed. A tree in wind gets its shape
    keys and the action 'wind' (set_wind_action). Returns the parts."""
    parts = species.mesh(cell=empty.sprig.cell, wind=wind_option(empty.sprig))
    action = wind_action_of(empty)
    existing = part_objects(empty)
    keyed = []
    for part in parts:
        label = "%s.%s" % (empty.name, part["name"])
        mesh = build_mesh(label, part)
        mesh.materials.append(build_material(label, part))
        obj = existing.pop(part["name"], None)
        if obj is None:
            obj = bpy.data.objects.new(label, mesh)
            obj["sprig_part"] = part["name"]
            obj.parent = empty
            for collection in empty.users_collection:
                collection.objects.link(obj)
        else:
            old = obj.data
            obj.data = mesh
            remove_mesh(old)
        if add_wind_keys(obj, part):
            keyed.append((obj, part))
    set_wind_action(bpy.context.scene, keyed, action)
    for obj in existing.values():
        old = obj.data
        bpy.data.objects.remove(obj)
        remove_mesh(old)
    return parts


def remove_mesh(mesh):
    """Removes a mesh no object uses, with its materials and their images."""
    if mesh.users:
        return
    materials = [m for m in mesh.materials if m]
    bpy.data.meshes.remove(mesh)
    for mat in materials:
        if mat.users:
            continue
        images = [n.image for n in mat.node_tree.nodes if n.type == "TEX_IMAGE" and n.image]
        bpy.data.materials.remove(mat)
        for image in images:
            if not image.users:
                bpy.data.images.remove(image)


def regenerate(empty):
    """Loads the species again with the panel's values and replaces its meshes."""
    settings = empty.sprig
    if settings.building or not settings.live or not settings.file:
        return
    settings.building = True
    try:
        rebuild_parts(empty, load_species(settings))
    finally:
        settings.building = False


def regenerate_owner(id_data):
    if isinstance(id_data, bpy.types.Object) and id_data.sprig.file:
        try:
            regenerate(id_data)
        except Exception as e:  # the old meshes stay; the error goes to the console
            print("sprig: %s" % e)


def import_species(context, path, root="/", cell=0.0):
    """An empty named after the species with one child mesh object per part. Returns the empty."""
    species = sprig_module().load(path, root=root)
    empty = bpy.data.objects.new(species.name, None)
    empty.empty_display_type = "PLAIN_AXES"
    context.collection.objects.link(empty)
    settings = empty.sprig
    settings.building = True  # setting the values below must not rebuild
    settings.file, settings.root, settings.kind, settings.cell = os.path.abspath(path), root, species.kind, cell
    for name, value in species.defines().items():
        d = settings.defines.add()
        d.name, d.value, d.default = name, value, value
    settings.max_steps = settings.steps = species.steps or 0
    settings.has_wind = species.wind is not None
    settings.wind_speed, settings.wind_direction = species.wind or (0.0, 0.0)
    settings.building = False
    rebuild_parts(empty, species)
    return empty


def species_owner(obj):
    """The species empty of obj: itself or its parent."""
    while obj is not None:
        if obj.sprig.file:
            return obj
        obj = obj.parent
    return None


# ---- Operators and panel ---------------------------------------------------------------------


class SPRIG_OT_import(bpy.types.Operator, ImportHelper):
    """Import a Sprig species file as mesh objects under an empty"""
    bl_idname = "sprig.import_species"
    bl_label = "Import Sprig species"
    bl_options = {"REGISTER", "UNDO"}
    filename_ext = ".yaml"
    filter_glob: StringProperty(default="*.yaml;*.yml;*.lsys;*.l", options={"HIDDEN"})
    root: StringProperty(name="Root", default="/", description="Referenced files must lie inside this folder")
    cell: FloatProperty(name="Cell", min=0.0, default=0.0, description="Polygonization cell size (0: the species' own)")

    def execute(self, context):
        try:
            empty = import_species(context, self.filepath, self.root, self.cell)
        except Exception as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}
        for obj in context.selected_objects:
            obj.select_set(False)
        empty.select_set(True)
        context.view_layer.objects.active = empty
        return {"FINISHED"}


class SpeciesOperator:
    """An operator on the selected species (its empty or a part): run(context, empty); an
    error of Sprig's is reported and cancels."""

    @classmethod
    def poll(cls, context):
        return species_owner(context.object) is not None

    def execute(self, context):
        try:
            return self.run(context, species_owner(context.object))
        except Exception as e:
            self.report({"ERROR"}, str(e))
            return {"CANCELLED"}


class SPRIG_OT_regenerate(SpeciesOperator, bpy.types.Operator):
    """Build the species' meshes again with the panel's values"""
    bl_idname = "sprig.regenerate"
    bl_label = "Regenerate"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context, empty):
        live = empty.sprig.live
        empty.sprig.live = True
        try:
            regenerate(empty)
        finally:
            empty.sprig.live = live
        return {"FINISHED"}


class SPRIG_OT_reset(SpeciesOperator, bpy.types.Operator):
    """Set every #define and the steps back to the file's values"""
    bl_idname = "sprig.reset"
    bl_label = "Reset to file"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context, empty):
        settings = empty.sprig
        settings.building = True
        try:
            for d in settings.defines:
                d.value = d.default
            settings.steps = settings.max_steps
        finally:
            settings.building = False
        regenerate(empty)
        return {"FINISHED"}


class SPRIG_OT_wind_frames(SpeciesOperator, bpy.types.Operator):
    """Set the scene's frame range to one loop of the wind (20 s at the scene's fps): played on
    repeat, the sway runs on without a jump"""
    bl_idname = "sprig.wind_frames"
    bl_label = "Frame range to wind loop"
    bl_options = {"REGISTER", "UNDO"}

    def run(self, context, empty):
        scene = context.scene
        fps = scene.render.fps / scene.render.fps_base
        # frame 1 is time 0; the frame after the last is time 20 s, the same pose as frame 1
        scene.frame_start, scene.frame_end = 1, round(WIND_LOOP_SECONDS * fps)
        return {"FINISHED"}


WIND_LOOP_SECONDS = 20.0  # the module's wind["loop_seconds"] (model/wind_export.h kWindLoopSeconds)


class SPRIG_OT_render(SpeciesOperator, bpy.types.Operator):
    """Render the species with Sprig's own renderer into the image "<species> (Sprig)\""""
    bl_idname = "sprig.render"
    bl_label = "Render with Sprig"
    width: IntProperty(name="Width", default=0, min=0, description="0: the species' render size")
    height: IntProperty(name="Height", default=0, min=0)
    spp: IntProperty(name="Samples", default=0, min=0, description="0: the species' own")

    def run(self, context, empty):
        pixels = load_species(empty.sprig).render(self.width or None, self.height or None, spp=self.spp or None,
                                                  linear=True)
        image = render_image(empty.name + " (Sprig)", np.asarray(pixels))
        for area in context.screen.areas if context.screen else []:
            if area.type == "IMAGE_EDITOR":
                area.spaces.active.image = image
        self.report({"INFO"}, "rendered %s: %d x %d" % (image.name, image.size[0], image.size[1]))
        return {"FINISHED"}


def render_image(name, linear_rgba):
    """The image datablock name (made or resized) holding linear RGBA pixels (H, W, 4, top row first)."""
    height, width = linear_rgba.shape[:2]
    image = bpy.data.images.get(name)
    if image is None or not image.is_float:
        image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
    elif tuple(image.size) != (width, height):
        image.scale(width, height)
    image.pixels.foreach_set(np.ascontiguousarray(linear_rgba[::-1], np.float32).ravel())
    image.update()
    return image


class SPRIG_PT_panel(bpy.types.Panel):
    """The species of the active object: its kind, #defines, steps and buttons."""
    bl_label = "Sprig"
    bl_idname = "SPRIG_PT_panel"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Sprig"

    def draw(self, context):
        layout = self.layout
        layout.operator(SPRIG_OT_import.bl_idname, icon="IMPORT")
        empty = species_owner(context.object)
        if empty is None:
            layout.label(text="Select an imported species")
            return
        settings = empty.sprig
        layout.label(text="%s (%s)" % (empty.name, settings.kind), icon="OUTLINER_OB_EMPTY")
        col = layout.column(align=True)
        if settings.max_steps > 0:
            col.prop(settings, "steps")
        for d in settings.defines:
            col.prop(d, "value", text=d.name)
        if not settings.defines and settings.max_steps == 0:
            col.label(text="No #defines: a %s has no grammar" % settings.kind)
        layout.prop(settings, "cell")
        if settings.has_wind:
            row = layout.row(align=True)
            row.prop(settings, "wind_speed")
            row.prop(settings, "wind_direction")
            layout.operator(SPRIG_OT_wind_frames.bl_idname, icon="PREVIEW_RANGE")
        row = layout.row(align=True)
        row.prop(settings, "live")
        row.operator(SPRIG_OT_regenerate.bl_idname, icon="FILE_REFRESH")
        row.operator(SPRIG_OT_reset.bl_idname, text="", icon="LOOP_BACK")
        layout.operator(SPRIG_OT_render.bl_idname, icon="RENDER_STILL")


class SprigPreferences(bpy.types.AddonPreferences):
    bl_idname = __name__
    module_folder: StringProperty(name="sprig module folder", subtype="DIR_PATH",
                                  description="The folder holding the sprig package: the build's build/python")

    def draw(self, context):
        self.layout.prop(self, "module_folder")


def menu_import(self, context):
    self.layout.operator(SPRIG_OT_import.bl_idname, text="Sprig species (.yaml)")


classes = (SprigDefine, SprigSpecies, SprigPreferences, SPRIG_OT_import, SPRIG_OT_regenerate, SPRIG_OT_reset,
           SPRIG_OT_wind_frames, SPRIG_OT_render, SPRIG_PT_panel)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Object.sprig = PointerProperty(type=SprigSpecies)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)


def unregister():
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    del bpy.types.Object.sprig
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
