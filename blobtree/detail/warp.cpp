#include "blobtree/detail/warp.h"

#include "blobtree/detail/geometry.h"

#include <glm/geometric.hpp>

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sprig::blobtree::detail {

BendFrame makeBendFrame(const Bend& b, const Box3& childBox) {
  BendFrame f;
  Vec3 ab = b.b - b.a;
  float L = glm::length(ab);
  if (!(L > 0.0f)) throw std::invalid_argument("bend: the segment a-b has zero length");
  f.u = ab / L;
  f.n = perpendicular(f.u, b.direction);
  f.z = glm::cross(f.u, f.n);
  f.M = 0.5f * (b.a + b.b);
  if (!(b.sagitta > 0.0f)) {
    f.straight = true;
    return f;
  }
  f.straight = false;
  float s = b.sagitta;
  f.rho = (0.25f * L * L + s * s) / (2.0f * s);
  f.C = f.M + (s - f.rho) * f.n;
  f.phi = std::atan2(0.5f * L, f.rho - s);
  float arc = 2.0f * f.phi * f.rho;
  f.stretch = L / arc;
  if (childBox.empty()) return f;
  float xmax = 0.0f, ymin = 1e30f;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? childBox.hi.x : childBox.lo.x, (i & 2) ? childBox.hi.y : childBox.lo.y,
                (i & 4) ? childBox.hi.z : childBox.lo.z};
    Vec3 d = corner - f.M;
    xmax = std::max(xmax, std::abs(glm::dot(d, f.u)));
    ymin = std::min(ymin, glm::dot(d, f.n));
  }
  if (ymin <= -0.98f * f.rho)
    throw std::invalid_argument("bend: the child's support reaches the bend centre (support radius must stay below the bend radius " +
                                std::to_string(f.rho) + ")");
  if (xmax >= 0.98f * float(kPi) * f.rho * f.stretch)
    throw std::invalid_argument("bend: the child's support would wrap past a half turn");
  f.yMinChild = ymin;
  f.setSupport(childBox);
  return f;
}

namespace {

/// atan2 with a relative error below 2.4e-7 (about 2 float ulps) over the whole plane
/// (tests/blobtree checks it against std::atan2). The bend evaluates it once per point and
/// libm's atan2f was a quarter of the time of a bent tree's render. The polynomial is the
/// minimax fit of atan on [0, tan(π/8)] after the usual octant reductions; the branches are
/// selects, though GCC 12 vectorizes them only with -fno-trapping-math, which measured no
/// faster (docs/PERFORMANCE.md, Trees).
inline float atan2Fast(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float mx = std::max(ax, ay), mn = std::min(ax, ay);
  float a = mn / (mx > 0.0f ? mx : 1.0f);  // in [0, 1]; divisions outside the selects
  const bool upper = a > 0.41421356f;       // tan(π/8): reduce by π/4
  const float reduced = (a - 1.0f) / (a + 1.0f);
  a = upper ? reduced : a;
  const float z = a * a;
  float r = (((8.05374449538e-2f * z - 1.38776856032e-1f) * z + 1.99777106478e-1f) * z - 3.33329491539e-1f) * z * a + a;
  r = upper ? r + 0.78539816f : r;
  r = ay > ax ? 1.57079633f - r : r;
  r = x < 0.0f ? 3.14159265f - r : r;
  return y < 0.0f ? -r : r;
}

/// A point's coordinates in the bend plane: along u, along n, and the distance from C.
struct BendPolar {
  float uu, vv, rp;
};

/// The bend's world → local map of one point; shared by the scalar and batched paths so
/// both give the same bits. Returns the plane coordinates the Jacobian needs.
inline BendPolar bendLocal(const BendFrame& f, float px, float py, float pz, float& ox, float& oy, float& oz) {
  const float rx = px - f.C.x, ry = py - f.C.y, rz = pz - f.C.z;
  const float uu = rx * f.u.x + ry * f.u.y + rz * f.u.z;
  const float vv = rx * f.n.x + ry * f.n.y + rz * f.n.z;
  const float ww = rx * f.z.x + ry * f.z.y + rz * f.z.z;
  const float rp = std::sqrt(uu * uu + vv * vv);
  const float x = atan2Fast(uu, vv) * (f.rho * f.stretch), y = rp - f.rho;
  ox = f.M.x + x * f.u.x + y * f.n.x + ww * f.z.x;
  oy = f.M.y + x * f.u.y + y * f.n.y + ww * f.z.y;
  oz = f.M.z + x * f.u.z + y * f.n.z + ww * f.z.z;
  return {uu, vv, rp};
}

// The lane types and bendLanes in SSE (the build's baseline), for the array form below.
#define SPRIG_LANES_AVX2 0
#include "blobtree/detail/lanes.inc"
#undef SPRIG_LANES_AVX2

}  // namespace

