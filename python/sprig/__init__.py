"""Sprig from Python: load species, check them, derive, mesh, render and animate them.

Every call runs the same library functions as the `sprig` command (docs/PYTHON.md), so a
render, an export or a derived string equals the command's for the same options. Long calls
release the GIL, report progress to an optional callback ``progress(label, done, total)``,
and stop on Ctrl-C (KeyboardInterrupt).
"""

import os
import struct
import zlib

import numpy as np

from . import _sprig
from ._sprig import Diagnostic, InputError, Species

__version__ = _sprig.__version__
__all__ = ["load", "check", "Species", "Diagnostic", "InputError", "Image", "Animation", "set_progress_bars"]


def _png_bytes(pixels):
    """An 8-bit RGB or RGBA PNG of pixels (H, W, 3 or 4 uint8), compressed with zlib."""
    a = np.ascontiguousarray(pixels, dtype=np.uint8)
    height, width, channels = a.shape
    colour_type = {3: 2, 4: 6}[channels]
    rows = np.concatenate([np.zeros((height, 1), np.uint8), a.reshape(height, width * channels)], axis=1)

    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows.tobytes(), 6)) +
            chunk(b"IEND", b""))


class Image(np.ndarray):
    """A rendered image: an (H, W, 4) or (H, W, 3) uint8 numpy array of 8-bit sRGB values (the
    values `sprig render` writes to PNG), which Jupyter shows as a picture."""

    def _repr_png_(self):
        return _png_bytes(self)

    def save(self, path):
        """Writes the image as a PNG file (the pixels `sprig render -o x.png` writes)."""
        with open(path, "wb") as f:
            f.write(_png_bytes(self))


def _image(a, linear):
    return a if linear else a.view(Image)


def load(path, overrides=None, seed=None, steps=None, root=".", allow_outside_paths=False, progress=None):
    """Reads a species file (.yaml), a grammar (.lsys, cpfg's .l) or a vlab object folder.

    overrides: {NAME: number}, the grammar's #define values (the command's -D NAME=VALUE);
    seed, steps: a tree's random seed and derivation length (--seed, --steps);
    root, allow_outside_paths: where referenced files may lie (--root, --allow-outside-paths;
    the root defaults to the current folder, as for the command).
    Raises InputError (with file, line, column, severity, message) for bad input."""
    return _sprig._load(os.fspath(path), {str(k): float(v) for k, v in (overrides or {}).items()}, seed, steps,
                        os.fspath(root), allow_outside_paths, progress)


def check(path, **options):
    """Every diagnostic of a file, as `sprig check` finds them: a list of Diagnostic (empty
    when the file is fine). options as for load."""
    try:
        species = load(path, **options)
    except InputError as e:
        return e.diagnostics
    return species.check()


def set_progress_bars(on):
    """Lets Sprig draw its own progress bars on stderr when it is a terminal (off at import)."""
    _sprig._set_progress_bars(bool(on))


def _render(self, width=None, height=None, spp=None, mode="exact", stage=None, fraction=1.0, age=None, view=None,
            alpha=True, linear=False, progress=None):
    """Renders the species as `sprig render` does: an Image of (height, width, 4) uint8 (3
    channels with alpha=False), or linear RGBA float32 with linear=True.

    width, height, spp: default the species' render settings (one side given keeps the
    aspect); mode: 'exact', 'mesh' or 'skeleton'; stage, fraction, age: --stage, --fraction,
    --age; view: (azimuth, elevation[, fov]) in degrees, as --view."""
    a = self._render(width or 0, height or 0, spp or 0, mode, stage, fraction, age,
                     None if view is None else [float(v) for v in view], alpha, linear, progress)
    return _image(a, linear)


def _wind_value(wind):
    """wind= as the C++ module takes it: None, or [speed] / [speed, direction]."""
    if wind is None:
        return None
    return [float(wind)] if np.isscalar(wind) else [float(v) for v in wind]


