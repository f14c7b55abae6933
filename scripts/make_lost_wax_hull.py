#!/usr/bin/env python3
"""Writes species/meshes_solid/cat_hull.obj: the convex hull of the bronze cat of
species/fig_solid_06_lost_wax.yaml (Cutler et al. §5.1: "we use the convex hull of the
original surface as a second mesh" for the clay mold). The cat is a union of Sprig's exact
fields; this samples their surfaces (spheres, capped cylinders, a box) and takes the hull
with SciPy's Qhull (Debian python3-scipy). Run from the repository root; deterministic."""
import math
import numpy as np
from scipy.spatial import ConvexHull

# The primitives of the species file (keep in step with it).
SPHERES = [((0.0, 0.38, 0.0), 0.27), ((0.12, 0.78, 0.0), 0.16)]
CYLINDERS = [  # center, radius, height, axis
    ((0.08, 0.95, 0.08), 0.035, 0.14, (0.0, 1.0, 0.0)),
    ((0.08, 0.95, -0.08), 0.035, 0.14, (0.0, 1.0, 0.0)),
    ((-0.3, 0.3, 0.0), 0.045, 0.42, (-0.45, 1.0, 0.0)),
]
BOXES = [((0.0, 0.05, 0.0), (0.7, 0.1, 0.46))]

def sphere_points(c, r, n=40):
    pts = []
    for i in range(n + 1):
        th = math.pi * i / n
        for j in range(2 * n):
            ph = math.pi * j / n
            pts.append((c[0] + r * math.sin(th) * math.cos(ph), c[1] + r * math.cos(th), c[2] + r * math.sin(th) * math.sin(ph)))
    return pts

def cylinder_points(c, r, h, axis, n=48):
    a = np.array(axis, float)
    a /= np.linalg.norm(a)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(helper, a)
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    pts = []
    for s in (-0.5 * h, 0.5 * h):
        for j in range(n):
            ph = 2 * math.pi * j / n
            pts.append(tuple(np.array(c) + a * s + r * (math.cos(ph) * u + math.sin(ph) * v)))
    return pts

def box_points(c, size):
    return [(c[0] + sx * size[0] / 2, c[1] + sy * size[1] / 2, c[2] + sz * size[2] / 2)
            for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]

if __name__ == "__main__":
    pts = []
    for c, r in SPHERES:
        pts += sphere_points(c, r)
    for c, r, h, a in CYLINDERS:
        pts += cylinder_points(c, r, h, a)
    for c, s in BOXES:
        pts += box_points(c, s)
    P = np.array(pts)
    hull = ConvexHull(P)
    used = sorted(set(int(i) for f in hull.simplices for i in f))
    index = {v: k + 1 for k, v in enumerate(used)}
    centre = P[used].mean(axis=0)
    with open("species/meshes_solid/cat_hull.obj", "w") as f:
        f.write("# convex hull of the lost-wax cat (species/fig_solid_06_lost_wax.yaml)\n# written by scripts/make_lost_wax_hull.py\n")
        for v in used:
            f.write("v %.6f %.6f %.6f\n" % tuple(P[v]))
        for tri in hull.simplices:
            a, b, c = (P[i] for i in tri)
            n = np.cross(b - a, c - a)
            if np.dot(n, a - centre) < 0:
                tri = (tri[0], tri[2], tri[1])
            f.write("f %d %d %d\n" % tuple(index[int(i)] for i in tri))
    print("cat_hull.obj: %d vertices, %d triangles" % (len(used), len(hull.simplices)))
