#include "blobtree/compiled.h"

#include "blobtree/detail/tape.h"
#include "core/parallel.h"

#include <immintrin.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

namespace sprig::blobtree {

using namespace detail;

namespace detail {

// ---- BVH -------------------------------------------------------------------------------

namespace {
constexpr uint32_t kBvhLeaf = 4;
constexpr uint32_t kBvhMinChildren = 9;  ///< n-ary nodes with at least this many children get a BVH

void buildRec(Tape& tape, uint32_t nodeIndex, std::vector<uint32_t>& order, uint32_t begin, uint32_t end,
              const std::vector<Box3>& boxes, const std::vector<Vec3>& centers) {
  Box3 b, cb;
  for (uint32_t i = begin; i < end; ++i) {
    b.extend(boxes[order[i]]);
    cb.extend(centers[order[i]]);
  }
  tape.bvh[nodeIndex].box = b;
  if (end - begin <= kBvhLeaf) {
    tape.bvh[nodeIndex].first = uint32_t(tape.bvhItems.size());
    tape.bvh[nodeIndex].count = end - begin;
    for (uint32_t i = begin; i < end; ++i) tape.bvhItems.push_back(order[i]);
    return;
  }
  Vec3 ext = cb.size();
  int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  uint32_t mid = (begin + end) / 2;
  std::nth_element(order.begin() + begin, order.begin() + mid, order.begin() + end,
                   [&](uint32_t a, uint32_t c) { return centers[a][axis] < centers[c][axis]; });
  uint32_t left = uint32_t(tape.bvh.size());
  tape.bvh.emplace_back();
  tape.bvh.emplace_back();
  tape.bvh[nodeIndex].first = left;
  tape.bvh[nodeIndex].count = 0;
  buildRec(tape, left, order, begin, mid, boxes, centers);
  buildRec(tape, left + 1, order, mid, end, boxes, centers);
}
}  // namespace

int32_t buildBvh(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items) {
  std::vector<uint32_t> order(boxes.size());
  std::iota(order.begin(), order.end(), 0u);
  std::vector<Vec3> centers(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) {
    // Unbounded boxes (cutters) sort by the origin.
    centers[i] = isHuge(boxes[i]) || boxes[i].empty() ? Vec3(0.0f) : boxes[i].center();
  }
  int32_t root = int32_t(tape.bvh.size());
  tape.bvh.emplace_back();
  size_t firstItem = tape.bvhItems.size();
  buildRec(tape, uint32_t(root), order, 0, uint32_t(boxes.size()), boxes, centers);
  // Map local indices to the caller's items.
  for (size_t i = firstItem; i < tape.bvhItems.size(); ++i) tape.bvhItems[i] = items[tape.bvhItems[i]];
  return root;
}

namespace {
inline uint64_t cellKey(int x, int y, int z) {
  return (uint64_t(uint32_t(x + (1 << 20)) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(y + (1 << 20)) & 0x1FFFFF) << 21) |
         uint64_t(uint32_t(z + (1 << 20)) & 0x1FFFFF);
}
inline uint32_t hashKey(uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return uint32_t(k);
}
}  // namespace

int32_t buildGrid(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items) {
  PointGrid g;
  std::vector<float> ext;
  Box3 all;
  for (const Box3& b : boxes) {
    if (b.empty() || isHuge(b)) continue;
    Vec3 e = b.size();
    ext.push_back(std::max(e.x, std::max(e.y, e.z)));
    all.extend(b);
  }
  if (ext.empty()) return -1;
  std::nth_element(ext.begin(), ext.begin() + long(ext.size() / 2), ext.end());
  // Half the median child extent: a child spans 2-4 cells per axis, a cell lists few children.
  float cell = std::max(0.5f * ext[ext.size() / 2], 1e-6f);
  // Keep the grid's key range within 21 bits per axis.
  Vec3 span = all.size();
  cell = std::max(cell, std::max(span.x, std::max(span.y, span.z)) / float(1 << 19));
  g.origin = all.lo;
  g.bounds = all;
  g.invCell = 1.0f / cell;
  std::vector<std::pair<uint64_t, uint32_t>> pairs;
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Box3& b = boxes[i];
    if (b.empty()) continue;
    if (isHuge(b)) {
      g.always.push_back(items[i]);
      continue;
    }
    glm::ivec3 lo = glm::ivec3(glm::floor((b.lo - g.origin) * g.invCell));
    glm::ivec3 hi = glm::ivec3(glm::floor((b.hi - g.origin) * g.invCell));
    glm::ivec3 n = hi - lo + 1;
    if (int64_t(n.x) * n.y * n.z > 512) {
      g.always.push_back(items[i]);
      continue;
    }
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) pairs.push_back({cellKey(x, y, z), items[i]});
  }
  std::sort(pairs.begin(), pairs.end());
  size_t unique = 0;
  for (size_t i = 0; i < pairs.size(); ++i)
    if (i == 0 || pairs[i].first != pairs[i - 1].first) ++unique;
  uint32_t cap = 16;
  while (cap < 2 * unique) cap *= 2;
  g.mask = cap - 1;
  g.tableKey.assign(cap, PointGrid::kEmptyKey);
  g.tableFirst.assign(cap, 0);
  g.tableCount.assign(cap, 0);
  for (size_t i = 0; i < pairs.size();) {
    size_t j = i;
    while (j < pairs.size() && pairs[j].first == pairs[i].first) ++j;
    uint32_t slot = hashKey(pairs[i].first) & g.mask;
    while (g.tableKey[slot] != PointGrid::kEmptyKey) slot = (slot + 1) & g.mask;
    g.tableKey[slot] = pairs[i].first;
    g.tableFirst[slot] = uint32_t(g.items.size());
    g.tableCount[slot] = uint32_t(j - i);
    for (size_t k = i; k < j; ++k) g.items.push_back(pairs[k].second);
    i = j;
  }
  tape.grids.push_back(std::move(g));
  return int32_t(tape.grids.size() - 1);
}

}  // namespace detail

