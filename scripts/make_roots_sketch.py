#!/usr/bin/env python3
"""Writes species/meshes_solid/roots.png, the roots sketch of the urban tree (Cutler et al.
§5.2, the 2D_EXTRUDE of its URBAN_TREE script): dark root strokes radiating from a dark
disc at the centre (the trunk's foot) on white. Each root is a chain of discs whose
direction wanders a little and whose radius tapers toward the tip; some fork once.
Python's standard library only (the PNG is written with zlib). Run from the repository
root; the output is deterministic (seeded)."""
import math, os, random, struct, zlib

SIZE = 256  # pixels on each side; the species lays them over 2.4 m


def write_png(path, pixels, w, h):
    """8-bit greyscale PNG, rows top first."""
    raw = b"".join(b"\x00" + bytes(pixels[y * w:(y + 1) * w]) for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def main():
    rng = random.Random(7)
    img = [255] * (SIZE * SIZE)

    def disc(cx, cy, r):
        for y in range(max(0, int(cy - r - 1)), min(SIZE, int(cy + r + 2))):
            for x in range(max(0, int(cx - r - 1)), min(SIZE, int(cx + r + 2))):
                if (x + 0.5 - cx) ** 2 + (y + 0.5 - cy) ** 2 <= r * r:
                    img[y * SIZE + x] = 0

    def root(x, y, angle, r0, length, forks, wander=0.06):
        steps = int(length)
        for i in range(steps):
            t = i / steps
            disc(x, y, r0 * (1 - t) + 1.6 * t)
            angle += rng.uniform(-wander, wander)
            x += math.cos(angle)
            y += math.sin(angle)
            if forks and i == steps // 2:
                root(x, y, angle + rng.choice([-1, 1]) * rng.uniform(0.5, 0.8), r0 * (1 - t) * 0.7, length * 0.4, False, wander)

    c = SIZE / 2
    disc(c, c, 22)  # the trunk's foot (radius 0.2 m at 2.4 m per 256 pixels)
    n = 7
    for k in range(n):
        # The first root runs straight along +x through the centre row, so a cut at z = 0 shows it.
        a = 2 * math.pi * (k + (rng.uniform(-0.2, 0.2) if k else 0.0)) / n
        root(c + 14 * math.cos(a), c + 14 * math.sin(a), a, rng.uniform(6.5, 9.0), rng.uniform(80, 112), k % 2 == 0,
             0.06 if k else 0.0)
    out = os.path.join("species", "meshes_solid", "roots.png")
    write_png(out, img, SIZE, SIZE)
    print(out)


if __name__ == "__main__":
    main()
