"""Shared helpers of the Python module's tests: the `sprig` binary to compare with, and a
PNG reader (zlib and numpy only) for its images."""

import json
import os
import struct
import subprocess
import zlib

import numpy as np
import pytest

TREE = "python/tests/data/tiny_tree.yaml"
BAD = "python/tests/data/bad.yaml"
WINDY = "python/tests/data/tiny_windy_tree.yaml"


def sprig_bin():
    path = os.environ.get("SPRIG_BIN", "build/sprig")
    if not os.path.exists(path):
        pytest.skip("the sprig binary is not built (set SPRIG_BIN)")
    return path


def run_sprig(*args):
    """Runs the sprig binary quietly; returns its stdout (bytes). Fails the test on a non-zero exit."""
    r = subprocess.run([sprig_bin(), "--quiet", *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    assert r.returncode == 0, r.stderr.decode()
    return r.stdout


def read_png(path):
    """An 8-bit, non-interlaced RGB or RGBA PNG as an (H, W, C) uint8 array."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        tag, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + length]
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour, _, _, interlace = header
    assert depth == 8 and interlace == 0 and colour in (2, 6)
    channels = 3 if colour == 2 else 4
    stride = width * channels
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(height, stride + 1)
    out = np.zeros((height, stride), np.uint8)
    prev = np.zeros(stride, np.uint8)
    for y in range(height):
        kind, line = raw[y, 0], raw[y, 1:]
        if kind == 0:
            row = line.copy()
        elif kind == 1:  # sub: a running sum along each channel
            row = (np.cumsum(line.reshape(width, channels).astype(np.int64), axis=0) & 0xFF).astype(np.uint8).ravel()
        elif kind == 2:  # up
            row = line + prev
        else:  # average (3) and Paeth (4), pixel by pixel
            cur, up, r = line.tolist(), prev.tolist(), [0] * stride
            for x in range(stride):
                a = r[x - channels] if x >= channels else 0
                b = up[x]
                if kind == 3:
                    p = (a + b) // 2
                else:
                    c = up[x - channels] if x >= channels else 0
                    pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                    p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                r[x] = (cur[x] + p) & 0xFF
            row = np.array(r, np.uint8)
        out[y] = row
        prev = row
    return out.reshape(height, width, channels)


_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
_TYPES = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}


class Glb:
    """A .glb read with numpy alone: its JSON (self.json) and any accessor as an array
    (dense or sparse, float or integer; normalized integers are not scaled)."""

    def __init__(self, path):
        data = open(path, "rb").read()
        assert data[:4] == b"glTF"
        pos, self.json, self.bin = 12, None, b""
        while pos < len(data):
            length, tag = struct.unpack("<I4s", data[pos:pos + 8])
            body = data[pos + 8:pos + 8 + length]
            if tag == b"JSON":
                self.json = json.loads(body)
            elif tag == b"BIN\x00":
                self.bin = body
            pos += 8 + length

    def _view(self, view, offset, dtype, count):
        v = self.json["bufferViews"][view]
        start = v.get("byteOffset", 0) + offset
        return np.frombuffer(self.bin, dtype, count, start)

    def accessor(self, index):
        a = self.json["accessors"][index]
        n, dtype = _COMPONENTS[a["type"]], _TYPES[a["componentType"]]
        if "bufferView" in a:
            out = self._view(a["bufferView"], a.get("byteOffset", 0), dtype, a["count"] * n).copy()
        else:
            out = np.zeros(a["count"] * n, dtype)
        if "sparse" in a:
            s = a["sparse"]
            idx = self._view(s["indices"]["bufferView"], s["indices"].get("byteOffset", 0),
                             _TYPES[s["indices"]["componentType"]], s["count"])
            values = self._view(s["values"]["bufferView"], s["values"].get("byteOffset", 0), dtype, s["count"] * n)
            out.reshape(-1, n)[idx.astype(np.int64)] = values.reshape(-1, n)
        return out.reshape(a["count"], n) if n > 1 else out