namespace {

// ---- Traversal helpers -------------------------------------------------------------------

/// Calls f(item) for the BVH items whose box passes test(box).
template <class Test, class F>
inline void walkBvh(const Tape& T, int32_t root, Test&& test, F&& f) {
  uint32_t stack[64];
  int sp = 0;
  stack[sp++] = uint32_t(root);
  while (sp > 0) {
    const BvhNode& b = T.bvh[stack[--sp]];
    if (!test(b.box)) continue;
    if (b.count > 0) {
      for (uint32_t i = 0; i < b.count; ++i) f(T.bvhItems[b.first + i]);
    } else {
      stack[sp++] = b.first + 1;
      stack[sp++] = b.first;
    }
  }
}

/// Calls f(childTapeIndex) for the children of n that may be non-zero at p.
template <class F>
inline void childrenAt(const Tape& T, const TNode& n, Vec3 p, F&& f) {
  if (n.grid >= 0) {
    const PointGrid& g = T.grids[size_t(n.grid)];
    for (uint32_t c : g.always) f(c);
    if (!g.bounds.contains(p)) return;
    Vec3 q = glm::floor((p - g.origin) * g.invCell);
    uint64_t key = cellKey(int(q.x), int(q.y), int(q.z));
    uint32_t slot = hashKey(key) & g.mask;
    while (true) {
      uint64_t k = g.tableKey[slot];
      if (k == key) {
        const uint32_t* it = g.items.data() + g.tableFirst[slot];
        for (uint32_t i = 0, e = g.tableCount[slot]; i < e; ++i) f(it[i]);
        return;
      }
      if (k == PointGrid::kEmptyKey) return;
      slot = (slot + 1) & g.mask;
    }
  }
  if (n.bvh >= 0) {
    walkBvh(T, n.bvh, [&](const Box3& b) { return b.contains(p); }, f);
  } else {
    for (uint32_t i = 0; i < n.count; ++i) f(T.kids[n.first + i]);
  }
}

/// Calls f(child) for the children of n whose support overlaps box. A box inside one cell
/// of the node's point grid (a batch of nearby points, a surface cell) reads that cell's
/// short list in O(1); larger boxes walk the BVH.
template <class F>
inline void childrenIn(const Tape& T, const TNode& n, const Box3& box, F&& f) {
  if (n.grid >= 0) {
    const PointGrid& g = T.grids[size_t(n.grid)];
    if (g.bounds.contains(box.lo) && g.bounds.contains(box.hi)) {
      Vec3 qlo = glm::floor((box.lo - g.origin) * g.invCell), qhi = glm::floor((box.hi - g.origin) * g.invCell);
      if (qlo == qhi) {
        // Every child overlapping box overlaps this grid cell, so it is listed here.
        for (uint32_t c : g.always)
          if (T.nodes[c].box.overlaps(box)) f(c);
        uint64_t key = cellKey(int(qlo.x), int(qlo.y), int(qlo.z));
        for (uint32_t slot = hashKey(key) & g.mask;; slot = (slot + 1) & g.mask) {
          uint64_t k = g.tableKey[slot];
          if (k == key) {
            const uint32_t* it = g.items.data() + g.tableFirst[slot];
            for (uint32_t i = 0, e = g.tableCount[slot]; i < e; ++i)
              if (T.nodes[it[i]].box.overlaps(box)) f(it[i]);
            return;
          }
          if (k == PointGrid::kEmptyKey) return;
        }
      }
    }
  }
  if (n.bvh >= 0) {
    walkBvh(T, n.bvh, [&](const Box3& b) { return b.overlaps(box); }, f);
  } else {
    for (uint32_t i = 0; i < n.count; ++i) {
      uint32_t c = T.kids[n.first + i];
      if (T.nodes[c].box.overlaps(box)) f(c);
    }
  }
}

/// Streaming super-elliptic sum: m = max f, s = Σ (f/m)^n.
struct RicciAcc {
  float m = 0.0f, s = 0.0f;
  void add(float f, float n) {
    if (f <= 0.0f) return;
    if (f > m) {
      s = (m > 0.0f ? s * std::pow(m / f, n) : 0.0f) + 1.0f;
      m = f;
    } else {
      s += std::pow(f / m, n);
    }
  }
  float value(float n) const { return m > 0.0f ? m * std::pow(s, 1.0f / n) : 0.0f; }
};

// ---- Value ---------------------------------------------------------------------------------

/// The heavy parameters of an operator node.
inline const TParams& params(const Tape& T, const TNode& n) { return T.params[n.prim]; }

float evalV(const Tape& T, uint32_t ni, Vec3 p, bool cull);

inline Vec3 warpLocal(const Tape& T, const TNode& n, Vec3 p, Mat3* jt) {
  const TParams& P = params(T, n);
  switch (n.kind) {
    case NodeKind::Transform:
      if (jt) *jt = P.jt;
      return Vec3(P.localFromWorld * Vec4(p, 1.0f));
    case NodeKind::Bend: return P.bend.localFromWorld(p, jt);
    case NodeKind::Twist: return twistLocal(P.twist, p, jt);
    case NodeKind::Taper: return taperLocal(P.taper, p, jt);
    default: return p;
  }
}

float evalV(const Tape& T, uint32_t ni, Vec3 p, bool cull) {
  const TNode& n = T.nodes[ni];
  if (cull && !n.box.contains(p)) return 0.0f;
  switch (n.kind) {
    case NodeKind::Point:
    case NodeKind::Segment:
    case NodeKind::Cone:
    case NodeKind::Torus:
    case NodeKind::Halfspace:
    case NodeKind::Box: return primValue(T.prims[n.prim], p, nullptr);
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
      float fmax = 0.0f, dsum = 0.0f, dmax = 0.0f;
      auto add = [&](uint32_t c) {
        float f = std::max(0.0f, evalV(T, c, p, cull));
        float d = pcmD(params(T, n).pcm, f, nullptr);
        dsum += d;
        if (f > fmax) { fmax = f; dmax = d; }
      };
      if (cull) childrenAt(T, n, p, add);
      else for (uint32_t i = 0; i < n.count; ++i) add(T.kids[n.first + i]);
      return fmax > 0.0f ? std::max(0.0f, fmax + dsum - dmax) : 0.0f;
    }
    case NodeKind::Negative: return -n.weight * evalV(T, T.kids[n.first], p, cull);
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: return evalV(T, T.kids[n.first], warpLocal(T, n, p, nullptr), cull);
  }
  return 0.0f;
}

// ---- Sample (value, gradient, attributes) --------------------------------------------------

struct AttrAcc {
  Vec2 uvSum{0.0f};
  float wSum = 0.0f;
  std::array<uint16_t, Attributes::kMaxTextures> ids{};
  std::array<float, Attributes::kMaxTextures> w{};
  int count = 0;

