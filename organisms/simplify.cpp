#include "organisms/simplify.h"

#include "organisms/edge_collapse.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <tuple>
#include <utility>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace sprig::organisms {

namespace {

// Edge counts of an index buffer of triangles.
MeshTopology topologyOf(const std::vector<unsigned int>& indices) {
  Mesh m;
  m.triangles.resize(indices.size() / 3);
  std::memcpy(m.triangles.data(), indices.data(), m.triangles.size() * sizeof(glm::uvec3));
  return analyzeTopology(m);
}

}  // namespace

size_t dropFoldedPairs(std::vector<unsigned int>& indices) {
  // Key: the sorted vertices, the orientation (even or odd permutation of the sorted order)
  // and the triangle's number; sorted, a folded pair is an even and an odd entry of one
  // vertex set.
  struct Key {
    std::array<unsigned, 3> v;
    bool odd;
    size_t face;
    bool operator<(const Key& o) const { return std::tie(v, odd, face) < std::tie(o.v, o.odd, o.face); }
  };
  const size_t faces = indices.size() / 3;
  std::vector<Key> keys(faces);
  for (size_t f = 0; f < faces; ++f) {
    const unsigned a = indices[3 * f], b = indices[3 * f + 1], c = indices[3 * f + 2];
    // The rotations of (a, b, c) with the smallest vertex first: (m, x, y) is odd when x > y.
    const unsigned m = std::min({a, b, c});
    const auto [x, y] = m == a ? std::pair(b, c) : m == b ? std::pair(c, a) : std::pair(a, b);
    keys[f] = {{m, std::min(x, y), std::max(x, y)}, x > y, f};
  }
  std::sort(keys.begin(), keys.end());
  std::vector<bool> drop(faces, false);
  size_t pairs = 0;
  for (size_t i = 0; i < faces;) {
    size_t j = i, odd = i;
    while (j < faces && keys[j].v == keys[i].v) ++j;
    while (odd < j && !keys[odd].odd) ++odd;  // [i, odd) even, [odd, j) odd
    for (size_t e = i, o = odd; e < odd && o < j; ++e, ++o, ++pairs) drop[keys[e].face] = drop[keys[o].face] = true;
    i = j;
  }
  if (pairs == 0) return 0;
  size_t kept = 0;
  for (size_t f = 0; f < faces; ++f)
    if (!drop[f]) std::copy_n(indices.begin() + 3 * f, 3, indices.begin() + 3 * kept++);
  indices.resize(3 * kept);
  return pairs;
}

