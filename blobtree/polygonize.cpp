#include "blobtree/polygonize.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <atomic>
#include <bit>
#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "blobtree/detail/marching_tets.h"
#include "core/parallel.h"
#include "core/progress.h"

namespace sprig::blobtree {

namespace {

using detail::cornerOffset;
using detail::kNoCell;
using detail::kTets;
using detail::kTriangleCount;
using detail::TetEmitter;

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
    slots_.assign(cap, Slot{kEmpty, kNoCell});
    mask_ = cap - 1;
  }
  void insert(uint64_t key, uint32_t id) {
    size_t i = slot(key);
    while (slots_[i].key != kEmpty && slots_[i].key != key) i = (i + 1) & mask_;
    slots_[i] = Slot{key, id};
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
  std::vector<Slot> slots_;
  size_t mask_ = 0;
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
  const float diag = glm::length(size);
  float h = diag / options.sizeDivisions;
  float feature = blob.smallestFeature();
  if (feature > 0.0f) h = std::min(h, options.featureFraction * feature);
  if (options.maxDivisions > 0.0f) h = std::max(h, diag / options.maxDivisions);
  return h;
}

PolygonizeResult polygonizeDetailed(const CompiledBlob& blob, const PolygonizeOptions& options) {
  PolygonizeResult res;
  float requested = resolveCellSize(blob, options);
  if (requested <= 0.0f || blob.bounds().empty()) return res;

  // ---- 1. Cells that may hold the surface ------------------------------------------
  auto clock = std::chrono::steady_clock::now();
  auto lap = [&clock] {
    auto now = std::chrono::steady_clock::now();
    double s = std::chrono::duration<double>(now - clock).count();
    clock = now;
    return s;
  };
  // Cells of exactly the requested edge; no Lipschitz bounds or primitive lists (the
  // tracer's needs, not ours).
  CellSet cs = blob.surfaceCells(requested, SurfaceCellOptions{.exactCellSize = true, .lipschitz = false,
                                                               .primitiveLists = false});
  res.cellSeconds = lap();
  res.cellSize = cs.cellSize;
  res.surfaceCells = cs.cells.size();
  const size_t nCells = cs.cells.size();
  if (nCells == 0) return res;
  if (nCells >= (size_t(1) << 29)) throw std::invalid_argument("polygonize: too many surface cells; use a larger cell size");
  for (const Cell& c : cs.cells)
    for (int a = 0; a < 3; ++a)
      if (c.index[a] < 0 || c.index[a] + 1 >= kAxisLimit)
        throw std::invalid_argument("polygonize: the grid has more than 2^20 cells on an axis; use a larger cell size");

  // ---- 2. One sample per distinct cell corner ---------------------------------------
  // A grid point g belongs to the kept cell g − offset(c') with the smallest corner code c'
  // (the cell whose low corner it is, when kept). Points are numbered by owner cell, then
  // by corner code: no sort, and the numbering does not depend on the thread count.
  CellHash cellIndex(nCells);
  for (size_t i = 0; i < nCells; ++i) {
    const auto& idx = cs.cells[i].index;
    cellIndex.insert(pointKey(idx[0], idx[1], idx[2]), uint32_t(i));
  }
  // The owner slot (cell · 8 + corner) of grid point g, or kNoCell when no kept cell holds it.
  auto ownerSlot = [&](glm::ivec3 g) -> uint32_t {
    for (int c = 0; c < 8; ++c) {
      glm::ivec3 lo = g - cornerOffset(c);
      if (lo.x < 0 || lo.y < 0 || lo.z < 0) continue;
      uint32_t j = cellIndex.find(pointKey(lo.x, lo.y, lo.z));
      if (j != kNoCell) return j * 8 + uint32_t(c);
    }
    return kNoCell;
  };
  std::vector<uint32_t> cornerPoint(nCells * 8);  // first the owner slot, then the point index
  std::vector<uint8_t> ownedMask(nCells);
  std::vector<uint32_t> pointBase(nCells + 1, 0);
  parallelFor(0, nCells, [&](size_t i) {
    const glm::ivec3 idx(cs.cells[i].index[0], cs.cells[i].index[1], cs.cells[i].index[2]);
    // Corner c is owned by the neighbour idx + offset(c) − offset(c') with the smallest
    // c' < c that is kept, else by this cell. Neighbours by displacement (27 of them),
    // each looked up at most once.
    std::array<uint32_t, 27> neighbour;
    neighbour.fill(kNoCell - 1);  // not looked up yet
    auto find = [&](glm::ivec3 d) {
      uint32_t& n = neighbour[size_t((d.x + 1) + 3 * (d.y + 1) + 9 * (d.z + 1))];
      if (n == kNoCell - 1) {
        glm::ivec3 g = idx + d;
        n = g.x < 0 || g.y < 0 || g.z < 0 ? kNoCell : cellIndex.find(pointKey(g.x, g.y, g.z));
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
      cornerPoint[i * 8 + size_t(c)] = slot;
      if (slot == uint32_t(i * 8 + size_t(c))) owned |= uint8_t(1u << c);
    }
    ownedMask[i] = owned;
    pointBase[i + 1] = uint32_t(std::popcount(unsigned(owned)));
  }, 1024);
  for (size_t i = 0; i < nCells; ++i) pointBase[i + 1] += pointBase[i];
  auto pointOfSlot = [&](uint32_t slot) {
    uint32_t j = slot / 8, c = slot % 8;
    return pointBase[j] + uint32_t(std::popcount(unsigned(ownedMask[j]) & ((1u << c) - 1u)));
  };
  const size_t nPoints = pointBase[nCells];
  std::vector<uint64_t> pointKeys(nPoints);
  parallelFor(0, nCells, [&](size_t i) {
    const auto& idx = cs.cells[i].index;
    for (int c = 0; c < 8; ++c) {
      uint32_t& cp = cornerPoint[i * 8 + size_t(c)];
      cp = pointOfSlot(cp);
      if ((ownedMask[i] >> c) & 1) {
        glm::ivec3 g = glm::ivec3(idx[0], idx[1], idx[2]) + cornerOffset(c);
        pointKeys[cp] = pointKey(g.x, g.y, g.z);
      }
    }
  }, 1024);
  res.gridSamples = nPoints;

  // Points are numbered in cell order and the cells come in recursive octree order, so a
  // run of consecutive points is a compact cluster: batches of kSampleBatch of them share
  // one tree walk and evaluate each nearby primitive over the whole batch.
  std::vector<float> values(nPoints);
  {
    constexpr size_t kSampleBatch = 128;
    size_t nBatches = (nPoints + kSampleBatch - 1) / kSampleBatch;
    parallelFor(0, nBatches, [&](size_t bi) {
      std::array<Vec3, kSampleBatch> pts;
      size_t b = bi * kSampleBatch, n = std::min(kSampleBatch, nPoints - b);
      for (size_t k = 0; k < n; ++k) pts[k] = gridPosition(cs, keyCoords(pointKeys[b + k]));
      blob.values(std::span<const Vec3>(pts.data(), n), std::span<float>(values.data() + b, n));
    }, 16);
  }
  if (options.progress && ProgressSettings::cancelRequested()) throw Cancelled();

  res.sampleSeconds = lap();

  // ---- 3. Cells with a sign change ----------------------------------------------------
  std::vector<uint8_t> insideMask(nCells);
  parallelFor(0, nCells, [&](size_t i) {
    uint8_t m = 0;
    for (int c = 0; c < 8; ++c)
      if (values[cornerPoint[i * 8 + c]] > kIso) m |= uint8_t(1u << c);
    insideMask[i] = m;
  }, 4096);
  std::vector<uint32_t> active;
  for (size_t i = 0; i < nCells; ++i)
    if (insideMask[i] != 0 && insideMask[i] != 0xff) active.push_back(uint32_t(i));

  // Closure: a cell whose face carries a sign change needs the neighbour across that face
  // triangulated too, or the mesh would have a hole there. Interval bounds keep every
  // such neighbour up to rounding (a corner exactly on F = 0.5 can fall just outside a
  // neighbour's bound), so the rare missing ones are added here, with their corners
  // sampled once and shared through the same point table.
  std::vector<glm::ivec3> cellCoords(nCells);
  for (size_t i = 0; i < nCells; ++i) cellCoords[i] = {cs.cells[i].index[0], cs.cells[i].index[1], cs.cells[i].index[2]};
  size_t extraCells = 0;
  std::map<uint64_t, uint32_t> extraPoints;  // grid points sampled for added cells
  {
    std::map<uint64_t, uint32_t> addedCells;
    auto pointIndex = [&](glm::ivec3 g) -> uint32_t {
      uint64_t key = pointKey(g.x, g.y, g.z);
      uint32_t slot = ownerSlot(g);
      if (slot != kNoCell) return pointOfSlot(slot);
      auto [e, inserted] = extraPoints.emplace(key, uint32_t(pointKeys.size()));
      if (inserted) {
        pointKeys.push_back(key);
        values.push_back(blob.value(gridPosition(cs, g)));
      }
      return e->second;
    };
    // Face f = 2·axis + side; its four corners are those with bit `axis` equal to side.
    std::vector<uint32_t> frontier = active;
    while (!frontier.empty()) {
      // Neighbours across sign-changing faces that no cell covers (read-only scan, in chunks).
      constexpr size_t kScan = 4096;
      std::vector<std::vector<uint64_t>> wantedParts((frontier.size() + kScan - 1) / kScan);
      parallelFor(0, wantedParts.size(), [&](size_t ch) {
        size_t end = std::min(frontier.size(), (ch + 1) * kScan);
        for (size_t f = ch * kScan; f < end; ++f) {
          uint32_t i = frontier[f];
          uint8_t m = insideMask[i];
          for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
              int in = 0;
              for (int c = 0; c < 8; ++c)
                if (((c >> axis) & 1) == side) in += (m >> c) & 1;
              if (in == 0 || in == 4) continue;
              glm::ivec3 n = cellCoords[i];
              n[axis] += side ? 1 : -1;
              if (n[axis] < 0 || n[axis] + 1 >= kAxisLimit) continue;
              uint64_t key = pointKey(n.x, n.y, n.z);
              if (cellIndex.find(key) == kNoCell && !addedCells.count(key)) wantedParts[ch].push_back(key);
            }
        }
      });
      std::vector<uint64_t> wanted = concat(wantedParts);
      std::sort(wanted.begin(), wanted.end());
      wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
      frontier.clear();
      for (uint64_t key : wanted) {
        glm::ivec3 g = keyCoords(key);
        uint32_t id = uint32_t(cellCoords.size());
        addedCells.emplace(key, id);
        cellCoords.push_back(g);
        uint8_t m = 0;
        for (int c = 0; c < 8; ++c) {
          uint32_t u = pointIndex(g + cornerOffset(c));
          cornerPoint.push_back(u);
          if (values[u] > kIso) m |= uint8_t(1u << c);
        }
        insideMask.push_back(m);
        if (m != 0 && m != 0xff) {
          active.push_back(id);
          frontier.push_back(id);
        }
      }
      extraCells += wanted.size();
    }
  }
  res.gridSamples = pointKeys.size();
  res.activeCells = active.size();
  res.extraCells = extraCells;
  if (active.empty()) return res;

  // ---- 4. Vertex numbering and marching tetrahedra -----------------------------------
  // Every crossing edge P -> P + d (d a corner code) belongs to the cell with low corner P;
  // that cell has the crossing between its corners 0 and d, so it is active (kept by the
  // bounds or added by the closure). Vertices are numbered by owner cell, then by d.
  const size_t nActive = active.size();
  CellHash activeIndex(nActive);
  for (size_t a = 0; a < nActive; ++a) {
    glm::ivec3 g = cellCoords[active[a]];
    activeIndex.insert(pointKey(g.x, g.y, g.z), uint32_t(a));
  }
  std::vector<uint8_t> crossMask(nActive);
  std::vector<uint32_t> vertexBase(nActive + 1, 0);
  std::vector<uint32_t> owners(nActive * 8);
  parallelFor(0, nActive, [&](size_t a) {
    uint8_t m = insideMask[active[a]], cross = 0;
    for (int d = 1; d < 8; ++d)
      if (((m >> d) & 1) != (m & 1)) cross |= uint8_t(1u << d);
    crossMask[a] = cross;
    vertexBase[a + 1] = uint32_t(std::popcount(unsigned(cross)));
    glm::ivec3 g = cellCoords[active[a]];
    owners[a * 8] = uint32_t(a);
    for (int lo = 1; lo < 8; ++lo) {
      glm::ivec3 n = g + cornerOffset(lo);
      owners[a * 8 + size_t(lo)] = activeIndex.find(pointKey(n.x, n.y, n.z));
    }
  }, 2048);
  for (size_t a = 0; a < nActive; ++a) vertexBase[a + 1] += vertexBase[a];
  const size_t nVerts = vertexBase[nActive];

  constexpr size_t kChunk = 2048;
  size_t nChunks = (nActive + kChunk - 1) / kChunk;
  // Triangles are counted per chunk first, then written in place (no per-chunk buffers).
  std::vector<size_t> triBase(nChunks + 1, 0);
  parallelFor(0, nChunks, [&](size_t ch) {
    size_t begin = ch * kChunk, end = std::min(nActive, begin + kChunk), n = 0;
    for (size_t a = begin; a < end; ++a) n += kTriangleCount[insideMask[active[a]]];
    triBase[ch + 1] = n;
  });
  for (size_t ch = 0; ch < nChunks; ++ch) triBase[ch + 1] += triBase[ch];
  Mesh& mesh = res.mesh;
  mesh.triangles.resize(triBase[nChunks]);
  parallelFor(0, nChunks, [&](size_t ch) {
    size_t begin = ch * kChunk, end = std::min(nActive, begin + kChunk);
    TetEmitter em{nullptr, vertexBase.data(), crossMask.data(), mesh.triangles.data() + triBase[ch]};
    for (size_t a = begin; a < end; ++a) {
      em.owners = &owners[a * 8];
      uint8_t m = insideMask[active[a]];
      for (const auto& t : kTets) {
        bool in[4] = {bool(m >> t[0] & 1), bool(m >> t[1] & 1), bool(m >> t[2] & 1), bool(m >> t[3] & 1)};
        em.run(t, in);
      }
    }
    if (em.out != mesh.triangles.data() + triBase[ch + 1]) throw std::logic_error("polygonize: triangle count mismatch");
  });
  std::vector<uint32_t>().swap(owners);

  // The inside and outside grid point of each vertex's edge.
  std::vector<EdgeRec> edges(nVerts);
  parallelFor(0, nActive, [&](size_t a) {
    const uint32_t* cp = &cornerPoint[size_t(active[a]) * 8];
    bool lowInside = insideMask[active[a]] & 1;
    uint32_t v = vertexBase[a];
    for (int d = 1; d < 8; ++d)
      if ((crossMask[a] >> d) & 1) edges[v++] = lowInside ? EdgeRec{cp[0], cp[d]} : EdgeRec{cp[d], cp[0]};
  }, 2048);

  res.triangulateSeconds = lap();

  // ---- 5. Vertices: root search along each edge, then normal and attributes ----------
  std::unique_ptr<Progress> bar;
  if (options.progress) bar = std::make_unique<Progress>("polygonize", nVerts);
  mesh.positions.resize(nVerts);
  if (options.normals) mesh.normals.resize(nVerts);
  if (options.attributes) {
    mesh.uvs.resize(nVerts);
    res.attributes.resize(nVerts);
  }
  std::vector<uint8_t> evals(nVerts, 0);
  std::vector<uint8_t> flatGradient(nVerts, 0);
  // Fixed blocks of vertices (consecutive edge keys: spatially coherent rows) iterate in
  // lockstep, each step one batched values() call over the block's unconverged vertices.
  // Blocks do not depend on the thread count, so neither do the results.
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
      pIn[k] = gridPosition(cs, keyCoords(pointKeys[e.inside]));
      pOut[k] = gridPosition(cs, keyCoords(pointKeys[e.outside]));
      a[k] = 0.0, b[k] = 1.0, side[k] = 0;
      fa[k] = double(values[e.inside]) - kIso, fb[k] = double(values[e.outside]) - kIso;
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
      if (options.normals || options.attributes) {
        Sample smp = blob.sample(p);
        if (options.normals) {
          float len = glm::length(smp.gradient);
          if (len > 1e-20f && std::isfinite(len)) mesh.normals[v] = -smp.gradient / len;
          else flatGradient[v] = 1;
        }
        if (options.attributes) {
          mesh.uvs[v] = smp.attributes.uv;
          res.attributes[v] = smp.attributes;
        }
      }
    }
    if (bar) bar->advance(n);
  });
  if (bar) bar->finish();

  // Vertices where the gradient vanishes take the area-weighted normal of their triangles.
  if (options.normals && std::find(flatGradient.begin(), flatGradient.end(), 1) != flatGradient.end()) {
    std::vector<Vec3> acc(nVerts, Vec3(0.0f));
    for (const auto& tri : mesh.triangles) {
      Vec3 n = glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x], mesh.positions[tri.z] - mesh.positions[tri.x]);
      for (int k = 0; k < 3; ++k)
        if (flatGradient[tri[k]]) acc[tri[k]] += n;
    }
    for (size_t v = 0; v < nVerts; ++v)
      if (flatGradient[v]) {
        float len = glm::length(acc[v]);
        mesh.normals[v] = len > 0.0f ? acc[v] / len : Vec3(0, 1, 0);
      }
  }

  res.vertexSeconds = lap();
  size_t total = pointKeys.size() + (options.normals || options.attributes ? nVerts : 0);
  for (uint8_t n : evals) total += n;
  res.fieldEvaluations = total;
  return res;
}

Mesh polygonize(const CompiledBlob& blob, const PolygonizeOptions& options) {
  return std::move(polygonizeDetailed(blob, options).mesh);
}

}  // namespace sprig::blobtree
