#include "blobtree/detail/interval_eval.h"

#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <limits>

namespace sprig::blobtree::detail {

/// The child-space box covering the preimage of world box under warp node n.
Box3 localBoxOf(const TNode& n, const Tape& T, const Box3& box) {
  const Box3& cb = T.nodes[T.kids[n.first]].box;
  switch (n.kind) {
    case NodeKind::Transform: return transformBox(params(T, n).localFromWorld, box);
    case NodeKind::Bend: return params(T, n).bend.localBox(box, cb);
    case NodeKind::Twist: {
      float h0, h1, r;
      axialExtent(box, params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
      return cylinderBox(params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r).intersected(cb);
    }
    case NodeKind::Taper: {
      float h0, h1, r;
      axialExtent(box, params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r);
      float smin = std::min(taperScale(params(T, n).taper, h0), taperScale(params(T, n).taper, h1));
      if (smin <= 0.0f) return cb;
      return cylinderBox(params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r / smin).intersected(cb);
    }
    default: return box;
  }
}

namespace {

float evalLocalL(const Tape& T, uint32_t ni, const Box3& box);

}  // namespace

Interval evalI(const Tape& T, uint32_t ni, const Box3& box) {
  const TNode& n = T.nodes[ni];
  if (box.empty() || !box.overlaps(n.box)) return {0.0f, 0.0f};
  if (isPrimitive(n.kind)) {
    Interval r = primInterval(T.prim(n.prim), box);
    if (!n.box.contains(box.lo) || !n.box.contains(box.hi)) r.lo = std::min(r.lo, 0.0f);
    return r;
  }
  switch (n.kind) {
    case NodeKind::Blend:
    case NodeKind::Ricci:
    case NodeKind::Union:
    case NodeKind::Pcm: return evalNaryI(T, n, box, [&](auto&& visit) { childrenIn(T, n, box, visit); });
    case NodeKind::Intersect: {
      Interval r{std::numeric_limits<float>::max(), std::numeric_limits<float>::max()};
      for (uint32_t k = 0; k < n.count; ++k) {
        Interval i = evalI(T, T.kids[n.first + k], box);
        r.lo = std::min(r.lo, i.lo);
        r.hi = std::min(r.hi, i.hi);
      }
      return {std::max(0.0f, r.lo), std::max(0.0f, r.hi)};
    }
    case NodeKind::Difference: {
      Interval a = evalI(T, T.kids[n.first], box);
      Interval b = evalI(T, T.kids[n.first + 1], box);
      return {std::max(0.0f, std::min(a.lo, 1.0f - b.hi)), std::max(0.0f, std::min(a.hi, 1.0f - b.lo))};
    }
    case NodeKind::Negative: {
      Interval i = evalI(T, T.kids[n.first], box);
      return {-n.weight * i.hi, -n.weight * i.lo};
    }
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: return evalI(T, T.kids[n.first], localBoxOf(n, T, box));
    default: break;  // the primitive kinds, bounded above
  }
  return {0.0f, 0.0f};
}

/// Local Lipschitz bound, never above the node's global bound (both are sound).
float evalL(const Tape& T, uint32_t ni, const Box3& box) {
  return std::min(evalLocalL(T, ni, box), T.nodes[ni].lip);
}

namespace {

float evalLocalL(const Tape& T, uint32_t ni, const Box3& box) {
  const TNode& n = T.nodes[ni];
  if (box.empty() || !box.overlaps(n.box)) return 0.0f;
  // A primitive's own slope over the box (primLipschitz): small where the box lies near
  // the support's rim or deep inside, which is where most terms of a cell's sums are.
  if (isPrimitive(n.kind)) return primLipschitz(T.prim(n.prim), box);
  switch (n.kind) {
    case NodeKind::Blend:
    case NodeKind::Pcm: {
      // A PCM node is F = f₁ + d(f₂) + Σ_{j>2} max(0, d(f_j)) (PcmAccum::value with the
      // strongest child f₁ and the second f₂; bulge − max(0, d₁) + min(0, d₂) leaves that),
      // continuous where the children swap ranks. So ∂F/∂f_j is 1 for the strongest child and
      // at most |d'| <= maxSlope (>= 1.05) for any other: |F(p) − F(q)| <= maxSlope·Σ L_j·|p − q|,
      // not (1 + maxSlope)·Σ L_j, which counted f₁ and its own d₁ both.
      float s = 0.0f;
      childrenIn(T, n, box, [&](uint32_t c) { s += evalL(T, c, box); });
      return n.kind == NodeKind::Pcm ? s * params(T, n).pcm.maxSlope : s;
    }
    case NodeKind::Ricci: {
      // F = ‖(f₁⁺, …, f_k⁺)‖ₙ (RicciAcc keeps f > 0 only), and a norm is 1-Lipschitz in
      // itself: |F(p) − F(q)| <= ‖(|f₁⁺(p) − f₁⁺(q)|, …)‖ₙ <= ‖(L₁, …, L_k)‖ₙ·|p − q|. So the
      // bound is the same super-elliptic blend of the children's bounds: at most k^(1/n)
      // times the largest (1.0017 for two children under n = 400), never above their sum.
      // Widened by 1e-5 for the rounding of the pow.
      RicciAcc acc;
      float s = 0.0f;
      childrenIn(T, n, box, [&](uint32_t c) {
        const float l = evalL(T, c, box);
        acc.add(l, n.exponent);
        s += l;
      });
      return std::min(s, acc.value(n.exponent) * 1.00001f);
    }
    case NodeKind::Union:
    case NodeKind::Intersect:
    case NodeKind::Difference: {
      // A child whose support misses the box contributes 0, so only those reaching it are
      // visited: a tree's root unites one group per junction, and walking all of them per
      // cell made the bound cost grow with the whole tree.
      float m = 0.0f;
      childrenIn(T, n, box, [&](uint32_t c) { m = std::max(m, evalL(T, c, box)); });
      return m;
    }
    case NodeKind::Negative: return n.weight * evalL(T, T.kids[n.first], box);
    case NodeKind::Transform: return params(T, n).jNorm * evalL(T, T.kids[n.first], transformBox(params(T, n).localFromWorld, box));
    case NodeKind::Bend: {
      const Box3 local = params(T, n).bend.localBox(box, T.nodes[T.kids[n.first]].box);
      return local.empty() ? 0.0f : params(T, n).bend.jacobianBound(box) * evalL(T, T.kids[n.first], local);
    }
    case NodeKind::Twist: {
      float h0, h1, r;
      axialExtent(box, params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
      return (1.0f + std::abs(params(T, n).twist.rateRadPerUnit) * r) * evalL(T, T.kids[n.first], localBoxOf(n, T, box));
    }
    case NodeKind::Taper: {
      float h0, h1, r;
      axialExtent(box, params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r);
      float smin = std::min(taperScale(params(T, n).taper, h0), taperScale(params(T, n).taper, h1));
      if (smin <= 0.0f) return n.lip;
      float ds = std::abs(params(T, n).taper.scale1 - params(T, n).taper.scale0) / params(T, n).taper.length;
      return (1.0f / smin + 1.0f + ds * r / (smin * smin)) * evalL(T, T.kids[n.first], localBoxOf(n, T, box));
    }
    default: break;  // the primitive kinds, bounded above
  }
  return n.lip;
}

}  // namespace

}  // namespace sprig::blobtree::detail
