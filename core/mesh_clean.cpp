#include "core/mesh_clean.h"

#include <cmath>
#include <algorithm>
#include <numeric>

namespace sprig {

namespace {

uint32_t findRoot(std::vector<uint32_t>& parent, uint32_t v) {
  while (parent[v] != v) {
    parent[v] = parent[parent[v]];
    v = parent[v];
  }
  return v;
}

DVec3 windingNormal(const Mesh& mesh, const glm::uvec3& t) {
  const DVec3 a(mesh.positions[t.x]), b(mesh.positions[t.y]), c(mesh.positions[t.z]);
  return glm::cross(b - a, c - a);  // twice the area, along the winding normal
}

}  // namespace

std::vector<uint32_t> triangleComponents(const Mesh& mesh, size_t* count) {
  std::vector<uint32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (const auto& t : mesh.triangles) {
    const uint32_t a = findRoot(parent, t.x), b = findRoot(parent, t.y), c = findRoot(parent, t.z);
    parent[b] = a;
    parent[findRoot(parent, c)] = a;
  }
  std::vector<uint32_t> idOfRoot(mesh.positions.size(), UINT32_MAX);
  std::vector<uint32_t> out(mesh.triangles.size());
  uint32_t next = 0;
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const uint32_t r = findRoot(parent, mesh.triangles[i].x);
    if (idOfRoot[r] == UINT32_MAX) idOfRoot[r] = next++;
    out[i] = idOfRoot[r];
  }
  if (count) *count = next;
  return out;
}

size_t facesAgainstWinding(const Mesh& mesh) {
  if (mesh.normals.size() != mesh.positions.size()) return 0;
  size_t n = 0;
  for (const auto& t : mesh.triangles) {
    const DVec3 w = windingNormal(mesh, t);
    for (int k = 0; k < 3; ++k)
      if (glm::dot(DVec3(mesh.normals[t[k]]), w) < 0) {
        ++n;
        break;
      }
  }
  return n;
}

DegenerateReport removeDegenerateTriangles(Mesh& mesh, std::vector<size_t>* kept) {
  // A zero-area triangle whose corners coincide (two vertices at one position: a
  // polygonizer's root found at a grid corner shared by two edges) is a slit in the
  // surface: removed alone it would leave its neighbours open along it. Its coincident
  // vertices become one (the lower index, everywhere), which turns the neighbours across
  // the slit into edge-sharing triangles again; collinear corners are only removed.
  std::vector<uint32_t> to(mesh.positions.size());
  std::iota(to.begin(), to.end(), 0u);
  auto root = [&](uint32_t v) {
    while (to[v] != v) v = to[v] = to[to[v]];
    return v;
  };
  auto zeroArea = [&](const glm::uvec3& f) {
    const DVec3 a(mesh.positions[f[0]]), b(mesh.positions[f[1]]), c(mesh.positions[f[2]]);
    return glm::cross(b - a, c - a) == DVec3(0.0);
  };
  std::vector<char> cause(mesh.triangles.size(), 0);  // 1 repeated index, 2 zero area
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 f = mesh.triangles[t];
    if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) {
      cause[t] = 1;
    } else if (zeroArea(f)) {
      cause[t] = 2;
      for (int k = 0; k < 3; ++k) {
        const uint32_t a = f[k], b = f[(k + 1) % 3];
        if (mesh.positions[a] != mesh.positions[b]) continue;
        const uint32_t ra = root(a), rb = root(b);
        to[std::max(ra, rb)] = std::min(ra, rb);
      }
    }
  }
  DegenerateReport report;
  const bool materials = mesh.materials.size() == mesh.triangles.size();
  if (kept) kept->clear();
  size_t out = 0;
  for (size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3 f(root(mesh.triangles[t][0]), root(mesh.triangles[t][1]), root(mesh.triangles[t][2]));
    const bool repeated = f[0] == f[1] || f[1] == f[2] || f[2] == f[0];
    if (cause[t] == 1 || (cause[t] == 0 && repeated)) {
      ++report.repeatedIndex;
      continue;
    }
    if (cause[t] == 2 || repeated) {
      ++report.zeroArea;
      continue;
    }
    if (kept) kept->push_back(t);
    if (materials) mesh.materials[out] = mesh.materials[t];
    mesh.triangles[out++] = f;
  }
  mesh.triangles.resize(out);
  if (materials) mesh.materials.resize(out);
  return report;
}

