#include "blobtree/detail/primitive.h"

#include "blobtree/detail/geometry.h"

#include <cassert>

namespace sprig::blobtree::detail {

namespace {

Box3 sphereBox(Vec3 c, float r) { return Box3{c - r, c + r}; }

}  // namespace

Prim makePrim(const Node& n, Kernel kernel) {
  Prim P;
  P.kind = n.kind;
  P.kernel = kernel;
  P.weight = n.weight;
  P.tex = n.texture;
  P.hasAttributes = !n.texture.relief;
  float slope = kernelSlope(kernel) * std::abs(n.weight);
  switch (n.kind) {
    case NodeKind::Point: {
      P.a = n.p0;
      P.R0 = supportRadius(kernel, n.ra);
      P.box = sphereBox(P.a, P.R0);
      P.lipschitz = slope / P.R0;
      P.isoRadiusMin = P.isoRadiusMax = n.ra;
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
      P.isoRadiusMax = std::max(n.ra, rb);
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
      P.isoRadiusMin = P.isoRadiusMax = n.rb;
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

namespace {

/// The range of distances r from box to a sized primitive's core (point, segment, circle)
/// and of its support radius R over the box, from the box's centre widened by its half
/// diagonal. False for unsized kinds.
struct DistanceRange {
  float dmin, dmax, Rmin, Rmax;
};

bool distanceRange(const Prim& P, const Box3& box, DistanceRange& r) {
  const Vec3 c = box.center(), h = 0.5f * box.size();
  const float hd = glm::length(h);
  switch (P.kind) {
    case NodeKind::Point: {
      Vec3 q = glm::clamp(P.a, box.lo, box.hi);
      r = {glm::length(q - P.a), glm::length(glm::max(glm::abs(P.a - box.lo), glm::abs(P.a - box.hi))), P.R0, P.R0};
      return true;
    }
    case NodeKind::Segment:
    case NodeKind::Cone: {
      float dc = distToSegment(c, P.a, P.ab, P.invLen2);
      float tc = glm::dot(c - P.a, P.ab) * P.invLen2;
      float te = glm::dot(h, glm::abs(P.ab)) * P.invLen2;
      float t0 = std::clamp(tc - te, 0.0f, 1.0f), t1 = std::clamp(tc + te, 0.0f, 1.0f);
      float Ra = P.R0 + P.dR * t0, Rb = P.R0 + P.dR * t1;
      r = {std::max(0.0f, dc - hd), dc + hd, std::min(Ra, Rb), std::max(Ra, Rb)};
      return true;
    }
    case NodeKind::Torus: {
      Vec3 q = c - P.a;
      float hh = glm::dot(q, P.axis);
      float rho = glm::length(q - hh * P.axis);
      float dc = std::sqrt((rho - P.major) * (rho - P.major) + hh * hh);
      r = {std::max(0.0f, dc - hd), dc + hd, P.R0, P.R0};
      return true;
    }
    default: return false;
  }
}

/// A halfspace's or a box's bound over box: its ramp is flat (0 or the weight) outside the
/// slab |sd| < ramp/2 around its plane or faces, so over a box whose signed distances all
/// lie outside it the gradient is 0 everywhere. The saw cut of a pruned branch (ramp 1e-3,
/// bound 1000) bounds only the cells its plane passes through, not every cell of the branch.
float rampLipschitz(const Prim& P, const Box3& box) {
  auto outsideRamp = [&](float sd, float e) {
    const float half = 0.5f / P.invRamp;
    return sd - e >= half || sd + e <= -half;
  };
  switch (P.kind) {
    case NodeKind::Halfspace: {
      const float sd = glm::dot(box.center() - P.a, P.axis);
      const float e = glm::dot(0.5f * box.size(), glm::abs(P.axis));
      return outsideRamp(sd, e) ? 0.0f : P.lipschitz;
    }
    case NodeKind::Box: {
      // sdBox is 1-Lipschitz, so over the box it lies within the half-diagonal of its centre's.
      const float sd = sdBox(box.center(), P.lo, P.hi, nullptr);
      return outsideRamp(sd, glm::length(0.5f * box.size())) ? 0.0f : P.lipschitz;
    }
    default: return P.lipschitz;
  }
}

}  // namespace

float kernelSlopeArg(Kernel k) {
  // Wyvill: d/dx of 6x(1−x²)² vanishes at x² = 1/5. Soft objects: |φ'| = 4/9·x(1−x²)(11−6x²),
  // whose derivative vanishes at 30x⁴ − 51x² + 11 = 0, x² = (51 − √1281)/60.
  return k == Kernel::Wyvill ? 0.44721360f : 0.50347364f;
}

float kernelSlopeAt(Kernel k, float x) {
  if (!(x < 1.0f)) return 0.0f;
  x = std::max(x, 0.0f);
  return 2.0f * x * std::abs(kernelDG(k, x * x));
}

float primLipschitz(const Prim& P, const Box3& box) {
  DistanceRange r;
  if (!distanceRange(P, box, r)) return rampLipschitz(P, box);
  // |∇f| = |w|·|φ'(x)|·|∇x| with x = r/R(t) and |∇x| <= √(1+m²)/R(t) (m = dR/|ab|; the
  // global bound, P.lipschitz = |w|·max|φ'|·√(1+m²)/min R, is the same product with φ'
  // at its peak and R at its least). Over the box x lies in [dmin/Rmax, dmax/Rmin] and
  // R(t) >= Rmin, and φ' is unimodal there, so its largest value is at the peak clamped
  // to that range. The range is widened by 1e-4 of R and the result by 1e-4 so that
  // rounding in the centre distance cannot make the bound fall short.
  const float slack = 1e-4f * r.Rmax;
  const float xlo = std::max(0.0f, r.dmin - slack) / r.Rmax, xhi = (r.dmax + slack) / r.Rmin;
  if (!(xlo < 1.0f)) return 0.0f;
  const float peak = kernelSlopeAt(P.kernel, std::clamp(kernelSlopeArg(P.kernel), xlo, xhi));
  const float m = P.len > 0.0f ? P.dR / P.len : 0.0f;
  const float local = 1.0001f * std::abs(P.weight) * peak * std::sqrt(1.0f + m * m) / r.Rmin;
  return std::min(local, P.lipschitz);
}

Interval primInterval(const Prim& P, const Box3& box) {
  DistanceRange d;
  if (distanceRange(P, box, d)) {
    float smin = d.dmin * d.dmin / (d.Rmax * d.Rmax), smax = d.dmax * d.dmax / (d.Rmin * d.Rmin);
    float fhi = smin >= 1.0f ? 0.0f : kernelG(P.kernel, smin);
    float flo = smax >= 1.0f ? 0.0f : kernelG(P.kernel, smax);
    Interval r{flo * P.weight, fhi * P.weight};
    if (P.weight < 0.0f) std::swap(r.lo, r.hi);
    return r;
  }
  Vec3 c = box.center();
  Vec3 h = 0.5f * box.size();
  auto ramp = [&](float sdlo, float sdhi) {
    Interval r{std::clamp(0.5f - sdhi * P.invRamp, 0.0f, 1.0f) * P.weight,
               std::clamp(0.5f - sdlo * P.invRamp, 0.0f, 1.0f) * P.weight};
    if (P.weight < 0.0f) std::swap(r.lo, r.hi);
    return r;
  };
  switch (P.kind) {
    case NodeKind::Halfspace: {
      float sd = glm::dot(c - P.a, P.axis);
      float e = glm::dot(h, glm::abs(P.axis));
      return ramp(sd - e, sd + e);
    }
    case NodeKind::Box: {
      float sd = sdBox(c, P.lo, P.hi, nullptr);
      return ramp(sd - glm::length(h), sd + glm::length(h));
    }
    default: return {};
  }
}

}  // namespace sprig::blobtree::detail
