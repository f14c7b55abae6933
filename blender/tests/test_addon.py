"""The Sprig add-on in Blender's background mode (docs/BLENDER.md): enables it from the source
folder, imports a tree, a shell, an organism and a solid, and checks their objects, meshes,
materials, the Z-up conversion, that changing a #define rebuilds the tree, and a small tree's
wind (shape keys and the action 'wind', equal to the module's targets and weights).

    blender -b --factory-startup --python blender/tests/test_addon.py [-- BUILD_PYTHON_FOLDER]

Exits 1 on the first failure (ctest blender_addon, label heavy)."""

import os
import sys
import time
import traceback

import addon_utils
import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if args:
    os.environ["SPRIG_PYTHONPATH"] = args[0]


def species(name):
    return os.path.join(SOURCE, "species", name)


def mesh_of(empty):
    """Every child's world-space vertex positions, stacked (N, 3), and the children."""
    children = sorted(empty.children, key=lambda o: o.name)
    points = []
    for obj in children:
        co = np.empty(len(obj.data.vertices) * 3, np.float32)
        obj.data.vertices.foreach_get("co", co)
        points.append(co.reshape(-1, 3))
    return np.concatenate(points), children


def check_species(empty, kind, parts, textured):
    """empty is named after the species, holds the expected parts, each with triangles and one material."""
    assert empty.type == "EMPTY" and empty.sprig.kind == kind, (empty.name, empty.sprig.kind)
    points, children = mesh_of(empty)
    names = sorted(o["sprig_part"] for o in children)
    assert names == sorted(parts), (empty.name, names)
    for obj in children:
        assert obj.type == "MESH" and obj.parent == empty
        assert len(obj.data.vertices) > 0 and len(obj.data.polygons) > 0, obj.name
        assert len(obj.data.materials) == 1 and obj.data.materials[0].use_nodes, obj.name
        nodes = obj.data.materials[0].node_tree.nodes
        assert "Principled BSDF" in nodes
        has_image = any(n.type == "TEX_IMAGE" and n.image and n.image.size[0] > 0 for n in nodes)
        assert has_image == textured, (obj.name, has_image)
        # the texture holds absolute colours; without one, the vertex colours give the base colour
        has_attribute = any(n.type == "ATTRIBUTE" and n.attribute_name == "Col" for n in nodes)
        assert has_attribute == (not textured and "Col" in obj.data.color_attributes), obj.name
        base = nodes["Principled BSDF"].inputs["Base Color"]
        assert base.is_linked == (has_image or has_attribute), obj.name
    return points


def evaluated(obj):
    """obj's vertex positions after its shape keys at the current frame (N, 3)."""
    eval_obj = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = eval_obj.to_mesh()
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    eval_obj.to_mesh_clear()
    return co.reshape(-1, 3)


def check_wind(tree, sprig):
    """The tree's wood and leaves carry Basis + the module's targets and share one action whose
    fcurves are the module's weights at 1 + t x fps; at keyframe k every evaluated vertex is the
    module's position plus sum of weight x displacement. Returns the parts by name."""
    parts = {p["name"]: p for p in sprig.load(tree.sprig.file).mesh(wind=(tree.sprig.wind_speed,
                                                                         tree.sprig.wind_direction))}
    objects = {o["sprig_part"]: o for o in tree.children}
    assert sorted(objects) == sorted(parts) == ["leaves", "wood"], sorted(objects)
    scene = bpy.context.scene
    fps = scene.render.fps / scene.render.fps_base
    actions = set()
    for name, obj in objects.items():
        wind, keys = parts[name]["wind"], obj.data.shape_keys
        assert keys is not None and [k.name for k in keys.key_blocks] == ["Basis"] + wind["names"], name
        action = keys.animation_data.action
        actions.add(action)
        for k, key_name in enumerate(wind["names"]):
            fcurve = action.fcurves.find('key_blocks["%s"].value' % key_name)
            assert fcurve is not None and len(fcurve.keyframe_points) == len(wind["times"]) == 601, key_name
            co = np.empty(2 * 601, np.float32)
            fcurve.keyframe_points.foreach_get("co", co)
            assert np.allclose(co[0::2], 1 + wind["times"] * fps, atol=1e-3), key_name
            assert np.array_equal(co[1::2], wind["weights"][k]), key_name
            assert fcurve.keyframe_points[7].interpolation == "LINEAR" and fcurve.modifiers[0].type == "CYCLES"
        for keyframe in (0, 45, 300):  # whole frames at 24 fps
            scene.frame_set(round(1 + wind["times"][keyframe] * fps))
            expect = parts[name]["positions"] + np.einsum("k,kvc->vc", wind["weights"][:, keyframe], wind["targets"])
            got = evaluated(obj)
            assert np.allclose(got, np.stack([expect[:, 0], -expect[:, 2], expect[:, 1]], 1), atol=2e-5), \
                (name, keyframe, np.abs(got - expect).max())
    assert len(actions) == 1 and next(iter(actions)).name.startswith("wind"), actions
    return objects