float atan2Approx(float y, float x) { return atan2Fast(y, x); }

Vec3 BendFrame::localFromWorld(Vec3 p, Mat3* jt) const {
  if (straight) {
    if (jt) *jt = Mat3(1.0f);
    return p;
  }
  Vec3 q;
  const auto [uu, vv, rp] = bendLocal(*this, p.x, p.y, p.z, q.x, q.y, q.z);
  if (jt) {
    float inv = rp > 1e-20f ? 1.0f / rp : 0.0f;
    Vec3 A = (stretch * rho * inv * inv) * (vv * u - uu * n);
    Vec3 B = inv * (uu * u + vv * n);
    *jt = glm::outerProduct(A, u) + glm::outerProduct(B, n) + glm::outerProduct(z, z);
  }
  return q;
}

void BendFrame::localFromWorld(const float* x, const float* y, const float* z, float* lx, float* ly, float* lz,
                               int count) const {
  // Four points per SSE step (lanes.inc's bendLanes, which batch_eval.cpp also runs eight
  // to a step in its AVX2 region), the rest one by one: the same bits either way.
  const int n4 = straight ? count : count & ~3;
  bendLanes<F4>(*this, x, y, z, lx, ly, lz, n4);
  for (int i = n4; i < count; ++i) bendLocal(*this, x[i], y[i], z[i], lx[i], ly[i], lz[i]);
}

Vec3 BendFrame::worldFromLocal(Vec3 q) const {
  if (straight) return q;
  Vec3 d = q - M;
  float x = glm::dot(d, u), y = glm::dot(d, n), zz = glm::dot(d, z);
  float theta = x / (rho * stretch);
  return C + (rho + y) * (std::sin(theta) * u + std::cos(theta) * n) + zz * z;
}

