#include "blobtree/blobtree.h"

#include "blobtree/detail/field.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sprig::blobtree {

using namespace detail;

float supportRadius(Kernel kernel, float isoRadius) {
  return kernel == Kernel::Wyvill ? isoRadius / kWyvillIso : 2.0f * isoRadius;
}
float kernelValue(Kernel kernel, float s) { return s >= 1.0f ? 0.0f : kernelG(kernel, std::max(s, 0.0f)); }
float kernelSlope(Kernel kernel) { return kernel == Kernel::Wyvill ? kWyvillSlope : kSoftSlope; }

// ---- Detail: primitives ------------------------------------------------------------------
namespace detail {
namespace {

/// A unit vector perpendicular to axis, from preferred when possible.
Vec3 perpendicular(Vec3 axis, Vec3 preferred) {
  Vec3 p = preferred - glm::dot(preferred, axis) * axis;
  if (glm::dot(p, p) < 1e-12f) {
    Vec3 t = std::abs(axis.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 0, 1);
    p = t - glm::dot(t, axis) * axis;
  }
  return glm::normalize(p);
}

Box3 sphereBox(Vec3 c, float r) { return Box3{c - r, c + r}; }

}  // namespace

Prim makePrim(const Node& n, Kernel kernel) {
  Prim P;
  P.kind = n.kind;
  P.kernel = kernel;
  P.weight = n.weight;
  P.tex = n.texture;
  float slope = kernelSlope(kernel) * std::abs(n.weight);
  switch (n.kind) {
    case NodeKind::Point: {
      P.a = n.p0;
      P.R0 = supportRadius(kernel, n.ra);
      P.box = sphereBox(P.a, P.R0);
      P.lipschitz = slope / P.R0;
      P.isoRadiusMin = n.ra;
      P.axis = Vec3(0, 1, 0);
      P.e1 = perpendicular(P.axis, n.texture.refDir);
      P.e2 = glm::cross(P.axis, P.e1);
      break;
    }
    case NodeKind::Segment:
    case NodeKind::Cone: {
      P.a = n.p0;
      P.ab = n.p1 - n.p0;
      P.len = glm::length(P.ab);
      P.invLen2 = 1.0f / (P.len * P.len);
      float rb = n.kind == NodeKind::Segment ? n.ra : n.rb;
      P.R0 = supportRadius(kernel, n.ra);
      float R1 = supportRadius(kernel, rb);
      P.dR = R1 - P.R0;
      P.box = sphereBox(n.p0, P.R0);
      P.box.extend(sphereBox(n.p1, R1));
      float m = P.dR / P.len;
      P.lipschitz = slope * std::sqrt(1.0f + m * m) / std::min(P.R0, R1);
      P.isoRadiusMin = std::min(n.ra, rb);
      P.axis = P.ab / P.len;
      P.e1 = perpendicular(P.axis, n.texture.refDir);
      P.e2 = glm::cross(P.axis, P.e1);
      break;
    }
    case NodeKind::Torus: {
      P.a = n.p0;
      P.axis = glm::normalize(n.p1);
      P.major = n.ra;
      P.R0 = supportRadius(kernel, n.rb);
      P.box = cylinderBox(P.a, P.axis, -P.R0, P.R0, P.major + P.R0);
      P.lipschitz = slope / P.R0;
      P.isoRadiusMin = n.rb;
      P.e1 = perpendicular(P.axis, n.texture.refDir);
      P.e2 = glm::cross(P.axis, P.e1);
      break;
    }
    case NodeKind::Halfspace:
      P.a = n.p0;
      P.axis = glm::normalize(n.p1);
      P.invRamp = 1.0f / n.ra;
      P.box = hugeBox();
      P.lipschitz = P.invRamp * std::abs(n.weight);
      P.hasAttributes = false;
      break;
    case NodeKind::Box:
      P.lo = n.p0;
      P.hi = n.p1;
      P.invRamp = 1.0f / n.ra;
      P.box = Box3{n.p0 - 0.5f * n.ra, n.p1 + 0.5f * n.ra};
      P.lipschitz = P.invRamp * std::abs(n.weight);
      P.hasAttributes = false;
      break;
    default: assert(false);
  }
  return P;
}

Vec2 primUv(const Prim& P, Vec3 p) {
  Vec2 uv{0.0f};
  switch (P.kind) {
    case NodeKind::Point: {
      Vec3 q = p - P.a;
      float l = glm::length(q);
      uv.x = std::atan2(glm::dot(q, P.e2), glm::dot(q, P.e1)) / kTwoPi + 0.5f;
      uv.y = l > 0.0f ? std::acos(std::clamp(glm::dot(q, P.axis) / l, -1.0f, 1.0f)) / float(kPi) : 0.5f;
      break;
    }
    case NodeKind::Segment:
    case NodeKind::Cone: {
      Vec3 ap = p - P.a;
      float t = std::clamp(glm::dot(ap, P.ab) * P.invLen2, 0.0f, 1.0f);
      Vec3 dv = ap - t * P.ab;
      uv.x = std::atan2(glm::dot(dv, P.e2), glm::dot(dv, P.e1)) / kTwoPi + 0.5f;
      uv.y = t * P.len + P.tex.vOffset;
      break;
    }
    case NodeKind::Torus: {
      Vec3 q = p - P.a;
      float h = glm::dot(q, P.axis);
      Vec3 perp = q - h * P.axis;
      uv.x = std::atan2(glm::dot(perp, P.e2), glm::dot(perp, P.e1)) / kTwoPi + 0.5f;
      uv.y = std::atan2(h, glm::length(perp) - P.major) / kTwoPi + 0.5f;
      break;
    }
    default: break;
  }
  return uv * P.tex.uvScale + P.tex.uvOffset;
}

Interval primInterval(const Prim& P, const Box3& box) {
  Vec3 c = box.center();
  Vec3 h = 0.5f * box.size();
  float hd = glm::length(h);
  auto fromDistances = [&](float dmin, float dmax, float Rmin, float Rmax) {
    float smin = dmin * dmin / (Rmax * Rmax), smax = dmax * dmax / (Rmin * Rmin);
    float fhi = smin >= 1.0f ? 0.0f : kernelG(P.kernel, smin);
    float flo = smax >= 1.0f ? 0.0f : kernelG(P.kernel, smax);
    Interval r{flo * P.weight, fhi * P.weight};
    if (P.weight < 0.0f) std::swap(r.lo, r.hi);
    return r;
  };
  auto ramp = [&](float sdlo, float sdhi) {
    Interval r{std::clamp(0.5f - sdhi * P.invRamp, 0.0f, 1.0f) * P.weight,
               std::clamp(0.5f - sdlo * P.invRamp, 0.0f, 1.0f) * P.weight};
    if (P.weight < 0.0f) std::swap(r.lo, r.hi);
    return r;
  };
  switch (P.kind) {
    case NodeKind::Point: {
      Vec3 q = glm::clamp(P.a, box.lo, box.hi);
      float dmin = glm::length(q - P.a);
      float dmax = glm::length(glm::max(glm::abs(P.a - box.lo), glm::abs(P.a - box.hi)));
      return fromDistances(dmin, dmax, P.R0, P.R0);
    }
    case NodeKind::Segment:
    case NodeKind::Cone: {
      float dc = distToSegment(c, P.a, P.ab, P.invLen2);
      float tc = glm::dot(c - P.a, P.ab) * P.invLen2;
      float te = glm::dot(h, glm::abs(P.ab)) * P.invLen2;
      float t0 = std::clamp(tc - te, 0.0f, 1.0f), t1 = std::clamp(tc + te, 0.0f, 1.0f);
      float Ra = P.R0 + P.dR * t0, Rb = P.R0 + P.dR * t1;
      return fromDistances(std::max(0.0f, dc - hd), dc + hd, std::min(Ra, Rb), std::max(Ra, Rb));
    }
    case NodeKind::Torus: {
      Vec3 q = c - P.a;
      float hh = glm::dot(q, P.axis);
      float rho = glm::length(q - hh * P.axis);
      float dc = std::sqrt((rho - P.major) * (rho - P.major) + hh * hh);
      return fromDistances(std::max(0.0f, dc - hd), dc + hd, P.R0, P.R0);
    }
    case NodeKind::Halfspace: {
      float sd = glm::dot(c - P.a, P.axis);
      float e = glm::dot(h, glm::abs(P.axis));
      return ramp(sd - e, sd + e);
    }
    case NodeKind::Box: {
      float sd = sdBox(c, P.lo, P.hi, nullptr);
      return ramp(sd - hd, sd + hd);
    }
    default: return {};
  }
}

// ---- Detail: PCM ---------------------------------------------------------------------------

PcmDerived derivePcm(const PcmParams& p) {
  PcmDerived d;
  d.c = p.iso;
  d.w = p.width;
  d.k = p.slope;
  d.a0 = p.bulgeScale * p.slope * p.width * 0.25f;
  float m = 1.0f;
  for (int i = 0; i <= 256; ++i) {
    float dh;
    pcmH(d, d.w * float(i) / 256.0f, &dh);
    m = std::max(m, std::abs(dh));
  }
  d.maxSlope = m * 1.05f;
  return d;
}

// ---- Detail: warps -------------------------------------------------------------------------

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
  if (straight) {
    std::copy(x, x + count, lx);
    std::copy(y, y + count, ly);
    std::copy(z, z + count, lz);
    return;
  }
  for (int i = 0; i < count; ++i) bendLocal(*this, x[i], y[i], z[i], lx[i], ly[i], lz[i]);
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
float rectMinDist(Range U, Range V) {
  float du = U.lo > 0.0f ? U.lo : (U.hi < 0.0f ? -U.hi : 0.0f);
  float dv = V.lo > 0.0f ? V.lo : (V.hi < 0.0f ? -V.hi : 0.0f);
  return std::sqrt(du * du + dv * dv);
}
}  // namespace