SimplifiedMesh simplifyMesh(const Mesh& mesh, size_t targetFaces, float maxRelativeError, bool linkCheck, bool lockBorder) {
  linkCheck = linkCheck && lockBorder;
  SimplifiedMesh out;
  SimplifyReport& report = out.report;
  report.inputTriangles = mesh.triangleCount();
  size_t n = mesh.vertexCount();
  bool hasColors = !mesh.colors.empty() && mesh.colors.size() == n;

  // Positions with -0 made +0: welding compares bytes.
  std::vector<Vec3> positions(n);
  for (size_t i = 0; i < n; ++i) {
    const Vec3& p = mesh.positions[i];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw std::invalid_argument("simplifyMesh: vertex " + std::to_string(i) + " has a position that is not finite");
    positions[i] = p + Vec3(0.0f);
  }
  std::vector<unsigned int> indices;
  indices.reserve(mesh.triangleCount() * 3);
  for (const auto& t : mesh.triangles) {
    if (t.x >= n || t.y >= n || t.z >= n)
      throw std::invalid_argument("simplifyMesh: a triangle index is out of range (" + std::to_string(n) + " vertices)");
    indices.insert(indices.end(), {t.x, t.y, t.z});
  }

  // 1. Weld coincident positions; drop triangles that weld to a line or a point.
  std::vector<unsigned int> remap(n);
  size_t welded = meshopt_generateVertexRemap(remap.data(), indices.data(), indices.size(), positions.data(), n, sizeof(Vec3));
  meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
  std::vector<Vec3> weldedPositions(welded), weldedColors(hasColors ? welded : 0);
  meshopt_remapVertexBuffer(weldedPositions.data(), positions.data(), n, sizeof(Vec3), remap.data());
  if (hasColors) meshopt_remapVertexBuffer(weldedColors.data(), mesh.colors.data(), n, sizeof(Vec3), remap.data());
  size_t kept = 0;
  for (size_t t = 0; t < indices.size(); t += 3) {
    unsigned a = indices[t], b = indices[t + 1], c = indices[t + 2];
    if (a == b || b == c || a == c) continue;
    indices[kept++] = a, indices[kept++] = b, indices[kept++] = c;
  }
  indices.resize(kept);
  report.weldedVertices = welded;
  if (indices.empty()) return out;
  const float* xyz = &weldedPositions[0].x;

  // 2. Edge collapses down to the target, the border locked (meshoptimizer asserts that
  // the target is no larger than the mesh). meshoptimizer 0.18 does not test the link
  // condition, so a collapse now and then pinches the surface: an edge of four faces, or
  // a triangle folded onto its reverse. A result of a manifold input that is pinched, or
  // whose boundary changed, is replaced by Sprig's own link-checked collapses
  // (organisms/edge_collapse.h). Without the link check (levels of detail), the folds are
  // removed, which leaves the surface closed.
  size_t target = std::min(targetFaces, indices.size() / 3);
  std::vector<unsigned int> simplified(indices.size());
  float error = 0;
  size_t count = meshopt_simplify(simplified.data(), indices.data(), indices.size(), xyz, welded, sizeof(Vec3),
                                  target * 3, maxRelativeError, lockBorder ? unsigned(meshopt_SimplifyLockBorder) : 0u, &error);
  simplified.resize(count);
  float scale = meshopt_simplifyScale(xyz, welded, sizeof(Vec3));
  MeshTopology input = linkCheck ? topologyOf(indices) : MeshTopology{};
  // Topology of the result as meshoptimizer made it, then its folds removed once.
  MeshTopology result = linkCheck && input.manifold() ? topologyOf(simplified) : MeshTopology{};
  report.foldedPairs = dropFoldedPairs(simplified);
  count = simplified.size();
  if (linkCheck && input.manifold() &&
      (!result.manifold() || result.boundaryEdges != input.boundaryEdges || report.foldedPairs > 0)) {
    EdgeCollapseResult own = collapseEdges(weldedPositions, indices, target, maxRelativeError * scale);
    simplified = std::move(own.indices);
    error = scale > 0 ? own.error / scale : 0;
    report.linkChecked = true;
    report.foldedPairs = dropFoldedPairs(simplified);  // none: kept for the case it ever has
    count = simplified.size();
  }

  // 3. Compact: only used vertices, in order of first use.
  std::vector<unsigned int> compact(welded);
  size_t used = meshopt_optimizeVertexFetchRemap(compact.data(), simplified.data(), count, welded);
  meshopt_remapIndexBuffer(simplified.data(), simplified.data(), count, compact.data());
  PolyMesh& poly = out.mesh;
  poly.positions.resize(used);
  meshopt_remapVertexBuffer(poly.positions.data(), weldedPositions.data(), welded, sizeof(Vec3), compact.data());
  if (hasColors) {
    poly.colors.resize(used);
    meshopt_remapVertexBuffer(poly.colors.data(), weldedColors.data(), welded, sizeof(Vec3), compact.data());
  }
  poly.faceVertices.assign(simplified.begin(), simplified.end());
  poly.faceSizes.assign(count / 3, 3);

  out.source.assign(used, 0);
  std::vector<uint32_t> lowest(welded, UINT32_MAX);  // welded vertex -> lowest input vertex
  for (size_t i = n; i-- > 0;)
    if (remap[i] != ~0u) lowest[remap[i]] = uint32_t(i);
  for (size_t w = 0; w < welded; ++w)
    if (compact[w] != ~0u) out.source[compact[w]] = lowest[w];

  report.faces = count / 3;
  report.vertices = used;
  report.relativeError = error;
  report.absoluteError = error * scale;
  return out;
}

PolyMesh simplifyToFaceCount(const Mesh& mesh, size_t targetFaces, float maxRelativeError) {
  return simplifyMesh(mesh, targetFaces, maxRelativeError).mesh;
}

namespace {

// The triangle mesh of a simplification, every per-vertex array of the input carried to the
// vertices that remain.
Mesh carried(const Mesh& mesh, SimplifiedMesh& s, SimplifyReport* report, std::vector<uint32_t>* source) {
  if (report) *report = s.report;
  Mesh out;
  out.positions = std::move(s.mesh.positions);
  out.triangles.resize(s.mesh.faceCount());
  for (size_t f = 0; f < out.triangles.size(); ++f)
    out.triangles[f] = glm::uvec3(s.mesh.faceVertices[3 * f], s.mesh.faceVertices[3 * f + 1], s.mesh.faceVertices[3 * f + 2]);
  auto carry = [&](const auto& from, auto& to) {
    if (from.size() != mesh.vertexCount()) return;
    to.resize(s.source.size());
    for (size_t v = 0; v < s.source.size(); ++v) to[v] = from[s.source[v]];
  };
  carry(mesh.normals, out.normals);
  carry(mesh.uvs, out.uvs);
  carry(mesh.colors, out.colors);
  if (source) *source = std::move(s.source);
  return out;
}

}  // namespace

Mesh simplifyToError(const Mesh& mesh, float maxRelativeError, SimplifyReport* report, std::vector<uint32_t>* source) {
  SimplifiedMesh s = simplifyMesh(mesh, 0, maxRelativeError);
  return carried(mesh, s, report, source);
}

Mesh simplifyToCount(const Mesh& mesh, size_t targetFaces, SimplifyReport* report, bool lockBorder) {
  // An error bound of 1: the whole extent, so the face count alone stops the collapses.
  SimplifiedMesh s = simplifyMesh(mesh, targetFaces, 1.0f, false, lockBorder);
  return carried(mesh, s, report, nullptr);
}

}  // namespace sprig::organisms