namespace {
struct Range {
  float lo = 1e30f, hi = -1e30f;
  void add(float v) { lo = std::min(lo, v); hi = std::max(hi, v); }
};
Box3 boxFromFrame(Vec3 origin, Vec3 u, Vec3 n, Vec3 z, Range x, Range y, Range w) {
  Box3 b;
  for (int i = 0; i < 8; ++i)
    b.extend(origin + ((i & 1) ? x.hi : x.lo) * u + ((i & 2) ? y.hi : y.lo) * n + ((i & 4) ? w.hi : w.lo) * z);
  return b;
}
void frameRanges(const Box3& box, Vec3 origin, Vec3 u, Vec3 n, Vec3 z, Range& x, Range& y, Range& w) {
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z};
    Vec3 d = corner - origin;
    x.add(glm::dot(d, u));
    y.add(glm::dot(d, n));
    w.add(glm::dot(d, z));
  }
}
/// The ranges of frameRanges from the box's centre and half size (|d·a| over the box is
/// at most |c·a| + h·|a|), three dot products and three of absolute values instead of 24,
/// widened by 1e-6 of the magnitudes for the rounding of either form.
void frameRangesOfBox(const Box3& box, Vec3 origin, Vec3 u, Vec3 n, Vec3 z, Range& x, Range& y, Range& w) {
  const Vec3 c = 0.5f * (box.lo + box.hi) - origin, h = 0.5f * (box.hi - box.lo);
  const float slack = 1e-6f * (std::max({std::abs(box.lo.x), std::abs(box.lo.y), std::abs(box.lo.z), std::abs(box.hi.x),
                                          std::abs(box.hi.y), std::abs(box.hi.z)}) +
                               std::max({std::abs(origin.x), std::abs(origin.y), std::abs(origin.z)}));
  auto range = [&](Vec3 a, Range& r) {
    const float m = glm::dot(c, a), e = glm::dot(h, glm::abs(a)) + slack;
    r.lo = m - e;
    r.hi = m + e;
  };
  range(u, x);
  range(n, y);
  range(z, w);
}
/// The axis-aligned box of the frame box origin + [x]·u + [y]·n + [w]·z, as boxFromFrame's
/// eight corners give it, from its centre and half size, widened by 1e-6 of the magnitudes.
Box3 boxOfFrame(Vec3 origin, Vec3 u, Vec3 n, Vec3 z, Range x, Range y, Range w) {
  const float xm = 0.5f * (x.lo + x.hi), ym = 0.5f * (y.lo + y.hi), wm = 0.5f * (w.lo + w.hi);
  const float xh = 0.5f * (x.hi - x.lo), yh = 0.5f * (y.hi - y.lo), wh = 0.5f * (w.hi - w.lo);
  const Vec3 c = origin + xm * u + ym * n + wm * z;
  const float slack = 1e-6f * (std::max({std::abs(origin.x), std::abs(origin.y), std::abs(origin.z)}) + std::abs(xm) + xh +
                               std::abs(ym) + yh + std::abs(wm) + wh);
  const Vec3 h = xh * glm::abs(u) + yh * glm::abs(n) + wh * glm::abs(z) + slack;
  return Box3{c - h, c + h};
}
float rectMinDist(Range U, Range V) {
  float du = U.lo > 0.0f ? U.lo : (U.hi < 0.0f ? -U.hi : 0.0f);
  float dv = V.lo > 0.0f ? V.lo : (V.hi < 0.0f ? -V.hi : 0.0f);
  return std::sqrt(du * du + dv * dv);
}
}  // namespace

namespace {
/// The image of childBox under the bend, in the frame about C: U along u, V along n (both
/// widened for rounding) and w along z.
void supportRanges(const BendFrame& f, const Box3& childBox, Range& U, Range& V, Range& w) {
  Range x, y;
  frameRanges(childBox, f.M, f.u, f.n, f.z, x, y, w);
  float k = 1.0f / (f.rho * f.stretch);
  float th0 = x.lo * k, th1 = x.hi * k;
  float r0 = f.rho + y.lo, r1 = f.rho + y.hi;
  const float pi = float(kPi);
  float angles[7] = {th0, th1, -pi, -0.5f * pi, 0.0f, 0.5f * pi, pi};
  for (float a : angles) {
    if (a < th0 || a > th1) continue;
    for (float r : {r0, r1}) {
      U.add(r * std::sin(a));
      V.add(r * std::cos(a));
    }
  }
  // Inflate slightly for rounding.
  float eps = 1e-5f * (r1 + 1.0f);
  U.lo -= eps; U.hi += eps; V.lo -= eps; V.hi += eps;
}
}  // namespace

Box3 BendFrame::worldBox(const Box3& childBox) const {
  if (straight || childBox.empty() || isHuge(childBox)) return childBox;
  Range U, V, w;
  supportRanges(*this, childBox, U, V, w);
  return boxFromFrame(C, u, n, z, U, V, w);
}

void BendFrame::setSupport(const Box3& childBox) {
  bounded = false;
  if (straight || childBox.empty() || isHuge(childBox)) return;
  Range U, V, w;
  supportRanges(*this, childBox, U, V, w);
  // w is measured from M in supportRanges and from C in mayReach (C − M is along n, so
  // the same in exact arithmetic): widen it as U and V are.
  const float eps = 1e-5f * (std::max(std::abs(U.lo), std::abs(U.hi)) + std::max(std::abs(V.lo), std::abs(V.hi)) +
                             std::max(std::abs(w.lo), std::abs(w.hi)) + 1.0f);
  uLo = U.lo - eps;
  uHi = U.hi + eps;
  vLo = V.lo - eps;
  vHi = V.hi + eps;
  wLo = w.lo - eps;
  wHi = w.hi + eps;
  bounded = true;
}