Box3 BendFrame::worldBox(const Box3& childBox) const {
  if (straight || childBox.empty() || isHuge(childBox)) return childBox;
  Range x, y, w;
  frameRanges(childBox, M, u, n, z, x, y, w);
  float k = 1.0f / (rho * stretch);
  float th0 = x.lo * k, th1 = x.hi * k;
  float r0 = rho + y.lo, r1 = rho + y.hi;
  Range U, V;
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
  return boxFromFrame(C, u, n, z, U, V, w);
}

Box3 BendFrame::localBox(const Box3& worldB, const Box3& childBox) const {
  if (straight) return worldB;
  Range U, V, W;
  frameRanges(worldB, C, u, n, z, U, V, W);
  if (U.lo <= 0.0f && U.hi >= 0.0f && V.lo <= 0.0f && V.hi >= 0.0f) return childBox;
  Range th;
  if (V.lo < 0.0f && U.lo < 0.0f && U.hi > 0.0f) {
    th.lo = -float(kPi);
    th.hi = float(kPi);
  } else {
    for (float uu : {U.lo, U.hi})
      for (float vv : {V.lo, V.hi}) th.add(std::atan2(uu, vv));
  }
  Range R;
  R.lo = rectMinDist(U, V);
  R.hi = std::sqrt(std::max(U.lo * U.lo, U.hi * U.hi) + std::max(V.lo * V.lo, V.hi * V.hi));
  float k = rho * stretch;
  Range x{th.lo * k, th.hi * k}, y{R.lo - rho, R.hi - rho};
  float eps = 1e-5f * (R.hi + 1.0f);
  x.lo -= eps; x.hi += eps; y.lo -= eps; y.hi += eps;
  return boxFromFrame(M, u, n, z, x, y, W).intersected(childBox);
}