  void addTexture(uint16_t id, float weight) {
    for (int i = 0; i < count; ++i)
      if (ids[size_t(i)] == id) { w[size_t(i)] += weight; return; }
    if (count < Attributes::kMaxTextures) {
      ids[size_t(count)] = id;
      w[size_t(count)] = weight;
      ++count;
      return;
    }
    // Replace the lightest when heavier.
    int k = 0;
    for (int i = 1; i < count; ++i)
      if (w[size_t(i)] < w[size_t(k)]) k = i;
    if (w[size_t(k)] < weight) { ids[size_t(k)] = id; w[size_t(k)] = weight; }
  }
  void merge(const AttrAcc& o) {
    uvSum += o.uvSum;
    wSum += o.wSum;
    for (int i = 0; i < o.count; ++i) addTexture(o.ids[size_t(i)], o.w[size_t(i)]);
  }
};

struct SV {
  float v = 0.0f;
  Vec3 g{0.0f};
  AttrAcc acc;
};

SV evalS(const Tape& T, uint32_t ni, Vec3 p) {
  const TNode& n = T.nodes[ni];
  SV r;
  if (!n.box.contains(p)) return r;
  switch (n.kind) {
    case NodeKind::Point:
    case NodeKind::Segment:
    case NodeKind::Cone:
    case NodeKind::Torus:
    case NodeKind::Halfspace:
    case NodeKind::Box: {
      const Prim& P = T.prims[n.prim];
      r.v = primValue(P, p, &r.g);
      if (P.hasAttributes && r.v > 0.0f) {
        r.acc.uvSum = r.v * primUv(P, p);
        r.acc.wSum = r.v;
        r.acc.addTexture(P.tex.textureId, r.v);
      }
      return r;
    }
    case NodeKind::Blend:
      childrenAt(T, n, p, [&](uint32_t c) {
        SV s = evalS(T, c, p);
        r.v += s.v;
        r.g += s.g;
        r.acc.merge(s.acc);
      });
      return r;
    case NodeKind::Ricci: {
      // F = m·S^(1/n); ∇F = Σ (fᵢ/F)^(n−1) ∇fᵢ = G·S^(−(n−1)/n), G = Σ (fᵢ/m)^(n−1) ∇fᵢ.
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
    case NodeKind::Union:
      childrenAt(T, n, p, [&](uint32_t c) {
        SV s = evalS(T, c, p);
        if (s.v > r.v) r = s;
      });
      return r;
    case NodeKind::Intersect: {
      SV best;
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
    case NodeKind::Difference: {
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
    case NodeKind::Pcm: {
      // F = f_max + Σ_{j≠max} d(f_j); ∇F = ∇f_max + Σ_{j≠max} d'(f_j)∇f_j.
      float fmax = 0.0f, dsum = 0.0f, dmax = 0.0f, dpmax = 0.0f;
      Vec3 gsum{0.0f}, gmax{0.0f};
      childrenAt(T, n, p, [&](uint32_t c) {
        SV s = evalS(T, c, p);
        float f = std::max(0.0f, s.v);
        if (s.v < 0.0f) s.g = Vec3(0.0f);
        float dp;
        float d = pcmD(params(T, n).pcm, f, &dp);
        dsum += d;
        gsum += dp * s.g;
        r.acc.merge(s.acc);
        if (f > fmax) { fmax = f; dmax = d; dpmax = dp; gmax = s.g; }
      });
      if (fmax <= 0.0f) return r;
      r.v = fmax + dsum - dmax;
      if (r.v <= 0.0f) { r.v = 0.0f; return r; }
      r.g = gmax + gsum - dpmax * gmax;
      return r;
    }
    case NodeKind::Negative: {
      SV s = evalS(T, T.kids[n.first], p);
      r.v = -n.weight * s.v;
      r.g = -n.weight * s.g;
      return r;
    }
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: {
      Mat3 jt;
      Vec3 q = warpLocal(T, n, p, &jt);
      SV s = evalS(T, T.kids[n.first], q);
      s.g = jt * s.g;
      return s;
    }
  }
  return r;
}

// ---- Intervals and Lipschitz bounds over boxes ---------------------------------------------

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

Interval evalI(const Tape& T, uint32_t ni, const Box3& box) {
  const TNode& n = T.nodes[ni];
  if (box.empty() || !box.overlaps(n.box)) return {0.0f, 0.0f};
  switch (n.kind) {
    case NodeKind::Point:
    case NodeKind::Segment:
    case NodeKind::Cone:
    case NodeKind::Torus:
    case NodeKind::Halfspace:
    case NodeKind::Box: {
      Interval r = primInterval(T.prims[n.prim], box);
      if (!n.box.contains(box.lo) || !n.box.contains(box.hi)) r.lo = std::min(r.lo, 0.0f);
      return r;
    }
    case NodeKind::Blend: {
      Interval r{0.0f, 0.0f};
      childrenIn(T, n, box, [&](uint32_t c) {
        Interval i = evalI(T, c, box);
        r.lo += i.lo;
        r.hi += i.hi;
      });
      return r;
    }
    case NodeKind::Ricci: {
      RicciAcc lo, hi;
      childrenIn(T, n, box, [&](uint32_t c) {
        Interval i = evalI(T, c, box);
        lo.add(i.lo, n.exponent);
        hi.add(i.hi, n.exponent);
      });
      return {lo.value(n.exponent), hi.value(n.exponent)};
    }
    case NodeKind::Union: {
      Interval r{0.0f, 0.0f};
      childrenIn(T, n, box, [&](uint32_t c) {
        Interval i = evalI(T, c, box);
        r.lo = std::max(r.lo, i.lo);
        r.hi = std::max(r.hi, i.hi);
      });
      return r;
    }
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
    case NodeKind::Pcm: {
      float maxLo = 0.0f, maxHi = 0.0f, dLo = 0.0f, dHi = 0.0f;
      const PcmDerived& d = params(T, n).pcm;
      childrenIn(T, n, box, [&](uint32_t c) {
        Interval i = evalI(T, c, box);
        float lo = std::max(0.0f, i.lo), hi = std::max(0.0f, i.hi);
        maxLo = std::max(maxLo, lo);
        maxHi = std::max(maxHi, hi);
        dLo += std::min(0.0f, d.c - hi);
        if (hi > d.c - d.w && lo < d.c) dHi += d.a0;
      });
      return {std::max(0.0f, maxLo + dLo), std::max(0.0f, maxHi + dHi)};
    }
    case NodeKind::Negative: {
      Interval i = evalI(T, T.kids[n.first], box);
      return {-n.weight * i.hi, -n.weight * i.lo};
    }
    case NodeKind::Transform:
    case NodeKind::Bend:
    case NodeKind::Twist:
    case NodeKind::Taper: return evalI(T, T.kids[n.first], localBoxOf(n, T, box));
  }
  return {0.0f, 0.0f};
}

float evalLocalL(const Tape& T, uint32_t ni, const Box3& box);

/// Local Lipschitz bound, never above the node's global bound (both are sound).
float evalL(const Tape& T, uint32_t ni, const Box3& box) {
  return std::min(evalLocalL(T, ni, box), T.nodes[ni].lip);
}

float evalLocalL(const Tape& T, uint32_t ni, const Box3& box) {
  const TNode& n = T.nodes[ni];
  if (box.empty() || !box.overlaps(n.box)) return 0.0f;
  switch (n.kind) {
    case NodeKind::Point:
    case NodeKind::Segment:
    case NodeKind::Cone:
    case NodeKind::Torus:
    case NodeKind::Halfspace:
    case NodeKind::Box: return n.lip;
    case NodeKind::Blend:
    case NodeKind::Ricci:
    case NodeKind::Pcm: {
      float s = 0.0f;
      childrenIn(T, n, box, [&](uint32_t c) { s += evalL(T, c, box); });
      return n.kind == NodeKind::Pcm ? s * (1.0f + params(T, n).pcm.maxSlope) : s;
    }
    case NodeKind::Union:
    case NodeKind::Intersect:
    case NodeKind::Difference: {
      float m = 0.0f;
      for (uint32_t k = 0; k < n.count; ++k) m = std::max(m, evalL(T, T.kids[n.first + k], box));
      return m;
    }
    case NodeKind::Negative: return n.weight * evalL(T, T.kids[n.first], box);
    case NodeKind::Transform: return params(T, n).jNorm * evalL(T, T.kids[n.first], transformBox(params(T, n).localFromWorld, box));
    case NodeKind::Bend:
      return params(T, n).bend.jacobianBound(box) * evalL(T, T.kids[n.first], params(T, n).bend.localBox(box, T.nodes[T.kids[n.first]].box));
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
  }
  return n.lip;
}

// ---- Batched values ------------------------------------------------------------------------

constexpr int kBlock = 256;  ///< points per batch (a multiple of 8)

struct Pts {
  const float* x;
  const float* y;
  const float* z;
  int n;   ///< real count
  int n8;  ///< padded count (multiple of 8, <= kBlock)
};

/// g(s) for 4 lanes, s already clamped to [0, 1].
template <Kernel K>
inline __m128 kernel4(__m128 s) {
  const __m128 one = _mm_set1_ps(1.0f);
  if constexpr (K == Kernel::Wyvill) {
    __m128 u = _mm_sub_ps(one, s);
    return _mm_mul_ps(_mm_mul_ps(u, u), u);
  } else {
    __m128 q = _mm_sub_ps(_mm_set1_ps(17.0f / 9.0f), _mm_mul_ps(s, _mm_set1_ps(4.0f / 9.0f)));
    q = _mm_add_ps(_mm_set1_ps(-22.0f / 9.0f), _mm_mul_ps(s, q));
    return _mm_add_ps(one, _mm_mul_ps(s, q));
  }
}

/// out[i] (+)= cone/segment field over the batch, 4 points per SSE step (the batch is
/// padded to a multiple of 8).
template <Kernel K, bool Add>
void coneBatch(const Prim& P, const Pts& pts, float* __restrict out) {
  const __m128 ax = _mm_set1_ps(P.a.x), ay = _mm_set1_ps(P.a.y), az = _mm_set1_ps(P.a.z);
  const __m128 bx = _mm_set1_ps(P.ab.x), by = _mm_set1_ps(P.ab.y), bz = _mm_set1_ps(P.ab.z);
  const __m128 il = _mm_set1_ps(P.invLen2), R0 = _mm_set1_ps(P.R0), dR = _mm_set1_ps(P.dR), w = _mm_set1_ps(P.weight);
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  for (int i = 0; i < pts.n8; i += 4) {
    __m128 px = _mm_sub_ps(_mm_loadu_ps(pts.x + i), ax);
    __m128 py = _mm_sub_ps(_mm_loadu_ps(pts.y + i), ay);
    __m128 pz = _mm_sub_ps(_mm_loadu_ps(pts.z + i), az);
    __m128 t = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(px, bx), _mm_mul_ps(py, by)), _mm_mul_ps(pz, bz)), il);
    t = _mm_min_ps(_mm_max_ps(t, zero), one);
    __m128 dx = _mm_sub_ps(px, _mm_mul_ps(t, bx));
    __m128 dy = _mm_sub_ps(py, _mm_mul_ps(t, by));
    __m128 dz = _mm_sub_ps(pz, _mm_mul_ps(t, bz));
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    __m128 R = _mm_add_ps(R0, _mm_mul_ps(dR, t));
    __m128 s = _mm_min_ps(_mm_div_ps(d2, _mm_mul_ps(R, R)), one);
    __m128 f = _mm_mul_ps(w, kernel4<K>(s));
    if constexpr (Add) f = _mm_add_ps(f, _mm_loadu_ps(out + i));
    _mm_storeu_ps(out + i, f);
  }
}

