"""The Python module against the `sprig` command: the same species and options give the
same pixels, bytes and strings."""

import os
import signal
import threading
import time

import numpy as np
import pytest

import sprig
from conftest import BAD, TREE, WINDY, Glb, read_png, run_sprig


@pytest.fixture(scope="module")
def tree():
    return sprig.load(TREE)


def test_load_reports_the_species(tree):
    assert (tree.name, tree.kind, tree.has_surface) == ("tiny_tree", "tree", True)
    assert tree.render_size == (96, 128)
    assert tree.check() == []
    assert tree.summary() == "tree species 'tiny_tree', 1 productions, 2 steps, BlobTree surface"


def test_bad_file_raises_input_error_with_its_location():
    with pytest.raises(sprig.InputError) as info:
        sprig.load(BAD)
    e = info.value
    assert (e.file, e.line, e.column, e.severity) == (BAD, 8, 3, "error")
    assert e.message == "unknown key 'angel' in turtle (did you mean 'angle'?)"
    assert len(e.diagnostics) == 1 and str(e).startswith(BAD + ":8:3: error: unknown key 'angel'")
    [d] = sprig.check(BAD)
    assert (d.file, d.line, d.column, d.severity, d.message) == (e.file, e.line, e.column, e.severity, e.message)


def test_derive_equals_the_command(tree):
    d = tree.derive()
    assert d["string"] + "\n" == run_sprig("derive", "--print", TREE).decode()
    assert d["steps"] == 2
    # 1 trunk + 2 forks + 4 twigs, each a child of the one before its bracket.
    assert d["starts"].shape == (7, 3) and d["ends"].shape == (7, 3)
    assert list(d["parents"]) == [-1, 0, 1, 1, 0, 4, 4]
    assert list(d["orders"]) == [0, 1, 2, 2, 1, 2, 2]
    np.testing.assert_allclose(np.linalg.norm(d["ends"] - d["starts"], axis=1), [1, .7, .7, .7, .7, .7, .7], rtol=1e-6)
    assert d["string"].count("A") == 4 and tree.derive(stage=0)["string"] == "!(0.2)F(1)A"


def test_overrides_are_the_commands_defines_and_steps():
    s = sprig.load(TREE, overrides={"LEN": 2.5}, steps=1)
    expected = run_sprig("derive", "--print", "-D", "LEN=2.5", "--steps", "1", TREE).decode()
    assert s.derive()["string"] + "\n" == expected
    assert s.derive()["string"].startswith("!(0.2)F(2.5)[+(35)!(0.12)F(1.75)A]")
    with pytest.raises(sprig.InputError, match="NOPE"):
        sprig.load(TREE, overrides={"NOPE": 1})


def test_defines_and_steps_are_the_grammars_after_overrides(tree):
    assert tree.defines() == {"LEN": 1.0} and tree.steps == 2
    other = sprig.load(TREE, overrides={"LEN": 2.5}, steps=1)
    assert other.defines() == {"LEN": 2.5} and other.steps == 1
    assert list(sprig.load("species/abop_2_6.yaml").defines()) == ["r1", "r2", "a0", "a2", "d", "wr"]
    shell = sprig.load("species/shell_cone.yaml")
    assert shell.defines() == {} and shell.steps is None


def test_render_equals_the_commands_png(tree, tmp_path):
    image = tree.render()
    assert isinstance(image, sprig.Image) and image.shape == (128, 96, 4) and image.dtype == np.uint8
    run_sprig("render", TREE, "-o", str(tmp_path / "cli.png"))
    assert np.array_equal(image, read_png(tmp_path / "cli.png"))
    assert 0 < (image[..., :3].std(axis=(0, 1))).min()  # not one flat colour
    # Options: size, samples, stage, view; and _repr_png_ encodes the same pixels.
    small = tree.render(48, 64, spp=1, stage=1, view=(90, 0))
    run_sprig("render", TREE, "-o", str(tmp_path / "small.png"), "--width", "48", "--height", "64", "--spp", "1",
              "--stage", "1", "--view", "90,0")
    assert np.array_equal(small, read_png(tmp_path / "small.png"))
    (tmp_path / "repr.png").write_bytes(small._repr_png_())
    assert np.array_equal(read_png(tmp_path / "repr.png"), small)
    assert tree.render(48, 64, spp=1, alpha=False).shape == (64, 48, 3)