float BendFrame::jacobianBound(const Box3& worldB) const {
  if (straight) return 1.0f;
  Range U, V, W;
  frameRanges(worldB, C, u, n, z, U, V, W);
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

Box3 cylinderBox(Vec3 origin, Vec3 axis, float h0, float h1, float r) {
  Vec3 e{r * std::sqrt(std::max(0.0f, 1.0f - axis.x * axis.x)), r * std::sqrt(std::max(0.0f, 1.0f - axis.y * axis.y)),
         r * std::sqrt(std::max(0.0f, 1.0f - axis.z * axis.z))};
  Vec3 p0 = origin + h0 * axis, p1 = origin + h1 * axis;
  return Box3{glm::min(p0, p1) - e, glm::max(p0, p1) + e};
}

void axialExtent(const Box3& box, Vec3 origin, Vec3 axis, float& h0, float& h1, float& rmax) {
  h0 = 1e30f;
  h1 = -1e30f;
  rmax = 0.0f;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z};
    Vec3 d = corner - origin;
    float h = glm::dot(d, axis);
    h0 = std::min(h0, h);
    h1 = std::max(h1, h);
    rmax = std::max(rmax, glm::length(d - h * axis));
  }
}

Box3 transformBox(const Mat4& m, const Box3& box) {
  if (box.empty() || isHuge(box)) return box;
  Box3 r;
  for (int i = 0; i < 8; ++i) {
    Vec3 corner{(i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z};
    r.extend(Vec3(m * Vec4(corner, 1.0f)));
  }
  return r;
}

float spectralNorm(const Mat3& m) {
  Mat3 a = glm::transpose(m) * m;
  Vec3 v = glm::normalize(Vec3(0.577f, 0.601f, 0.553f));
  float lambda = 0.0f;
  for (int i = 0; i < 64; ++i) {
    Vec3 w = a * v;
    float l = glm::length(w);
    if (l <= 0.0f) return 0.0f;
    lambda = l;
    v = w / l;
  }
  // Power iteration converges from below; inflate, and never exceed the Frobenius norm.
  float frob = std::sqrt(glm::dot(m[0], m[0]) + glm::dot(m[1], m[1]) + glm::dot(m[2], m[2]));
  return std::min(frob, std::sqrt(lambda) * 1.01f);
}

}  // namespace detail

