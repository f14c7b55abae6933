#pragma once
/// Private: the flattened tape of a CompiledBlob and its evaluators.

#include "blobtree/detail/field.h"

#include <cstdint>
#include <vector>

namespace sprig::blobtree::detail {

/// A BVH node: inner nodes have count 0 and children at `first` and `first + 1`;
/// leaves hold items [first, first + count) of Tape::bvhItems.
struct BvhNode {
  Box3 box;
  uint32_t first = 0;
  uint32_t count = 0;
};

/// A sparse uniform grid over an n-ary node's children for point queries: each occupied
/// cell lists the children whose support box overlaps it, found by open-addressing hashing.
/// A point query costs O(1) plus the children listed in its cell, independent of the
/// number of children (a BVH walk grows with log n and with box overlap).
struct PointGrid {
  Vec3 origin{0.0f};
  Box3 bounds;                       ///< union of the gridded children's boxes
  float invCell = 1.0f;
  uint32_t mask = 0;                 ///< table size − 1 (a power of two minus one)
  std::vector<uint64_t> tableKey;    ///< cell key per slot, kEmptyKey when free
  std::vector<uint32_t> tableFirst;  ///< into items
  std::vector<uint32_t> tableCount;
  std::vector<uint32_t> items;       ///< child tape indices, grouped by cell
  std::vector<uint32_t> always;      ///< children too large for the grid (visited for every point)
  static constexpr uint64_t kEmptyKey = ~uint64_t(0);
};

/// Parameters of operators that need more than a few floats (kept out of TNode so the
/// nodes the evaluators walk stay small and cache friendly).
struct TParams {
  PcmDerived pcm;
  Mat4 localFromWorld{1.0f}, worldFromLocal{1.0f};
  Mat3 jt{1.0f};         ///< transpose of d(local)/d(world) of a Transform
  float jNorm = 1.0f;    ///< spectral norm bound of d(local)/d(world) of a Transform
  BendFrame bend;
  Twist twist;
  Taper taper;
};

/// One compiled node. Children are Tape::kids[first, first + count).
struct TNode {
  Box3 box;              ///< support box (F = 0 outside)
  NodeKind kind = NodeKind::Point;
  uint32_t first = 0, count = 0;
  uint32_t prim = 0;     ///< leaves: index into Tape::prims; operators: index into Tape::params
  int32_t bvh = -1;      ///< BVH root over the children (n-ary nodes with many children)
  int32_t grid = -1;     ///< PointGrid over the children (same nodes as bvh)
  float lip = 0.0f;      ///< global Lipschitz bound
  float weight = 1.0f;   ///< Negative
  float exponent = 1.0f; ///< Ricci
};

/// The flattened tape.
struct Tape {
  std::vector<TNode> nodes;
  std::vector<uint32_t> kids;
  std::vector<Prim> prims;
  std::vector<TParams> params;
  std::vector<PointGrid> grids;
  std::vector<BvhNode> bvh;
  std::vector<uint32_t> bvhItems;
  uint32_t root = 0;
  bool empty = true;
  // Primitive instances (a primitive under its chain of transforms) for cell lists.
  std::vector<Box3> instBox;
  std::vector<uint32_t> instPrim;
  int32_t instBvh = -1;
  float minFeature = 0.0f;
};

/// Builds the PointGrid over children (boxes[i] is the box of items[i]); returns its index.
int32_t buildGrid(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items);

/// Builds a BVH over boxes (item i has box boxes[i]); returns the root index.
int32_t buildBvh(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items);

}  // namespace sprig::blobtree::detail
