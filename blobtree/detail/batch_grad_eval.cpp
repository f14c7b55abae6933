#include "blobtree/detail/batch_grad_eval.h"

#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sprig::blobtree::detail {

namespace {

constexpr int kBlock = 64;  ///< points per batch

struct Pts {
  const float* x;
  const float* y;
  const float* z;
  int n;
};

/// Value and gradient of one node over a batch, structure of arrays.
struct VG {
  float v[kBlock], gx[kBlock], gy[kBlock], gz[kBlock];
  void zero(int n) {
    std::fill(v, v + n, 0.0f);
    std::fill(gx, gx + n, 0.0f);
    std::fill(gy, gy + n, 0.0f);
    std::fill(gz, gz + n, 0.0f);
  }
  Vec3 g(int i) const { return Vec3(gx[i], gy[i], gz[i]); }
  void set(int i, float value, Vec3 grad) {
    v[i] = value;
    gx[i] = grad.x;
    gy[i] = grad.y;
    gz[i] = grad.z;
  }
};

void evalBG(const Tape& T, uint32_t ni, const Pts& pts, const Box3& pbox, VG& out);

/// Ricci (ricciS): F = m·S^(1/n), ∇F = G·S^(−(n−1)/n) with G = Σ (fᵢ/m)^(n−1) ∇fᵢ.
void ricciBG(const Tape& T, const TNode& n, const Pts& pts, const Box3& pbox, VG& out) {
  alignas(32) float S[kBlock], Gx[kBlock], Gy[kBlock], Gz[kBlock];
  out.zero(pts.n);  // v holds the running max m
  std::fill(S, S + pts.n, 0.0f);
  std::fill(Gx, Gx + pts.n, 0.0f);
  std::fill(Gy, Gy + pts.n, 0.0f);
  std::fill(Gz, Gz + pts.n, 0.0f);
  const float e = n.exponent;
  VG c;
  childrenIn(T, n, pbox, [&](uint32_t ci) {
    evalBG(T, ci, pts, pbox, c);
    for (int i = 0; i < pts.n; ++i) {
      const float f = c.v[i], m = out.v[i];
      if (f <= 0.0f) continue;
      if (f > m) {
        const float k = m > 0.0f ? m / f : 0.0f;
        const float ke = std::pow(k, e), ke1 = std::pow(k, e - 1.0f);
        S[i] = S[i] * ke + 1.0f;
        Gx[i] = Gx[i] * ke1 + c.gx[i];
        Gy[i] = Gy[i] * ke1 + c.gy[i];
        Gz[i] = Gz[i] * ke1 + c.gz[i];
        out.v[i] = f;
      } else {
        const float q = f / m, qe1 = std::pow(q, e - 1.0f);
        S[i] += std::pow(q, e);
        Gx[i] += qe1 * c.gx[i];
        Gy[i] += qe1 * c.gy[i];
        Gz[i] += qe1 * c.gz[i];
      }
    }
  });
  for (int i = 0; i < pts.n; ++i) {
    if (!(out.v[i] > 0.0f)) continue;
    const float s = std::pow(S[i], -(e - 1.0f) / e);
    out.v[i] = out.v[i] * std::pow(S[i], 1.0f / e);
    out.gx[i] = Gx[i] * s;
    out.gy[i] = Gy[i] * s;
    out.gz[i] = Gz[i] * s;
  }
}

/// PCM (pcmS without the contact attribute): F = PcmAccum::value();
/// ∇F = ∇f_max + Σ_{d_j >= 0} d'(f_j)∇f_j − [d_max >= 0] d'(f_max)∇f_max + [d_second < 0] d'(f_second)∇f_second.
void pcmBG(const Tape& T, const TNode& n, const Pts& pts, const Box3& pbox, VG& out) {
  PcmAccum acc[kBlock];
  float dp1[kBlock], dp2[kBlock];
  Vec3 g1[kBlock], g2[kBlock], gBulge[kBlock];
  for (int i = 0; i < pts.n; ++i) {
    acc[i] = PcmAccum{};
    dp1[i] = dp2[i] = 0.0f;
    g1[i] = g2[i] = gBulge[i] = Vec3(0.0f);
  }
  const PcmDerived& pp = params(T, n).pcm;
  VG c;
  childrenIn(T, n, pbox, [&](uint32_t ci) {
    evalBG(T, ci, pts, pbox, c);
    for (int i = 0; i < pts.n; ++i) {
      const float f = std::max(0.0f, c.v[i]);
      const Vec3 g = c.v[i] < 0.0f ? Vec3(0.0f) : c.g(i);
      float dp;
      const float d = pcmD(pp, f, &dp);
      if (d >= 0.0f) gBulge[i] += dp * g;
      if (f > acc[i].f1) {
        dp2[i] = dp1[i];
        g2[i] = g1[i];
        dp1[i] = dp;
        g1[i] = g;
      } else if (f > acc[i].f2) {
        dp2[i] = dp;
        g2[i] = g;
      }
      acc[i].add(f, d);
    }
  });
  for (int i = 0; i < pts.n; ++i) {
    out.set(i, 0.0f, Vec3(0.0f));
    if (acc[i].f1 <= 0.0f) continue;
    const float v = acc[i].value();
    if (v <= 0.0f) continue;
    Vec3 g = g1[i] + gBulge[i];
    if (acc[i].d1 >= 0.0f) g -= dp1[i] * g1[i];
    if (acc[i].d2 < 0.0f) g += dp2[i] * g2[i];
    out.set(i, v, g);
  }
}

/// A warp or transform: the child at the local points, gradients pulled back through jt.
void warpBG(const Tape& T, const TNode& n, const Pts& pts, VG& out) {
  alignas(32) float lx[kBlock], ly[kBlock], lz[kBlock];
  Mat3 jt[kBlock];
  Box3 lb;
  for (int i = 0; i < pts.n; ++i) {
    const Vec3 q = warpLocal(T, n, Vec3(pts.x[i], pts.y[i], pts.z[i]), &jt[i]);
    lx[i] = q.x;
    ly[i] = q.y;
    lz[i] = q.z;
    lb.extend(q);
  }
  const Pts lp{lx, ly, lz, pts.n};
  evalBG(T, T.kids[n.first], lp, lb, out);
  for (int i = 0; i < pts.n; ++i) {
    const Vec3 g = jt[i] * out.g(i);
    out.gx[i] = g.x;
    out.gy[i] = g.y;
    out.gz[i] = g.z;
  }
}

void evalNode(const Tape& T, const TNode& n, const Pts& pts, const Box3& pbox, VG& out) {
  if (!pbox.overlaps(n.box)) {
    out.zero(pts.n);
    return;
  }
  if (isPrimitive(n.kind)) {
    // evalS's test: F = 0 and no gradient outside the support box.
    const Prim& P = T.prim(n.prim);
    for (int i = 0; i < pts.n; ++i) {
      const Vec3 p(pts.x[i], pts.y[i], pts.z[i]);
      Vec3 g(0.0f);
      const float v = n.box.contains(p) ? primValue(P, p, &g) : 0.0f;
      out.set(i, v, g);
    }
    return;
  }
  switch (n.kind) {
    case NodeKind::Blend: {
      out.zero(pts.n);
      VG c;
      childrenIn(T, n, pbox, [&](uint32_t ci) {
        evalBG(T, ci, pts, pbox, c);
        for (int i = 0; i < pts.n; ++i) {
          out.v[i] += c.v[i];
          out.gx[i] += c.gx[i];
          out.gy[i] += c.gy[i];
          out.gz[i] += c.gz[i];
        }
      });
      return;
    }
    case NodeKind::Union: {
      out.zero(pts.n);
      VG c;
      childrenIn(T, n, pbox, [&](uint32_t ci) {
        evalBG(T, ci, pts, pbox, c);
        for (int i = 0; i < pts.n; ++i)
          if (c.v[i] > out.v[i]) out.set(i, c.v[i], c.g(i));
      });
      return;
    }
    case NodeKind::Intersect: {
      std::fill(out.v, out.v + pts.n, std::numeric_limits<float>::max());
      VG c;
      for (uint32_t k = 0; k < n.count; ++k) {
        evalBG(T, T.kids[n.first + k], pts, pbox, c);
        for (int i = 0; i < pts.n; ++i)
          if (c.v[i] < out.v[i]) out.set(i, c.v[i], c.g(i));
      }
      for (int i = 0; i < pts.n; ++i)
        if (out.v[i] <= 0.0f) out.set(i, 0.0f, Vec3(0.0f));
      return;
    }
    case NodeKind::Difference: {
      VG b;
      evalBG(T, T.kids[n.first], pts, pbox, out);
      evalBG(T, T.kids[n.first + 1], pts, pbox, b);
      for (int i = 0; i < pts.n; ++i) {
        const float nb = 1.0f - b.v[i];
        if (out.v[i] <= 0.0f || nb <= 0.0f) out.set(i, 0.0f, Vec3(0.0f));
        else if (out.v[i] > nb) out.set(i, nb, -b.g(i));
      }
      return;
    }
    case NodeKind::Ricci: ricciBG(T, n, pts, pbox, out); return;
    case NodeKind::Pcm: pcmBG(T, n, pts, pbox, out); return;
    case NodeKind::Negative:
      evalBG(T, T.kids[n.first], pts, pbox, out);
      for (int i = 0; i < pts.n; ++i) {
        out.v[i] *= -n.weight;
        out.gx[i] *= -n.weight;
        out.gy[i] *= -n.weight;
        out.gz[i] *= -n.weight;
      }
      return;
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: warpBG(T, n, pts, out); return;
    default: out.zero(pts.n); return;
  }
}

void evalBG(const Tape& T, uint32_t ni, const Pts& pts, const Box3& pbox, VG& out) {
  const TNode& n = T.nodes[ni];
  evalNode(T, n, pts, pbox, out);
  // evalS's test at every node: F = 0 and no gradient outside the support box.
  if (isPrimitive(n.kind) || (n.box.contains(pbox.lo) && n.box.contains(pbox.hi))) return;
  for (int i = 0; i < pts.n; ++i)
    if (!n.box.contains(Vec3(pts.x[i], pts.y[i], pts.z[i]))) out.set(i, 0.0f, Vec3(0.0f));
}

}  // namespace

void evalBatchGradient(const Tape& T, std::span<const Vec3> points, std::span<float> value, std::span<Vec3> gradient) {
  alignas(32) float x[kBlock], y[kBlock], z[kBlock];
  VG r;
  for (size_t b = 0; b < points.size(); b += kBlock) {
    const int n = int(std::min<size_t>(kBlock, points.size() - b));
    Box3 box;
    for (int i = 0; i < n; ++i) {
      const Vec3& p = points[b + size_t(i)];
      x[i] = p.x;
      y[i] = p.y;
      z[i] = p.z;
      box.extend(p);
    }
    evalBG(T, T.root, Pts{x, y, z, n}, box, r);
    for (int i = 0; i < n; ++i) {
      value[b + size_t(i)] = r.v[i];
      gradient[b + size_t(i)] = r.g(i);
    }
  }
}

}  // namespace sprig::blobtree::detail