Box3 BendFrame::localBox(const Box3& worldB, const Box3& childBox) const {
  if (straight) return worldB;
  if (worldB.empty()) return worldB;
  Range U, V, W;
  frameRangesOfBox(worldB, C, u, n, z, U, V, W);
  // Far from the bent child: a box whose frame ranges miss the support's oriented box (the
  // test mayReach makes per point) holds no point the child reaches, so its preimage is
  // empty (the child's bounds over it are 0), and the atan2s and the box below are not needed.
  if (bounded && (U.hi < uLo || U.lo > uHi || V.hi < vLo || V.lo > vHi || W.hi < wLo || W.lo > wHi)) return Box3{};
  if (U.lo <= 0.0f && U.hi >= 0.0f && V.lo <= 0.0f && V.hi >= 0.0f) return childBox;
  Range th;
  if (V.lo < 0.0f && U.lo < 0.0f && U.hi > 0.0f) {
    th.lo = -float(kPi);
    th.hi = float(kPi);
  } else {
    // atan2Fast, the map's own atan2 (within 2.4e-7·π of std::atan2, far below the
    // widening below, which counts it): libm's atan2f at the four corners was a quarter of
    // the time of a bent tree's surface cells.
    for (float uu : {U.lo, U.hi})
      for (float vv : {V.lo, V.hi}) th.add(atan2Fast(uu, vv));
  }
  Range R;
  R.lo = rectMinDist(U, V);
  R.hi = std::sqrt(std::max(U.lo * U.lo, U.hi * U.hi) + std::max(V.lo * V.lo, V.hi * V.hi));
  float k = rho * stretch;
  Range x{th.lo * k, th.hi * k}, y{R.lo - rho, R.hi - rho};
  float eps = 1e-5f * (R.hi + 1.0f) + 1e-6f * k;
  x.lo -= eps; x.hi += eps; y.lo -= eps; y.hi += eps;
  return boxOfFrame(M, u, n, z, x, y, W).intersected(childBox);
}

float BendFrame::jacobianBound(const Box3& worldB) const {
  if (straight) return 1.0f;
  Range U, V, W;
  frameRangesOfBox(worldB, C, u, n, z, U, V, W);
  float rEff = std::max(rectMinDist(U, V), rho + yMinChild);
  return std::max(1.0f, stretch * rho / rEff) * 1.0001f;
}

namespace {
Mat3 rotationAbout(Vec3 a, float ang) {
  float c = std::cos(ang), s = std::sin(ang);
  Mat3 K(0.0f);
  // Columns of the cross-product matrix [a]x.
  K[0] = Vec3(0.0f, a.z, -a.y);
  K[1] = Vec3(-a.z, 0.0f, a.x);
  K[2] = Vec3(a.y, -a.x, 0.0f);
  return c * Mat3(1.0f) + s * K + (1.0f - c) * glm::outerProduct(a, a);
}
}  // namespace

Vec3 twistLocal(const Twist& t, Vec3 p, Mat3* jt) {
  Vec3 q = p - t.origin;
  float h = glm::dot(q, t.axis);
  Mat3 R = rotationAbout(t.axis, -t.rateRadPerUnit * h);
  Vec3 rq = R * q;
  if (jt) *jt = glm::transpose(R) - t.rateRadPerUnit * glm::outerProduct(t.axis, glm::cross(t.axis, rq));
  return t.origin + rq;
}

Vec3 taperLocal(const Taper& t, Vec3 p, Mat3* jt) {
  Vec3 q = p - t.origin;
  float h = glm::dot(q, t.axis);
  Vec3 perp = q - h * t.axis;
  float s = taperScale(t, h);
  float ds = (t.scale1 - t.scale0) / t.length;
  if (jt) {
    Mat3 aa = glm::outerProduct(t.axis, t.axis);
    *jt = aa + (Mat3(1.0f) - aa) * (1.0f / s) - (ds / (s * s)) * glm::outerProduct(t.axis, perp);
  }
  return t.origin + h * t.axis + perp / s;
}

}  // namespace sprig::blobtree::detail