// ---- Public helpers -------------------------------------------------------------------------

float pcmDeform(const PcmParams& params, float fOther) { return pcmD(derivePcm(params), fOther, nullptr); }
float pcmDeformDerivative(const PcmParams& params, float fOther) {
  float d;
  pcmD(derivePcm(params), fOther, &d);
  return d;
}
float pcmBulgeMax(const PcmParams& params) { return derivePcm(params).a0; }

Bend Bend::fromAngle(Vec3 a, Vec3 b, Vec3 direction, float angleRad) {
  Bend r;
  r.a = a;
  r.b = b;
  r.direction = direction;
  float L = glm::length(b - a);
  float phi = 0.5f * angleRad;
  if (phi <= 0.0f) return r;
  float rho = 0.5f * L / std::sin(phi);
  r.sagitta = rho * (1.0f - std::cos(phi));
  return r;
}
float Bend::radius() const {
  float L = glm::length(b - a);
  return sagitta > 0.0f ? (0.25f * L * L + sagitta * sagitta) / (2.0f * sagitta) : std::numeric_limits<float>::infinity();
}
Vec3 Bend::worldFromLocal(Vec3 local) const { return makeBendFrame(*this, Box3{}).worldFromLocal(local); }
Vec3 Bend::localFromWorld(Vec3 world) const { return makeBendFrame(*this, Box3{}).localFromWorld(world); }

// ---- Builder --------------------------------------------------------------------------------

const Node& BlobTree::node(NodeId id) const {
  assert(id < nodes_.size());
  return nodes_[id];
}

void BlobTree::fail(const std::string& message) const { throw InputError(loc_, "blobtree: " + message); }

void BlobTree::check(NodeId id) const {
  if (id >= nodes_.size()) fail("unknown node id " + std::to_string(id));
}

