#pragma once
/// Private: primitive field math (kernels, the derived form of a primitive node, its
/// value, gradient, natural uv and interval bound over a box), shared by the builder's
/// reference evaluator and the compiled tape.

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace sprig::blobtree::detail {

inline constexpr float kWyvillIso = 0.45420202f;    ///< iso radius / R of (1−s)³ at 0.5
inline constexpr float kWyvillSlope = 1.7173002f;   ///< max |dφ/dx|, φ(x) = (1−x²)³
inline constexpr float kSoftSlope = 1.5834298f;     ///< max |dφ/dx| of the soft-object kernel
inline constexpr float kTwoPi = 6.28318530718f;

/// g(s) for s in [0, 1] (caller clamps).
inline float kernelG(Kernel k, float s) {
  if (k == Kernel::Wyvill) {
    float u = 1.0f - s;
    return u * u * u;
  }
  return 1.0f + s * (-22.0f / 9.0f + s * (17.0f / 9.0f - s * (4.0f / 9.0f)));
}
/// dg/ds for s in [0, 1].
inline float kernelDG(Kernel k, float s) {
  if (k == Kernel::Wyvill) {
    float u = 1.0f - s;
    return -3.0f * u * u;
  }
  return -22.0f / 9.0f + s * (34.0f / 9.0f - s * (12.0f / 9.0f));
}

/// A primitive with every derived quantity evaluation needs.
struct Prim {
  NodeKind kind = NodeKind::Point;
  Kernel kernel = Kernel::Wyvill;
  Vec3 a{0.0f}, ab{0.0f};  ///< point centre / segment start and direction; torus centre
  float invLen2 = 0.0f, len = 0.0f;
  float R0 = 1.0f, dR = 0.0f;  ///< support radius R(t) = R0 + dR·t
  float weight = 1.0f;
  Vec3 axis{0.0f, 1.0f, 0.0f};  ///< torus axis; halfspace normal
  float major = 0.0f;           ///< torus major radius
  Vec3 lo{0.0f}, hi{0.0f};      ///< box cutter
  float invRamp = 1.0f;
  Vec3 e1{1.0f, 0.0f, 0.0f}, e2{0.0f, 0.0f, 1.0f};  ///< uv frame perpendicular to the axis
  TextureAttr tex;
  bool hasAttributes = true;
  Box3 box;
  float lipschitz = 0.0f;
  float isoRadiusMin = 0.0f;
  float isoRadiusMax = 0.0f;  ///< largest 0.5-iso radius (a cone's thick end); 0 for unsized kinds
};

/// Builds the Prim of a primitive node.
Prim makePrim(const Node& n, Kernel kernel);

/// Signed distance to the box [lo, hi] and its gradient.
inline float sdBox(Vec3 p, Vec3 lo, Vec3 hi, Vec3* grad) {
  Vec3 c = 0.5f * (lo + hi), h = 0.5f * (hi - lo);
  Vec3 q = glm::abs(p - c) - h;
  Vec3 s{p.x < c.x ? -1.0f : 1.0f, p.y < c.y ? -1.0f : 1.0f, p.z < c.z ? -1.0f : 1.0f};
  Vec3 qo = glm::max(q, Vec3(0.0f));
  float outside = glm::length(qo);
  float inside = std::min(std::max(q.x, std::max(q.y, q.z)), 0.0f);
  if (grad) {
    if (outside > 0.0f) {
      *grad = s * qo / outside;
    } else {
      int ax = (q.x >= q.y && q.x >= q.z) ? 0 : (q.y >= q.z ? 1 : 2);
      Vec3 g{0.0f};
      g[ax] = s[ax];
      *grad = g;
    }
  }
  return outside + inside;
}

/// Field of a primitive at p; when grad is non-null also its gradient.
inline float primValue(const Prim& P, Vec3 p, Vec3* grad) {
  switch (P.kind) {
    case NodeKind::Point: {
      Vec3 d = p - P.a;
      float invR2 = 1.0f / (P.R0 * P.R0);
      float s = glm::dot(d, d) * invR2;
      if (s >= 1.0f) { if (grad) *grad = Vec3(0.0f); return 0.0f; }
      if (grad) *grad = (P.weight * kernelDG(P.kernel, s) * 2.0f * invR2) * d;
      return P.weight * kernelG(P.kernel, s);
    }
    case NodeKind::Segment:
    case NodeKind::Cone: {
      Vec3 ap = p - P.a;
      float traw = glm::dot(ap, P.ab) * P.invLen2;
      float t = std::clamp(traw, 0.0f, 1.0f);
      Vec3 dv = ap - t * P.ab;
      float d2 = glm::dot(dv, dv);
      float R = P.R0 + P.dR * t;
      float invR2 = 1.0f / (R * R);
      float s = d2 * invR2;
      if (s >= 1.0f) { if (grad) *grad = Vec3(0.0f); return 0.0f; }
      if (grad) {
        // ∇s = 2 d/R² − 2 d² R'(t)/R³ ∇t, ∇t = ab/|ab|² inside the segment.
        Vec3 gs = (2.0f * invR2) * dv;
        if (traw > 0.0f && traw < 1.0f) gs -= (2.0f * d2 * invR2 * P.dR / R * P.invLen2) * P.ab;
        *grad = (P.weight * kernelDG(P.kernel, s)) * gs;
      }
      return P.weight * kernelG(P.kernel, s);
    }
    case NodeKind::Torus: {
      Vec3 q = p - P.a;
      float h = glm::dot(q, P.axis);
      Vec3 perp = q - h * P.axis;
      float rho = glm::length(perp);
      float dr = rho - P.major;
      float invR2 = 1.0f / (P.R0 * P.R0);
      float s = (dr * dr + h * h) * invR2;
      if (s >= 1.0f) { if (grad) *grad = Vec3(0.0f); return 0.0f; }
      if (grad) {
        Vec3 radial = rho > 1e-20f ? perp / rho : Vec3(0.0f);
        *grad = (P.weight * kernelDG(P.kernel, s) * 2.0f * invR2) * (dr * radial + h * P.axis);
      }
      return P.weight * kernelG(P.kernel, s);
    }
    case NodeKind::Halfspace: {
      float sd = glm::dot(p - P.a, P.axis);
      float f = 0.5f - sd * P.invRamp;
      if (f <= 0.0f || f >= 1.0f) { if (grad) *grad = Vec3(0.0f); return P.weight * std::clamp(f, 0.0f, 1.0f); }
      if (grad) *grad = (-P.weight * P.invRamp) * P.axis;
      return P.weight * f;
    }
    case NodeKind::Box: {
      Vec3 g;
      float sd = sdBox(p, P.lo, P.hi, grad ? &g : nullptr);
      float f = 0.5f - sd * P.invRamp;
      if (f <= 0.0f || f >= 1.0f) { if (grad) *grad = Vec3(0.0f); return P.weight * std::clamp(f, 0.0f, 1.0f); }
      if (grad) *grad = (-P.weight * P.invRamp) * g;
      return P.weight * f;
    }
    default: return 0.0f;
  }
}

/// Natural (u,v) of a primitive at p, after its uv transform.
Vec2 primUv(const Prim& P, Vec3 p);

/// Sound interval of a primitive's field over box.
Interval primInterval(const Prim& P, const Box3& box);

/// |dφ/dx| of the radial profile φ(x) = g(x²) at x = r/R (0 for x >= 1); its maximum over
/// x is kernelSlope. Unimodal on [0, 1]: rises to kernelSlopeArg, then falls to 0 at x = 1.
float kernelSlopeAt(Kernel k, float x);
/// The x = r/R where |dφ/dx| is largest: 1/√5 (Wyvill), 0.50347 (soft objects).
float kernelSlopeArg(Kernel k);

/// Local Lipschitz bound of a primitive's field over box: a point, segment, cone or torus
/// gets its profile's largest slope over the box's range of r/R (kernelSlopeAt, widened
/// for rounding), which is 0 where the box misses the support and small where the box lies
/// deep inside or near the rim; a halfspace or a box 0 where its ramp is flat over the box;
/// never more than P.lipschitz.
float primLipschitz(const Prim& P, const Box3& box);

/// Distance from p to segment [a, a+ab].
inline float distToSegment(Vec3 p, Vec3 a, Vec3 ab, float invLen2) {
  float t = std::clamp(glm::dot(p - a, ab) * invLen2, 0.0f, 1.0f);
  return glm::length(p - a - t * ab);
}

}  // namespace sprig::blobtree::detail
