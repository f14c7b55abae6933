#include "blobtree/polygonize.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <atomic>
#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <sys/mman.h>

#include "blobtree/cell_size.h"
#include "blobtree/detail/dual_patches.h"
#include "blobtree/detail/marching_tets.h"
#include "core/diagnostics.h"
#include "core/parallel.h"
#include "core/phases.h"
#include "core/progress.h"
#include "core/timer.h"

namespace sprig::blobtree {

namespace {

using detail::cornerOffset;
using detail::kNoCell;
using detail::kTets;
using detail::kTriangleCount;
using detail::TetEmitter;

// Allocator of the polygonizer's large working arrays (cell hash, corner table, samples,
// vertex tables): resize(n) default-initializes (no zero fill of trivial types), since
// every array below is written in full by a parallel step after its resize, which then
// also touches its pages on both threads. Small (4 KB) pages: these arrays were once marked
// for transparent huge pages (0.95x the dual mesher's CPU time then, on a loaded machine),
// but a fresh 2 MB page is a whole block the kernel may have handed back to a virtual
// machine's host, and its first touch cost 7-10 times a small page's here (1.1-1.4 s
// against 0.12-0.18 s for 315 MB; bench_fresh_pages), so without them the 2,000-cone
// benchmark took 0.70-0.85x the time (docs/PERFORMANCE.md, "Fresh pages").
template <class T>
struct DefaultInitAllocator {
  using value_type = T;
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) {}
  T* allocate(size_t n) {
    if (void* p = std::malloc(n * sizeof(T))) return static_cast<T*>(p);
    throw std::bad_alloc();
  }
  void deallocate(T* p, size_t) { std::free(p); }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0) ::new (static_cast<void*>(p)) U;
    else ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const DefaultInitAllocator<U>&) const { return true; }
};
template <class T>
using BigVector = std::vector<T, DefaultInitAllocator<T>>;

// Frees the arrays' memory now. Both meshers return each working array once done with it,
// so that the arrays made after it (the mesh's) reuse its memory instead of growing the
// process: the dual mesher's peak resident set on the 2,000-cone benchmark fell from 942 MB
// to 420 MB (docs/PERFORMANCE.md, "Fresh pages").
template <class... C>
void releaseAll(C&... arrays) {
  ((C().swap(arrays)), ...);
}

// Resizes an output array of the polygonizer (the mesh's arrays, the attributes: plain
// std::vectors, 400+ MB on the 2,000-cone benchmark) from empty to n elements. resize()
// value-initializes on one thread, and its first touch of fresh pages was most of the
// dual mesher's serial time: 1.7 s of its 8.3 s vertex phase (loaded machine). So the
// block is reserved first and its pages are faulted in on every thread
// (MADV_POPULATE_WRITE, Linux 5.14; an older kernel refuses it and resize() faults them as
// before); resize() then only writes memory that is there. Results are unchanged.
template <class T>
void resizeOutput(std::vector<T>& v, size_t n) {
  constexpr size_t kPage = 4096, kChunk = size_t(8) << 20, kThreshold = size_t(4) << 20;
  if (v.empty() && n * sizeof(T) >= kThreshold) {
    v.reserve(n);
    const uintptr_t lo = (reinterpret_cast<uintptr_t>(v.data()) + kPage - 1) / kPage * kPage;
    const uintptr_t hi = (reinterpret_cast<uintptr_t>(v.data()) + n * sizeof(T)) / kPage * kPage;
    if (hi > lo) {
#ifdef MADV_POPULATE_WRITE  // glibc 2.35 and later
      parallelFor(0, (hi - lo + kChunk - 1) / kChunk, [&](size_t c) {
        const uintptr_t b = lo + c * kChunk;
        madvise(reinterpret_cast<void*>(b), std::min(hi - b, kChunk), MADV_POPULATE_WRITE);
      });
#endif
    }
  }
  v.resize(n);
}

// Grid points are keyed by their integer coordinates, 20 bits per axis; an edge of the
// Kuhn triangulation by (key of its low end) · 8 + (its direction as corner bits).
constexpr int kAxisBits = 20;
constexpr int64_t kAxisLimit = int64_t(1) << kAxisBits;
constexpr uint64_t kAxisMask = uint64_t(kAxisLimit - 1);

uint64_t pointKey(int64_t i, int64_t j, int64_t k) {
  return (uint64_t(i) << (2 * kAxisBits)) | (uint64_t(j) << kAxisBits) | uint64_t(k);
}

glm::ivec3 keyCoords(uint64_t key) {
  return {int((key >> (2 * kAxisBits)) & kAxisMask), int((key >> kAxisBits) & kAxisMask), int(key & kAxisMask)};
}

// Open-addressing map from a cell's key to its index. The slot of a cell is a hash of its
// 4x4x4 block, then its place in the block: the neighbours a cell looks up (and the next
// cells in octree order) mostly lie in the same few cache lines, where a plain hash of the
// key would cost a cache miss per lookup in tables of millions of cells.
class CellHash {
 public:
  explicit CellHash(size_t n) {
    size_t cap = 64;
    while (cap < 2 * n) cap <<= 1;
    // Filled in parallel: the table of a fine grid is 100+ MB, and its first touch (page
    // faults, then the fill) on one thread was a serial step of the polygonizer.
    slots_.resize(cap);  // trivially default-constructed: untouched until the fill below
    constexpr size_t kChunk = size_t(1) << 16;
    parallelFor(0, (cap + kChunk - 1) / kChunk, [&](size_t c) {
      std::fill(slots_.data() + c * kChunk, slots_.data() + std::min(cap, (c + 1) * kChunk), Slot{kEmpty, kNoCell});
    }, 1);
    mask_ = cap - 1;
  }
  /// Inserts key, safe to call from several threads at once (a slot is claimed by a
  /// compare-and-swap of its key). Which slot a key takes may depend on the threads'
  /// timing; what find() returns does not. False when the key was there already.
  bool insertConcurrent(uint64_t key, uint32_t id) {
    for (size_t i = slot(key);; i = (i + 1) & mask_) {
      uint64_t expected = kEmpty;
      if (std::atomic_ref<uint64_t>(slots_[i].key).compare_exchange_strong(expected, key, std::memory_order_relaxed)) {
        slots_[i].id = id;
        return true;
      }
      if (expected == key) return false;
    }
  }
  uint32_t find(uint64_t key) const {
    for (size_t i = slot(key);; i = (i + 1) & mask_) {
      const Slot& s = slots_[i];
      if (s.key == key) return s.id;
      if (s.key == kEmpty) return kNoCell;
    }
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t(0);
  struct Slot {
    uint64_t key;
    uint32_t id;
  };
  size_t slot(uint64_t key) const {
    // Key bits: i (20) | j (20) | k (20); the low 2 bits of each axis place the cell in
    // its block, the rest name the block.
    constexpr uint64_t kLow = 3;
    uint64_t local = (key & kLow) | ((key >> kAxisBits & kLow) << 2) | ((key >> (2 * kAxisBits) & kLow) << 4);
    uint64_t block = key & ~((kLow << (2 * kAxisBits)) | (kLow << kAxisBits) | kLow);
    block ^= block >> 33;
    block *= 0xff51afd7ed558ccdULL;
    block ^= block >> 33;
    return size_t((block << 6) | local) & mask_;
  }
  BigVector<Slot> slots_;
  size_t mask_ = 0;
};

// The indices i in [0, n) with pred(i), in order: counted per chunk, then written in place.
template <class Pred>
BigVector<uint32_t> indicesWhere(size_t n, Pred&& pred) {
  constexpr size_t kChunk = size_t(1) << 15;
  const size_t nChunks = (n + kChunk - 1) / kChunk;
  std::vector<size_t> base(nChunks + 1, 0);
  parallelFor(0, nChunks, [&](size_t ch) {
    for (size_t i = ch * kChunk; i < std::min(n, (ch + 1) * kChunk); ++i) base[ch + 1] += pred(i);
  });
  for (size_t ch = 0; ch < nChunks; ++ch) base[ch + 1] += base[ch];
  BigVector<uint32_t> out(base[nChunks]);
  parallelFor(0, nChunks, [&](size_t ch) {
    size_t k = base[ch];
    for (size_t i = ch * kChunk; i < std::min(n, (ch + 1) * kChunk); ++i)
      if (pred(i)) out[k++] = uint32_t(i);
  });
  return out;
}

// The kept cells by 4x4x4 brick (a cube two levels above the cells). The octree search
// lists the cells of a cube consecutively, in the order c = x + 2y + 4z at each level, so
// the kept cells of a brick are a run of the cell array in Morton order: a brick is the
// index of its first cell and a 64-bit mask of its kept cells, and a cell is found by a
// lookup in a hash of the bricks and a popcount. The hash holds an entry per brick, not
// per cell (on the 2,000-cone benchmark 172,069 bricks for 3,192,428 cells: 8 MB of slots
// where a hash of the cells took 134 MB, written and faulted in before any lookup), and
// a cell's neighbours lie in the 2x2x2 bricks around it, which a Cursor keeps from one
// lookup to the next. Both assumptions are checked as the index is built
// (std::logic_error).
class BrickIndex {
 public:
  BrickIndex(const std::vector<glm::ivec3>& cells, size_t n)
      : first_(indicesWhere(n, [&](size_t i) { return i == 0 || brickKey(cells[i]) != brickKey(cells[i - 1]); })),
        mask_(first_.size()), hash_(first_.size()) {
    first_.push_back(uint32_t(n));
    parallelFor(0, mask_.size(), [&](size_t b) {
      uint64_t mask = 0;
      for (uint32_t i = first_[b]; i < first_[b + 1]; ++i) {
        const unsigned m = mortonInBrick(cells[i]);
        if (mask >> m) throw std::logic_error("polygonize: the kept cells of a brick are not in octree order");
        mask |= uint64_t(1) << m;
      }
      mask_[b] = mask;
      if (!hash_.insertConcurrent(brickKey(cells[first_[b]]), uint32_t(b)))
        throw std::logic_error("polygonize: the kept cells of a brick are not consecutive");
    }, 1024);
  }