template <Kernel K, bool Add>
void pointBatch(const Prim& P, const Pts& pts, float* __restrict out) {
  const __m128 ax = _mm_set1_ps(P.a.x), ay = _mm_set1_ps(P.a.y), az = _mm_set1_ps(P.a.z);
  const __m128 iR2 = _mm_set1_ps(1.0f / (P.R0 * P.R0)), w = _mm_set1_ps(P.weight), one = _mm_set1_ps(1.0f);
  for (int i = 0; i < pts.n8; i += 4) {
    __m128 dx = _mm_sub_ps(_mm_loadu_ps(pts.x + i), ax);
    __m128 dy = _mm_sub_ps(_mm_loadu_ps(pts.y + i), ay);
    __m128 dz = _mm_sub_ps(_mm_loadu_ps(pts.z + i), az);
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    __m128 s = _mm_min_ps(_mm_mul_ps(d2, iR2), one);
    __m128 f = _mm_mul_ps(w, kernel4<K>(s));
    if constexpr (Add) f = _mm_add_ps(f, _mm_loadu_ps(out + i));
    _mm_storeu_ps(out + i, f);
  }
}

template <bool Add>
void primBatch(const Prim& P, const Pts& pts, float* out) {
  bool wy = P.kernel == Kernel::Wyvill;
  switch (P.kind) {
    case NodeKind::Segment:
    case NodeKind::Cone:
      if (wy) coneBatch<Kernel::Wyvill, Add>(P, pts, out);
      else coneBatch<Kernel::SoftObject, Add>(P, pts, out);
      return;
    case NodeKind::Point:
      if (wy) pointBatch<Kernel::Wyvill, Add>(P, pts, out);
      else pointBatch<Kernel::SoftObject, Add>(P, pts, out);
      return;
    default:
      for (int i = 0; i < pts.n; ++i) {
        float f = primValue(P, Vec3(pts.x[i], pts.y[i], pts.z[i]), nullptr);
        if constexpr (Add) out[i] += f;
        else out[i] = f;
      }
      return;
  }
}