def test_wind(load, sprig):
    """A tree in its species' wind: shape keys and the action 'wind' that moves it, kept by a
    regenerate, removed with wind 0; other kinds have no wind."""
    t0 = time.time()
    tree = load(os.path.join(SOURCE, "python", "tests", "data", "tiny_windy_tree.yaml"), 0.0)
    assert tree.sprig.has_wind and (tree.sprig.wind_speed, tree.sprig.wind_direction) == (6.0, 90.0)
    objects = check_wind(tree, sprig)
    bpy.context.scene.frame_set(1)
    still = evaluated(objects["wood"])
    bpy.context.scene.frame_set(100)
    swayed = evaluated(objects["wood"])
    moved = np.abs(swayed - still).max()
    assert 0.005 < moved < 0.5, moved  # metres, at the top of a 2 m tree in 6 m/s wind
    # the Cycles modifier: a loop (20 s at 24 fps) later, the same pose
    bpy.context.scene.frame_set(100 + 20 * 24)
    assert np.allclose(evaluated(objects["wood"]), swayed, atol=1e-6)
    keys = [len(objects[name].data.shape_keys.key_blocks) for name in ("wood", "leaves")]
    bpy.context.view_layer.objects.active = tree
    assert bpy.ops.sprig.regenerate() == {"FINISHED"}
    check_wind(tree, sprig)
    assert len([a for a in bpy.data.actions if a.users]) == 1
    tree.sprig.wind_speed = 9.0  # the slider rebuilds: the same action, stronger targets
    check_wind(tree, sprig)
    assert bpy.ops.sprig.wind_frames() == {"FINISHED"}
    assert (bpy.context.scene.frame_start, bpy.context.scene.frame_end) == (1, 480)  # 20 s at 24 fps
    tree.sprig.wind_speed = 0.0
    assert all(o.data.shape_keys is None for o in tree.children)
    assert len(bpy.data.actions) == 0 and len(bpy.data.shape_keys) == 0, (list(bpy.data.actions), list(bpy.data.shape_keys))
    print("wind: %d and %d shape keys, %.3f m of sway at frame 100; %.1f s" % (keys[0], keys[1], moved,
                                                                                  time.time() - t0))


