#include "core/mesh_corners.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <tuple>

namespace sprig {

namespace {

// Area-weighted (unnormalized: twice the area) winding normal of triangle t.
Vec3 faceNormal(const Mesh& mesh, size_t t) {
  const glm::uvec3& tri = mesh.triangles[t];
  const DVec3 a(mesh.positions[tri.x]), b(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
  return Vec3(glm::cross(b - a, c - a));
}

Vec3 unitOr(const Vec3& v, const Vec3& fallback) {
  const float len = glm::length(v);
  return len > 0 && std::isfinite(len) ? v / len : fallback;
}

}  // namespace

CreaseNormals splitCreaseNormals(const Mesh& mesh) {
  const size_t n = mesh.positions.size(), nt = mesh.triangles.size();
  std::vector<Vec3> faces(nt);
  for (size_t t = 0; t < nt; ++t) faces[t] = faceNormal(mesh, t);
  // Incident corners of each vertex (CSR: corners of vertex v are in [start[v], start[v+1])).
  std::vector<uint32_t> start(n + 1, 0);
  for (const auto& tri : mesh.triangles)
    for (int k = 0; k < 3; ++k) ++start[tri[k] + 1];
  for (size_t v = 0; v < n; ++v) start[v + 1] += start[v];
  std::vector<uint32_t> corners(nt * 3), fill(start.begin(), start.end() - 1);
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) corners[fill[mesh.triangles[t][k]]++] = uint32_t(t * 3 + k);

  CreaseNormals out;
  std::vector<Vec3>& values = out.normals.values;
  values.resize(n);
  out.normals.index.resize(nt * 3);
  const bool hasNormals = mesh.normals.size() == n;
  for (size_t v = 0; v < n; ++v) {
    Vec3 sum(0);
    bool crease = false;
    for (uint32_t i = start[v]; i < start[v + 1]; ++i) {
      const Vec3& fi = faces[corners[i] / 3];
      sum += fi;
      for (uint32_t j = start[v]; j < i && !crease; ++j)
        if (glm::dot(fi, faces[corners[j] / 3]) < 0) crease = true;
    }
    values[v] = hasNormals ? mesh.normals[v] : unitOr(sum, Vec3(0, 0, 1));
    if (!crease) {
      for (uint32_t i = start[v]; i < start[v + 1]; ++i) out.normals.index[corners[i]] = uint32_t(v);
      continue;
    }
    // Greedy groups of faces pairwise within 90° (dot >= 0), largest face first (ties by
    // corner order: deterministic). A face's dot with its group's sum is then |f|² plus
    // non-negative terms: every face is within 90° of its group's normal.
    std::vector<uint32_t> order(corners.begin() + start[v], corners.begin() + start[v + 1]);
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
      return glm::length(faces[a / 3]) > glm::length(faces[b / 3]);
    });
    std::vector<Vec3> groupSum;
    std::vector<std::vector<uint32_t>> groups;
    for (uint32_t c : order) {
      const Vec3& f = faces[c / 3];
      bool placed = false;
      for (size_t g = 0; g < groups.size() && !placed; ++g) {
        bool ok = true;  // within 90° of every face already in the group
        for (uint32_t m : groups[g]) ok = ok && glm::dot(faces[m / 3], f) >= 0;
        if (ok) groupSum[g] += f, groups[g].push_back(c), placed = true;
      }
      if (!placed) groupSum.push_back(f), groups.push_back({c});
    }
    for (size_t g = 0; g < groups.size(); ++g) {
      uint32_t id = uint32_t(v);
      if (g == 0) values[v] = unitOr(groupSum[0], values[v]);
      else id = uint32_t(values.size()), values.push_back(unitOr(groupSum[g], values[v]));
      for (uint32_t c : groups[g]) out.normals.index[c] = id;
    }
    if (groups.size() > 1) ++out.splitVertices, out.extraNormals += groups.size() - 1;
  }
  return out;
}

CornerTable<Vec2> cornerUvs(const Mesh& mesh, const UvSeamOptions& options) {
  const size_t n = mesh.positions.size(), nt = mesh.triangles.size();
  if (mesh.uvs.size() != n) throw std::invalid_argument("cornerUvs: the mesh has no uvs");
  CornerTable<Vec2> out;
  out.values = mesh.uvs;
  out.index.resize(nt * 3);
  std::map<std::tuple<uint32_t, int, int>, uint32_t> shifted;  // (vertex, du, dv) -> value
  for (size_t t = 0; t < nt; ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    Vec2 uv[3];
    int shift[3][2] = {};
    for (int k = 0; k < 3; ++k) uv[k] = mesh.uvs[tri[k]];
    for (int axis = 0; axis < 2; ++axis) {
      if (!(axis == 0 ? options.repeatU : options.repeatV) || options.continuous) continue;
      const float hi = std::max({uv[0][axis], uv[1][axis], uv[2][axis]});
      for (int k = 0; k < 3; ++k)
        if (uv[k][axis] < hi - 0.5f) {
          const float turns = std::ceil(hi - 0.5f - uv[k][axis]);
          if (!(turns < 1e6f)) continue;  // a non-finite or absurd uv: left as it is
          uv[k][axis] += turns;
          shift[k][axis] = int(turns);
        }
    }
    bool jump = false;
    for (int axis = 0; axis < 2; ++axis) {
      const float lo = std::min({uv[0][axis], uv[1][axis], uv[2][axis]});
      const float hi = std::max({uv[0][axis], uv[1][axis], uv[2][axis]});
      if (hi - lo > options.maxSpan[axis]) jump = true;
    }
    for (int k = 0; k < 3; ++k) {
      uint32_t id = tri[k];
      if (jump) id = tri[0];
      else if (shift[k][0] || shift[k][1]) {
        const auto key = std::make_tuple(uint32_t(tri[k]), shift[k][0], shift[k][1]);
        auto it = shifted.find(key);
        if (it == shifted.end()) {
          it = shifted.emplace(key, uint32_t(out.values.size())).first;
          out.values.push_back(uv[k]);
        }
        id = it->second;
      }
      out.index[t * 3 + size_t(k)] = id;
    }
  }
  return out;
}

