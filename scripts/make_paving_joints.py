#!/usr/bin/env python3
"""Writes species/meshes_solid/paving_joints.png, the joints of the brick paving of
species/fig_solid_07_displaced_paving.yaml (Cutler et al. §5.2, Fig. 7) as a 2D_EXTRUDE
sketch: black where a joint is, white on the bricks. A running bond of 0.35 × 0.15 m bricks
with 0.05 m joints (periods 0.4 m along x and 0.2 m along z, every other row shifted by
0.2 m), over the species' 2 × 2 m grid, 0.01 m per pixel, so every joint's edges lie on
pixel edges and on the grid's planes (multiples of its 0.05 m cell from -1). The species
extrudes it 0.05 m down from the paving's top as `nothing`: open grooves between the
bricks. Keep the numbers in step with the species' `brick_paving` expression. Python's
standard library only; run from the repository root. Deterministic."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_roots_sketch import write_png  # noqa: E402

PIXEL = 0.01            # metres per pixel
SIZE = 200              # pixels on each side: 2 m
ORIGIN = -1.0           # x and z of the image's left and top edges
BRICK_X, PERIOD_X = 35, 40   # pixels: brick length, brick plus joint (0.35, 0.4 m)
BRICK_Z, PERIOD_Z = 15, 20   # pixels: brick width, brick plus joint (0.15, 0.2 m)
SHIFT = 20              # pixels: the offset of every other row (0.2 m)


def is_joint(i, j):
    """Pixel column i (x) and row j (z, top row at z = -1)."""
    x = i + int(round(ORIGIN / PIXEL))                                     # pixels from x = 0
    z = j + int(round(ORIGIN / PIXEL))                                     # pixels from z = 0
    row = z // PERIOD_Z
    shift = SHIFT if row % 2 else 0
    return (x + shift) % PERIOD_X < PERIOD_X - BRICK_X or z % PERIOD_Z < PERIOD_Z - BRICK_Z


def main():
    img = [0 if is_joint(i, j) else 255 for j in range(SIZE) for i in range(SIZE)]
    out = "species/meshes_solid/paving_joints.png"
    write_png(out, img, SIZE, SIZE)
    print("%s: %d x %d, %d joint pixels" % (out, SIZE, SIZE, img.count(0)))


if __name__ == "__main__":
    main()