void evalB(const Tape& T, uint32_t ni, const Pts& pts, const Box3& pbox, float* out) {
  const TNode& n = T.nodes[ni];
  if (!pbox.overlaps(n.box)) {
    std::fill(out, out + pts.n8, 0.0f);
    return;
  }
  if (isPrimitive(n.kind)) {
    primBatch<false>(T.prims[n.prim], pts, out);
    return;
  }
  alignas(32) float tmp[kBlock];
  switch (n.kind) {
    case NodeKind::Blend:
      std::fill(out, out + pts.n8, 0.0f);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        const TNode& cn = T.nodes[c];
        if (isPrimitive(cn.kind)) {
          primBatch<true>(T.prims[cn.prim], pts, out);
        } else {
          evalB(T, c, pts, pbox, tmp);
          for (int i = 0; i < pts.n8; ++i) out[i] += tmp[i];
        }
      });
      return;
    case NodeKind::Union:
      std::fill(out, out + pts.n8, 0.0f);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        evalB(T, c, pts, pbox, tmp);
        for (int i = 0; i < pts.n8; ++i) out[i] = std::max(out[i], tmp[i]);
      });
      return;
    case NodeKind::Intersect:
      std::fill(out, out + pts.n8, std::numeric_limits<float>::max());
      for (uint32_t k = 0; k < n.count; ++k) {
        evalB(T, T.kids[n.first + k], pts, pbox, tmp);
        for (int i = 0; i < pts.n8; ++i) out[i] = std::min(out[i], tmp[i]);
      }
      for (int i = 0; i < pts.n8; ++i) out[i] = std::max(0.0f, out[i]);
      return;
    case NodeKind::Difference:
      evalB(T, T.kids[n.first], pts, pbox, out);
      evalB(T, T.kids[n.first + 1], pts, pbox, tmp);
      for (int i = 0; i < pts.n8; ++i) out[i] = std::max(0.0f, std::min(out[i], 1.0f - tmp[i]));
      return;
    case NodeKind::Ricci: {
      alignas(32) float S[kBlock];
      std::fill(out, out + pts.n8, 0.0f);  // running max m
      std::fill(S, S + pts.n8, 0.0f);
      // S >= 1 once a child contributes, so a term (f/m)^n < 2^-25 cannot change it in float:
      // f < m·2^(-25/n) skips the pow with the same bits (most points of a shell with small
      // bumps under n = 400). Likewise S == 1 (one contributor) gives m exactly.
      const float negligible = std::exp2(-25.0f / n.exponent);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        evalB(T, c, pts, pbox, tmp);
        for (int i = 0; i < pts.n; ++i) {
          if (tmp[i] < out[i] * negligible) continue;
          RicciAcc a{out[i], S[i]};
          a.add(tmp[i], n.exponent);
          out[i] = a.m;
          S[i] = a.s;
        }
      });
      for (int i = 0; i < pts.n; ++i)
        out[i] = out[i] > 0.0f ? (S[i] == 1.0f ? out[i] : out[i] * std::pow(S[i], 1.0f / n.exponent)) : 0.0f;
      return;
    }
    case NodeKind::Pcm: {
      alignas(32) float dsum[kBlock], dmax[kBlock];
      std::fill(out, out + pts.n8, 0.0f);
      std::fill(dsum, dsum + pts.n8, 0.0f);
      std::fill(dmax, dmax + pts.n8, 0.0f);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        evalB(T, c, pts, pbox, tmp);
        for (int i = 0; i < pts.n; ++i) {
          float f = std::max(0.0f, tmp[i]);
          float d = pcmD(params(T, n).pcm, f, nullptr);
          dsum[i] += d;
          if (f > out[i]) { out[i] = f; dmax[i] = d; }
        }
      });
      for (int i = 0; i < pts.n; ++i) out[i] = out[i] > 0.0f ? std::max(0.0f, out[i] + dsum[i] - dmax[i]) : 0.0f;
      return;
    }
    case NodeKind::Negative:
      evalB(T, T.kids[n.first], pts, pbox, out);
      for (int i = 0; i < pts.n8; ++i) out[i] *= -n.weight;
      return;
    case NodeKind::Bend: {
      alignas(32) float lx[kBlock], ly[kBlock], lz[kBlock];
      params(T, n).bend.localFromWorld(pts.x, pts.y, pts.z, lx, ly, lz, pts.n8);
      Box3 lb;
      for (int i = 0; i < pts.n8; ++i) lb.extend(Vec3(lx[i], ly[i], lz[i]));
      Pts lp{lx, ly, lz, pts.n, pts.n8};
      evalB(T, T.kids[n.first], lp, lb, out);
      return;
    }
    case NodeKind::Transform:
    case NodeKind::Twist:
    case NodeKind::Taper: {
      alignas(32) float lx[kBlock], ly[kBlock], lz[kBlock];
      Box3 lb;
      for (int i = 0; i < pts.n8; ++i) {
        Vec3 q = warpLocal(T, n, Vec3(pts.x[i], pts.y[i], pts.z[i]), nullptr);
        lx[i] = q.x;
        ly[i] = q.y;
        lz[i] = q.z;
        lb.extend(q);
      }
      Pts lp{lx, ly, lz, pts.n, pts.n8};
      evalB(T, T.kids[n.first], lp, lb, out);
      return;
    }
    default: std::fill(out, out + pts.n8, 0.0f); return;
  }
}

// ---- Compilation ---------------------------------------------------------------------------

struct Compiler {
  const BlobTree& tree;
  Tape& T;
  std::unordered_map<NodeId, uint32_t> done;