namespace {
bool finitePositive(float v) { return std::isfinite(v) && v > 0.0f; }
bool finiteVec(Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
}  // namespace

NodeId BlobTree::add(Node n) {
  auto childBox = [&](size_t i) { return nodes_[n.children[i]].bounds; };
  auto childLip = [&](size_t i) { return nodes_[n.children[i]].lipschitz; };
  for (NodeId c : n.children) check(c);
  n.bounds = Box3{};
  n.lipschitz = 0.0f;
  if (isPrimitive(n.kind)) {
    Prim P = makePrim(n, kernel_);
    n.bounds = P.box;
    n.lipschitz = P.lipschitz;
  } else {
    switch (n.kind) {
      case NodeKind::Blend:
      case NodeKind::Ricci:
      case NodeKind::Pcm:
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds.extend(childBox(i));
          n.lipschitz += childLip(i);
        }
        if (n.kind == NodeKind::Pcm) n.lipschitz *= 1.0f + derivePcm(n.pcm).maxSlope;
        break;
      case NodeKind::Union:
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds.extend(childBox(i));
          n.lipschitz = std::max(n.lipschitz, childLip(i));
        }
        break;
      case NodeKind::Intersect:
        n.bounds = n.children.empty() ? Box3{} : childBox(0);
        for (size_t i = 0; i < n.children.size(); ++i) {
          n.bounds = n.bounds.intersected(childBox(i));
          n.lipschitz = std::max(n.lipschitz, childLip(i));
        }
        if (n.bounds.empty()) n.bounds = Box3{};
        break;
      case NodeKind::Difference:
        n.bounds = childBox(0);
        n.lipschitz = std::max(childLip(0), childLip(1));
        break;
      case NodeKind::Negative:
        n.bounds = childBox(0);
        n.lipschitz = std::abs(n.weight) * childLip(0);
        break;
      case NodeKind::Transform:
        n.bounds = transformBox(n.worldFromLocal, childBox(0));
        n.lipschitz = childLip(0) * spectralNorm(Mat3(n.localFromWorld));
        break;
      case NodeKind::Bend: {
        BendFrame f;
        try {
          f = makeBendFrame(n.bend, childBox(0));
        } catch (const std::invalid_argument& e) {
          fail(e.what());
        }
        n.bounds = f.worldBox(childBox(0));
        n.lipschitz = childLip(0) * f.jacobianBound(n.bounds);
        break;
      }
      case NodeKind::Twist: {
        float h0, h1, r;
        axialExtent(childBox(0), n.twist.origin, n.twist.axis, h0, h1, r);
        n.bounds = isHuge(childBox(0)) ? childBox(0) : cylinderBox(n.twist.origin, n.twist.axis, h0, h1, r);
        n.lipschitz = childLip(0) * (1.0f + std::abs(n.twist.rateRadPerUnit) * r);
        break;
      }
      case NodeKind::Taper: {
        float h0, h1, r;
        axialExtent(childBox(0), n.taper.origin, n.taper.axis, h0, h1, r);
        float s0 = taperScale(n.taper, h0), s1 = taperScale(n.taper, h1);
        if (!(s0 > 0.0f && s1 > 0.0f)) fail("taper: the scale must stay positive over the child's support");
        float smin = std::min(s0, s1), smax = std::max(s0, s1);
        n.bounds = isHuge(childBox(0)) ? childBox(0) : cylinderBox(n.taper.origin, n.taper.axis, h0, h1, r * smax);
        float ds = std::abs(n.taper.scale1 - n.taper.scale0) / n.taper.length;
        n.lipschitz = childLip(0) * (1.0f / smin + 1.0f + ds * r * smax / (smin * smin));
        break;
      }
      default: break;
    }
  }
  nodes_.push_back(std::move(n));
  return NodeId(nodes_.size() - 1);
}

