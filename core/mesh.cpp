#include "core/mesh.h"

#include <algorithm>

namespace sprig {

Box3 Mesh::bounds() const {
  Box3 b;
  for (const auto& p : positions) b.extend(p);
  return b;
}

void Mesh::append(const Mesh& other) {
  bool wasEmpty = positions.empty();
  auto offset = static_cast<uint32_t>(positions.size());
  auto merge = [&](auto& mine, const auto& theirs) {
    if ((wasEmpty || !mine.empty()) && theirs.size() == other.positions.size() && !theirs.empty())
      mine.insert(mine.end(), theirs.begin(), theirs.end());
    else
      mine.clear();
  };
  merge(normals, other.normals);
  merge(uvs, other.uvs);
  merge(colors, other.colors);
  positions.insert(positions.end(), other.positions.begin(), other.positions.end());
  size_t oldTris = triangles.size();
  for (auto t : other.triangles) triangles.push_back(t + glm::uvec3(offset));
  if ((wasEmpty || materials.size() == oldTris) && other.materials.size() == other.triangles.size())
    materials.insert(materials.end(), other.materials.begin(), other.materials.end());
  else
    materials.clear();
}

MeshTopology analyzeTopology(const Mesh& mesh) {
  MeshTopology topo;
  // Each directed edge (a,b); an undirected edge is fine when used once in each direction.
  std::vector<std::pair<uint64_t, int>> edges;  // key = min<<32|max, sign = +1 if a<b
  edges.reserve(mesh.triangles.size() * 3);
  for (const auto& t : mesh.triangles) {
    if (t.x == t.y || t.y == t.z || t.x == t.z) ++topo.degenerateTriangles;
    uint32_t v[3] = {t.x, t.y, t.z};
    for (int i = 0; i < 3; ++i) {
      uint32_t a = v[i], b = v[(i + 1) % 3];
      uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      edges.push_back({key, a < b ? 1 : -1});
    }
  }
  std::sort(edges.begin(), edges.end());
  for (size_t i = 0; i < edges.size();) {
    size_t j = i;
    int sum = 0;
    while (j < edges.size() && edges[j].first == edges[i].first) sum += edges[j++].second;
    size_t uses = j - i;
    if (uses == 1) ++topo.boundaryEdges;
    else if (uses > 2) ++topo.nonManifoldEdges;
    else if (sum != 0) ++topo.inconsistentEdges;
    i = j;
  }
  return topo;
}

double signedVolume(const Mesh& mesh) {
  double v = 0;
  for (const auto& t : mesh.triangles) {
    glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    v += glm::dot(a, glm::cross(b, c));
  }
  return v / 6.0;
}

}  // namespace sprig
