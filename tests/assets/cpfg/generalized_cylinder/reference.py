#!/usr/bin/python3
"""Expected pieces of tests/assets/cpfg/generalized_cylinder: cpfg's Hermite generalized
cylinder (general.c, interpolate_connection) written with the Hermite basis functions
(independent of Sprig's power form): between control points p1 and p2 with headings H1,
H2, tangents H * |p2 - p1| * 1.2 (cpfg's default tangent parameters), the curve at
t = k/n, radius linear from w1/2 to w2/2. Sprig's frame: H = +Y, '+' turns toward -X."""
import numpy as np

def hermite(p1, h1, p2, h2, n, w1, w2):
    p1, h1, p2, h2 = map(np.array, (p1, h1, p2, h2))
    L = np.linalg.norm(p2 - p1)
    m1, m2 = h1 * L * 1.2, h2 * L * 1.2
    out = []
    for k in range(1, n + 1):
        t0, t = (k - 1) / n, k / n
        def at(t):
            return ((2*t**3 - 3*t**2 + 1) * p1 + (t**3 - 2*t**2 + t) * m1
                    + (-2*t**3 + 3*t**2) * p2 + (t**3 - t**2) * m2)
        out.append((at(t0), at(t), (w1 + (w2 - w1) * t0) / 2, (w1 + (w2 - w1) * t) / 2))
    return out

pieces = hermite((0, 0, 0), (0, 1, 0), (0, 2, 0), (0, 1, 0), 2, 0.2, 0.2)
pieces += hermite((0, 2, 0), (0, 1, 0), (-2, 2, 0), (-1, 0, 0), 4, 0.2, 0.4)
for a, b, ra, rb in pieces:
    print("{{%.12f, %.12f, %.12f}, {%.12f, %.12f, %.12f}, %.12f, %.12f}," % (*a, *b, ra, rb))
