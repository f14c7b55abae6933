#pragma once
// Self-intersection of a triangle mesh, for tests: an edge of one triangle that crosses
// another triangle sharing none of its vertices (a proper crossing of two triangles always
// has such an edge). Candidates come from a uniform grid over the triangles' boxes.

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "core/mesh.h"

namespace sprig::test {

// Whether segment a-b crosses triangle (p, q, r) strictly inside both (Moller-Trumbore,
// with margins so that touching at an edge or a vertex does not count).
inline bool segmentCrossesTriangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& p, const glm::dvec3& q,
                                   const glm::dvec3& r) {
  const glm::dvec3 d = b - a, e1 = q - p, e2 = r - p;
  const glm::dvec3 h = glm::cross(d, e2);
  const double det = glm::dot(e1, h);
  if (std::fabs(det) < 1e-18) return false;
  const glm::dvec3 s = a - p;
  const double u = glm::dot(s, h) / det;
  const glm::dvec3 qv = glm::cross(s, e1);
  const double v = glm::dot(d, qv) / det;
  const double t = glm::dot(e2, qv) / det;
  const double eps = 1e-7;
  return u > eps && v > eps && u + v < 1 - eps && t > eps && t < 1 - eps;
}

// The number of (edge, triangle) crossings of mesh, each edge counted once per triangle.
// where (optional) receives the midpoint of each crossing edge.
inline size_t selfIntersections(const Mesh& mesh, std::vector<Vec3>* where = nullptr) {
  const Box3 box = mesh.bounds();
  const size_t n = mesh.triangles.size();
  const double extent = std::max({box.hi.x - box.lo.x, box.hi.y - box.lo.y, box.hi.z - box.lo.z});
  const int res = std::max(1, int(std::cbrt(double(n)) * 2));
  const double cell = extent / res + 1e-12;
  auto cellOf = [&](const Vec3& p, int axis) { return std::clamp(int((p[axis] - box.lo[axis]) / cell), 0, res - 1); };
  auto key = [&](int i, int j, int k) { return (int64_t(i) * res + j) * res + k; };
  std::unordered_map<int64_t, std::vector<uint32_t>> grid;
  for (uint32_t t = 0; t < n; ++t) {
    Box3 b;
    for (int c = 0; c < 3; ++c) b.extend(mesh.positions[mesh.triangles[t][c]]);
    for (int i = cellOf(b.lo, 0); i <= cellOf(b.hi, 0); ++i)
      for (int j = cellOf(b.lo, 1); j <= cellOf(b.hi, 1); ++j)
        for (int k = cellOf(b.lo, 2); k <= cellOf(b.hi, 2); ++k) grid[key(i, j, k)].push_back(t);
  }
  size_t crossings = 0;
  std::vector<uint32_t> seen;
  for (uint32_t t = 0; t < n; ++t) {
    const auto& tri = mesh.triangles[t];
    for (int c = 0; c < 3; ++c) {
      const uint32_t ia = tri[c], ib = tri[(c + 1) % 3];
      if (ia > ib) continue;  // each undirected edge of a closed or open mesh once per face
      const Vec3 a = mesh.positions[ia], b = mesh.positions[ib];
      Box3 eb;
      eb.extend(a);
      eb.extend(b);
      seen.clear();
      for (int i = cellOf(eb.lo, 0); i <= cellOf(eb.hi, 0); ++i)
        for (int j = cellOf(eb.lo, 1); j <= cellOf(eb.hi, 1); ++j)
          for (int k = cellOf(eb.lo, 2); k <= cellOf(eb.hi, 2); ++k) {
            auto it = grid.find(key(i, j, k));
            if (it == grid.end()) continue;
            for (uint32_t o : it->second) {
              const auto& other = mesh.triangles[o];
              auto has = [&](uint32_t v) { return other[0] == v || other[1] == v || other[2] == v; };
              if (has(ia) || has(ib)) continue;
              if (std::find(seen.begin(), seen.end(), o) != seen.end()) continue;
              seen.push_back(o);
              if (segmentCrossesTriangle(a, b, mesh.positions[other[0]], mesh.positions[other[1]], mesh.positions[other[2]]))
              {
                ++crossings;
                if (where) where->push_back((a + b) * 0.5f);
              }
            }
          }
    }
  }
  return crossings;
}

}  // namespace sprig::test
