#pragma once
/// A small mesh the core tests share.

#include "core/mesh.h"

namespace sprig::test {

/// A unit cube with 8 shared vertices, 12 outward triangles and, with attributes, every
/// optional array (normals, uvs, colors, one material id per pair of faces).
inline Mesh cube(bool attributes) {
  Mesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back(Vec3(i & 1, (i >> 1) & 1, (i >> 2) & 1));
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  if (attributes) {
    for (const auto& p : m.positions) {
      m.normals.push_back(glm::normalize(p - Vec3(0.5f)));
      m.uvs.push_back(Vec2(p.x, 0.25f + 0.5f * p.y));
      m.colors.push_back(Vec3(p.x, 0.5f, p.z));
    }
    for (size_t t = 0; t < m.triangles.size(); ++t) m.materials.push_back(uint32_t(t / 4));
  }
  return m;
}

}  // namespace sprig::test
