#pragma once
// Welding of render and export parts for topology checks in tests.

#include <algorithm>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

#include "core/mesh.h"

namespace sprig::test {

// The meshes' triangles in one mesh, each mesh's boundary vertices (on an edge one
// triangle uses) merged with every boundary vertex at an identical position, as a viewer or
// slicer that welds by position does: parts are cut from one surface along shared
// vertices, and creases split vertices within a part. Interior vertices stay apart, even
// where two coincide.
inline Mesh weldBoundaries(const std::vector<const Mesh*>& meshes) {
  Mesh out;
  std::map<std::tuple<float, float, float>, uint32_t> index;
  for (const Mesh* m : meshes) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;  // undirected edge -> use count
    for (const auto& t : m->triangles)
      for (int k = 0; k < 3; ++k) ++edges[std::minmax(t[k], t[(k + 1) % 3])];
    std::vector<char> boundary(m->positions.size(), 0);
    for (const auto& [e, n] : edges)
      if (n == 1) boundary[e.first] = boundary[e.second] = 1;
    std::vector<uint32_t> remap(m->positions.size());
    for (size_t v = 0; v < m->positions.size(); ++v) {
      const Vec3& q = m->positions[v];
      if (!boundary[v]) {
        remap[v] = uint32_t(out.positions.size());
        out.positions.push_back(q);
        continue;
      }
      auto [it, fresh] = index.emplace(std::make_tuple(q.x, q.y, q.z), uint32_t(out.positions.size()));
      if (fresh) out.positions.push_back(q);
      remap[v] = it->second;
    }
    for (const auto& t : m->triangles) out.triangles.push_back(glm::uvec3(remap[t.x], remap[t.y], remap[t.z]));
  }
  return out;
}

}  // namespace sprig::test
