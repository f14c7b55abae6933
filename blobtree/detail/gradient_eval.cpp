#include "blobtree/detail/gradient_eval.h"

#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <limits>

namespace sprig::blobtree::detail {

namespace {

// The steps of evalS for the nodes that need more than a few lines, each called from one
// place (GCC 12 inlines all but primitiveS; sample throughput is unchanged).

/// A primitive's value and gradient, with its attributes weighted by the value.
SV primitiveS(const Prim& P, Vec3 p) {
  SV r;
  r.v = primValue(P, p, &r.g);
  if (P.hasAttributes && r.v > 0.0f) {
    const Vec2 uv = primUv(P, p);
    r.acc.uvSum = r.v * uv;
    r.acc.wSum = r.v;
    r.acc.addTexture(P.tex.textureId, r.v);
    r.acc.addLayer(Attributes::Layer{uv, P.tex.textureId, r.v});
  }
  return r;
}

/// Ricci: F = m·S^(1/n); ∇F = Σ (fᵢ/F)^(n−1) ∇fᵢ = G·S^(−(n−1)/n), G = Σ (fᵢ/m)^(n−1) ∇fᵢ.
SV ricciS(const Tape& T, const TNode& n, Vec3 p) {
  SV r;
  float m = 0.0f, S = 0.0f, e = n.exponent;
  Vec3 G{0.0f};
  childrenAt(T, n, p, [&](uint32_t c) {
    SV s = evalS(T, c, p);
    if (s.v <= 0.0f) return;
    r.acc.merge(s.acc);
    if (s.v > m) {
      float k = m > 0.0f ? m / s.v : 0.0f;
      S = S * std::pow(k, e) + 1.0f;
      G = G * std::pow(k, e - 1.0f) + s.g;
      m = s.v;
    } else {
      float q = s.v / m;
      S += std::pow(q, e);
      G += std::pow(q, e - 1.0f) * s.g;
    }
  });
  if (m > 0.0f) {
    r.v = m * std::pow(S, 1.0f / e);
    r.g = G * std::pow(S, -(e - 1.0f) / e);
  }
  return r;
}

/// Intersection: the smallest child's value and gradient, the first child's attributes.
SV intersectS(const Tape& T, const TNode& n, Vec3 p) {
  SV r, best;
  best.v = std::numeric_limits<float>::max();
  AttrAcc first;
  for (uint32_t i = 0; i < n.count; ++i) {
    SV s = evalS(T, T.kids[n.first + i], p);
    if (i == 0) first = s.acc;
    if (s.v < best.v) best = s;
  }
  if (best.v <= 0.0f) return r;
  r.v = best.v;
  r.g = best.g;
  r.acc = first;
  return r;
}

/// Difference min(f_a, 1 − f_b) with a's attributes.
SV differenceS(const Tape& T, const TNode& n, Vec3 p) {
  SV r;
  SV a = evalS(T, T.kids[n.first], p);
  if (a.v <= 0.0f) return r;
  SV b = evalS(T, T.kids[n.first + 1], p);
  float nb = 1.0f - b.v;
  if (nb <= 0.0f) return r;
  r.acc = a.acc;
  if (a.v <= nb) { r.v = a.v; r.g = a.g; }
  else { r.v = nb; r.g = -b.g; }
  return r;
}

/// PCM (tree paper Eq. 3, PcmAccum): F = f_max + Σ_{j≠max, f_j <= c} d(f_j) + min(0, d(f_second));
/// ∇F = ∇f_max + Σ_{j≠max, f_j <= c} d'(f_j)∇f_j + [f_second > c] d'(f_second)∇f_second.
SV pcmS(const Tape& T, const TNode& n, Vec3 p) {
  SV r;
  PcmAccum acc;
  float dp1 = 0.0f, dp2 = 0.0f;          // d'(f) of the strongest and second strongest child
  Vec3 g1{0.0f}, g2{0.0f};               // and their field gradients
  Vec3 gBulge{0.0f};                     // Σ d'(f_j)∇f_j over the children with f_j <= c
  float close1 = 0.0f, close2 = 0.0f;  // the two largest closenesses to contact
  Vec3 grad1{0.0f}, grad2{0.0f};        // and their gradients
  const PcmDerived& pp = params(T, n).pcm;
  childrenAt(T, n, p, [&](uint32_t c) {
    SV s = evalS(T, c, p);
    float f = std::max(0.0f, s.v);
    if (s.v < 0.0f) s.g = Vec3(0.0f);
    // Closeness is increasing in f, so the strongest child has the largest; the contact is
    // the second largest (the strongest non-maximal child's).
    const float close = f > 0.0f ? std::clamp(1.0f - (pp.c - f) / pp.w, 0.0f, 1.0f) : 0.0f;
    const Vec3 grad = close > 0.0f && close < 1.0f ? s.g / pp.w : Vec3(0.0f);  // ∇close = ∇f / w inside the band
    if (close > close1) {
      close2 = close1;
      grad2 = grad1;
      close1 = close;
      grad1 = grad;
    } else if (close > close2) {
      close2 = close;
      grad2 = grad;
    }
    float dp;
    float d = pcmD(pp, f, &dp);
    if (d >= 0.0f) gBulge += dp * s.g;
    r.acc.merge(s.acc);
    if (f > acc.f1) {
      dp2 = dp1;
      g2 = g1;
      dp1 = dp;
      g1 = s.g;
    } else if (f > acc.f2) {
      dp2 = dp;
      g2 = s.g;
    }
    acc.add(f, d);
  });
  if (acc.f1 <= 0.0f) return r;
  if (close2 > r.acc.contact) {
    r.acc.contact = close2;
    r.acc.contactGrad = grad2;
  }
  r.v = acc.value();
  if (r.v <= 0.0f) { r.v = 0.0f; return r; }
  r.g = g1 + gBulge;
  if (acc.d1 >= 0.0f) r.g -= dp1 * g1;
  if (acc.d2 < 0.0f) r.g += dp2 * g2;
  return r;
}

/// A warp or transform: the child at the local point, its gradient pulled back through jt.
SV warpS(const Tape& T, const TNode& n, Vec3 p) {
  Mat3 jt;
  Vec3 q = warpLocal(T, n, p, &jt);
  SV s = evalS(T, T.kids[n.first], q);
  s.g = jt * s.g;
  return s;
}

}  // namespace

SV evalS(const Tape& T, uint32_t ni, Vec3 p) {
  const TNode& n = T.nodes[ni];
  SV r;
  if (!n.box.contains(p)) return r;
  if (isPrimitive(n.kind)) return primitiveS(T.prim(n.prim), p);
  switch (n.kind) {
    case NodeKind::Blend:
      childrenAt(T, n, p, [&](uint32_t c) {
        SV s = evalS(T, c, p);
        r.v += s.v;
        r.g += s.g;
        r.acc.merge(s.acc);
      });
      return r;
    case NodeKind::Ricci: return ricciS(T, n, p);
    case NodeKind::Union:
      childrenAt(T, n, p, [&](uint32_t c) {
        SV s = evalS(T, c, p);
        if (s.v > r.v) r = s;
      });
      return r;
    case NodeKind::Intersect: return intersectS(T, n, p);
    case NodeKind::Difference: return differenceS(T, n, p);
    case NodeKind::Pcm: return pcmS(T, n, p);
    case NodeKind::Negative: {
      SV s = evalS(T, T.kids[n.first], p);
      r.v = -n.weight * s.v;
      r.g = -n.weight * s.g;
      return r;
    }
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: return warpS(T, n, p);
    default: break;  // the primitive kinds, sampled above
  }
  return r;
}

}  // namespace sprig::blobtree::detail