  uint32_t visit(NodeId id) {
    if (auto it = done.find(id); it != done.end()) return it->second;
    const Node& src = tree.node(id);
    std::vector<uint32_t> kids;
    kids.reserve(src.children.size());
    for (NodeId c : src.children) kids.push_back(visit(c));
    TNode n;
    n.kind = src.kind;
    n.box = src.bounds;
    n.lip = src.lipschitz;
    n.weight = src.weight;
    n.exponent = src.exponent;
    if (isPrimitive(src.kind)) {
      n.prim = uint32_t(T.prims.size());
      T.prims.push_back(makePrim(src, tree.kernel()));
    } else {
      TParams P;
      if (src.kind == NodeKind::Pcm) P.pcm = derivePcm(src.pcm);
      if (src.kind == NodeKind::Transform) {
        P.localFromWorld = src.localFromWorld;
        P.worldFromLocal = src.worldFromLocal;
        P.jt = glm::transpose(Mat3(src.localFromWorld));
        P.jNorm = spectralNorm(Mat3(src.localFromWorld));
      }
      if (src.kind == NodeKind::Bend) P.bend = makeBendFrame(src.bend, tree.node(src.children[0]).bounds);
      P.twist = src.twist;
      P.taper = src.taper;
      n.prim = uint32_t(T.params.size());
      T.params.push_back(P);
    }
    n.first = uint32_t(T.kids.size());
    n.count = uint32_t(kids.size());
    T.kids.insert(T.kids.end(), kids.begin(), kids.end());
    bool nary = src.kind == NodeKind::Blend || src.kind == NodeKind::Ricci || src.kind == NodeKind::Union ||
                src.kind == NodeKind::Pcm;
    if (nary && kids.size() >= kBvhMinChildren) {
      std::vector<Box3> boxes;
      for (uint32_t k : kids) boxes.push_back(T.nodes[k].box);
      n.bvh = buildBvh(T, boxes, kids);
      n.grid = buildGrid(T, boxes, kids);
    }
    uint32_t idx = uint32_t(T.nodes.size());
    T.nodes.push_back(n);
    done[id] = idx;
    return idx;
  }

  /// Forward (local to world) box map of a warp/transform node.
  Box3 forward(const TNode& n, const Box3& b) const {
    switch (n.kind) {
      case NodeKind::Transform: return transformBox(params(T, n).worldFromLocal, b);
      case NodeKind::Bend: return params(T, n).bend.worldBox(b);
      case NodeKind::Twist: {
        float h0, h1, r;
        axialExtent(b, params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
        return isHuge(b) ? b : cylinderBox(params(T, n).twist.origin, params(T, n).twist.axis, h0, h1, r);
      }
      case NodeKind::Taper: {
        float h0, h1, r;
        axialExtent(b, params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r);
        float smax = std::max(taperScale(params(T, n).taper, h0), taperScale(params(T, n).taper, h1));
        return isHuge(b) ? b : cylinderBox(params(T, n).taper.origin, params(T, n).taper.axis, h0, h1, r * smax);
      }
      default: return b;
    }
  }

  void instances(uint32_t ni, std::vector<uint32_t>& chain, const Box3& clip) {
    const TNode& n = T.nodes[ni];
    if (isPrimitive(n.kind)) {
      Box3 b = n.box;
      for (size_t k = chain.size(); k-- > 0;) b = forward(T.nodes[chain[k]], b);
      b = b.intersected(clip);
      if (b.empty()) return;
      T.instBox.push_back(b);
      T.instPrim.push_back(n.prim);
      return;
    }
    bool warp = n.kind == NodeKind::Transform || n.kind == NodeKind::Bend || n.kind == NodeKind::Twist ||
                n.kind == NodeKind::Taper;
    if (warp) chain.push_back(ni);
    for (uint32_t k = 0; k < n.count; ++k) instances(T.kids[n.first + k], chain, clip);
    if (warp) chain.pop_back();
  }
};

float modelSize(const Tape& T) {
  const Box3& b = T.nodes[T.root].box;
  if (b.empty() || isHuge(b)) return 1.0f;
  return std::max(glm::length(b.size()), 1e-20f);
}

}  // namespace

// ---- CompiledBlob ------------------------------------------------------------------------

CompiledBlob::CompiledBlob() : tape_(std::make_shared<Tape>()) {}
CompiledBlob::~CompiledBlob() = default;
CompiledBlob::CompiledBlob(const CompiledBlob&) = default;
CompiledBlob& CompiledBlob::operator=(const CompiledBlob&) = default;
CompiledBlob::CompiledBlob(CompiledBlob&&) noexcept = default;
CompiledBlob& CompiledBlob::operator=(CompiledBlob&&) noexcept = default;

CompiledBlob compile(const BlobTree& tree, NodeId root) {
  if (root >= tree.size()) throw std::invalid_argument("compile: unknown root node");
  auto tape = std::make_shared<Tape>();
  Compiler c{tree, *tape, {}};
  tape->root = c.visit(root);
  tape->empty = false;
  std::vector<uint32_t> chain;
  c.instances(tape->root, chain, tape->nodes[tape->root].box);
  if (!tape->instBox.empty()) {
    std::vector<uint32_t> items(tape->instBox.size());
    std::iota(items.begin(), items.end(), 0u);
    tape->instBvh = buildBvh(*tape, tape->instBox, items);
  }
  float mf = 0.0f;
  for (const Prim& P : tape->prims)
    if (P.isoRadiusMin > 0.0f) mf = mf == 0.0f ? P.isoRadiusMin : std::min(mf, P.isoRadiusMin);
  tape->minFeature = mf;
  CompiledBlob b;
  b.tape_ = std::move(tape);
  return b;
}

float CompiledBlob::value(Vec3 p) const { return tape_->empty ? 0.0f : evalV(*tape_, tape_->root, p, true); }
float CompiledBlob::valueNoCulling(Vec3 p) const { return tape_->empty ? 0.0f : evalV(*tape_, tape_->root, p, false); }

Vec3 CompiledBlob::gradient(Vec3 p) const { return tape_->empty ? Vec3(0.0f) : evalS(*tape_, tape_->root, p).g; }