  // Finds kept cells, remembering the last brick of each parity (brick coordinates mod
  // 2): the bricks a cell's 27 neighbours fall in form a 2x2x2 block, whose eight
  // parities differ, so none of them pushes out another.
  class Cursor {
   public:
    explicit Cursor(const BrickIndex& index) : index_(index) {
      key_.fill(~uint64_t(0));
      brick_.fill(kNoCell);
    }
    // The index of the kept cell at q (coordinates >= 0), or kNoCell.
    uint32_t find(glm::ivec3 q) {
      const uint64_t key = brickKey(q);
      const size_t way = size_t(((q.x >> 2) & 1) | (((q.y >> 2) & 1) << 1) | (((q.z >> 2) & 1) << 2));
      if (key != key_[way]) {
        key_[way] = key;
        brick_[way] = index_.hash_.find(key);
      }
      const uint32_t brick = brick_[way];
      if (brick == kNoCell) return kNoCell;
      const uint64_t mask = index_.mask_[brick];
      const unsigned m = mortonInBrick(q);
      if (!((mask >> m) & 1)) return kNoCell;
      return index_.first_[brick] + uint32_t(std::popcount(mask & ((uint64_t(1) << m) - 1)));
    }

   private:
    const BrickIndex& index_;
    std::array<uint64_t, 8> key_;
    std::array<uint32_t, 8> brick_;
  };
  // The index of the kept cell at q (coordinates >= 0), or kNoCell.
  uint32_t find(glm::ivec3 q) const { return Cursor(*this).find(q); }

 private:
  static uint64_t brickKey(glm::ivec3 q) { return pointKey(q.x >> 2, q.y >> 2, q.z >> 2); }
  // The cell's place in its brick's octree order: the bits of c = x + 2y + 4z of the
  // brick's child (coordinate bit 1), then of the cell in that child (bit 0).
  static unsigned mortonInBrick(glm::ivec3 q) {
    return unsigned((q.x & 1) | ((q.y & 1) << 1) | ((q.z & 1) << 2) | ((q.x & 2) << 2) | ((q.y & 2) << 3) | ((q.z & 2) << 4));
  }
  BigVector<uint32_t> first_;  // per brick: its first cell; then the cell count
  BigVector<uint64_t> mask_;   // per brick: its kept cells, bit mortonInBrick
  CellHash hash_;              // brick key -> brick
};

// A surface-crossing grid edge: its inside and outside grid point indices.
struct EdgeRec {
  uint32_t inside, outside;
};

Vec3 gridPosition(const CellSet& cs, glm::ivec3 g) {
  return cs.origin + Vec3(float(g.x) * cs.cellSize, float(g.y) * cs.cellSize, float(g.z) * cs.cellSize);
}

// Concatenates per-chunk vectors in chunk order.
template <class T>
std::vector<T> concat(std::vector<std::vector<T>>& parts) {
  size_t total = 0;
  for (const auto& p : parts) total += p.size();
  std::vector<T> out;
  out.reserve(total);
  for (auto& p : parts) {
    out.insert(out.end(), p.begin(), p.end());
    std::vector<T>().swap(p);
  }
  return out;
}

}  // namespace

float resolveCellSize(const CompiledBlob& blob, const PolygonizeOptions& options) {
  if (options.cellSize > 0.0f) return options.cellSize;
  if (!(options.featureFraction > 0.0f) || !(options.sizeDivisions > 0.0f))
    throw std::invalid_argument("polygonize: featureFraction and sizeDivisions must be positive");
  Box3 b = blob.bounds();
  if (b.empty()) return 0.0f;
  Vec3 size = b.size();
  if (!std::isfinite(size.x) || !std::isfinite(size.y) || !std::isfinite(size.z) || size.x > 1e30f)
    throw std::invalid_argument("polygonize: the blob is unbounded (a bare cutter); give a cell size and a bounded model");
  return autoCellSize(blob, CellSizeRule{.featureFraction = options.featureFraction,
                                         .coarsestDivisions = options.sizeDivisions,
                                         .finestDivisions = options.maxDivisions,
                                         .noFeatureDivisions = options.sizeDivisions,
                                         .limbFraction = options.limbFraction,
                                         .limbFinestDivisions = options.limbMaxDivisions});
}

namespace {

// The state the polygonizer's steps share: the kept cells, one sample per distinct grid
// point, the cells' inside masks, and the active cells (those with a sign change).
struct Grid {
  explicit Grid(CellSet cells)
      : cs(std::move(cells)), kept(cs.indices.size()), cellCoords(std::move(cs.indices)), keptCells(cellCoords, kept) {}

  CellSet cs;                            // the grid (origin, cell size); its indices move to cellCoords
  size_t kept;                           // cells the interval bounds kept: cellCoords[0, kept)
  std::vector<glm::ivec3> cellCoords;    // per cell (kept, then added): integer grid coordinates
  BrickIndex keptCells;                  // kept cell coordinates -> index into cellCoords
  std::map<uint64_t, uint32_t> added;    // the closure's cells: key -> index into cellCoords
  BigVector<uint32_t> cornerPoint;     // per cell (kept, then added) · 8 + corner: grid point index
  BigVector<uint8_t> ownedMask;        // per kept cell: corners whose grid point it owns
  BigVector<uint32_t> pointBase;       // per kept cell: its first owned point (prefix sums)
  BigVector<uint64_t> pointKeys;       // per grid point: its key
  BigVector<uint32_t> pointSlot;       // per grid point: its owner slot (kept cell · 8 + corner), or
                                       // kNoCell for a point the closure added
  BigVector<float> values;             // per grid point: F there
  BigVector<uint8_t> insideMask;       // per cell: corners with F > 0.5
  BigVector<uint32_t> active;          // cells with a sign change, kept ones first
  size_t extraCells = 0;                 // cells the closure added

