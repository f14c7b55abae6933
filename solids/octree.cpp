#include "solids/octree.h"

#include <algorithm>

#include "core/parallel.h"
#include "solids/chunked.h"

namespace sprig::solids {

namespace {

using Tet = std::array<uint32_t, 4>;
using I3 = std::array<int, 3>;

int64_t det(const I3& a, const I3& b, const I3& c, const I3& d) {
  const int64_t u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]},
                w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0]);
}

/// The five tetrahedra of a cube (corner c = dx + 2·dy + 4·dz) for both parities, positively
/// oriented: four corners cut off and the central tetrahedron, whose orientation alternates
/// so that face diagonals match between neighbouring cubes (§4.3). Parity 0 joins the
/// corners with an odd dx + dy + dz, parity 1 the even ones: either way a face's diagonal
/// joins its two corners whose level coordinates have an odd sum.
std::array<std::array<Tet, 5>, 2> cubePatterns() {
  std::array<std::array<Tet, 5>, 2> out = {{
      {{{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}, {1, 2, 4, 7}}},
      {{{1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}, {0, 3, 5, 6}}},
  }};
  auto corner = [](uint32_t c) { return I3{int(c & 1), int((c >> 1) & 1), int((c >> 2) & 1)}; };
  for (auto& pattern : out)
    for (Tet& t : pattern)
      if (det(corner(t[0]), corner(t[1]), corner(t[2]), corner(t[3])) < 0) std::swap(t[2], t[3]);
  return out;
}

/// Index arithmetic of the grid's cells and nodes.
struct Lattice {
  int n[3];        ///< cells per axis
  size_t nx, ny;   ///< nodes per row and per layer
  explicit Lattice(const Grid& g) : n{g.cells[0], g.cells[1], g.cells[2]}, nx(size_t(g.cells[0]) + 1), ny(size_t(g.cells[1]) + 1) {}
  size_t cells() const { return size_t(n[0]) * size_t(n[1]) * size_t(n[2]); }
  size_t cell(const I3& p) const { return size_t(p[0]) + size_t(n[0]) * (size_t(p[1]) + size_t(n[1]) * size_t(p[2])); }
  I3 cellAt(size_t c) const { return {int(c % size_t(n[0])), int((c / size_t(n[0])) % size_t(n[1])), int(c / (size_t(n[0]) * size_t(n[1])))}; }
  uint32_t node(const I3& p) const { return uint32_t(size_t(p[0]) + nx * (size_t(p[1]) + ny * size_t(p[2]))); }
  bool inside(const I3& p) const { return p[0] >= 0 && p[1] >= 0 && p[2] >= 0 && p[0] < n[0] && p[1] < n[1] && p[2] < n[2]; }
};

I3 add(I3 a, const I3& b, int s = 1) {
  for (int i = 0; i < 3; ++i) a[size_t(i)] += s * b[size_t(i)];
  return a;
}

