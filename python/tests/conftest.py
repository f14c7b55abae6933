"""Shared helpers of the Python module's tests: the `sprig` binary to compare with, and a
PNG reader (zlib and numpy only) for its images."""

import os
import struct
import subprocess
import zlib

import numpy as np
import pytest

TREE = "python/tests/data/tiny_tree.yaml"
BAD = "python/tests/data/bad.yaml"


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
