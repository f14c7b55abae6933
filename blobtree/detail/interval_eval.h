#pragma once
/// Private: the interval evaluators of the tape: bounds of F and of its Lipschitz
/// constant over an axis-aligned box.

#include "blobtree/detail/tape.h"
#include "blobtree/detail/traverse.h"

#include <algorithm>

namespace sprig::blobtree::detail {

/// Sound interval of F of tape node ni over box.
Interval evalI(const Tape& T, uint32_t ni, const Box3& box);
/// True for the n-ary kinds whose children evalI visits through childrenIn (Blend, Ricci,
/// Union, Pcm): those evalNaryI combines.
inline bool isNaryI(NodeKind k) {
  return k == NodeKind::Blend || k == NodeKind::Ricci || k == NodeKind::Union || k == NodeKind::Pcm;
}

/// evalI of n-ary node n (isNaryI(n.kind)) over box, with its children as forEach(visit)
/// calls visit(child): childrenIn's for evalI itself; a list filtered in the same order for
/// an octree descent (surfaceCells), which so gets the same bits without the grid lookup.
template <class ForEach>
Interval evalNaryI(const Tape& T, const TNode& n, const Box3& box, ForEach&& forEach) {
  switch (n.kind) {
    case NodeKind::Blend: {
      Interval r{0.0f, 0.0f};
      forEach([&](uint32_t c) {
        Interval i = evalI(T, c, box);
        r.lo += i.lo;
        r.hi += i.hi;
      });
      return r;
    }
    case NodeKind::Ricci: {
      RicciAcc lo, hi;
      forEach([&](uint32_t c) {
        Interval i = evalI(T, c, box);
        lo.add(i.lo, n.exponent);
        hi.add(i.hi, n.exponent);
      });
      return {lo.value(n.exponent), hi.value(n.exponent)};
    }
    case NodeKind::Union: {
      Interval r{0.0f, 0.0f};
      forEach([&](uint32_t c) {
        Interval i = evalI(T, c, box);
        r.lo = std::max(r.lo, i.lo);
        r.hi = std::max(r.hi, i.hi);
      });
      return r;
    }
    case NodeKind::Pcm: {
      // PcmAccum: F >= f_max + min(0, c − f_second) with f_second <= the second largest hi,
      // and F >= min(f_max, c); F <= f_max + a₀ per child whose field may be in the band.
      float maxLo = 0.0f, maxHi = 0.0f, hi2 = 0.0f, dHi = 0.0f;
      const PcmDerived& d = params(T, n).pcm;
      forEach([&](uint32_t c) {
        Interval i = evalI(T, c, box);
        float lo = std::max(0.0f, i.lo), hi = std::max(0.0f, i.hi);
        maxLo = std::max(maxLo, lo);
        hi2 = std::max(hi2, std::min(maxHi, hi));
        maxHi = std::max(maxHi, hi);
        if (hi > d.c - d.w && lo < d.c) dHi += d.a0;
      });
      const float lo = std::max(std::min(maxLo, d.c), maxLo + std::min(0.0f, d.c - hi2));
      return {std::max(0.0f, lo), std::max(0.0f, maxHi + dHi)};
    }
    default: return {0.0f, 0.0f};
  }
}

/// Local Lipschitz bound of tape node ni over box, never above the node's global bound.
float evalL(const Tape& T, uint32_t ni, const Box3& box);
/// The child-space box covering the preimage of world box under warp node n (Transform,
/// Bend, Twist, Taper; box itself for other kinds).
Box3 localBoxOf(const TNode& n, const Tape& T, const Box3& box);

}  // namespace sprig::blobtree::detail