MeshCleanReport cleanMesh(Mesh& mesh, const MeshCleanOptions& options) {
  MeshCleanReport r;
  r.facesAgainstBefore = facesAgainstWinding(mesh);
  const std::vector<uint32_t> comp = triangleComponents(mesh, &r.componentsBefore);
  r.componentsAfter = r.componentsBefore;

  // Step 1: signed volume of every component (divergence theorem, Σ a·(b×c)/6).
  std::vector<double> volume(r.componentsBefore, 0.0);
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    volume[comp[i]] += glm::dot(DVec3(mesh.positions[t.x]), glm::cross(DVec3(mesh.positions[t.y]), DVec3(mesh.positions[t.z]))) / 6.0;
  }
  r.modelVolume = std::accumulate(volume.begin(), volume.end(), 0.0);

  // Step 2: drop the components below the fraction, then the vertices no triangle uses.
  const double limit = options.minVolumeFraction * std::fabs(r.modelVolume);
  std::vector<char> drop(r.componentsBefore, 0);
  if (options.minVolumeFraction > 0 && r.componentsBefore > 1)
    for (size_t c = 0; c < volume.size(); ++c)
      if (std::fabs(volume[c]) < limit) {
        drop[c] = 1;
        ++(volume[c] >= 0 ? r.specks : r.voids);
      }
  if (r.specks + r.voids > 0) {
    std::vector<glm::uvec3> tris;
    std::vector<uint32_t> mats;
    const bool hasM = mesh.materials.size() == mesh.triangles.size();
    std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
      if (drop[comp[i]]) {
        ++r.removedTriangles;
        continue;
      }
      tris.push_back(mesh.triangles[i]);
      if (hasM) mats.push_back(mesh.materials[i]);
      for (int k = 0; k < 3; ++k) remap[mesh.triangles[i][k]] = 0;
    }
    uint32_t next = 0;
    for (uint32_t& m : remap)
      if (m == 0) m = next++;
    auto compact = [&](auto& array) {
      if (array.size() != mesh.positions.size()) return;
      size_t j = 0;
      for (size_t v = 0; v < array.size(); ++v)
        if (remap[v] != UINT32_MAX) array[j++] = array[v];
      array.resize(j);
    };
    compact(mesh.normals);
    compact(mesh.uvs);
    compact(mesh.colors);
    compact(mesh.positions);
    for (auto& t : tris) t = glm::uvec3(remap[t.x], remap[t.y], remap[t.z]);
    mesh.triangles = std::move(tris);
    if (hasM) mesh.materials = std::move(mats);
    r.componentsAfter = r.componentsBefore - r.specks - r.voids;
  }

  // Step 3: a vertex normal that points against any of its triangles' winding normals is
  // replaced by the area-weighted winding normal of its triangles.
  if (options.fixNormals && mesh.normals.size() == mesh.positions.size()) {
    std::vector<DVec3> sum(mesh.positions.size(), DVec3(0));
    std::vector<char> against(mesh.positions.size(), 0);
    for (const auto& t : mesh.triangles) {
      const DVec3 w = windingNormal(mesh, t);
      for (int k = 0; k < 3; ++k) {
        sum[t[k]] += w;
        if (glm::dot(DVec3(mesh.normals[t[k]]), w) < 0) against[t[k]] = 1;
      }
    }
    for (size_t v = 0; v < mesh.normals.size(); ++v) {
      const double len = glm::length(sum[v]);
      if (against[v] && len > 0) {
        mesh.normals[v] = Vec3(sum[v] / len);
        ++r.fixedNormals;
      }
    }
  }
  r.facesAgainstAfter = facesAgainstWinding(mesh);
  return r;
}

}  // namespace sprig
