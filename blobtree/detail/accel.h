#pragma once
/// Private: acceleration structures over the support boxes of an n-ary node's children
/// (and over the tape's primitive instances): a median-split BVH for box queries and a
/// hashed sparse uniform grid for point queries.

#include "core/types.h"

#include <cstdint>
#include <vector>

namespace sprig::blobtree::detail {

struct Tape;

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

/// n-ary nodes with at least this many children get a BVH and a point grid.
inline constexpr uint32_t kBvhMinChildren = 9;

/// The grid key of integer cell (x, y, z): 21 bits per axis.
inline uint64_t cellKey(int x, int y, int z) {
  return (uint64_t(uint32_t(x + (1 << 20)) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(y + (1 << 20)) & 0x1FFFFF) << 21) |
         uint64_t(uint32_t(z + (1 << 20)) & 0x1FFFFF);
}
/// The hash of a grid key (the finalizer of MurmurHash3).
inline uint32_t hashKey(uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdULL;
  k ^= k >> 33;
  return uint32_t(k);
}

/// Builds the PointGrid over children (boxes[i] is the box of items[i]) into tape.grids;
/// returns its index, or -1 when no child has a bounded box.
int32_t buildGrid(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items);

/// Builds a BVH over boxes (item i has box boxes[i]) into tape.bvh / tape.bvhItems; returns
/// the root index.
int32_t buildBvh(Tape& tape, const std::vector<Box3>& boxes, const std::vector<uint32_t>& items);

}  // namespace sprig::blobtree::detail