Sample CompiledBlob::sample(Vec3 p) const {
  Sample s;
  if (tape_->empty) return s;
  SV r = evalS(*tape_, tape_->root, p);
  s.value = r.v;
  s.gradient = r.g;
  if (r.acc.wSum > 0.0f) {
    s.attributes.uv = r.acc.uvSum / r.acc.wSum;
    // Sort textures by decreasing weight; normalize.
    std::array<int, Attributes::kMaxTextures> order{0, 1, 2, 3};
    for (int i = 1; i < r.acc.count; ++i)  // insertion sort, at most 4 entries
      for (int j = i; j > 0 && r.acc.w[size_t(order[size_t(j)])] > r.acc.w[size_t(order[size_t(j - 1)])]; --j)
        std::swap(order[size_t(j)], order[size_t(j - 1)]);
    float total = 0.0f;
    for (int i = 0; i < r.acc.count; ++i) total += r.acc.w[size_t(i)];
    for (int i = 0; i < r.acc.count; ++i) {
      s.attributes.textureIds[size_t(i)] = r.acc.ids[size_t(order[size_t(i)])];
      s.attributes.textureWeights[size_t(i)] = r.acc.w[size_t(order[size_t(i)])] / total;
    }
    s.attributes.textureCount = uint8_t(r.acc.count);
  }
  return s;
}

void CompiledBlob::values(std::span<const Vec3> points, std::span<float> out) const {
  assert(out.size() >= points.size());
  if (tape_->empty) {
    std::fill(out.begin(), out.begin() + long(points.size()), 0.0f);
    return;
  }
  alignas(32) float x[kBlock], y[kBlock], z[kBlock], r[kBlock];
  for (size_t b = 0; b < points.size(); b += kBlock) {
    int n = int(std::min<size_t>(kBlock, points.size() - b));
    int n8 = (n + 7) & ~7;
    Box3 box;
    for (int i = 0; i < n; ++i) {
      const Vec3& p = points[b + size_t(i)];
      x[i] = p.x;
      y[i] = p.y;
      z[i] = p.z;
      box.extend(p);
    }
    for (int i = n; i < n8; ++i) {
      x[i] = x[n - 1];
      y[i] = y[n - 1];
      z[i] = z[n - 1];
    }
    Pts pts{x, y, z, n, n8};
    evalB(*tape_, tape_->root, pts, box, r);
    std::copy(r, r + n, out.begin() + long(b));
  }
}

void CompiledBlob::valuesInCell(const Cell& cell, std::span<const Vec3> points, std::span<float> out) const {
  (void)cell;  // the batch's own bounding box (inside the cell) culls at least as well
  values(points, out);
}

Box3 CompiledBlob::bounds() const { return tape_->empty ? Box3{} : tape_->nodes[tape_->root].box; }

Interval CompiledBlob::valueBounds(const Box3& box) const {
  return tape_->empty ? Interval{} : evalI(*tape_, tape_->root, box);
}

float CompiledBlob::lipschitz(const Box3& box) const { return tape_->empty ? 0.0f : evalL(*tape_, tape_->root, box); }
float CompiledBlob::lipschitz() const { return tape_->empty ? 0.0f : tape_->nodes[tape_->root].lip; }

size_t CompiledBlob::primitiveCount() const { return tape_->instBox.size(); }
Box3 CompiledBlob::primitiveBounds(uint32_t i) const { return tape_->instBox.at(i); }
float CompiledBlob::smallestFeature() const { return tape_->minFeature; }

// ---- Ray intersection ------------------------------------------------------------------------

namespace {

/// Clips [s0, s1] of a unit-direction ray to box; false when empty.
bool clipToBox(const Box3& b, Vec3 o, Vec3 d, float& s0, float& s1) {
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-30f) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
      continue;
    }
    float inv = 1.0f / d[a];
    float ta = (b.lo[a] - o[a]) * inv, tb = (b.hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    s0 = std::max(s0, ta);
    s1 = std::min(s1, tb);
    if (s0 > s1) return false;
  }
  return true;
}

/// Refines a bracketed crossing of F − iso in [a, b] (fa, fb on opposite sides) by the
/// Illinois variant of regula falsi with a bisection safeguard.
float refine(const CompiledBlob& blob, Vec3 o, Vec3 d, float a, float b, float fa, float fb, float tol) {
  fa -= kIso;
  fb -= kIso;
  int side = 0;
  for (int it = 0; it < 60 && b - a > tol; ++it) {
    float m = (it % 4 == 3) ? 0.5f * (a + b) : (a * fb - b * fa) / (fb - fa);
    if (!(m > a && m < b)) m = 0.5f * (a + b);
    float fm = blob.value(o + m * d) - kIso;
    if ((fm > 0.0f) == (fa > 0.0f)) {
      a = m;
      fa = fm;
      if (side == -1) fb *= 0.5f;
      side = -1;
    } else {
      b = m;
      fb = fm;
      if (side == 1) fa *= 0.5f;
      side = 1;
    }
  }
  return std::abs(fa) < std::abs(fb) ? a : b;
}

std::optional<Hit> makeHit(const CompiledBlob& blob, const Ray& ray, Vec3 o, Vec3 d, float s, float dirLen) {
  Hit h;
  h.t = s / dirLen;
  h.point = o + s * d;
  Sample smp = blob.sample(h.point);
  float gl = glm::length(smp.gradient);
  h.normal = gl > 0.0f ? -smp.gradient / gl : -d;
  h.attributes = smp.attributes;
  (void)ray;
  return h;
}

}  // namespace

std::optional<Hit> CompiledBlob::intersect(const Ray& ray, float tmin, float tmax, const TraceOptions& opt) const {
  if (tape_->empty) return std::nullopt;
  float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f)) return std::nullopt;
  Vec3 d = ray.direction / dirLen, o = ray.origin;
  float s0 = tmin * dirLen, s1 = tmax * dirLen;
  Box3 root = bounds();
  if (!isHuge(root) && !clipToBox(root, o, d, s0, s1)) return std::nullopt;
  if (!(s1 > s0) && !(s1 == s0)) return std::nullopt;
  float size = isHuge(root) ? std::max(1.0f, s1 - s0) : modelSize(*tape_);
  float eps = std::max(opt.relativeTolerance * size, 1e-30f);
  float s = s0;
  float f = value(o + s * d);
  bool inside = f > kIso;
  float W = std::max(s1 - s0, eps);
  float wMin = 4.0f * eps;
  for (int step = 0; step < opt.maxSteps; ++step) {
    if (s >= s1) return std::nullopt;
    W = std::min(W, s1 - s);
    Vec3 pa = o + s * d, pb = o + (s + W) * d;
    Box3 box{glm::min(pa, pb), glm::max(pa, pb)};
    Interval iv = valueBounds(box);
    if ((!inside && iv.hi < kIso) || (inside && iv.lo > kIso)) {
      s += W;
      if (s >= s1) return std::nullopt;
      f = value(o + s * d);
      W *= 2.0f;
      continue;
    }
    float L = lipschitz(box);
    float safe = L > 0.0f ? std::abs(f - kIso) / L : W;
    if (safe >= W) {
      s += W;
      if (s >= s1) return std::nullopt;
      f = value(o + s * d);
      W *= 2.0f;
      continue;
    }
    if (W > 4.0f * safe && W > wMin) {
      W = std::max(4.0f * safe, wMin);
      continue;
    }
    if (safe < eps) {
      float s2 = std::min(s + 2.0f * eps, s1);
      float f2 = value(o + s2 * d);
      if ((f2 > kIso) != inside) return makeHit(*this, ray, o, d, refine(*this, o, d, s, s2, f, f2, eps * 1e-3f), dirLen);
      s = s2;
      f = f2;
      continue;
    }
    s += safe;
    f = value(o + s * d);
    if ((f > kIso) != inside) {
      // A crossing can only be reached at the end of a safe step when |f − iso| was 0.
      return makeHit(*this, ray, o, d, s, dirLen);
    }
  }
  return std::nullopt;
}