def _mesh(self, stage=None, fraction=1.0, age=None, cell=0.0, min_volume=_sprig.DEFAULT_MIN_VOLUME, simplify=None,
          wind=False, progress=None):
    """The surface as `sprig mesh` builds it: a list of parts (one dict each, parts without
    triangles left out) with name, positions (N, 3 float32), triangles (M, 3 uint32),
    normals, colors (linear RGB) and uvs (or None), material_ids, material, base_color,
    roughness, double_sided, alpha_cutoff, texture (linear RGBA float32 image or None),
    texture_corner_uvs (M, 3, 2 for a texture atlas, else None), wind and wind_attribute.
    cell: --cell (0 = automatic); min_volume: --min-volume; simplify: --simplify.

    wind (trees): True for the species' own wind (Species.wind), a speed in m/s or (speed,
    direction in degrees) as `sprig mesh --wind`; False (the default) for none. With wind,
    wind_attribute is the .glb's `_WIND` (N, 4 float32) and, when the part sways (speed > 0),
    wind is a dict of the .glb's morph targets and animation: names (K target names),
    targets (K, N, 3 float32 displacements of the positions), times (F keyframe seconds over
    loop_seconds, the last equal to it), weights (K, F float32) and animation ('wind');
    otherwise both are None (docs/MESHES.md "Wind"). A speed for a kind without wind raises
    ValueError; True gives None there."""
    windy = wind is True
    value = None if isinstance(wind, bool) else _wind_value(wind)
    return self._mesh(stage, fraction, age, cell, min_volume, simplify, windy, value, progress)


def _export(self, path, stage=None, fraction=1.0, age=None, cell=0.0, min_volume=_sprig.DEFAULT_MIN_VOLUME, simplify=None,
            wind=None, progress=None):
    """Writes the mesh as `sprig mesh SPECIES -o path` does (.ply, .obj + .mtl, .glb; solids
    also .msh, .vtu, .mesh): the same bytes for the same options. wind: a speed in m/s or
    (speed, direction in degrees), as --wind (a tree's .glb only); None: the species' own."""
    self._export(os.fspath(path), stage, fraction, age, cell, min_volume, simplify, _wind_value(wind), progress)


class Animation:
    """The frames of a growth animation (Species.animate), rendered one at a time as they are
    asked for: the images `sprig animate -o FOLDER/` writes, in order."""

    def __init__(self, frames, linear):
        self._frames = frames
        self._linear = linear

    def __iter__(self):
        return self

    def __next__(self):
        return _image(next(self._frames), self._linear)

    def __len__(self):
        return len(self._frames)

    @property
    def size(self):
        """(width, height) of every frame."""
        return self._frames.size


def _animate(self, frames_per_stage=6, stages=None, width=None, height=None, samples=None, fps=12.0, wind=None,
             wind_seconds=4.0, alpha=True, linear=False, progress=None):
    """The growth animation as `sprig animate` renders it: an Animation (an iterator of
    Image frames; len() is the frame count).

    stages: (first, last) steps (--stages A..B; either may be None); wind: speed in m/s or
    (speed, direction in degrees) (--wind); fps and wind_seconds as --fps, --wind-seconds."""
    first, last = stages if stages is not None else (None, None)
    speed, direction = (wind, 0.0) if np.isscalar(wind) else (wind or (0.0, 0.0))
    frames = self._animate(frames_per_stage, first, last, width or 0, height or 0, samples or 0, fps, float(speed),
                           float(direction), wind_seconds, alpha, linear, progress)
    return Animation(frames, linear)


def _derive(self, stage=None, progress=None):
    """`sprig derive` for a tree: a dict with string (the module string `sprig derive --print`
    prints), steps, seed, and the skeleton's internodes as arrays: starts and ends (N, 3),
    base_radii and tip_radii (N), parents, orders and created_at_step (N int32)."""
    return self._derive(stage, progress)


Species._derive = Species.derive
Species.derive = _derive
Species.render = _render
Species.mesh = _mesh
Species.export = _export
Species.animate = _animate
Species.__repr__ = lambda self: "<sprig.Species %s '%s'>" % (self.kind, self.name)