  // The owner slot (cell · 8 + corner) of grid point g, or kNoCell when no kept cell holds it.
  uint32_t ownerSlot(glm::ivec3 g) const {
    for (int c = 0; c < 8; ++c) {
      glm::ivec3 lo = g - cornerOffset(c);
      if (lo.x < 0 || lo.y < 0 || lo.z < 0) continue;
      uint32_t j = keptCells.find(lo);
      if (j != kNoCell) return j * 8 + uint32_t(c);
    }
    return kNoCell;
  }
  // The cell (kept or added) at cell + offset(c), c = 1..7, or kNoCell. A kept cell there
  // owns that corner point with code 0 (the smallest code owns a point), so for a kept cell
  // this reads two arrays instead of a hash lookup; only where the closure added cells can
  // a neighbour missing from the point table still exist, and only then is the hash asked.
  uint32_t upperNeighbour(uint32_t cell, int c) const {
    if (cell < kept) {
      const uint32_t s = pointSlot[cornerPoint[size_t(cell) * 8 + size_t(c)]];
      if (s % 8 == 0) return s / 8;
      if (extraCells == 0) return kNoCell;
    }
    return findCell(cellCoords[cell] + cornerOffset(c));
  }
  // The cell (kept or added) at q (coordinates >= 0), or kNoCell.
  uint32_t findCell(glm::ivec3 q) const {
    const uint32_t j = keptCells.find(q);
    if (j != kNoCell || added.empty()) return j;
    const auto it = added.find(pointKey(q.x, q.y, q.z));
    return it == added.end() ? kNoCell : it->second;
  }
  // The grid point index of an owner slot.
  uint32_t pointOfSlot(uint32_t slot) const {
    uint32_t j = slot / 8, c = slot % 8;
    return pointBase[j] + uint32_t(std::popcount(unsigned(ownedMask[j]) & ((1u << c) - 1u)));
  }
};

// Step 1: the cells of exactly the requested edge whose interval bound may hold the
// surface; no Lipschitz bounds or primitive lists (the tracer's needs, not ours).
CellSet keptCells(const CompiledBlob& blob, float requested) {
  CellSet cs = blob.surfaceCells(requested, SurfaceCellOptions{.exactCellSize = true, .lipschitz = false,
                                                               .primitiveLists = false, .indicesOnly = true});
  if (cs.indices.size() >= (size_t(1) << 29)) throw std::invalid_argument("polygonize: too many surface cells; use a larger cell size");
  for (const glm::ivec3& c : cs.indices)
    for (int a = 0; a < 3; ++a)
      if (c[a] < 0 || c[a] + 1 >= kAxisLimit)
        throw std::invalid_argument("polygonize: the grid has more than 2^20 cells on an axis; use a larger cell size");
  return cs;
}

// Step 2a for kept cell i: the owner slot of each corner (in cornerPoint), the corners it
// owns and their count (pointBase[i + 1]). Corner c is owned by the neighbour
// idx + offset(c) − offset(c') with the smallest c' < c that is kept, else by this cell.
// Neighbours by displacement (27 of them), each looked up at most once.
void numberCellCorners(Grid& g, size_t i, BrickIndex::Cursor& cells) {
  const glm::ivec3 idx = g.cellCoords[i];
  std::array<uint32_t, 27> neighbour;
  neighbour.fill(kNoCell - 1);  // not looked up yet
  auto find = [&](glm::ivec3 d) {
    uint32_t& n = neighbour[size_t((d.x + 1) + 3 * (d.y + 1) + 9 * (d.z + 1))];
    if (n == kNoCell - 1) {
      glm::ivec3 q = idx + d;
      n = q.x < 0 || q.y < 0 || q.z < 0 ? kNoCell : cells.find(q);
    }
    return n;
  };
  uint8_t owned = 0;
  for (int c = 0; c < 8; ++c) {
    uint32_t slot = uint32_t(i * 8 + size_t(c));
    for (int c2 = 0; c2 < c; ++c2) {
      uint32_t j = find(cornerOffset(c) - cornerOffset(c2));
      if (j != kNoCell) {
        slot = j * 8 + uint32_t(c2);
        break;
      }
    }
    g.cornerPoint[i * 8 + size_t(c)] = slot;
    if (slot == uint32_t(i * 8 + size_t(c))) owned |= uint8_t(1u << c);
  }
  g.ownedMask[i] = owned;
  g.pointBase[i + 1] = uint32_t(std::popcount(unsigned(owned)));
}

// Step 2a: number the distinct cell corners. A grid point g belongs to the kept cell
// g − offset(c') with the smallest corner code c' (the cell whose low corner it is, when
// kept). Points are numbered by owner cell, then by corner code: no sort, and the
// numbering does not depend on the thread count.
void numberCorners(Grid& g) {
  const size_t nCells = g.kept;
  g.cornerPoint.resize(nCells * 8);  // first the owner slot, then the point index
  g.ownedMask.resize(nCells);
  g.pointBase.assign(nCells + 1, 0);
  parallelForRange(0, nCells, [&](size_t begin, size_t end) {
    BrickIndex::Cursor cells(g.keptCells);
    for (size_t i = begin; i < end; ++i) numberCellCorners(g, i, cells);
  }, 1024);
  for (size_t i = 0; i < nCells; ++i) g.pointBase[i + 1] += g.pointBase[i];
  g.pointKeys.resize(g.pointBase[nCells]);
  g.pointSlot.resize(g.pointBase[nCells]);
  parallelFor(0, nCells, [&](size_t i) {
    const glm::ivec3 idx = g.cellCoords[i];
    for (int c = 0; c < 8; ++c) {
      uint32_t& cp = g.cornerPoint[i * 8 + size_t(c)];
      cp = g.pointOfSlot(cp);
      if ((g.ownedMask[i] >> c) & 1) {
        glm::ivec3 q = idx + cornerOffset(c);
        g.pointKeys[cp] = pointKey(q.x, q.y, q.z);
        g.pointSlot[cp] = uint32_t(i * 8 + size_t(c));
      }
    }
  }, 1024);
}

// Step 2b: one sample per grid point. Points are numbered in cell order and the cells come
// in recursive octree order, so a run of consecutive points is a compact cluster: batches
// of kSampleBatch of them share one tree walk and evaluate each nearby primitive over the
// whole batch.
void sampleCorners(const CompiledBlob& blob, Grid& g) {
  const size_t nPoints = g.pointKeys.size();
  g.values.resize(nPoints);
  constexpr size_t kSampleBatch = 128;
  size_t nBatches = (nPoints + kSampleBatch - 1) / kSampleBatch;
  parallelFor(0, nBatches, [&](size_t bi) {
    std::array<Vec3, kSampleBatch> pts;
    size_t b = bi * kSampleBatch, n = std::min(kSampleBatch, nPoints - b);
    for (size_t k = 0; k < n; ++k) pts[k] = gridPosition(g.cs, keyCoords(g.pointKeys[b + k]));
    blob.values(std::span<const Vec3>(pts.data(), n), std::span<float>(g.values.data() + b, n));
  }, 16);
}

// Step 3a: the inside mask of every kept cell and the active ones.
void classifyCells(Grid& g) {
  const size_t nCells = g.kept;
  g.insideMask.resize(nCells);
  parallelFor(0, nCells, [&](size_t i) {
    uint8_t m = 0;
    for (int c = 0; c < 8; ++c)
      if (g.values[g.cornerPoint[i * 8 + c]] > kIso) m |= uint8_t(1u << c);
    g.insideMask[i] = m;
  }, 4096);
  // The active cells in index order.
  g.active = indicesWhere(nCells, [&](size_t i) { return g.insideMask[i] != 0 && g.insideMask[i] != 0xff; });
}

// The neighbours of the frontier's cells across sign-changing faces that no cell covers
// yet, sorted and unique (a read-only scan, in chunks). Face f = 2·axis + side; its four
// corners are those with bit `axis` equal to side.
std::vector<uint64_t> uncoveredNeighbours(const Grid& g, const std::vector<uint32_t>& frontier,
                                          const std::map<uint64_t, uint32_t>& addedCells) {
  constexpr size_t kScan = 4096;
  std::vector<std::vector<uint64_t>> wantedParts((frontier.size() + kScan - 1) / kScan);
  parallelFor(0, wantedParts.size(), [&](size_t ch) {
    BrickIndex::Cursor cells(g.keptCells);
    size_t end = std::min(frontier.size(), (ch + 1) * kScan);
    for (size_t f = ch * kScan; f < end; ++f) {
      uint32_t i = frontier[f];
      uint8_t m = g.insideMask[i];
      for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
          int in = 0;
          for (int c = 0; c < 8; ++c)
            if (((c >> axis) & 1) == side) in += (m >> c) & 1;
          if (in == 0 || in == 4) continue;
          glm::ivec3 n = g.cellCoords[i];
          n[axis] += side ? 1 : -1;
          if (n[axis] < 0 || n[axis] + 1 >= kAxisLimit) continue;
          uint64_t key = pointKey(n.x, n.y, n.z);
          if (cells.find(n) == kNoCell && !addedCells.count(key)) wantedParts[ch].push_back(key);
        }
    }
  });
  std::vector<uint64_t> wanted = concat(wantedParts);
  std::sort(wanted.begin(), wanted.end());
  wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
  return wanted;
}

