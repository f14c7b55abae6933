#pragma once
/// Meshes the organisms tests share: an icosphere, its triangle soup, a checked topology
/// and CGAL's free meshes (docs/MESHES.md).

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "core/mesh.h"
#include "core/polymesh.h"
#include "tests/paths.h"

namespace sprig::test {

/// An icosphere of 20·4^levels triangles (outward), every vertex on the sphere.
inline Mesh icosphere(int levels, const Vec3& center, float radius) {
  const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
  std::vector<Vec3> p = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                         {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  for (auto& v : p) v = glm::normalize(v);
  std::vector<glm::uvec3> tris = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                  {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                                  {3, 8, 9},   {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      auto key = std::minmax(a, b);
      auto [it, fresh] = mid.try_emplace(key, uint32_t(p.size()));
      if (fresh) p.push_back(glm::normalize(p[key.first] + p[key.second]));
      return it->second;
    };
    std::vector<glm::uvec3> next;
    for (const auto& tri : tris) {
      uint32_t a = midpoint(tri.x, tri.y), b = midpoint(tri.y, tri.z), c = midpoint(tri.z, tri.x);
      next.insert(next.end(), {{tri.x, a, c}, {tri.y, b, a}, {tri.z, c, b}, {a, b, c}});
    }
    tris = std::move(next);
  }
  Mesh m;
  for (const auto& v : p) m.positions.push_back(center + radius * v);
  m.triangles = tris;
  return m;
}

/// The same triangles with three vertices of their own each (a "triangle soup"), and a
/// normal per vertex: welding must join them again.
inline Mesh unwelded(const Mesh& in) {
  Mesh m;
  for (const auto& t : in.triangles) {
    auto base = uint32_t(m.positions.size());
    for (int k = 0; k < 3; ++k) m.positions.push_back(in.positions[t[k]]);
    Vec3 nrm = glm::normalize(glm::cross(in.positions[t.y] - in.positions[t.x], in.positions[t.z] - in.positions[t.x]));
    m.normals.insert(m.normals.end(), {nrm, nrm, nrm});
    m.triangles.push_back({base, base + 1, base + 2});
  }
  return m;
}

/// checkPolyMesh's counts, requiring that it reports no error.
inline PolyTopology checked(const PolyMesh& m) {
  DiagnosticList d;
  PolyTopology t = checkPolyMesh(m, d);
  CHECK(d.items().empty());
  return t;
}

/// CGAL's free meshes extracted into dir/meshes by scripts/extract-meshes.sh, or nullopt
/// (with a SKIP warning) where libcgal-demo is not installed.
inline std::optional<std::filesystem::path> freeMeshes(const std::filesystem::path& dir) {
  const std::filesystem::path tarball = "/usr/share/doc/libcgal-demo/data.tar.gz";
  if (!std::filesystem::exists(tarball)) {
    WARN("SKIP: " << tarball << " is missing (scripts/install-deps.sh installs libcgal-demo)");
    return std::nullopt;
  }
  std::filesystem::path out = dir / "meshes";
  std::string cmd = std::string("bash '") + SPRIG_SOURCE_DIR + "/scripts/extract-meshes.sh' '" + out.string() + "' > /dev/null";
  REQUIRE(std::system(cmd.c_str()) == 0);
  return out;
}

}  // namespace sprig::test
