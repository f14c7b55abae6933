#pragma once
/// Private: walking the tape. Which children of an n-ary node a point or a box can reach
/// (through its point grid or BVH), the heavy parameters of an operator, the local point of
/// a warp, and the streaming super-elliptic sum, shared by every evaluator.

#include "blobtree/detail/tape.h"

#include <cmath>

namespace sprig::blobtree::detail {

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

/// When box lies inside one cell of point grid g: true, with items[0, count) the children
/// that cell lists (none when no child reaches it). False when box straddles cells or leaves
/// the grid. A box inside a box for which this is true lies in the same cell (the cell
/// index is a monotone function of the coordinates).
inline bool gridCellOf(const PointGrid& g, const Box3& box, const uint32_t*& items, uint32_t& count) {
  if (!g.bounds.contains(box.lo) || !g.bounds.contains(box.hi)) return false;
  Vec3 qlo = glm::floor((box.lo - g.origin) * g.invCell), qhi = glm::floor((box.hi - g.origin) * g.invCell);
  if (qlo != qhi) return false;
  items = nullptr;
  count = 0;
  uint64_t key = cellKey(int(qlo.x), int(qlo.y), int(qlo.z));
  for (uint32_t slot = hashKey(key) & g.mask;; slot = (slot + 1) & g.mask) {
    uint64_t k = g.tableKey[slot];
    if (k == key) {
      items = g.items.data() + g.tableFirst[slot];
      count = g.tableCount[slot];
      return true;
    }
    if (k == PointGrid::kEmptyKey) return true;
  }
}

/// Calls f(child) for the children of n whose support overlaps box. A box inside one cell
/// of the node's point grid (a batch of nearby points, a surface cell) reads that cell's
/// short list in O(1); larger boxes walk the BVH.
template <class F>
inline void childrenIn(const Tape& T, const TNode& n, const Box3& box, F&& f) {
  const uint32_t* items;
  uint32_t count;
  if (n.grid >= 0 && gridCellOf(T.grids[size_t(n.grid)], box, items, count)) {
    // Every child overlapping box overlaps this grid cell, so it is listed here.
    for (uint32_t c : T.grids[size_t(n.grid)].always)
      if (T.nodes[c].box.overlaps(box)) f(c);
    for (uint32_t i = 0; i < count; ++i)
      if (T.nodes[items[i]].box.overlaps(box)) f(items[i]);
    return;
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

/// When box lies inside one cell of n's point grid: true, and out holds the children
/// childrenIn(T, n, box) visits, in its order. Then for any box b inside box, childrenIn
/// visits exactly the children of out whose support overlaps b, in the same order, so a
/// descent through nested boxes filters the list instead of asking the grid again. False
/// (out unchanged) otherwise.
inline bool gridChildrenIn(const Tape& T, const TNode& n, const Box3& box, std::vector<uint32_t>& out) {
  const uint32_t* items;
  uint32_t count;
  if (n.grid < 0 || !gridCellOf(T.grids[size_t(n.grid)], box, items, count)) return false;
  out.clear();
  childrenIn(T, n, box, [&](uint32_t c) { out.push_back(c); });
  return true;
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

/// The heavy parameters of an operator node.
inline const TParams& params(const Tape& T, const TNode& n) { return T.param(n.prim); }

/// The child-space point of warp/transform node n at world point p; with jt, the transpose
/// of d(local)/d(world) there.
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

}  // namespace sprig::blobtree::detail