def main():
    t0 = time.time()
    sys.path.insert(0, os.path.join(SOURCE, "blender"))
    addon = addon_utils.enable("sprig_addon", default_set=True, handle_error=lambda e: (_ for _ in ()).throw(e))
    assert hasattr(bpy.types.Object, "sprig"), "the add-on did not register"
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)

    def load(name, cell):
        before = set(bpy.data.objects)
        assert bpy.ops.sprig.import_species(filepath=species(name), root="/", cell=cell) == {"FINISHED"}
        empties = [o for o in set(bpy.data.objects) - before if o.type == "EMPTY"]
        assert len(empties) == 1, empties
        return empties[0]

    # A tree at 4 of its 10 steps, coarse (cell 0.05 m): Y-up 2.8 m tall becomes Z-up.
    tree = load("abop_2_6.yaml", 0.05)
    assert tree.name == "ABOP 2.6 monopodial tree", tree.name
    assert [d.name for d in tree.sprig.defines] == ["r1", "r2", "a0", "a2", "d", "wr"]
    assert tree.sprig.max_steps == 10 and tree.sprig.steps == 10
    imported = len(mesh_of(tree)[0])
    bpy.context.view_layer.objects.active = tree
    tree.sprig.steps = 4  # the slider's update callback rebuilds
    points = check_species(tree, "tree", ["wood"], textured=True)
    assert points[:, 2].max() > 2.0 and points[:, 2].max() > points[:, 1].max() + 1.5, points.max(0)
    before = (len(points), points.max(0).copy())
    wood = tree.children[0].data.name
    # r1 (the main axis' length ratio) from 0.9 to 0.6: a shorter, smaller tree
    tree.sprig.defines["r1"].value = 0.6
    after, _ = mesh_of(tree)
    assert len(after) != before[0] or not np.allclose(after.max(0), before[1]), (len(after), before)
    assert after[:, 2].max() < before[1][2] - 0.1, (after.max(0), before[1])
    assert tree.children[0].data.name != wood and wood not in bpy.data.meshes, "the old mesh was not replaced"
    # Live off: no rebuild until Regenerate; Reset: the file's values (10 steps) again
    tree.sprig.live = False
    tree.sprig.defines["r1"].value = 0.75
    assert len(mesh_of(tree)[0]) == len(after)
    assert bpy.ops.sprig.regenerate() == {"FINISHED"}
    assert len(mesh_of(tree)[0]) not in (len(after), before[0]), len(mesh_of(tree)[0])
    tree.sprig.live = True
    assert bpy.ops.sprig.reset() == {"FINISHED"}
    assert tree.sprig.steps == 10 and abs(tree.sprig.defines["r1"].value - 0.9) < 1e-6
    assert len(mesh_of(tree)[0]) == imported, (len(mesh_of(tree)[0]), imported)
    print("tree: %d -> %d vertices, top %.2f -> %.2f m" % (before[0], len(after), before[1][2], after[:, 2].max()))

    # Sprig's renderer into an image datablock
    assert bpy.ops.sprig.render(width=48, height=40, spp=1) == {"FINISHED"}
    image = bpy.data.images["ABOP 2.6 monopodial tree (Sprig)"]
    assert tuple(image.size) == (48, 40)
    pixels = np.empty(48 * 40 * 4, np.float32)
    image.pixels.foreach_get(pixels)
    rgb = pixels.reshape(-1, 4)[:, :3]
    assert np.abs(rgb - rgb[0]).max(axis=1).max() > 0.05, "the render is one colour"

    test_wind(load, addon.sprig_module())

    shell = load("shell_cone.yaml", 2.0)
    check_species(shell, "shell", ["inside", "whorl"], textured=True)
    assert len(shell.sprig.defines) == 0 and shell.sprig.max_steps == 0
    organism = load("fig_org_05a_berry_level1.yaml", 0.0)
    check_species(organism, "organism", ["organism"], textured=False)
    solid = load("solid_layered_sphere.yaml", 0.0)
    points = check_species(solid, "solid", ["foil"], textured=False)
    # a sphere of radius 0.98, exported standing on the ground at the origin (Z up in Blender)
    assert np.allclose(points.max(0) - points.min(0), [1.96, 1.96, 1.96], atol=2e-4), points.max(0) - points.min(0)
    assert abs(points[:, 2].min()) < 1e-5 and np.allclose(points.max(0)[:2], [0.98, 0.98], atol=1e-4), points.max(0)
    for empty in (shell, organism, solid):  # no wind, no shape keys
        assert not empty.sprig.has_wind and all(o.data.shape_keys is None for o in empty.children), empty.name
    assert len([o for o in bpy.data.objects if o.type == "EMPTY"]) == 5
    assert len([o for o in bpy.data.objects if o.type == "MESH"]) == 7
    print("blender add-on test passed in %.1f s" % (time.time() - t0))


try:
    main()
except Exception:
    traceback.print_exc()
    sys.stdout.flush()
    os._exit(1)
sys.stdout.flush()
os._exit(0)
