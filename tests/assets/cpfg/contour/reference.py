#!/usr/bin/python3
"""Contour samples of tests/assets/cpfg/contour by cpfg's MakeContour (general.c), in numpy:
the uniform cubic B-spline of the points (closed: wrapping), lengths in x and y measured at
10 parameters per segment (closed: num segments and the closing chord; open: num - 3),
`sides` points at equal length steps with the parameter interpolated linearly between the
measured ones, a closed contour rotated so that its point at parameter 0 is on +x."""
import numpy as np

M = np.array([[-1, 3, -3, 1], [3, -6, 3, 0], [-3, 0, 3, 0], [1, 4, 1, 0]]) / 6.0

def spline(P, t):
    first = int(np.floor(t)); x = t - first
    w = np.array([x**3, x**2, x, 1.0]) @ M
    idx = [(first + k) % len(P) for k in range(4)]
    return w @ P[idx]

def make_contour(P, closed, sides, n=10):
    P = np.asarray(P, dtype=np.float32).astype(np.float64)  # cpfg reads floats
    segs = len(P) if closed else len(P) - 3
    ts = [i + j / n for i in range(segs) for j in range(n)]
    pts = np.array([spline(P, t) for t in ts])
    d = np.concatenate([[0.0], np.hypot(*(np.diff(pts[:, :2], axis=0).T))])
    lengths = np.cumsum(d)
    total = lengths[-1]
    rot = np.eye(2)
    if closed:
        p0 = spline(P, 0.0)
        total += np.hypot(*(pts[-1, :2] - p0[:2]))
        c, s = p0[:2] / np.hypot(*p0[:2])
        rot = np.array([[c, s], [-s, c]])
    step = total / sides
    out = []
    j = 0
    for i in range(sides if closed else sides + 1):
        want = i * step
        t = 0.0
        if i > 0:
            while lengths[j] < want and j < len(lengths) - 1: j += 1
            j2 = j - 1
            t = j2 / n + (want - lengths[j2]) / (lengths[j] - lengths[j2]) / n
        p = spline(P, t)
        out.append(list(rot @ p[:2]) + [p[2] if len(p) > 2 else 0.0])
    if closed: out.append(out[0])
    return np.array(out)

if __name__ == '__main__':
    blade = [[2, 0, 0], [0, 1, 0], [0, 1, 0], [-2, 0, 0], [0, -1, 0], [0, -1, 0]]
    strip = [[-1, 0], [-0.5, 0.3], [0, 0.5], [0.5, 0.3], [1, 0]]
    np.set_printoptions(precision=12, suppress=True)
    for name, c in (('blade 6', make_contour(blade, True, 6)), ('strip 4', make_contour(strip, False, 4))):
        print(name)
        for p in c: print('{%.12f, %.12f, %.12f},' % tuple(p))
