#!/usr/bin/env python3
"""Writes bark.png: a 128 x 256 bark image that repeats in both directions (s around a
branch, t along it), so cpfg's seam (s = 0 = 1) and the repeats along t do not show.
Vertical furrows that wander, periodic value noise for colour. Python's standard library
only; deterministic (fixed seed)."""
import math, random, struct, zlib

W, H = 128, 256
random.seed(17)


def periodic_noise(nx, ny):
    """Smooth value noise on an nx x ny lattice that wraps around: f(u, v) for u, v in [0, 1)."""
    g = [[random.random() for _ in range(nx)] for _ in range(ny)]

    def f(u, v):
        x, y = u * nx, v * ny
        i, j = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - i, y - j
        sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
        a = g[j % ny][i % nx]
        b = g[j % ny][(i + 1) % nx]
        c = g[(j + 1) % ny][i % nx]
        d = g[(j + 1) % ny][(i + 1) % nx]
        return (a * (1 - sx) + b * sx) * (1 - sy) + (c * (1 - sx) + d * sx) * sy

    return f


wander = periodic_noise(4, 6)
fine = periodic_noise(32, 64)
blotch = periodic_noise(8, 12)
furrows = 7  # around the branch: an integer, so s = 0 and s = 1 meet
rows = []
for y in range(H):
    t = 1.0 - (y + 0.5) / H
    row = []
    for x in range(W):
        s = (x + 0.5) / W
        phase = furrows * s + 1.2 * (wander(s, t) - 0.5) + 0.15 * math.sin(2 * math.pi * 2 * t)
        ridge = abs(math.sin(math.pi * phase)) ** 1.3  # 0 in a furrow, 1 on a plate
        n = fine(s, t)
        b = blotch(s, t)
        light = 0.25 + 0.55 * ridge * (0.7 + 0.3 * n) + 0.1 * (b - 0.5)
        r = min(255, int(255 * light * (0.78 + 0.1 * b)))
        g = min(255, int(255 * light * (0.66 + 0.05 * n)))
        bl = min(255, int(255 * light * 0.52))
        row.append((r, g, bl))
    rows.append(row)

raw = b"".join(b"\x00" + bytes(c for px in r for c in px) for r in rows)


def chunk(tag, data):
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)


png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", W, H, 8, 2, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
open("bark.png", "wb").write(png)
