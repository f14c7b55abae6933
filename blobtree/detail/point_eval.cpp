#include "blobtree/detail/point_eval.h"

#include "blobtree/detail/traverse.h"

#include <algorithm>
#include <limits>

namespace sprig::blobtree::detail {

float evalV(const Tape& T, uint32_t ni, Vec3 p, bool cull) {
  const TNode& n = T.nodes[ni];
  if (cull && !n.box.contains(p)) return 0.0f;
  if (isPrimitive(n.kind)) return primValue(T.prim(n.prim), p, nullptr);
  switch (n.kind) {
    case NodeKind::Blend: {
      float s = 0.0f;
      if (cull) childrenAt(T, n, p, [&](uint32_t c) { s += evalV(T, c, p, cull); });
      else for (uint32_t i = 0; i < n.count; ++i) s += evalV(T, T.kids[n.first + i], p, cull);
      return s;
    }
    case NodeKind::Ricci: {
      RicciAcc acc;
      if (cull) childrenAt(T, n, p, [&](uint32_t c) { acc.add(evalV(T, c, p, cull), n.exponent); });
      else for (uint32_t i = 0; i < n.count; ++i) acc.add(evalV(T, T.kids[n.first + i], p, cull), n.exponent);
      return acc.value(n.exponent);
    }
    case NodeKind::Union: {
      float m = 0.0f;
      if (cull) childrenAt(T, n, p, [&](uint32_t c) { m = std::max(m, evalV(T, c, p, cull)); });
      else for (uint32_t i = 0; i < n.count; ++i) m = std::max(m, evalV(T, T.kids[n.first + i], p, cull));
      return m;
    }
    case NodeKind::Intersect: {
      float m = std::numeric_limits<float>::max();
      for (uint32_t i = 0; i < n.count; ++i) m = std::min(m, evalV(T, T.kids[n.first + i], p, cull));
      return std::max(0.0f, m);
    }
    case NodeKind::Difference: {
      float a = evalV(T, T.kids[n.first], p, cull);
      if (a <= 0.0f) return 0.0f;
      return std::max(0.0f, std::min(a, 1.0f - evalV(T, T.kids[n.first + 1], p, cull)));
    }
    case NodeKind::Pcm: {
      PcmAccum acc;
      auto add = [&](uint32_t c) {
        float f = std::max(0.0f, evalV(T, c, p, cull));
        acc.add(f, pcmD(params(T, n).pcm, f, nullptr));
      };
      if (cull) childrenAt(T, n, p, add);
      else for (uint32_t i = 0; i < n.count; ++i) add(T.kids[n.first + i]);
      return acc.value();
    }
    case NodeKind::Negative: return -n.weight * evalV(T, T.kids[n.first], p, cull);
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: return evalV(T, T.kids[n.first], warpLocal(T, n, p, nullptr), cull);
    default: break;  // the primitive kinds, evaluated above
  }
  return 0.0f;
}

}  // namespace sprig::blobtree::detail
