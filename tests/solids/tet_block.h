#pragma once
/// A structured block of tetrahedra for the FEM tests: nx × ny × nz cubic cells of the box
/// [origin, origin + size], each split into five tetrahedra with alternating orientation (the
/// pattern of meshSolid, §4.3), so faces match between neighbouring cells. One material (0).

#include <array>
#include <utility>

#include "solids/solid.h"

namespace sprig::test {

inline solids::TetMesh tetBlock(std::array<int, 3> n, DVec3 origin, DVec3 size) {
  using Tet = std::array<uint32_t, 4>;
  std::array<std::array<Tet, 5>, 2> pattern = {{
      {{{0, 1, 2, 4}, {3, 1, 2, 7}, {5, 1, 4, 7}, {6, 2, 4, 7}, {1, 2, 4, 7}}},
      {{{1, 0, 3, 5}, {2, 0, 3, 6}, {4, 0, 5, 6}, {7, 3, 5, 6}, {0, 3, 5, 6}}},
  }};
  auto corner = [](uint32_t c) { return DVec3(c & 1, (c >> 1) & 1, (c >> 2) & 1); };
  for (auto& p : pattern)
    for (Tet& t : p) {
      const DVec3 a = corner(t[0]);
      if (glm::dot(corner(t[1]) - a, glm::cross(corner(t[2]) - a, corner(t[3]) - a)) < 0) std::swap(t[2], t[3]);
    }
  solids::TetMesh m;
  auto node = [&](int i, int j, int k) { return uint32_t(i + (n[0] + 1) * (j + (n[1] + 1) * k)); };
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i)
        m.positions.push_back(origin + size * DVec3(double(i) / n[0], double(j) / n[1], double(k) / n[2]));
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (const Tet& t : pattern[size_t((i + j + k) & 1)]) {
          Tet q;
          for (int c = 0; c < 4; ++c)
            q[size_t(c)] = node(i + int(t[size_t(c)] & 1), j + int((t[size_t(c)] >> 1) & 1), k + int((t[size_t(c)] >> 2) & 1));
          m.tets.push_back(q);
          m.materials.push_back(0);
        }
  return m;
}

}  // namespace sprig::test