// Step 3b, closure: a cell whose face carries a sign change needs the neighbour across
// that face triangulated too, or the mesh would have a hole there. Interval bounds keep
// every such neighbour up to rounding (a corner exactly on F = 0.5 can fall just outside a
// neighbour's bound), so the rare missing ones are added here, with their corners sampled
// once and shared through the same point table.
void closeFaces(const CompiledBlob& blob, Grid& g) {
  std::map<uint64_t, uint32_t> extraPoints;  // grid points sampled for added cells
  std::map<uint64_t, uint32_t> addedCells;
  auto pointIndex = [&](glm::ivec3 q) -> uint32_t {
    uint64_t key = pointKey(q.x, q.y, q.z);
    uint32_t slot = g.ownerSlot(q);
    if (slot != kNoCell) return g.pointOfSlot(slot);
    auto [e, inserted] = extraPoints.emplace(key, uint32_t(g.pointKeys.size()));
    if (inserted) {
      g.pointKeys.push_back(key);
      g.pointSlot.push_back(kNoCell);
      g.values.push_back(blob.value(gridPosition(g.cs, q)));
    }
    return e->second;
  };
  std::vector<uint32_t> frontier(g.active.begin(), g.active.end());
  while (!frontier.empty()) {
    std::vector<uint64_t> wanted = uncoveredNeighbours(g, frontier, addedCells);
    frontier.clear();
    for (uint64_t key : wanted) {
      glm::ivec3 q = keyCoords(key);
      uint32_t id = uint32_t(g.cellCoords.size());
      addedCells.emplace(key, id);
      g.cellCoords.push_back(q);
      uint8_t m = 0;
      for (int c = 0; c < 8; ++c) {
        uint32_t u = pointIndex(q + cornerOffset(c));
        g.cornerPoint.push_back(u);
        if (g.values[u] > kIso) m |= uint8_t(1u << c);
      }
      g.insideMask.push_back(m);
      if (m != 0 && m != 0xff) {
        g.active.push_back(id);
        frontier.push_back(id);
      }
    }
    g.extraCells += wanted.size();
  }
  // Grid::findCell finds the added cells there from here on.
  g.added = std::move(addedCells);
}

// The mesh's vertices, one per crossing grid edge: numbered by owner cell, then by edge
// direction, with the inside and outside grid point of each edge.
struct Vertices {
  BigVector<uint8_t> crossMask;    // per active cell: bit d set when edge 0 -> d crosses
  BigVector<uint32_t> vertexBase;  // per active cell: its first vertex (prefix sums)
  BigVector<uint32_t> owners;      // per active cell · 8 + low-corner code: the owning active cell
  BigVector<EdgeRec> edges;        // per vertex
};

// Each cell's index in Grid::active, or kNoCell (a second hash of the active cells cost a
// serial pass of 2.6 M inserts and 128 MB of slots on the 2,000-cone benchmark).
BigVector<uint32_t> activeIndexOf(const Grid& g) {
  BigVector<uint32_t> activeOf(g.cellCoords.size());
  parallelFor(0, activeOf.size(), [&](size_t i) { activeOf[i] = kNoCell; }, size_t(1) << 16);
  parallelFor(0, g.active.size(), [&](size_t a) { activeOf[g.active[a]] = uint32_t(a); }, size_t(1) << 14);
  return activeOf;
}

// Step 4a: every crossing edge P -> P + d (d a corner code) belongs to the cell with low
// corner P; that cell has the crossing between its corners 0 and d, so it is active (kept
// by the bounds or added by the closure). Vertices are numbered by owner cell, then by d.
// Each active cell's neighbours at its corners (owners) come from Grid::upperNeighbour.
Vertices numberVertices(const Grid& g, uint8_t directions) {
  const BigVector<uint32_t> activeOf = activeIndexOf(g);
  const size_t nActive = g.active.size();
  Vertices v;
  v.crossMask.resize(nActive);
  v.vertexBase.assign(nActive + 1, 0);
  v.owners.resize(nActive * 8);
  parallelFor(0, nActive, [&](size_t a) {
    uint8_t m = g.insideMask[g.active[a]], cross = 0;
    for (int d = 1; d < 8; ++d)
      if (((directions >> d) & 1) && ((m >> d) & 1) != (m & 1)) cross |= uint8_t(1u << d);
    v.crossMask[a] = cross;
    v.vertexBase[a + 1] = uint32_t(std::popcount(unsigned(cross)));
    v.owners[a * 8] = uint32_t(a);
    for (int lo = 1; lo < 8; ++lo) {
      const uint32_t j = g.upperNeighbour(g.active[a], lo);
      v.owners[a * 8 + size_t(lo)] = j == kNoCell ? kNoCell : activeOf[j];
    }
  }, 2048);
  for (size_t a = 0; a < nActive; ++a) v.vertexBase[a + 1] += v.vertexBase[a];
  // The inside and outside grid point of each vertex's edge.
  v.edges.resize(v.vertexBase[nActive]);
  parallelFor(0, nActive, [&](size_t a) {
    const uint32_t* cp = &g.cornerPoint[size_t(g.active[a]) * 8];
    bool lowInside = g.insideMask[g.active[a]] & 1;
    uint32_t k = v.vertexBase[a];
    for (int d = 1; d < 8; ++d)
      if ((v.crossMask[a] >> d) & 1) v.edges[k++] = lowInside ? EdgeRec{cp[0], cp[d]} : EdgeRec{cp[d], cp[0]};
  }, 2048);
  return v;
}

// Step 4b: marching tetrahedra over the active cells. Triangles are counted per chunk
// first, then written in place (no per-chunk buffers).
std::vector<glm::uvec3> triangulate(const Grid& g, const Vertices& v) {
  const size_t nActive = g.active.size();
  constexpr size_t kChunk = 2048;
  size_t nChunks = (nActive + kChunk - 1) / kChunk;
  std::vector<size_t> triBase(nChunks + 1, 0);
  parallelFor(0, nChunks, [&](size_t ch) {
    size_t begin = ch * kChunk, end = std::min(nActive, begin + kChunk), n = 0;
    for (size_t a = begin; a < end; ++a) n += kTriangleCount[g.insideMask[g.active[a]]];
    triBase[ch + 1] = n;
  });
  for (size_t ch = 0; ch < nChunks; ++ch) triBase[ch + 1] += triBase[ch];
  std::vector<glm::uvec3> triangles;
  resizeOutput(triangles, triBase[nChunks]);
  parallelFor(0, nChunks, [&](size_t ch) {
    size_t begin = ch * kChunk, end = std::min(nActive, begin + kChunk);
    TetEmitter em{nullptr, v.vertexBase.data(), v.crossMask.data(), triangles.data() + triBase[ch]};
    for (size_t a = begin; a < end; ++a) {
      em.owners = &v.owners[a * 8];
      uint8_t m = g.insideMask[g.active[a]];
      for (const auto& t : kTets) {
        bool in[4] = {bool(m >> t[0] & 1), bool(m >> t[1] & 1), bool(m >> t[2] & 1), bool(m >> t[3] & 1)};
        em.run(t, in);
      }
    }
    if (em.out != triangles.data() + triBase[ch + 1]) throw std::logic_error("polygonize: triangle count mismatch");
  });
  return triangles;
}

