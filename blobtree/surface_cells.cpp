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

/// The eight children of it, in the order c = x + 2y + 4z.
template <class Fn>
void forChildren(const Item& it, Fn&& fn) {
  for (int c = 0; c < 8; ++c) {
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

/// The octree search below one cube, depth first with children in the order c = x + 2y + 4z
/// (the order of the cells in the CellSet). Every cube's bound is evalI of the root; when
/// the root is an n-ary node with a point grid and a cube lies inside one grid cell, the
/// root's children reaching it are listed once (gridChildrenIn) and each cube below takes
/// its own list by filtering its parent's: the same children in the same order as
/// childrenIn would give, so the same bounds bit for bit, without a grid lookup per cube
/// (3.2 M cells and about as many inner cubes on the 2,000-cone benchmark).
template <class BoxOf>
class SubtreeWalk {
 public:
  SubtreeWalk(const Tape& T, int depth, const BoxOf& boxOf)
      : T_(T), root_(T.nodes[T.root]), depth_(depth), boxOf_(boxOf), lists_(size_t(depth) + 1) {}

  /// Calls leaf(item, box, bound) for every cube at the last level whose bound holds kIso,
  /// below and including it. listed: lists_[it.level − 1] holds the root's children
  /// reaching the parent cube.
  template <class Leaf>
  void visit(const Item& it, bool listed, Leaf&& leaf) {
    const Box3 b = boxOf_(it);
    std::vector<uint32_t>& mine = lists_[size_t(it.level)];
    Interval iv;
    if (listed) {
      mine.clear();
      const std::vector<uint32_t>& parent = lists_[size_t(it.level) - 1];
      iv = b.empty() || !b.overlaps(root_.box) ? Interval{0.0f, 0.0f} : evalNaryI(T_, root_, b, [&](auto&& f) {
        for (uint32_t c : parent)
          if (T_.nodes[c].box.overlaps(b)) {
            mine.push_back(c);
            f(c);
          }
      });
    } else {
      iv = evalI(T_, T_.root, b);
    }
    if (!iv.contains(kIso)) return;
    if (it.level == depth_) {
      leaf(it, b, iv);
      return;
    }
    // (A bound holding kIso means b overlaps the root's box.)
    if (!listed) listed = isNaryI(root_.kind) && gridChildrenIn(T_, root_, b, mine);
    forChildren(it, [&](const Item& child) { visit(child, listed, leaf); });
  }

 private:
  const Tape& T_;
  const TNode& root_;
  const int depth_;
  const BoxOf& boxOf_;
  std::vector<std::vector<uint32_t>> lists_;  ///< per level: the root's children reaching the cube there
};

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

/// Subtrees' cell indices concatenated in order into out, in parallel into an array sized once.
void concatenate(std::vector<std::vector<glm::ivec3>>& indicesOf, std::vector<glm::ivec3>& out) {
  std::vector<size_t> base(indicesOf.size() + 1, 0);
  for (size_t k = 0; k < indicesOf.size(); ++k) base[k + 1] = base[k] + indicesOf[k].size();
  out.resize(base.back());
  parallelFor(0, indicesOf.size(), [&](size_t k) {
    std::copy(indicesOf[k].begin(), indicesOf[k].end(), out.begin() + long(base[k]));
    std::vector<glm::ivec3>().swap(indicesOf[k]);
  }, 1);
}

}  // namespace

CellSet CompiledBlob::surfaceCells(float cellSize, const SurfaceCellOptions& options) const {
  if (!(cellSize > 0.0f)) throw std::invalid_argument("surfaceCells: cellSize must be positive");
  if (options.indicesOnly && (options.lipschitz || options.primitiveLists || options.prunedTapes))
    throw std::invalid_argument("surfaceCells: indicesOnly fills the indices alone (lipschitz, primitiveLists and prunedTapes off)");
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
  // Top levels sequentially, so each subtree below is an independent task: five levels
  // (up to 32,768 cubes, a few thousand of them near the surface) leave the tasks small
  // enough that neither thread waits long for the other's last one.
  int split = std::min(depth, 5);
  std::vector<Item> frontier{{{0, 0, 0}, 0}};
  for (int l = 0; l < split; ++l) {
    std::vector<Item> next;
    for (const Item& it : frontier) {
      if (!valueBounds(boxOf(it)).contains(kIso)) continue;
      forChildren(it, [&](const Item& child) { next.push_back(child); });
    }
    frontier = std::move(next);
  }
  std::vector<std::vector<Cell>> cellsOf(frontier.size());
  std::vector<std::vector<uint32_t>> primsOf(frontier.size());
  // Pruned-tape keys, per frontier subtree: keysOf[k] concatenated, keyEnd[k][i] ends cell i's.
  std::vector<std::vector<uint32_t>> keysOf(frontier.size());
  std::vector<std::vector<uint32_t>> keyEnd(frontier.size());
  std::vector<std::vector<glm::ivec3>> indicesOf(frontier.size());
  parallelFor(0, frontier.size(), [&](size_t k) {
    SubtreeWalk walk(T, depth, boxOf);
    walk.visit(frontier[k], false, [&](const Item& it, const Box3& b, Interval iv) {
      if (options.indicesOnly) {
        indicesOf[k].emplace_back(it.idx[0], it.idx[1], it.idx[2]);
        return;
      }
      Cell cell;
      cell.box = b;
      cell.index = it.idx;
      cell.bounds = iv;
      // With pruned tapes the bound is taken from the cell's own tape below (the same
      // children reach the box; a walk of a few nodes instead of the whole tape).
      if (options.lipschitz && !options.prunedTapes) cell.lipschitz = evalL(T, T.root, b);
      auto& prims = primsOf[k];
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
      cellsOf[k].push_back(cell);
    });
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
  if (options.indicesOnly) concatenate(indicesOf, out.indices);
  else concatenate(cellsOf, primsOf, out);
  return out;
}

}  // namespace sprig::blobtree
