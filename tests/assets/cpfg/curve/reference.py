#!/usr/bin/python3
"""Expected values of tests/assets/cpfg/curve by cpfg's algorithm (curveXYZ.cpp) over
scipy's B-splines (independent of Sprig's basis code). A curve's control points, with
multiplicities expanded (closed: the first three repeated after the last; phantom: the
reflections 2 p1 - p2 added at both ends), are a uniform cubic B-spline over integer knots
at parameter 3 + u (N - 3.000001), a clamped one at u (N - 3.000001), or Bezier segments
of 3k + 1 points; curveX(n, t) is the point at normalized arc length t of the polyline
through `samples` points at u = i / (samples - 1), interpolated linearly; curveGAL(n) the
polyline's length."""
import numpy as np
from scipy.interpolate import BSpline

def read(name):
    pts, kind, dim = [], 'bspline', 2
    for line in open(name):
        line = line.strip()
        if not line or line.startswith('//'): continue
        if ':' in line:
            key, val = line.split(':', 1)
            if key == 'type': kind = val.strip()
            if key in ('dim', 'dimension'): dim = int(val)
            continue
        v = [float(x) for x in line.split()]
        p = [np.float32(v[0]), np.float32(v[1]), np.float32(v[2]) if dim > 2 else 0.0]
        pts += [p] * (int(v[3]) if dim == 4 else 1)
    return np.array(pts, dtype=np.float64), kind

def evaluator(pts, kind):
    if kind == 'bspline-closed': pts = np.vstack([pts, pts[:3]])
    if kind == 'bspline-phantom': pts = np.vstack([2 * pts[0] - pts[1], pts, 2 * pts[-1] - pts[-2]])
    n = len(pts)
    if kind == 'bezier':
        segs = 1 + (n - 4) // 3
        b = BSpline(np.array([0, 0, 0, 0, 1, 1, 1, 1.0]), np.zeros((4, 3)), 3)
        def f(u):
            c = int(u / (1.000001 / segs))
            t = (u - c * (1.0 / segs)) * segs / 1.000001
            return BSpline(b.t, pts[3 * c:3 * c + 4], 3)(t)
        return f
    if kind == 'bspline-endpoint':
        knots = np.array([0.0 if k < 4 else (n - 3.0 if k > n - 1 else k - 3.0) for k in range(n + 4)])
        s = BSpline(knots, pts, 3)
        return lambda u: s(u * (n - 3.000001))
    s = BSpline(np.arange(n + 4, dtype=np.float64), pts, 3)
    return lambda u: s(3 + u * (n - 3.000001))

def curve(name, samples=100):
    f = evaluator(*read(name))
    p = np.array([f(i / (samples - 1)) for i in range(samples)])
    l = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(p, axis=0), axis=1))])
    total = l[-1]
    l = l / total
    def at(t):
        t = min(max(t, 0.0), 1.0)
        lo = min(max(int(np.searchsorted(l, t, side='right')) - 1, 0), samples - 2)
        return f((lo + (t - l[lo]) / (l[lo + 1] - l[lo])) / (samples - 1))
    return at, total

if __name__ == '__main__':
    c1, g1 = curve('profile.con')
    c2, g2 = curve('arch.con', 50)
    c3, g3 = curve('loop.con')
    c4, g4 = curve('ends.con', 20)
    c5, g5 = curve('phantom.con')
    vals = [c1(0.3)[0], c1(0.3)[1], c1(0)[0], c1(1)[1], g1,
            c2(0.5)[0], c2(0.5)[1], c2(0.5)[2], c2(0.9)[2], g2,
            c3(0.25)[0], c3(0.6)[1], g3,
            c4(0.7)[0], c4(0.7)[1], c4(-2)[1],
            c5(0.1)[0], c5(0.45)[1]]
    print(', '.join('%.12f' % v for v in vals))
