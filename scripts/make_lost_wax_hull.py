#!/usr/bin/env python3
"""Writes species/meshes_solid/cat_hull.obj: the convex hull of the bronze cat of
species/fig_solid_06_lost_wax.yaml and its base (Cutler et al. §5.1: "we use the convex hull
of the original surface as a second mesh" for the clay mold). The cat is the blob species
species/meshes_solid/bronze_cat.yaml: this has Sprig mesh it (`sprig mesh`, at its
mesh.cell), adds the corners of the solid's base box, and takes the hull of those points
with SciPy's Qhull (Debian python3-scipy). Run from the repository root after building
Sprig: `python3 scripts/make_lost_wax_hull.py [path/to/sprig]` (default build/sprig).
Deterministic."""
import os
import subprocess
import sys
import tempfile
import numpy as np
from scipy.spatial import ConvexHull

CAT = "species/meshes_solid/bronze_cat.yaml"
# The base box of the species file, {min, max} (keep in step with it).
BASE = ((-0.32, 0.0, -0.28), (0.36, 0.08, 0.32))
OUT = "species/meshes_solid/cat_hull.obj"

def cat_vertices(sprig):
    with tempfile.TemporaryDirectory() as tmp:
        obj = os.path.join(tmp, "cat.obj")
        subprocess.run([sprig, "mesh", CAT, "-o", obj], check=True, stdout=subprocess.DEVNULL)
        with open(obj) as f:
            return [tuple(float(x) for x in line.split()[1:4]) for line in f if line.startswith("v ")]

def box_points(lo, hi):
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]

if __name__ == "__main__":
    sprig = sys.argv[1] if len(sys.argv) > 1 else "build/sprig"
    P = np.array(cat_vertices(sprig) + box_points(*BASE))
    hull = ConvexHull(P)
    used = sorted(set(int(i) for f in hull.simplices for i in f))
    index = {v: k + 1 for k, v in enumerate(used)}
    centre = P[used].mean(axis=0)
    with open(OUT, "w") as f:
        f.write("# convex hull of the lost-wax cat (species/meshes_solid/bronze_cat.yaml) and its base\n"
                "# written by scripts/make_lost_wax_hull.py\n")
        for v in used:
            f.write("v %.6f %.6f %.6f\n" % tuple(P[v]))
        for tri in hull.simplices:
            a, b, c = (P[i] for i in tri)
            n = np.cross(b - a, c - a)
            if np.dot(n, a - centre) < 0:
                tri = (tri[0], tri[2], tri[1])
            f.write("f %d %d %d\n" % tuple(index[int(i)] for i in tri))
    print("%s: %d vertices, %d triangles" % (OUT, len(used), len(hull.simplices)))