/// The leaf level of every cell after bottom-up merging (see the header).
std::vector<uint8_t> coarsen(const Lattice& L, int levels, const std::vector<uint64_t>& nodeClass, const MergeTest& interpolated) {
  std::vector<uint8_t> level(L.cells(), 0);
  // A cell's class: its corners' common class, or mixed. Read at a leaf's first cell.
  std::vector<uint64_t> cls(L.cells());
  parallelFor(0, L.cells(), [&](size_t c) {
    const I3 p = L.cellAt(c);
    const uint64_t k = nodeClass[L.node(p)];
    for (int q = 1; q < 8 && k != kMixedClass; ++q)
      if (nodeClass[L.node(add(p, I3{q & 1, (q >> 1) & 1, (q >> 2) & 1}))] != k) {
        cls[c] = kMixedClass;
        return;
      }
    cls[c] = k;
  }, 4096);
  for (int l = 1; l <= levels; ++l) {
    const int s = 1 << l, h = s / 2;
    const int g[3] = {L.n[0] / s, L.n[1] / s, L.n[2] / s};
    const size_t candidates = size_t(g[0]) * size_t(g[1]) * size_t(g[2]);
    if (!candidates) break;
    // Decide every merge of this level first: a merge only raises cells from level l-1 to
    // l, which no other decision of the level depends on (the same result in any order).
    std::vector<uint8_t> merge(candidates, 0);
    parallelFor(0, candidates, [&](size_t c) {
      const I3 base = {int(c % size_t(g[0])) * s, int((c / size_t(g[0])) % size_t(g[1])) * s, int(c / (size_t(g[0]) * size_t(g[1]))) * s};
      // A leaf's class is read at its first cell: the common class of its nodes, or mixed.
      const uint64_t k = cls[L.cell(base)];
      bool uniform = k != kMixedClass;
      for (int q = 0; q < 8; ++q) {
        const size_t child = L.cell(add(base, I3{(q & 1) * h, ((q >> 1) & 1) * h, ((q >> 2) & 1) * h}));
        if (level[child] != l - 1) return;
        uniform = uniform && cls[child] == k;
      }
      if (!uniform && !(interpolated && interpolated(base, s))) return;
      // Every cell touching the block is in a leaf of level l - 1 or more.
      auto fine = [&](int x, int y, int z) {
        const I3 q = {x, y, z};
        return L.inside(q) && level[L.cell(q)] + 1 < l;
      };
      for (int z = base[2] - 1; z <= base[2] + s; ++z)
        for (int y = base[1] - 1; y <= base[1] + s; ++y) {
          if (z < base[2] || z >= base[2] + s || y < base[1] || y >= base[1] + s) {
            for (int x = base[0] - 1; x <= base[0] + s; ++x)
              if (fine(x, y, z)) return;
          } else if (fine(base[0] - 1, y, z) || fine(base[0] + s, y, z)) {
            return;
          }
        }
      merge[c] = uniform ? 1 : 2;
    }, 64);
    bool any = false;
    for (size_t c = 0; c < candidates; ++c) {
      if (!merge[c]) continue;
      any = true;
      const I3 base = {int(c % size_t(g[0])) * s, int((c / size_t(g[0])) % size_t(g[1])) * s, int(c / (size_t(g[0]) * size_t(g[1]))) * s};
      if (merge[c] == 2) cls[L.cell(base)] = kMixedClass;
      for (int z = 0; z < s; ++z)
        for (int y = 0; y < s; ++y)
          std::fill_n(level.begin() + long(L.cell(add(base, I3{0, y, z}))), s, uint8_t(l));
    }
    if (!any) break;
  }
  return level;
}

/// The triangles of the square with corner o, sides of t cells along axes u and w
/// (the square of a cell of level lt, t = 2^lt), as its leaves' corners split it.
void squareTriangles(const Lattice& L, const std::vector<uint8_t>& isCorner, I3 o, int u, int w, int t,
                     std::vector<std::array<I3, 3>>& out) {
  I3 du{0, 0, 0}, dw{0, 0, 0};
  du[size_t(u)] = 1;
  dw[size_t(w)] = 1;
  // The perimeter, counter-clockwise in (u, w), with every leaf corner on it.
  I3 ring[4] = {o, add(o, du, t), add(add(o, du, t), dw, t), add(o, dw, t)};
  const I3 step[4] = {du, dw, add(I3{0, 0, 0}, du, -1), add(I3{0, 0, 0}, dw, -1)};
  std::vector<I3> poly;
  for (int e = 0; e < 4; ++e) {
    poly.push_back(ring[e]);
    for (int i = 1; i < t; ++i) {
      const I3 p = add(ring[e], step[e], i);
      if (isCorner[L.node(p)]) poly.push_back(p);
    }
  }
  if (poly.size() == 4) {
    // The diagonal of the five-tetrahedra pattern: the corners whose level coordinates sum odd.
    const int a = ((ring[0][0] + ring[0][1] + ring[0][2]) / t) & 1 ? 0 : 1;
    out.push_back({ring[a], ring[a + 2], ring[a + 1]});
    out.push_back({ring[a], ring[a + 2], ring[(a + 3) % 4]});
    return;
  }
  const I3 centre = add(add(o, du, t / 2), dw, t / 2);
  for (size_t i = 0; i < poly.size(); ++i) out.push_back({centre, poly[i], poly[(i + 1) % poly.size()]});
}

}  // namespace