def test_mesh_parts_and_export_equal_the_command(tree, tmp_path):
    [wood] = tree.mesh()
    assert wood["name"] == "wood"
    n, m = len(wood["positions"]), len(wood["triangles"])
    assert wood["positions"].shape == (n, 3) and wood["positions"].dtype == np.float32
    assert wood["triangles"].shape == (m, 3) and wood["triangles"].dtype == np.uint32
    assert wood["normals"].shape == (n, 3) and int(wood["triangles"].max()) == n - 1
    # A closed surface: every edge is used twice, once in each direction.
    t = wood["triangles"].astype(np.int64)
    edges = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    assert len(np.unique(edges, axis=0)) == len(edges) == 3 * m
    assert len(np.unique(np.sort(edges, axis=1), axis=0)) * 2 == len(edges)
    for ext in ("glb", "ply"):
        tree.export(tmp_path / ("py." + ext))
        run_sprig("mesh", TREE, "-o", str(tmp_path / ("cli." + ext)))
        assert (tmp_path / ("py." + ext)).read_bytes() == (tmp_path / ("cli." + ext)).read_bytes()
    # OBJ names its MTL file: the same name in two folders.
    (tmp_path / "py").mkdir()
    (tmp_path / "cli").mkdir()
    tree.export(tmp_path / "py" / "cell.obj", cell=0.05)
    run_sprig("mesh", TREE, "-o", str(tmp_path / "cli" / "cell.obj"), "--cell", "0.05")
    for name in ("cell.obj", "cell.mtl"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()
    coarse = tree.mesh(cell=0.05)[0]
    assert 0 < len(coarse["triangles"]) < m


def test_animate_frames_equal_the_commands(tree, tmp_path):
    frames = tree.animate(frames_per_stage=2, stages=(1, 2), width=32, height=40, samples=1)
    # Step 1 grown, then step 2's new modules at 1/2 and at full size.
    assert len(frames) == 3 and frames.size == (32, 40)
    images = list(frames)
    run_sprig("animate", TREE, "-o", str(tmp_path / "frames"), "--frames-per-stage", "2", "--stages", "1..2",
              "--width", "32", "--height", "40", "--samples", "1")
    names = sorted(os.listdir(tmp_path / "frames"))
    assert names == ["frame_%05d.png" % i for i in range(3)]
    for image, name in zip(images, names):
        assert image.shape == (40, 32, 4)
        assert np.array_equal(image, read_png(tmp_path / "frames" / name))


def test_progress_callback_and_interrupt(tree):
    seen = []
    tree.render(48, 64, spp=1, progress=lambda label, done, total: seen.append((label, done, total)))
    assert seen and seen[-1] == ("render tiny_tree", seen[-1][2], seen[-1][2]) and seen[-1][2] > 0

    def stop(label, done, total):
        raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        tree.render(400, 400, spp=16, progress=stop)
    # Ctrl-C while rendering (sent 50 ms after the first tiles are done): the render stops with
    # KeyboardInterrupt, long before its 64 million rays are cast, and the next call works.
    timer = threading.Timer(0.05, lambda: os.kill(os.getpid(), signal.SIGINT))

    def interrupt_soon(label, done, total):
        if not timer.is_alive() and not timer.finished.is_set():
            timer.start()

    start = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        tree.render(2000, 2000, spp=16, progress=interrupt_soon)
    timer.join()
    assert timer.finished.is_set() and time.monotonic() - start < 5
    assert tree.render(48, 64, spp=1).shape == (64, 48, 4)


def test_bad_options_are_value_errors(tree):
    with pytest.raises(ValueError, match="--mode fast: expected exact, mesh or skeleton"):
        tree.render(mode="fast")
    with pytest.raises(ValueError):
        tree.render(stage=7)
    with pytest.raises(ValueError, match="unknown mesh extension"):
        tree.export("x.stl")


def test_mesh_wind_equals_the_glbs_morph_targets_and_animation(tmp_path):
    windy = sprig.load(WINDY)
    assert windy.wind == (6.0, 90.0) and sprig.load(TREE).wind == (0.0, 0.0)
    parts = {p["name"]: p for p in windy.mesh(wind=True)}
    assert sorted(parts) == ["leaves", "wood"]
    # The module's .glb (the species' wind) is the command's with --wind 6,90.
    windy.export(tmp_path / "py.glb")
    run_sprig("mesh", WINDY, "-o", str(tmp_path / "cli.glb"), "--wind", "6,90")
    assert (tmp_path / "py.glb").read_bytes() == (tmp_path / "cli.glb").read_bytes()
    glb = Glb(tmp_path / "py.glb")
    [anim] = [a for a in glb.json["animations"] if a["name"] == "wind"]
    assert len(anim["channels"]) == 2
    for channel in anim["channels"]:
        assert channel["target"]["path"] == "weights"
        node = glb.json["nodes"][channel["target"]["node"]]
        mesh = glb.json["meshes"][node["mesh"]]
        part, names = parts[node["name"]], mesh["extras"]["targetNames"]
        wind, n = part["wind"], len(part["positions"])
        assert wind["animation"] == "wind" and wind["loop_seconds"] == 20.0
        # the wood has no flutter: 10 targets (static, gust, 4 sways); the leaves 12
        assert wind["names"] == names and len(names) == (10 if node["name"] == "wood" else 12), names
        assert wind["targets"].shape == (len(names), n, 3) and wind["targets"].dtype == np.float32
        assert part["wind_attribute"].shape == (n, 4)
        sampler = anim["samplers"][channel["sampler"]]
        times = glb.accessor(sampler["input"])
        assert len(times) == 601 and times[-1] == 20.0
        assert np.array_equal(wind["times"], times)
        assert np.array_equal(wind["weights"], glb.accessor(sampler["output"]).reshape(len(times), len(names)).T)
        assert np.array_equal(wind["weights"][0], np.ones(601, np.float32))  # static
        # Every glTF vertex moves as the part's vertex at its position (the .glb splits
        # vertices at creases; LOD0 is the whole mesh here).
        [prim] = mesh["primitives"]
        where = {p.tobytes(): i for i, p in enumerate(part["positions"])}
        index = np.array([where[p.tobytes()] for p in glb.accessor(prim["attributes"]["POSITION"])])
        for k, target in enumerate(prim["targets"]):
            assert np.array_equal(glb.accessor(target["POSITION"]), wind["targets"][k][index]), names[k]
        assert np.abs(wind["targets"]).max() > 0.01
    # No wind asked, wind 0, a kind without wind: no targets; a speed for a shell is an error.
    assert all(p["wind"] is None and p["wind_attribute"] is None for p in windy.mesh())
    assert all(p["wind"] is None and p["wind_attribute"] is not None for p in windy.mesh(wind=0))
    stronger = {p["name"]: p["wind"] for p in windy.mesh(wind=(12, 90))}
    assert np.abs(stronger["wood"]["targets"]).max() > np.abs(parts["wood"]["wind"]["targets"]).max()
    berry = sprig.load("species/fig_org_05a_berry_level1.yaml")
    assert berry.wind is None and all(p["wind"] is None for p in berry.mesh(wind=True))
    with pytest.raises(ValueError, match="wind sways trees; an organism species has no wind"):
        berry.mesh(wind=5)
    with pytest.raises(ValueError, match="0 <= speed <= 60"):
        windy.mesh(wind=(61, 0))
    with pytest.raises(ValueError, match="give a .glb name"):
        windy.export(tmp_path / "w.ply", wind=3)
