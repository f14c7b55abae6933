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

/// One compiled node. Children are Tape::kids[first, first + count).
struct TNode {
  NodeKind kind = NodeKind::Point;
  uint32_t first = 0, count = 0;
  uint32_t prim = 0;     ///< leaves: index into Tape::prims
  int32_t bvh = -1;      ///< BVH root over the children (n-ary nodes with many children)
  Box3 box;              ///< support box (F = 0 outside)
  float lip = 0.0f;      ///< global Lipschitz bound
  float weight = 1.0f;   ///< Negative
  float exponent = 1.0f; ///< Ricci
  PcmDerived pcm;
  Mat4 localFromWorld{1.0f}, worldFromLocal{1.0f};
  Mat3 jt{1.0f};         ///< transpose of d(local)/d(world) of a Transform
  float jNorm = 1.0f;    ///< spectral norm bound of d(local)/d(world) of a Transform
  BendFrame bend;
  Twist twist;
  Taper taper;
};

/// The flattened tape.
struct Tape {
  std::vector<TNode> nodes;
  std::vector<uint32_t> kids;
  std::vector<Prim> prims;
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

/// Builds a BVH over boxes (item i has box boxes[i]); returns the root index.
int32_t buildBvh(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items);

}  // namespace sprig::blobtree::detail