std::vector<Tet> cellTetrahedra(const Grid& grid, int levels, const std::vector<uint64_t>& nodeClass,
                                const std::function<bool(const uint32_t*)>& keep, CellStats* stats,
                                const MergeTest& interpolated) {
  const Lattice L(grid);
  const std::vector<uint8_t> level = levels > 0 ? coarsen(L, std::min(levels, 7), nodeClass, interpolated) : std::vector<uint8_t>(L.cells(), 0);
  auto isLeaf = [&](size_t c, const I3& p) {
    const int s = 1 << level[c];
    return p[0] % s == 0 && p[1] % s == 0 && p[2] % s == 0;
  };
  // Every leaf's corners, kept or not: both sides of a square must see the same vertices.
  std::vector<uint8_t> isCorner;
  if (levels > 0) {
    isCorner.assign(L.nx * L.ny * size_t(L.n[2] + 1), 0);
    for (size_t c = 0; c < L.cells(); ++c) {
      const I3 p = L.cellAt(c);
      if (!isLeaf(c, p)) continue;
      const int s = 1 << level[c];
      for (int q = 0; q < 8; ++q) isCorner[L.node(add(p, I3{(q & 1) * s, ((q >> 1) & 1) * s, ((q >> 2) & 1) * s}))] = 1;
    }
  }
  const auto patterns = cubePatterns();
  struct Counts {
    size_t leaves = 0, coarse = 0, transition = 0;
  };
  std::vector<Counts> counts((L.cells() + kChunk - 1) / kChunk);
  std::vector<Tet> tets = chunked<Tet>(L.cells(), [&](size_t lo, size_t hi, std::vector<Tet>& out) {
    Counts& n = counts[lo / kChunk];
    std::vector<std::array<I3, 3>> tris;
    for (size_t c = lo; c < hi; ++c) {
      const I3 p = L.cellAt(c);
      if (!isLeaf(c, p)) continue;
      const int l = level[c], s = 1 << l;
      uint32_t corner[8];
      for (int q = 0; q < 8; ++q) corner[q] = L.node(add(p, I3{(q & 1) * s, ((q >> 1) & 1) * s, ((q >> 2) & 1) * s}));
      if (!keep(corner)) continue;
      ++n.leaves;
      if (l > 0) ++n.coarse;
      // The faces' triangles; the cube is plain when each face is one square of two.
      tris.clear();
      bool plain = true;
      for (int a = 0; l > 0 && a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
          const int u = (a + 1) % 3, w = (a + 2) % 3;
          I3 o = p;
          o[size_t(a)] += side * s;
          I3 across = p;
          across[size_t(a)] += side ? s : -1;
          const bool split = L.inside(across) && level[L.cell(across)] < l;
          const size_t before = tris.size();
          if (split) {
            const int h = s / 2;
            for (int q = 0; q < 4; ++q) {
              I3 oq = o;
              oq[size_t(u)] += (q & 1) * h;
              oq[size_t(w)] += (q >> 1) * h;
              squareTriangles(L, isCorner, oq, u, w, h, tris);
            }
          } else {
            squareTriangles(L, isCorner, o, u, w, s, tris);
          }
          if (tris.size() - before != 2) plain = false;
        }
      if (plain) {
        for (const Tet& t : patterns[size_t((p[0] / s + p[1] / s + p[2] / s) & 1)])
          out.push_back({corner[t[0]], corner[t[1]], corner[t[2]], corner[t[3]]});
        continue;
      }
      ++n.transition;
      const I3 centre = add(p, I3{s / 2, s / 2, s / 2});
      for (auto& tri : tris) {
        if (det(centre, tri[0], tri[1], tri[2]) < 0) std::swap(tri[1], tri[2]);
        out.push_back({L.node(centre), L.node(tri[0]), L.node(tri[1]), L.node(tri[2])});
      }
    }
  });
  if (stats) {
    *stats = {};
    for (const Counts& n : counts) stats->leaves += n.leaves, stats->coarseLeaves += n.coarse, stats->transition += n.transition;
  }
  return tets;
}

}  // namespace sprig::solids
