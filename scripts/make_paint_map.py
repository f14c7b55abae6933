#!/usr/bin/env python3
"""Writes species/meshes_solid/candy_paint.png, the image map of the painted-velocity candy
(Cutler et al. §2.4, Fig. 3a, painted as a texture rather than on the vertices): a white
Archimedean spiral stroke on black, 256 x 256 pixels, laid over the candy's top by the
species (velocity: painted: image). Python's standard library only (the PNG is written with
zlib, as scripts/make_roots_sketch.py does). Run from the repository root; deterministic."""
import math, os, sys

sys.path.insert(0, os.path.dirname(__file__))
from make_roots_sketch import write_png  # noqa: E402

SIZE = 256


def main():
    img = [0] * (SIZE * SIZE)
    c = SIZE / 2
    # r = a·θ over two and a half turns, a stroke 12 pixels wide whose edge fades over 8
    # pixels (about two cells of the species' grid: a sharper step in speed leaves the
    # front's lattice visible on the ridge's walls).
    turns, r_max, half, soft = 2.5, 0.46 * SIZE, 6.0, 8.0
    a = r_max / (2 * math.pi * turns)
    for y in range(SIZE):
        for x in range(SIZE):
            dx, dy = x + 0.5 - c, y + 0.5 - c
            r = math.hypot(dx, dy)
            theta = math.atan2(dy, dx) % (2 * math.pi)
            best = 1e9
            for k in range(int(turns) + 2):  # the spiral's arms at this angle: r = a(θ + 2πk)
                rs = a * (theta + 2 * math.pi * k)
                if rs <= r_max:
                    best = min(best, abs(r - rs))
            t = min(1.0, max(0.0, (half + soft / 2 - best) / soft))
            v = t * t * (3 - 2 * t)
            img[y * SIZE + x] = int(round(255 * v))
    out = os.path.join("species", "meshes_solid", "candy_paint.png")
    write_png(out, img, SIZE, SIZE)
    print(out)


if __name__ == "__main__":
    main()