// Whether the vertices get uvs, and their blended attributes (PolygonizeOptions::vertexData).
bool wantsUvs(const PolygonizeOptions& o) { return o.vertexData != PolygonizeOptions::VertexData::None; }
bool wantsBlend(const PolygonizeOptions& o) { return o.vertexData == PolygonizeOptions::VertexData::Blend; }

// The output arrays of nVerts vertices that options ask for.
void resizeVertexArrays(const PolygonizeOptions& options, size_t nVerts, PolygonizeResult& res) {
  resizeOutput(res.mesh.positions, nVerts);
  if (options.normals) resizeOutput(res.mesh.normals, nVerts);
  if (wantsUvs(options)) resizeOutput(res.mesh.uvs, nVerts);
  if (wantsBlend(options)) resizeOutput(res.attributes, nVerts);
}

// Vertex v's normal −∇F/|∇F| (or a mark in flatGradient where the gradient vanishes), uv
// and attributes from the field's sample there, as options ask.
void storeSample(const PolygonizeOptions& options, const Sample& smp, size_t v, PolygonizeResult& res,
                 std::vector<uint8_t>& flatGradient) {
  if (options.normals) {
    float len = glm::length(smp.gradient);
    if (len > 1e-20f && std::isfinite(len)) res.mesh.normals[v] = -smp.gradient / len;
    else flatGradient[v] = 1;
  }
  if (wantsUvs(options)) res.mesh.uvs[v] = smp.attributes.uv;
  if (wantsBlend(options)) res.attributes[v] = smp.attributes;
}

// Where a grid corner lies on the surface to within rounding, the root search puts the
// vertex of every edge from that corner onto the corner itself: distinct vertices at one
// position, which every weld by position (the simplifier's, a viewer's, a slicer's, a test's
// weld of a shell's parts) merges into a pinch, with degenerate triangles and edges of four
// triangles. Such vertices are moved kCornerSpacings float spacings (of the edge's largest
// coordinate) out along their own edges. The Kuhn edges at a corner are at least 35.26°
// apart, so two vertices that far out along two of them lie at least 0.6 · 16 = 9.6
// spacings apart, and one that far from a vertex nearer the corner, more than their
// positions' rounding (about 2 spacings a coordinate, under 7 in all): no two vertices share
// a position, and the mesh stays the closed 2-manifold marching tetrahedra made, whatever
// welds it. Two vertices can share a position only when both lie within a few spacings of
// one corner (vertices near different corners are a cell apart), so only vertices within
// kCornerSpacings of a corner are compared, corner by corner.
constexpr double kCornerSpacings = 16.0;

// kCornerSpacings float spacings as a fraction of the edge pIn-pOut (0.25 or more: the edge
// is too short for it).
double cornerMargin(Vec3 pIn, Vec3 pOut) {
  const Vec3 far = glm::max(glm::abs(pIn), glm::abs(pOut));
  const float largest = std::max({far.x, far.y, far.z, FLT_MIN});
  const double spacing = std::ldexp(1.0, std::ilogb(largest) - (FLT_MANT_DIG - 1));
  return kCornerSpacings * spacing / glm::length(glm::dvec3(pOut) - glm::dvec3(pIn));
}

// A vertex's end of its edge within the corner margin: 0 neither, 1 inside, 2 outside.
enum NearCorner : uint8_t { kNearNone = 0, kNearInside = 1, kNearOutside = 2 };

// Step 5a: every vertex moved onto F = 0.5 along its edge, with its normal and attributes.
// Fixed blocks of vertices (consecutive edge keys: spatially coherent rows) iterate in
// lockstep, each step one batched values() call over the block's unconverged vertices.
// Blocks do not depend on the thread count, so neither do the results. Returns the root
// search's field evaluations per vertex; flatGradient marks vertices without a gradient,
// and nearCorner, when given, the vertices within the corner margin of an end (NearCorner).
std::vector<uint8_t> placeVertices(const CompiledBlob& blob, const PolygonizeOptions& options, const Grid& g,
                                   const BigVector<EdgeRec>& edges, PolygonizeResult& res,
                                   std::vector<uint8_t>& flatGradient, std::vector<uint8_t>* nearCorner = nullptr) {
  const size_t nVerts = edges.size();
  Mesh& mesh = res.mesh;
  std::unique_ptr<Progress> bar;
  if (options.progress) bar = std::make_unique<Progress>("polygonize", nVerts);
  resizeVertexArrays(options, nVerts, res);
  std::vector<uint8_t> evals(nVerts, 0);
  flatGradient.assign(nVerts, 0);
  if (nearCorner) nearCorner->assign(nVerts, kNearNone);
  constexpr size_t kBlock = 64;
  size_t nBlocks = (nVerts + kBlock - 1) / kBlock;
  parallelFor(0, nBlocks, [&](size_t blk) {
    size_t begin = blk * kBlock, end = std::min(nVerts, begin + kBlock);
    size_t n = end - begin;
    // Illinois regula falsi on g(t) = F(lerp(pIn, pOut, t)) − 0.5 with g(0) > 0 >= g(1).
    std::array<Vec3, kBlock> pIn, pOut, pts;
    std::array<double, kBlock> a, b, fa, fb, t;
    std::array<int8_t, kBlock> side;
    std::array<float, kBlock> out;
    std::array<uint32_t, kBlock> live;
    size_t nLive = 0;
    for (size_t k = 0; k < n; ++k) {
      const EdgeRec& e = edges[begin + k];
      pIn[k] = gridPosition(g.cs, keyCoords(g.pointKeys[e.inside]));
      pOut[k] = gridPosition(g.cs, keyCoords(g.pointKeys[e.outside]));
      a[k] = 0.0, b[k] = 1.0, side[k] = 0;
      fa[k] = double(g.values[e.inside]) - kIso, fb[k] = double(g.values[e.outside]) - kIso;
      t[k] = fa[k] / (fa[k] - fb[k]);
      if (options.refineSteps > 0) live[nLive++] = uint32_t(k);
    }
    for (int step = 0; step < options.refineSteps && nLive > 0; ++step) {
      for (size_t j = 0; j < nLive; ++j) {
        uint32_t k = live[j];
        pts[j] = pIn[k] + float(t[k]) * (pOut[k] - pIn[k]);
      }
      blob.values(std::span<const Vec3>(pts.data(), nLive), std::span<float>(out.data(), nLive));
      size_t kept = 0;
      for (size_t j = 0; j < nLive; ++j) {
        uint32_t k = live[j];
        ++evals[begin + k];
        float f = out[j] - kIso;
        if (std::fabs(f) < options.fieldTolerance) continue;
        if (f > 0.0f) {
          a[k] = t[k], fa[k] = f;
          if (side[k] == 1) fb[k] *= 0.5;
          side[k] = 1;
        } else {
          b[k] = t[k], fb[k] = f;
          if (side[k] == -1) fa[k] *= 0.5;
          side[k] = -1;
        }
        if (b[k] - a[k] < 1e-7) continue;
        t[k] = a[k] + fa[k] * (b[k] - a[k]) / (fa[k] - fb[k]);
        live[kept++] = k;
      }
      nLive = kept;
    }
    for (size_t k = 0; k < n; ++k) {
      size_t v = begin + k;
      Vec3 p = pIn[k] + float(t[k]) * (pOut[k] - pIn[k]);
      mesh.positions[v] = p;
      if (options.normals || wantsUvs(options)) storeSample(options, blob.sample(p), v, res, flatGradient);
      if (nearCorner) {
        const double margin = cornerMargin(pIn[k], pOut[k]);
        if (margin < 0.25) (*nearCorner)[v] = t[k] < margin ? kNearInside : t[k] > 1.0 - margin ? kNearOutside : kNearNone;
      }
    }
    if (bar) bar->advance(n);
  });
  if (bar) bar->finish();
  return evals;
}

