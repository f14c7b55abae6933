// CompiledBlob::surfaceCells (declared in blobtree/compiled.h): the sparse octree search for
// the grid cells whose interval bound may hold the surface.

#include "blobtree/compiled.h"
#include "blobtree/detail/interval_eval.h"
#include "blobtree/detail/prune.h"
#include "blobtree/detail/tape.h"
#include "blobtree/detail/traverse.h"
#include "core/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <span>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace sprig::blobtree {

using namespace detail;

namespace {

/// A cube of the octree search: its index at its level (edge E / 2^level).
struct Item {
  std::array<int32_t, 3> idx;
  int level;
};

/// The eight children of it, in the order c = x + 2y + 4z (or the reverse).
template <class Fn>
void forChildren(const Item& it, bool reverse, Fn&& fn) {
  for (int k = 0; k < 8; ++k) {
    const int c = reverse ? 7 - k : k;
    fn(Item{{it.idx[0] * 2 + (c & 1), it.idx[1] * 2 + ((c >> 1) & 1), it.idx[2] * 2 + ((c >> 2) & 1)}, it.level + 1});
  }
}

/// The distinct pruned-tape keys of every cell, in cell order (deterministic): keysOf[k]
/// holds subtree k's keys end to end, keyEnd[k][i] ends cell i's. Sets each cell's `tape`
/// to its key's index among the distinct ones.
std::vector<std::span<const uint32_t>> distinctKeys(const std::vector<std::vector<uint32_t>>& keysOf,
                                                    const std::vector<std::vector<uint32_t>>& keyEnd,
                                                    std::vector<std::vector<Cell>>& cellsOf) {
  std::unordered_map<std::string_view, uint32_t> index;
  std::vector<std::span<const uint32_t>> distinct;
  for (size_t k = 0; k < cellsOf.size(); ++k) {
    uint32_t start = 0;
    for (size_t i = 0; i < cellsOf[k].size(); ++i) {
      std::span<const uint32_t> key(keysOf[k].data() + start, keyEnd[k][i] - start);
      start = keyEnd[k][i];
      std::string_view bytes(reinterpret_cast<const char*>(key.data()), key.size_bytes());
      auto [it, fresh] = index.try_emplace(bytes, uint32_t(distinct.size()));
      if (fresh) distinct.push_back(key);
      cellsOf[k][i].tape = it->second;
    }
  }
  return distinct;
}

/// Subtrees' cells and primitive lists concatenated in order into out, in parallel into
/// arrays sized once (the cells of a fine grid are hundreds of MB: growing them by
/// push_back copied and faulted them in again at every doubling, on one thread).
void concatenate(std::vector<std::vector<Cell>>& cellsOf, const std::vector<std::vector<uint32_t>>& primsOf, CellSet& out) {
  std::vector<size_t> cellBase(cellsOf.size() + 1, 0), primBase(cellsOf.size() + 1, 0);
  for (size_t k = 0; k < cellsOf.size(); ++k) {
    cellBase[k + 1] = cellBase[k] + cellsOf[k].size();
    primBase[k + 1] = primBase[k] + primsOf[k].size();
  }
  out.cells.resize(cellBase.back());
  out.primitives.resize(primBase.back());
  parallelFor(0, cellsOf.size(), [&](size_t k) {
    const uint32_t base = uint32_t(primBase[k]);
    Cell* dst = out.cells.data() + cellBase[k];
    for (const Cell& c : cellsOf[k]) {
      *dst = c;
      dst->firstPrimitive += base;
      ++dst;
    }
    std::copy(primsOf[k].begin(), primsOf[k].end(), out.primitives.begin() + long(primBase[k]));
    std::vector<Cell>().swap(cellsOf[k]);
  }, 1);
}

}  // namespace

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

  // Both faces from the grid (origin + index·e), never lo + e: the neighbour's lo is computed
  // the same way, so adjacent cells share their faces bit for bit and tile space without
  // cracks (lo + e may round an ulp short, and a ray running inside that crack, such as one
  // whose direction has an x component of 1e-16 through x = 0, would meet no cell). Halving
  // e is exact, so the faces agree across levels too.
  auto boxOf = [&](const Item& it) {
    float e = E / float(1 << it.level);
    Vec3 lo = out.origin + Vec3(float(it.idx[0]), float(it.idx[1]), float(it.idx[2])) * e;
    Vec3 hi = out.origin + Vec3(float(it.idx[0] + 1), float(it.idx[1] + 1), float(it.idx[2] + 1)) * e;
    return Box3{lo, hi};
  };
  // Top levels sequentially, so each subtree below is an independent task.
  int split = std::min(depth, 3);
  std::vector<Item> frontier{{{0, 0, 0}, 0}};
  for (int l = 0; l < split; ++l) {
    std::vector<Item> next;
    for (const Item& it : frontier) {
      if (!valueBounds(boxOf(it)).contains(kIso)) continue;
      forChildren(it, false, [&](const Item& child) { next.push_back(child); });
    }
    frontier = std::move(next);
  }
  std::vector<std::vector<Cell>> cellsOf(frontier.size());
  std::vector<std::vector<uint32_t>> primsOf(frontier.size());
  // Pruned-tape keys, per frontier subtree: keysOf[k] concatenated, keyEnd[k][i] ends cell i's.
  std::vector<std::vector<uint32_t>> keysOf(frontier.size());
  std::vector<std::vector<uint32_t>> keyEnd(frontier.size());
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
        forChildren(it, true, [&](const Item& child) { stack.push_back(child); });
        continue;
      }
      Cell cell;
      cell.box = b;
      cell.index = it.idx;
      cell.bounds = iv;
      // With pruned tapes the bound is taken from the cell's own tape below (the same
      // children reach the box; a walk of a few nodes instead of the whole tape).
      if (options.lipschitz && !options.prunedTapes) cell.lipschitz = evalL(T, T.root, b);
      cell.firstPrimitive = uint32_t(prims.size());
      if (options.primitiveLists && T.instBvh >= 0)
        walkBvh(T, T.instBvh, [&](const Box3& bb) { return bb.overlaps(b); }, [&](uint32_t i) {
          if (T.instBox[i].overlaps(b)) prims.push_back(i);
        });
      cell.primitiveCount = uint32_t(prims.size()) - cell.firstPrimitive;
      if (options.prunedTapes) {
        // A margin of 1/64 cell keeps ray samples rounded just outside the box covered.
        pruneKey(T, b.expanded(edge / 64.0f), keysOf[k]);
        keyEnd[k].push_back(uint32_t(keysOf[k].size()));
      }
      cells.push_back(cell);
    }
  }, 1);
  if (options.prunedTapes) {
    // Each distinct tape built once.
    const std::vector<std::span<const uint32_t>> distinct = distinctKeys(keysOf, keyEnd, cellsOf);
    out.tapes.resize(distinct.size());
    parallelFor(0, distinct.size(), [&](size_t i) {
      CompiledBlob b;
      b.tape_ = buildPruned(tape_, distinct[i]);
      out.tapes[i] = std::move(b);
    }, 64);
    if (options.lipschitz)
      parallelFor(0, frontier.size(), [&](size_t k) {
        for (Cell& c : cellsOf[k]) c.lipschitz = out.tapes[c.tape].lipschitz(c.box);
      }, 1);
  }
  concatenate(cellsOf, primsOf, out);
  return out;
}

}  // namespace sprig::blobtree
