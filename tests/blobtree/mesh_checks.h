#pragma once
// Checks of polygonized meshes shared by the polygonizer's tests.

#include <catch2/catch.hpp>

#include <algorithm>
#include <set>
#include <utility>

#include "core/mesh.h"

namespace sprig::test {

// Euler characteristic V − E + F of a closed mesh (2 − 2·genus per component).
inline long euler(const Mesh& m) {
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) edges.insert(std::minmax(t[k], t[(k + 1) % 3]));
  return long(m.vertexCount()) - long(edges.size()) + long(m.triangleCount());
}

// Closed (no boundary edge), 2-manifold, consistently oriented, no degenerate triangle.
inline void requireClosedManifold(const Mesh& m) {
  MeshTopology topo = analyzeTopology(m);
  CHECK(m.triangleCount() > 0);
  CHECK(topo.boundaryEdges == 0);
  CHECK(topo.nonManifoldEdges == 0);
  CHECK(topo.inconsistentEdges == 0);
  CHECK(topo.degenerateTriangles == 0);
}

}  // namespace sprig::test
