#pragma once
// Checks of polygonized meshes shared by the polygonizer's tests.

#include <catch2/catch.hpp>

#include <algorithm>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

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

// The mesh with every group of vertices at one position merged into one, as a viewer, a
// slicer or the simplifier (meshopt_generateVertexRemap) welds it.
inline Mesh weldByPosition(const Mesh& m) {
  Mesh out;
  std::map<std::tuple<float, float, float>, uint32_t> index;
  std::vector<uint32_t> remap(m.positions.size());
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const Vec3& q = m.positions[v];
    auto [it, fresh] = index.emplace(std::make_tuple(q.x, q.y, q.z), uint32_t(out.positions.size()));
    if (fresh) out.positions.push_back(q);
    remap[v] = it->second;
  }
  for (const auto& t : m.triangles) out.triangles.push_back(glm::uvec3(remap[t.x], remap[t.y], remap[t.z]));
  return out;
}

}  // namespace sprig::test
