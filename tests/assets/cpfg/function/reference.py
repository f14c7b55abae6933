#!/usr/bin/python3
"""Expected func(n, x) values of tests/assets/cpfg/function, by cpfg's algorithm
(splinefun.cpp) over scipy's B-splines (independent of Sprig's basis code): a clamped
uniform cubic B-spline over the control points, y at the curve point whose x is within
0.001 of the argument by bisection on the parameter, and, for more than 2 samples, values
precomputed at i / (samples - 1) and interpolated linearly."""
import numpy as np
from scipy.interpolate import BSpline

def curve(points):
    p = np.array(points, dtype=np.float32).astype(np.float64)  # cpfg reads floats
    n = len(p) - 1
    knots = np.concatenate([[0.0] * 4, np.arange(1, n - 2), [n - 2.0] * 4])
    spline = BSpline(knots, p, 3)
    return lambda d: spline(d * (n - 2))

def bisect(c, x):
    low, high = 0.0, 1.0
    while True:
        check = (low + high) / 2
        px, py = c(check)
        if px > x: high = check
        else: low = check
        if abs(px - x) <= 0.001: return py

def func(points, samples, x):
    c = curve(points)
    x = min(max(x, 0.0), 1.0)
    if samples <= 2: return bisect(c, x)
    vals = [bisect(c, i / (samples - 1)) for i in range(samples)]
    index = x * (samples - 1)
    i = int(np.floor(index))
    if i >= samples - 1: return vals[-1]
    w = index - i
    return (1 - w) * vals[i] + w * vals[i + 1]

a = [(0, 0), (0.333333, 0), (0.666667, 1), (1, 1)]
b = [(0, 0.2), (0.2, 0.9), (0.5, 0.1), (0.8, 0.6), (1.0, 0.3)]
c = [(0, 1), (0.4, 0), (0.4, 0), (0.7, 0.2), (1, 0.5)]
for name, pts, s, x in [("a", a, 0, 0.25), ("a", a, 0, 0.7), ("a", a, 0, -1), ("a", a, 0, 2),
                        ("b", b, 5, 0.3), ("b", b, 5, 0.6), ("c", c, 0, 0.5), ("a", a, 0, 0.5)]:
    print(f"{name}({x}) = {func(pts, s, x):.12f}")