NodeId BlobTree::point(Vec3 center, float radius, TextureAttr tex) {
  if (!finiteVec(center) || !finitePositive(radius)) fail("point: radius must be positive and finite");
  Node n;
  n.kind = NodeKind::Point;
  n.p0 = center;
  n.ra = radius;
  n.texture = tex;
  return add(std::move(n));
}

NodeId BlobTree::segment(Vec3 a, Vec3 b, float radius, TextureAttr tex) {
  if (!finiteVec(a) || !finiteVec(b) || !finitePositive(radius)) fail("segment: radius must be positive and finite");
  if (!(glm::length(b - a) > 0.0f)) fail("segment: the endpoints coincide");
  Node n;
  n.kind = NodeKind::Segment;
  n.p0 = a;
  n.p1 = b;
  n.ra = n.rb = radius;
  n.texture = tex;
  return add(std::move(n));
}

NodeId BlobTree::cone(Vec3 a, Vec3 b, float radiusA, float radiusB, TextureAttr tex) {
  if (!finiteVec(a) || !finiteVec(b) || !finitePositive(radiusA) || !finitePositive(radiusB))
    fail("cone: radii must be positive and finite");
  if (!(glm::length(b - a) > 0.0f)) fail("cone: the endpoints coincide");
  Node n;
  n.kind = NodeKind::Cone;
  n.p0 = a;
  n.p1 = b;
  n.ra = radiusA;
  n.rb = radiusB;
  n.texture = tex;
  return add(std::move(n));
}

NodeId BlobTree::torus(Vec3 center, Vec3 axis, float majorRadius, float minorRadius, TextureAttr tex) {
  if (!finiteVec(center) || !finitePositive(majorRadius) || !finitePositive(minorRadius))
    fail("torus: radii must be positive and finite");
  if (!(glm::length(axis) > 0.0f)) fail("torus: the axis is zero");
  Node n;
  n.kind = NodeKind::Torus;
  n.p0 = center;
  n.p1 = glm::normalize(axis);
  n.ra = majorRadius;
  n.rb = minorRadius;
  n.texture = tex;
  return add(std::move(n));
}

NodeId BlobTree::halfspace(Vec3 point, Vec3 normal, float ramp) {
  if (!finiteVec(point) || !(glm::length(normal) > 0.0f)) fail("halfspace: the normal is zero");
  if (!finitePositive(ramp)) fail("halfspace: ramp must be positive");
  Node n;
  n.kind = NodeKind::Halfspace;
  n.p0 = point;
  n.p1 = glm::normalize(normal);
  n.ra = ramp;
  return add(std::move(n));
}

NodeId BlobTree::box(Vec3 lo, Vec3 hi, float ramp) {
  if (!finiteVec(lo) || !finiteVec(hi) || !(lo.x < hi.x && lo.y < hi.y && lo.z < hi.z)) fail("box: need lo < hi on every axis");
  if (!finitePositive(ramp)) fail("box: ramp must be positive");
  Node n;
  n.kind = NodeKind::Box;
  n.p0 = lo;
  n.p1 = hi;
  n.ra = ramp;
  return add(std::move(n));
}

NodeId BlobTree::setWeight(NodeId primitive, float weight) {
  check(primitive);
  Node& n = nodes_[primitive];
  if (!isPrimitive(n.kind)) fail("setWeight: node is not a primitive");
  if (!std::isfinite(weight)) fail("setWeight: weight must be finite");
  n.weight = weight;
  Prim P = makePrim(n, kernel_);
  n.bounds = P.box;
  n.lipschitz = P.lipschitz;
  return primitive;
}

NodeId BlobTree::blend(std::span<const NodeId> children) {
  Node n;
  n.kind = NodeKind::Blend;
  n.children.assign(children.begin(), children.end());
  return add(std::move(n));
}

NodeId BlobTree::ricci(std::span<const NodeId> children, float exponent) {
  if (!(std::isfinite(exponent) && exponent >= 1.0f)) fail("ricci: n must be >= 1");
  Node n;
  n.kind = NodeKind::Ricci;
  n.exponent = exponent;
  n.children.assign(children.begin(), children.end());
  return add(std::move(n));
}