// Step 5b: vertices that share a position with another (see kCornerSpacings) moved out
// along their edges, with their normal and attributes; returns how many.
size_t separateVertices(const CompiledBlob& blob, const PolygonizeOptions& options, const Grid& g,
                        const BigVector<EdgeRec>& edges, const std::vector<uint8_t>& nearCorner,
                        PolygonizeResult& res, std::vector<uint8_t>& flatGradient) {
  const BigVector<uint32_t> near = indicesWhere(nearCorner.size(), [&](size_t v) { return nearCorner[v] != kNearNone; });
  auto cornerOf = [&](uint32_t v) { return nearCorner[v] == kNearInside ? edges[v].inside : edges[v].outside; };
  std::vector<std::pair<uint32_t, uint32_t>> byCorner;  // (grid point, vertex)
  byCorner.reserve(near.size());
  for (uint32_t v : near) byCorner.push_back({cornerOf(v), v});
  std::sort(byCorner.begin(), byCorner.end());
  std::vector<uint32_t> moving;
  for (size_t i = 0, j = 0; i < byCorner.size(); i = j) {
    while (j < byCorner.size() && byCorner[j].first == byCorner[i].first) ++j;
    for (size_t a = i; a < j; ++a)
      for (size_t b = i; b < j; ++b)
        if (a != b && res.mesh.positions[byCorner[a].second] == res.mesh.positions[byCorner[b].second]) {
          moving.push_back(byCorner[a].second);
          break;
        }
  }
  for (uint32_t v : moving) {
    const Vec3 pIn = gridPosition(g.cs, keyCoords(g.pointKeys[edges[v].inside]));
    const Vec3 pOut = gridPosition(g.cs, keyCoords(g.pointKeys[edges[v].outside]));
    const double margin = cornerMargin(pIn, pOut);
    const Vec3 p = pIn + float(nearCorner[v] == kNearInside ? margin : 1.0 - margin) * (pOut - pIn);
    res.mesh.positions[v] = p;
    flatGradient[v] = 0;
    if (options.normals || wantsUvs(options)) storeSample(options, blob.sample(p), v, res, flatGradient);
  }
  return moving.size();
}

// Step 5c: vertices where the gradient vanishes take the area-weighted normal of their
// triangles.
void fixFlatNormals(Mesh& mesh, const std::vector<uint8_t>& flatGradient) {
  if (std::find(flatGradient.begin(), flatGradient.end(), 1) == flatGradient.end()) return;
  std::vector<Vec3> acc(mesh.positions.size(), Vec3(0.0f));
  for (const auto& tri : mesh.triangles) {
    Vec3 n = glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]);
    for (int k = 0; k < 3; ++k)
      if (flatGradient[tri[k]]) acc[tri[k]] += n;
  }
  for (size_t v = 0; v < mesh.positions.size(); ++v)
    if (flatGradient[v]) {
      float len = glm::length(acc[v]);
      mesh.normals[v] = len > 0.0f ? acc[v] / len : Vec3(0, 1, 0);
    }
}


// Dual marching cubes (blobtree/detail/dual_patches.h): a vertex per surface patch of each
// active cell, a quad (two triangles) per crossing axis edge of the grid. Steps 4-5 of the
// file comment for PolygonizeOptions::Mesher::DualMarchingCubes.
class DualMesher {
 public:
  DualMesher(const CompiledBlob& blob, const PolygonizeOptions& options, Grid& g, PolygonizeResult& res)
      : blob_(blob), options_(options), g_(g), res_(res), nActive_(g.active.size()),
        // Crossing axis edges (directions 1, 2, 4), each owned by the cell at its low end.
        v_(numberVertices(g, uint8_t((1u << 1) | (1u << 2) | (1u << 4)))) {}

  void run() {
    // Each working array is released once the steps below no longer read it (releaseAll).
    releaseAll(g_.pointSlot, g_.ownedMask, g_.pointBase);  // (the vertex numbering's)
    const std::vector<uint8_t> evals = crossingPoints();
    gridPoints_ = g_.pointKeys.size();
    edgeCount_ = v_.edges.size();
    releaseAll(g_.pointKeys, v_.edges);
    cellPatchesAll();
    releaseAll(g_.cornerPoint, g_.values);
    Mesh& mesh = res_.mesh;
    const size_t nVerts = patchBase_[nActive_];
    // With uvs, the batched path samples each vertex once all are placed and the quads
    // made (sampleVertices), so that the normals, uvs and attributes reuse the pages of
    // every working array released by then. The samples are those it took at once before.
    const bool deferred = options_.batchedNewton && wantsUvs(options_);
    if (deferred) {
      resizeOutput(mesh.positions, nVerts);
    } else {
      resizeVertexArrays(options_, nVerts, res_);
      flatGradient_.assign(nVerts, 0);
    }
    if (options_.progress) bar_ = std::make_unique<Progress>("polygonize", nActive_);
    // Each patch's vertex: the mean of its crossing points, then Newton steps along the
    // gradient toward F = 0.5, kept inside the cell (so the quads keep their layout).
    const size_t blocks = (nActive_ + kCellBlock - 1) / kCellBlock;
    if (options_.batchedNewton) parallelFor(0, blocks, [&](size_t blk) { placeBlockBatched(blk); });
    else parallelFor(0, blocks, [&](size_t blk) { placeBlockScalar(blk); });
    if (bar_) bar_->finish();
    releaseAll(cross_);
    quads();
    if (deferred) {
      releaseAll(v_.owners, v_.crossMask, v_.vertexBase, patches_, patchBase_, g_.active, g_.insideMask, g_.cellCoords);
      sampleVertices();
    }
    if (options_.normals) fixFlatNormals(mesh, flatGradient_);
    size_t total = gridPoints_ + sampleCount_.load();
    for (uint8_t k : evals) total += k;
    res_.fieldEvaluations = total;
  }

 private:
  static constexpr int kNewtonSteps = 3;
  static constexpr size_t kCellBlock = 256;

  /// The crossing point's index of edge e of active cell a.
  uint32_t edgePoint(size_t a, int e) const {
    uint32_t owner = v_.owners[a * 8 + size_t(detail::lowCorner(e))];
    unsigned d = 1u << detail::edgeAxis(e);
    if (owner == kNoCell || !((v_.crossMask[owner] >> d) & 1)) throw std::logic_error("polygonize: crossing edge without an owner cell");
    return v_.vertexBase[owner] + uint32_t(std::popcount(unsigned(v_.crossMask[owner]) & ((1u << d) - 1u)));
  }

  /// The crossing points on the edges, by the same root search as the tetrahedra's
  /// vertices. The patch's Newton steps land the vertex on the surface; its starting mean
  /// needs only the crossings of the corner values' linear interpolation (as in Nielson's
  /// dual marching cubes), so no field is evaluated on the edges. Measured on the 2,000-cone
  /// scene: 11.9 M field evaluations instead of 18.3 M with three regula-falsi steps per
  /// edge, and the vertices that end more than 1e-3 off F = 0.5 (clamped in their cell at
  /// creases) 0.15 % instead of 0.09 % (tests/blobtree/dual_mesher_test.cpp bounds them).
  /// Returns the field evaluations per edge.
  std::vector<uint8_t> crossingPoints() {
    PolygonizeOptions edgeOptions = options_;
    edgeOptions.normals = edgeOptions.progress = false;
    edgeOptions.vertexData = PolygonizeOptions::VertexData::None;
    edgeOptions.refineSteps = 0;
    PolygonizeResult crossings;
    std::vector<uint8_t> unusedFlat;
    std::vector<uint8_t> evals = placeVertices(blob_, edgeOptions, g_, v_.edges, crossings, unusedFlat);
    cross_ = std::move(crossings.mesh.positions);
    return evals;
  }

