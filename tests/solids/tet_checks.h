#pragma once
/// Checks of tetrahedral meshes shared by the solids tests.

#include <algorithm>
#include <array>
#include <map>
#include <vector>

#include <catch2/catch.hpp>

#include "core/mesh.h"
#include "solids/solid.h"

namespace sprig::test {

/// Number of faces used by exactly one, two, and more than two tetrahedra.
inline std::array<size_t, 3> faceUses(const solids::TetMesh& m) {
  std::map<std::array<uint32_t, 3>, int> uses;
  for (const auto& q : m.tets)
    for (const auto& f : solids::kTetFaces) {
      std::array<uint32_t, 3> k = {q[size_t(f[0])], q[size_t(f[1])], q[size_t(f[2])]};
      std::sort(k.begin(), k.end());
      ++uses[k];
    }
  std::array<size_t, 3> out{0, 0, 0};
  for (const auto& [k, n] : uses) ++out[size_t(std::min(n, 3) - 1)];
  return out;
}

/// The volume of each material's tetrahedra.
inline std::map<uint16_t, double> volumeByMaterial(const solids::TetMesh& m) {
  std::map<uint16_t, double> v;
  for (size_t t = 0; t < m.tets.size(); ++t) v[m.materials[t]] += m.volume(t);
  return v;
}

/// The triangles tris on the mesh's vertices, as a Mesh (for analyzeTopology).
inline Mesh meshOf(const solids::TetMesh& m, const std::vector<solids::InterfaceTriangle>& tris) {
  Mesh out;
  for (const DVec3& p : m.positions) out.positions.push_back(Vec3(p));
  for (const auto& t : tris) out.triangles.push_back({t.v[0], t.v[1], t.v[2]});
  return out;
}

/// Checks what every mesher and improvement keeps: positive tetrahedra, faces used by at
/// most two tetrahedra, a closed manifold visible interface.
inline void checkValid(const solids::TetMesh& m) {
  for (size_t t = 0; t < m.tets.size(); ++t) REQUIRE(m.volume(t) > 0);
  CHECK(faceUses(m)[2] == 0);
  size_t bad = 99;
  const auto visible = solids::visibleInterface(m, &bad);
  CHECK(bad == 0);
  const MeshTopology top = analyzeTopology(meshOf(m, visible));
  CHECK(top.closed());
  CHECK(top.manifold());
}

}  // namespace sprig::test