NodeId BlobTree::unite(std::span<const NodeId> children) {
  Node n;
  n.kind = NodeKind::Union;
  n.children.assign(children.begin(), children.end());
  return add(std::move(n));
}

NodeId BlobTree::intersect(std::span<const NodeId> children) {
  if (children.empty()) fail("intersect: needs at least one child");
  Node n;
  n.kind = NodeKind::Intersect;
  n.children.assign(children.begin(), children.end());
  return add(std::move(n));
}

NodeId BlobTree::difference(NodeId a, NodeId b) {
  Node n;
  n.kind = NodeKind::Difference;
  n.children = {a, b};
  return add(std::move(n));
}

NodeId BlobTree::controlledBlend(std::span<const NodeId> children, const std::vector<std::vector<uint32_t>>& groups) {
  std::vector<bool> grouped(children.size(), false);
  std::vector<NodeId> parts;
  for (const auto& g : groups) {
    std::vector<NodeId> members;
    for (uint32_t i : g) {
      if (i >= children.size()) fail("controlledBlend: group index " + std::to_string(i) + " out of range");
      members.push_back(children[i]);
      grouped[i] = true;
    }
    if (members.empty()) continue;
    parts.push_back(members.size() == 1 ? members[0] : blend(members));
  }
  for (size_t i = 0; i < children.size(); ++i)
    if (!grouped[i]) parts.push_back(children[i]);
  return unite(parts);
}

NodeId BlobTree::pcm(std::span<const NodeId> children, PcmParams params) {
  if (!(params.width > 0.0f && params.width <= params.iso)) fail("pcm: width must be in (0, iso]");
  if (!(params.slope >= 0.0f && std::isfinite(params.slope))) fail("pcm: slope must be >= 0");
  if (!(params.bulgeScale >= 0.0f && std::isfinite(params.bulgeScale))) fail("pcm: bulgeScale must be >= 0");
  Node n;
  n.kind = NodeKind::Pcm;
  n.pcm = params;
  n.children.assign(children.begin(), children.end());
  return add(std::move(n));
}

NodeId BlobTree::pcm(NodeId a, NodeId b, PcmParams params) {
  NodeId c[2] = {a, b};
  return pcm(std::span<const NodeId>(c, 2), params);
}

NodeId BlobTree::negative(NodeId child, float weight) {
  if (!(std::isfinite(weight) && weight >= 0.0f)) fail("negative: weight must be >= 0");
  Node n;
  n.kind = NodeKind::Negative;
  n.weight = weight;
  n.children = {child};
  return add(std::move(n));
}

NodeId BlobTree::transform(NodeId child, const Mat4& worldFromLocal) {
  float det = glm::determinant(worldFromLocal);
  if (!std::isfinite(det) || std::abs(det) < 1e-12f) fail("transform: the matrix is not invertible");
  Node n;
  n.kind = NodeKind::Transform;
  n.worldFromLocal = worldFromLocal;
  n.localFromWorld = glm::inverse(worldFromLocal);
  n.children = {child};
  return add(std::move(n));
}

NodeId BlobTree::translate(NodeId child, Vec3 offset) { return transform(child, glm::translate(Mat4(1.0f), offset)); }
NodeId BlobTree::scale(NodeId child, Vec3 factors) { return transform(child, glm::scale(Mat4(1.0f), factors)); }
NodeId BlobTree::rotate(NodeId child, Vec3 axis, float angleRad) {
  if (!(glm::length(axis) > 0.0f)) fail("rotate: the axis is zero");
  return transform(child, glm::rotate(Mat4(1.0f), angleRad, glm::normalize(axis)));
}

NodeId BlobTree::bend(NodeId child, const Bend& b) {
  if (!(b.sagitta >= 0.0f && std::isfinite(b.sagitta))) fail("bend: sagitta must be >= 0");
  if (!(glm::length(b.b - b.a) > 0.0f)) fail("bend: the segment a-b has zero length");
  if (b.sagitta > glm::length(b.b - b.a)) fail("bend: sagitta must not exceed the chord length");
  Node n;
  n.kind = NodeKind::Bend;
  n.bend = b;
  n.children = {child};
  return add(std::move(n));
}