  /// The active cell across each low face (−x, −y, −z) of every active cell, or kNoCell:
  /// the owners table names the cell across each high face, and each active cell is the
  /// low neighbour of at most one cell per axis, so a scatter fills it without a lookup.
  BigVector<uint32_t> lowNeighbours() const {
    BigVector<uint32_t> low(3 * nActive_);
    parallelFor(0, low.size(), [&](size_t i) { low[i] = kNoCell; }, size_t(1) << 16);
    parallelFor(0, nActive_, [&](size_t a) {
      for (int axis = 0; axis < 3; ++axis) {
        const uint32_t n = v_.owners[a * 8 + (size_t(1) << axis)];
        if (n != kNoCell) low[size_t(n) * 3 + size_t(axis)] = uint32_t(a);
      }
    }, size_t(1) << 13);
    return low;
  }

  /// The patches of every active cell, numbered by cell (patchBase_: prefix sums).
  void cellPatchesAll() {
    patches_ = BigVector<detail::CellPatches>(nActive_);
    patchBase_ = BigVector<uint32_t>(nActive_ + 1, 0);
    const BigVector<uint32_t> low = lowNeighbours();
    parallelFor(0, nActive_, [&](size_t a) {
      auto valuesOf = [&](size_t cell, float* f) {
        for (int c = 0; c < 8; ++c) f[c] = g_.values[g_.cornerPoint[cell * 8 + size_t(c)]] - kIso;
      };
      float f[8], fn[8];
      valuesOf(g_.active[a], f);
      // Ambiguous faces whose diagonal corners both cells join are decided for manifoldness.
      int8_t forced[6];
      for (int face = 0; face < 6; ++face) {
        forced[face] = -1;
        const int axis = face / 2, side = face % 2;
        const uint32_t j = side ? v_.owners[a * 8 + (size_t(1) << axis)] : low[a * 3 + size_t(axis)];
        if (j == kNoCell) continue;
        valuesOf(g_.active[j], fn);
        forced[face] = detail::forcedFaceDecision(f, fn, axis, side);
      }
      patches_[a] = detail::cellPatches(f, forced);
      patchBase_[a + 1] = uint32_t(patches_[a].count);
    }, 2048);
    for (size_t a = 0; a < nActive_; ++a) patchBase_[a + 1] += patchBase_[a];
  }

  /// The start of each patch of active cell a (the mean of its crossings) and the cell's box.
  void patchStart(size_t a, Vec3* start, Vec3& lo, Vec3& hi) const {
    const detail::CellPatches& cp = patches_[a];
    std::array<Vec3, 4> sum{};
    std::array<int, 4> n{};
    for (int e = 0; e < 12; ++e)
      if (cp.patch[e] >= 0) {
        sum[size_t(cp.patch[e])] += cross_[edgePoint(a, e)];
        ++n[size_t(cp.patch[e])];
      }
    lo = gridPosition(g_.cs, g_.cellCoords[g_.active[a]]);
    hi = lo + Vec3(g_.cs.cellSize);
    for (int k = 0; k < cp.count; ++k) start[k] = sum[size_t(k)] / float(n[size_t(k)]);
  }

  /// The same steps as placeBlockScalar, in lockstep over the patches of a block of cells:
  /// each step one valuesAndGradients() call over the block's unconverged vertices
  /// (consecutive cells in octree order: a compact cluster).
  void placeBlockBatched(size_t blk) {
    const size_t begin = blk * kCellBlock, end = std::min(nActive_, begin + kCellBlock);
    const size_t first = patchBase_[begin], n = patchBase_[end] - first;
    std::vector<Vec3> p(n), lo(n), hi(n), grad(n), pts(n), gOut(n);
    std::vector<float> val(n), vOut(n);
    std::vector<uint32_t> live(n);
    for (size_t a = begin; a < end; ++a) {
      Vec3 l, h;
      patchStart(a, &p[patchBase_[a] - first], l, h);
      for (uint32_t k = patchBase_[a] - uint32_t(first); k < patchBase_[a + 1] - first; ++k) lo[k] = l, hi[k] = h;
    }
    size_t samples = n;
    blob_.valuesAndGradients(p, val, grad);
    size_t nLive = 0;
    if (options_.refineSteps > 0)
      for (size_t k = 0; k < n; ++k) live[nLive++] = uint32_t(k);
    for (int step = 0; step < kNewtonSteps && nLive > 0; ++step) {
      size_t moved = 0;
      for (size_t j = 0; j < nLive; ++j) {
        const uint32_t k = live[j];
        const float r = val[k] - kIso, gg = glm::dot(grad[k], grad[k]);
        if (std::fabs(r) < options_.fieldTolerance || !(gg > 1e-30f) || !std::isfinite(gg)) continue;
        const Vec3 q = glm::clamp(p[k] - (r / gg) * grad[k], lo[k], hi[k]);
        if (q == p[k]) continue;
        p[k] = q;
        pts[moved] = q;
        live[moved++] = k;
      }
      nLive = moved;
      if (nLive == 0) break;
      blob_.valuesAndGradients(std::span<const Vec3>(pts.data(), nLive), std::span<float>(vOut.data(), nLive),
                               std::span<Vec3>(gOut.data(), nLive));
      samples += nLive;
      for (size_t j = 0; j < nLive; ++j) val[live[j]] = vOut[j], grad[live[j]] = gOut[j];
    }
    for (size_t k = 0; k < n; ++k) {
      const size_t vi = first + k;
      res_.mesh.positions[vi] = p[k];
      if (!wantsUvs(options_) && options_.normals) {  // (with uvs: sampleVertices)
        Sample smp;
        smp.value = val[k];
        smp.gradient = grad[k];
        storeSample(options_, smp, vi, res_, flatGradient_);
      }
    }
    sampleCount_ += samples;
    if (bar_) bar_->advance(end - begin);
  }

  /// Every placed vertex's normal, uv and attributes from one sample() at it, in fixed
  /// blocks (the batched path with uvs; the arrays are made here).
  void sampleVertices() {
    const size_t nVerts = res_.mesh.positions.size();
    resizeVertexArrays(options_, nVerts, res_);  // (positions: already that size)
    flatGradient_.assign(nVerts, 0);
    constexpr size_t kBlock = 1024;
    parallelFor(0, (nVerts + kBlock - 1) / kBlock, [&](size_t blk) {
      const size_t end = std::min(nVerts, (blk + 1) * kBlock);
      for (size_t v = blk * kBlock; v < end; ++v)
        storeSample(options_, blob_.sample(res_.mesh.positions[v]), v, res_, flatGradient_);
    });
    sampleCount_ += nVerts;
  }

  /// Newton steps one vertex at a time, with F and ∇F from CompiledBlob::sample.
  void placeBlockScalar(size_t blk) {
    const size_t begin = blk * kCellBlock, end = std::min(nActive_, begin + kCellBlock);
    size_t samples = 0;
    for (size_t a = begin; a < end; ++a) {
      Vec3 start[4], lo, hi;
      patchStart(a, start, lo, hi);
      for (int k = 0; k < patches_[a].count; ++k) {
        Vec3 p = start[k];
        Sample smp = blob_.sample(p);
        ++samples;
        for (int step = 0; step < kNewtonSteps && options_.refineSteps > 0; ++step) {
          float r = smp.value - kIso, gg = glm::dot(smp.gradient, smp.gradient);
          if (std::fabs(r) < options_.fieldTolerance || !(gg > 1e-30f) || !std::isfinite(gg)) break;
          Vec3 q = glm::clamp(p - (r / gg) * smp.gradient, lo, hi);
          if (q == p) break;
          p = q;
          smp = blob_.sample(p);
          ++samples;
        }
        size_t vi = patchBase_[a] + size_t(k);
        res_.mesh.positions[vi] = p;
        storeSample(options_, smp, vi, res_, flatGradient_);
      }
    }
    sampleCount_ += samples;
    if (bar_) bar_->advance(end - begin);
  }

