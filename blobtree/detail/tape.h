#pragma once
/// Private: the flattened tape of a CompiledBlob (its evaluators are in
/// point_eval.h, gradient_eval.h, interval_eval.h and batch_eval.h).

#include "blobtree/detail/accel.h"
#include "blobtree/detail/field.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace sprig::blobtree::detail {

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

/// The flattened tape. A pruned tape (blobtree/detail/prune.h) holds only its own nodes
/// and child lists and reads primitives and operator parameters from its base, which it
/// keeps alive; TNode::prim indexes the base's arrays.
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
  float minLimb = 0.0f;  ///< smallest isoRadiusMax of a sized primitive (CompiledBlob::thinnestLimb)
  std::shared_ptr<const Tape> base;  ///< set on pruned tapes: the owner of prims and params

  /// Primitive i (this tape's or, for a pruned tape, its base's).
  const Prim& prim(uint32_t i) const { return base ? base->prims[i] : prims[i]; }
  /// Operator parameters i (this tape's or, for a pruned tape, its base's).
  const TParams& param(uint32_t i) const { return base ? base->params[i] : params[i]; }
};

}  // namespace sprig::blobtree::detail
