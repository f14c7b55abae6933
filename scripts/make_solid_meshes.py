#!/usr/bin/env python3
"""Writes the closed meshes of the solid species (species/meshes_solid/): a candy (a
superellipsoid, the rounded cushion of Cutler et al. Fig. 1) and an almond (an ellipsoid
pinched toward one end). Run from the repository root; the output is deterministic."""
import math, os

def spow(v, e):
    return math.copysign(abs(v) ** e, v)

def write_uv(path, point, lat=24, lon=48, comment="", paint=None):
    """A closed latitude-longitude mesh: poles, lat-1 rings of lon vertices, CCW outward.
    paint(x, y, z) -> grey level in [0, 1] writes it as each vertex's sRGB colour."""
    verts = [point(0.0, 0.0)]
    for i in range(1, lat):
        th = math.pi * i / lat
        for j in range(lon):
            verts.append(point(th, 2 * math.pi * j / lon))
    verts.append(point(math.pi, 0.0))
    south = len(verts)  # 1-based index of the last vertex
    ring = lambda i, j: 2 + (i - 1) * lon + (j % lon)  # 1-based
    faces = []
    for j in range(lon):
        faces.append((1, ring(1, j + 1), ring(1, j)))
    for i in range(1, lat - 1):
        for j in range(lon):
            faces.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1), ring(i + 1, j)))
    for j in range(lon):
        faces.append((south, ring(lat - 1, j), ring(lat - 1, j + 1)))
    with open(path, "w") as f:
        f.write("# %s\n# written by scripts/make_solid_meshes.py\n" % comment)
        for v in verts:
            if paint:
                g = paint(*v)
                f.write("v %.6f %.6f %.6f %.4f %.4f %.4f\n" % (v + (g, g, g)))
            else:
                f.write("v %.6f %.6f %.6f\n" % v)
        for fc in faces:
            f.write("f " + " ".join(str(k) for k in fc) + "\n")

def candy(th, ph):
    # Superellipsoid: semi-axes 1 x 0.42 x 0.7 (y up), exponents 0.5 around and 0.6 across.
    c, s = math.cos(th), math.sin(th)
    return (1.0 * spow(s, 0.6) * spow(math.cos(ph), 0.5), 0.42 * spow(c, 0.6), 0.7 * spow(s, 0.6) * spow(math.sin(ph), 0.5))

def almond(th, ph):
    # Ellipsoid 0.6 x 0.2 x 0.34 along x, narrowed toward +x (the tip) and rounded at -x.
    c, s = math.cos(th), math.sin(th)
    x = 0.6 * c
    taper = 1.0 - 0.45 * max(0.0, c) ** 2
    return (x, 0.2 * taper * s * math.cos(ph), 0.34 * taper * s * math.sin(ph))

def ring_paint(x, y, z):
    # Fig. 3a's painted velocity: a white ring of radius 0.45 on the top of the candy, black elsewhere.
    if y < 0.1:
        return 0.0
    r = math.hypot(x, z)
    return max(0.0, 1.0 - abs(r - 0.45) / 0.12)

if __name__ == "__main__":
    out = "species/meshes_solid"
    os.makedirs(out, exist_ok=True)
    write_uv(os.path.join(out, "candy.obj"), candy, 32, 64, "candy: superellipsoid 2 x 0.84 x 1.4, closed")
    # The almond's poles lie on its long (x) axis.
    write_uv(os.path.join(out, "almond.obj"), lambda th, ph: almond(th, ph), 32, 48, "almond: tapered ellipsoid 1.2 x 0.4 x 0.68, closed")
    write_uv(os.path.join(out, "candy_painted.obj"), candy, 64, 128, "candy painted with a ring on top (vertex colours), closed",
             ring_paint)