  /// A quad per crossing edge, joining its patch in the four cells around it, ordered
  /// counter-clockwise seen from the outside; split along its shorter diagonal. The quad
  /// of the edge along axis owned by cell q (its low end is q's corner 0) is made by the
  /// cell m = q − e_b − e_c, which holds the edge as its edge 4·axis + 3 and reaches the
  /// other three cells through its owners table (no lookup); the quad's two triangles go
  /// to the slots of the edge's vertex number, so the order of the cells does not matter.
  void quads() {
    Mesh& mesh = res_.mesh;
    resizeOutput(mesh.triangles, 2 * edgeCount_);
    parallelFor(0, nActive_, [&](size_t m) {
      const uint8_t mask = g_.insideMask[g_.active[m]];
      for (int axis = 0; axis < 3; ++axis) {
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        const int from = (1 << b) | (1 << c), to = from | (1 << axis);
        if (((mask >> from) & 1) == ((mask >> to) & 1)) continue;
        static constexpr int kAround[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // counter-clockwise about +axis
        uint32_t quad[4];
        for (int k = 0; k < 4; ++k) {
          // Cell q − kAround[k] is m + (1 − kAround[k]) along b and c.
          const size_t lo = size_t(((1 - kAround[k][0]) << b) | ((1 - kAround[k][1]) << c));
          const uint32_t j = v_.owners[m * 8 + lo];
          const int e = 4 * axis + kAround[k][0] + 2 * kAround[k][1];
          if (j == kNoCell || patches_[j].patch[size_t(e)] < 0) throw std::logic_error("polygonize: crossing edge without its four cells");
          quad[k] = patchBase_[j] + uint32_t(patches_[j].patch[size_t(e)]);
        }
        if (!((mask >> from) & 1)) std::swap(quad[1], quad[3]);  // the outside is toward −axis
        const size_t t = 2 * size_t(edgePoint(m, 4 * axis + 3));
        const std::vector<Vec3>& P = mesh.positions;
        if (glm::length(P[quad[0]] - P[quad[2]]) <= glm::length(P[quad[1]] - P[quad[3]])) {
          mesh.triangles[t] = {quad[0], quad[1], quad[2]};
          mesh.triangles[t + 1] = {quad[0], quad[2], quad[3]};
        } else {
          mesh.triangles[t] = {quad[0], quad[1], quad[3]};
          mesh.triangles[t + 1] = {quad[1], quad[2], quad[3]};
        }
      }
    }, 2048);
  }

  const CompiledBlob& blob_;
  const PolygonizeOptions& options_;
  Grid& g_;  ///< its arrays are released as the mesher is done with them (releaseAll)
  PolygonizeResult& res_;
  const size_t nActive_;
  Vertices v_;
  size_t gridPoints_ = 0, edgeCount_ = 0;  ///< g_.pointKeys.size(), v_.edges.size() before their release
  std::vector<Vec3> cross_;  ///< the crossing point of each crossing edge
  BigVector<detail::CellPatches> patches_;
  BigVector<uint32_t> patchBase_;
  std::vector<uint8_t> flatGradient_;
  std::unique_ptr<Progress> bar_;
  std::atomic<size_t> sampleCount_{0};
};

// Steps 4-5 by dual marching cubes; g's working arrays are released on the way (releaseAll).
void dualMesh(const CompiledBlob& blob, const PolygonizeOptions& options, Grid& g, PolygonizeResult& res) {
  DualMesher(blob, options, g, res).run();
}

}  // namespace

PolygonizeResult polygonizeDetailed(const CompiledBlob& blob, const PolygonizeOptions& options) {
  const Phase phase("polygonize");
  PolygonizeResult res;
  float requested = resolveCellSize(blob, options);
  if (requested <= 0.0f || blob.bounds().empty()) return res;
  auto clock = std::chrono::steady_clock::now();
  double cpuClock = processCpuSeconds();
  // The wall seconds since the last lap; the process's CPU seconds into cpu.
  auto lap = [&clock, &cpuClock](double& cpu) {
    auto now = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(now - clock).count(), c = processCpuSeconds();
    clock = now;
    cpu = c - cpuClock;
    cpuClock = c;
    return s;
  };

  // The grid is checked before any cell is found: a tiny cell over a large model would
  // otherwise allocate without bound while the sparse cells are collected.
  {
    Vec3 size = blob.bounds().size();
    double cells = std::max({double(size.x), double(size.y), double(size.z)}) / double(requested);
    if (!(cells < double(kAxisLimit - 2))) {
      // The numbers as computed (double): a model reaching infinity gives no finite count.
      char buf[160];
      if (std::isfinite(cells))
        std::snprintf(buf, sizeof buf, cells < 1e15 ? "a polygonization cell of %g gives a grid of %.0f cells on an axis"
                                                    : "a polygonization cell of %g gives a grid of %g cells on an axis",
                      double(requested), cells);
      else
        std::snprintf(buf, sizeof buf, "a polygonization cell of %g over a model whose bounds are not finite gives no finite grid",
                      double(requested));
      throw InputError(SourceLoc{}, std::string(buf) + ", more than the limit of " + std::to_string(kAxisLimit - 2) +
                                        " (2^20): use a larger cell (sprig mesh --cell, a blob's cell_size)");
    }
  }
  // 1. Cells that may hold the surface.
  Grid g(keptCells(blob, requested));
  res.cellSeconds = lap(res.cellCpuSeconds);
  res.cellSize = g.cs.cellSize;
  res.surfaceCells = g.kept;
  if (g.kept == 0) return res;

  // 2. One sample per distinct cell corner.
  numberCorners(g);
  res.gridSamples = g.pointKeys.size();
  sampleCorners(blob, g);
  if (options.progress && ProgressSettings::cancelRequested()) throw Cancelled();
  res.sampleSeconds = lap(res.sampleCpuSeconds);

  // 3. Cells with a sign change, closed across faces.
  classifyCells(g);
  closeFaces(blob, g);
  res.gridSamples = g.pointKeys.size();
  res.activeCells = g.active.size();
  res.extraCells = g.extraCells;
  if (g.active.empty()) return res;

  if (options.mesher == PolygonizeOptions::Mesher::DualMarchingCubes) {
    dualMesh(blob, options, g, res);
    res.vertexSeconds = lap(res.vertexCpuSeconds);
    return res;
  }

  // 4. Vertex numbering and marching tetrahedra.
  Vertices v = numberVertices(g, 0xfe);
  res.mesh.triangles = triangulate(g, v);
  // The root search reads only the grid points' keys and values (releaseAll).
  releaseAll(v.owners, v.crossMask, v.vertexBase, g.cornerPoint, g.pointSlot, g.ownedMask, g.pointBase, g.insideMask,
             g.active, g.cellCoords);
  res.triangulateSeconds = lap(res.triangulateCpuSeconds);

  // 5. Vertices: root search along each edge, then normal and attributes.
  std::vector<uint8_t> flatGradient;
  std::vector<uint8_t> nearCorner;
  std::vector<uint8_t> evals = placeVertices(blob, options, g, v.edges, res, flatGradient, &nearCorner);
  res.separatedVertices = separateVertices(blob, options, g, v.edges, nearCorner, res, flatGradient);
  if (options.normals) fixFlatNormals(res.mesh, flatGradient);
  res.vertexSeconds = lap(res.vertexCpuSeconds);
  const size_t nVerts = v.edges.size();
  size_t total = g.pointKeys.size() + (options.normals || wantsUvs(options) ? nVerts : 0);
  for (uint8_t n : evals) total += n;
  res.fieldEvaluations = total + (options.normals || wantsUvs(options) ? res.separatedVertices : 0);
  return res;
}

Mesh polygonize(const CompiledBlob& blob, const PolygonizeOptions& options) {
  return std::move(polygonizeDetailed(blob, options).mesh);
}

}  // namespace sprig::blobtree