NodeId BlobTree::bend(NodeId child, Vec3 a, Vec3 b, float sagitta, Vec3 direction) {
  Bend bd;
  bd.a = a;
  bd.b = b;
  bd.sagitta = sagitta;
  bd.direction = direction;
  return bend(child, bd);
}

NodeId BlobTree::twist(NodeId child, const Twist& t) {
  if (!(glm::length(t.axis) > 0.0f)) fail("twist: the axis is zero");
  Node n;
  n.kind = NodeKind::Twist;
  n.twist = t;
  n.twist.axis = glm::normalize(t.axis);
  n.children = {child};
  return add(std::move(n));
}

NodeId BlobTree::taper(NodeId child, const Taper& t) {
  if (!(glm::length(t.axis) > 0.0f)) fail("taper: the axis is zero");
  if (!finitePositive(t.length)) fail("taper: length must be positive");
  Node n;
  n.kind = NodeKind::Taper;
  n.taper = t;
  n.taper.axis = glm::normalize(t.axis);
  n.children = {child};
  return add(std::move(n));
}

// ---- Reference evaluator ------------------------------------------------------------------

float BlobTree::value(NodeId id, Vec3 p) const {
  check(id);
  const Node& n = nodes_[id];
  if (isPrimitive(n.kind)) return primValue(makePrim(n, kernel_), p, nullptr);
  switch (n.kind) {
    case NodeKind::Blend: {
      float s = 0.0f;
      for (NodeId c : n.children) s += value(c, p);
      return s;
    }
    case NodeKind::Ricci: {
      float m = 0.0f, sum = 0.0f;
      for (NodeId c : n.children) {
        float f = std::max(0.0f, value(c, p));
        if (f <= 0.0f) continue;
        if (f > m) {
          sum = (m > 0.0f ? sum * std::pow(m / f, n.exponent) : 0.0f) + 1.0f;
          m = f;
        } else {
          sum += std::pow(f / m, n.exponent);
        }
      }
      return m > 0.0f ? m * std::pow(sum, 1.0f / n.exponent) : 0.0f;
    }
    case NodeKind::Union: {
      float m = 0.0f;
      for (NodeId c : n.children) m = std::max(m, value(c, p));
      return m;
    }
    case NodeKind::Intersect: {
      float m = std::numeric_limits<float>::max();
      for (NodeId c : n.children) m = std::min(m, value(c, p));
      return std::max(0.0f, m);
    }
    case NodeKind::Difference:
      return std::max(0.0f, std::min(value(n.children[0], p), 1.0f - value(n.children[1], p)));
    case NodeKind::Pcm: {
      PcmDerived d = derivePcm(n.pcm);
      float fmax = 0.0f, dsum = 0.0f, dmax = 0.0f;
      for (NodeId c : n.children) {
        float f = std::max(0.0f, value(c, p));
        float dd = pcmD(d, f, nullptr);
        dsum += dd;
        if (f > fmax) { fmax = f; dmax = dd; }
      }
      return fmax > 0.0f ? std::max(0.0f, fmax + dsum - dmax) : 0.0f;
    }
    case NodeKind::Negative: return -n.weight * value(n.children[0], p);
    case NodeKind::Transform: return value(n.children[0], Vec3(n.localFromWorld * Vec4(p, 1.0f)));
    case NodeKind::Bend:
      return value(n.children[0], makeBendFrame(n.bend, nodes_[n.children[0]].bounds).localFromWorld(p));
    case NodeKind::Twist: return value(n.children[0], twistLocal(n.twist, p, nullptr));
    case NodeKind::Taper: return value(n.children[0], taperLocal(n.taper, p, nullptr));
    default: return 0.0f;
  }
}

}  // namespace sprig::blobtree