std::optional<Hit> CompiledBlob::intersectCell(const Cell& cell, const Ray& ray, float tmin, float tmax,
                                               const TraceOptions& opt) const {
  if (tape_->empty) return std::nullopt;
  float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f)) return std::nullopt;
  Vec3 d = ray.direction / dirLen, o = ray.origin;
  float s0 = tmin * dirLen, s1 = tmax * dirLen;
  if (!clipToBox(cell.box, o, d, s0, s1)) return std::nullopt;
  float eps = std::max(opt.relativeTolerance * modelSize(*tape_), 1e-30f);
  float L = std::max(cell.lipschitz, 1e-30f);
  float s = s0;
  float f = value(o + s * d);
  bool inside = f > kIso;
  for (int step = 0; step < opt.maxSteps; ++step) {
    float safe = std::abs(f - kIso) / L;
    if (s + safe > s1) return std::nullopt;
    if (safe < eps) {
      float s2 = s + 2.0f * eps;
      if (s2 > s1) s2 = s1;
      if (s2 <= s) return std::nullopt;
      float f2 = value(o + s2 * d);
      if ((f2 > kIso) != inside) return makeHit(*this, ray, o, d, refine(*this, o, d, s, s2, f, f2, eps * 1e-3f), dirLen);
      s = s2;
      f = f2;
      continue;
    }
    s += safe;
    f = value(o + s * d);
    if ((f > kIso) != inside) return makeHit(*this, ray, o, d, s, dirLen);
  }
  return std::nullopt;
}

// ---- Surface cells ---------------------------------------------------------------------------

CellSet CompiledBlob::surfaceCells(float cellSize, const SurfaceCellOptions& options) const {
  if (!(cellSize > 0.0f)) throw std::invalid_argument("surfaceCells: cellSize must be positive");
  CellSet out;
  if (tape_->empty) return out;
  Box3 rb = bounds();
  if (rb.empty()) return out;
  if (isHuge(rb)) throw std::invalid_argument("surfaceCells: the model is unbounded (a bare cutter)");
  float E = std::max(rb.size().x, std::max(rb.size().y, rb.size().z)) * 1.0001f + 1e-20f;
  int depth = std::max(0, int(std::ceil(std::log2(E / cellSize))));
  if (depth > 20) throw std::invalid_argument("surfaceCells: cellSize too small for the model");
  if (options.exactCellSize) E = cellSize * float(1 << depth);
  float edge = E / float(1 << depth);
  out.origin = rb.center() - Vec3(0.5f * E);
  out.cellSize = edge;
  const Tape& T = *tape_;

  struct Item {
    std::array<int32_t, 3> idx;
    int level;
  };
  auto boxOf = [&](const Item& it) {
    float e = E / float(1 << it.level);
    Vec3 lo = out.origin + Vec3(float(it.idx[0]), float(it.idx[1]), float(it.idx[2])) * e;
    return Box3{lo, lo + Vec3(e)};
  };
  // Top levels sequentially, so each subtree below is an independent task.
  int split = std::min(depth, 3);
  std::vector<Item> frontier{{{0, 0, 0}, 0}};
  for (int l = 0; l < split; ++l) {
    std::vector<Item> next;
    for (const Item& it : frontier) {
      if (!valueBounds(boxOf(it)).contains(kIso)) continue;
      for (int c = 0; c < 8; ++c)
        next.push_back({{it.idx[0] * 2 + (c & 1), it.idx[1] * 2 + ((c >> 1) & 1), it.idx[2] * 2 + ((c >> 2) & 1)}, l + 1});
    }
    frontier = std::move(next);
  }
  std::vector<std::vector<Cell>> cellsOf(frontier.size());
  std::vector<std::vector<uint32_t>> primsOf(frontier.size());
  parallelFor(0, frontier.size(), [&](size_t k) {
    std::vector<Item> stack{frontier[k]};
    auto& cells = cellsOf[k];
    auto& prims = primsOf[k];
    while (!stack.empty()) {
      Item it = stack.back();
      stack.pop_back();
      Box3 b = boxOf(it);
      Interval iv = valueBounds(b);
      if (!iv.contains(kIso)) continue;
      if (it.level < depth) {
        for (int c = 7; c >= 0; --c)
          stack.push_back({{it.idx[0] * 2 + (c & 1), it.idx[1] * 2 + ((c >> 1) & 1), it.idx[2] * 2 + ((c >> 2) & 1)},
                           it.level + 1});
        continue;
      }
      Cell cell;
      cell.box = b;
      cell.index = it.idx;
      cell.bounds = iv;
      if (options.lipschitz) cell.lipschitz = evalL(T, T.root, b);
      cell.firstPrimitive = uint32_t(prims.size());
      if (options.primitiveLists && T.instBvh >= 0)
        walkBvh(T, T.instBvh, [&](const Box3& bb) { return bb.overlaps(b); }, [&](uint32_t i) {
          if (T.instBox[i].overlaps(b)) prims.push_back(i);
        });
      cell.primitiveCount = uint32_t(prims.size()) - cell.firstPrimitive;
      cells.push_back(cell);
    }
  }, 1);
  for (size_t k = 0; k < frontier.size(); ++k) {
    uint32_t base = uint32_t(out.primitives.size());
    for (Cell c : cellsOf[k]) {
      c.firstPrimitive += base;
      out.cells.push_back(c);
    }
    out.primitives.insert(out.primitives.end(), primsOf[k].begin(), primsOf[k].end());
  }
  return out;
}

}  // namespace sprig::blobtree