Mesh unweld(const Mesh& mesh, const CornerTable<Vec3>& normals, const CornerTable<Vec2>& uvs, std::vector<uint32_t>* origin) {
  const size_t n = mesh.positions.size(), nt = mesh.triangles.size();
  const bool hasN = !normals.index.empty(), hasUv = !uvs.index.empty();
  if ((hasN && normals.index.size() != nt * 3) || (hasUv && uvs.index.size() != nt * 3))
    throw std::invalid_argument("unweld: a corner table does not have 3 entries per triangle");
  Mesh out = mesh;
  if (hasN && out.normals.size() != n) out.normals.assign(n, Vec3(0, 0, 1));
  if (hasUv && out.uvs.size() != n) out.uvs.assign(n, Vec2(0));
  const bool hasC = mesh.colors.size() == n;
  // Per vertex: the (normal, uv) pairs seen so far and their output vertex.
  std::vector<uint32_t> firstN(n, UINT32_MAX), firstUv(n, UINT32_MAX);
  std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> extra;
  if (origin) {
    origin->resize(n);
    for (size_t v = 0; v < n; ++v) (*origin)[v] = uint32_t(v);
  }
  for (size_t t = 0; t < nt; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = mesh.triangles[t][k];
      const uint32_t ni = hasN ? normals.index[t * 3 + size_t(k)] : 0;
      const uint32_t ui = hasUv ? uvs.index[t * 3 + size_t(k)] : 0;
      if (firstN[v] == UINT32_MAX) {
        firstN[v] = ni, firstUv[v] = ui;
        if (hasN) out.normals[v] = normals.values[ni];
        if (hasUv) out.uvs[v] = uvs.values[ui];
        continue;
      }
      if (firstN[v] == ni && firstUv[v] == ui) continue;
      const auto key = std::make_tuple(v, ni, ui);
      auto it = extra.find(key);
      if (it == extra.end()) {
        it = extra.emplace(key, uint32_t(out.positions.size())).first;
        out.positions.push_back(mesh.positions[v]);
        if (hasN) out.normals.push_back(normals.values[ni]);
        else if (out.normals.size() + 1 == out.positions.size()) out.normals.push_back(mesh.normals[v]);
        if (hasUv) out.uvs.push_back(uvs.values[ui]);
        else if (out.uvs.size() + 1 == out.positions.size()) out.uvs.push_back(mesh.uvs[v]);
        if (hasC) out.colors.push_back(mesh.colors[v]);
        if (origin) origin->push_back(v);
      }
      out.triangles[t][k] = it->second;
    }
  return out;
}

glm::vec4 cornerTangent(const Vec3 p[3], const Vec2 uv[3], const Vec3& normal) {
  const glm::dvec3 e1 = glm::dvec3(p[1]) - glm::dvec3(p[0]), e2 = glm::dvec3(p[2]) - glm::dvec3(p[0]);
  const glm::dvec2 d1 = glm::dvec2(uv[1]) - glm::dvec2(uv[0]), d2 = glm::dvec2(uv[2]) - glm::dvec2(uv[0]);
  glm::dvec3 n = glm::dvec3(normal);
  const double nl = glm::length(n);
  n = nl > 0 && std::isfinite(nl) ? n / nl : glm::dvec3(0, 0, 1);
  // dP/ds and dP/dt of the affine map (s, t) → P (Lengyel's per-triangle tangent).
  const double det = d1.x * d2.y - d2.x * d1.y;
  glm::dvec3 t(0.0), b(0.0);
  if (std::abs(det) > 0) {
    t = (e1 * d2.y - e2 * d1.y) / det;
    b = (e2 * d1.x - e1 * d2.x) / det;
  }
  const double raw = glm::length(t);
  t -= n * glm::dot(n, t);
  double tl = glm::length(t);
  if (!(tl > 1e-6 * raw) || !std::isfinite(tl)) {
    // Any direction perpendicular to n: the axis least along it, made perpendicular.
    const glm::dvec3 axis = std::abs(n.x) < 0.577 ? glm::dvec3(1, 0, 0) : std::abs(n.y) < 0.577 ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, 1);
    t = axis - n * glm::dot(n, axis);
    tl = glm::length(t);
    b = glm::cross(n, t);
  }
  t /= tl;
  const float w = glm::dot(glm::cross(n, t), b) < 0 ? -1.0f : 1.0f;
  return glm::vec4(float(t.x), float(t.y), float(t.z), w);
}

}  // namespace sprig
