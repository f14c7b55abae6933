#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <optional>

#include "core/polymesh.h"
#include "organisms/edge_collapse.h"
#include "tests/organisms/meshes.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

std::vector<uint32_t> indicesOf(const Mesh& m) {
  std::vector<uint32_t> out;
  for (const auto& t : m.triangles) out.insert(out.end(), {t.x, t.y, t.z});
  return out;
}

PolyMesh polyOf(const std::vector<Vec3>& positions, const std::vector<uint32_t>& indices) {
  PolyMesh p;
  p.positions = positions;
  p.faceVertices = indices;
  p.faceSizes.assign(indices.size() / 3, 3);
  return p;
}

}  // namespace

TEST_CASE("collapseEdges", "[organisms]") {
  const Vec3 center(-1, 0.5f, 2);
  const float radius = 3;
  SECTION("a closed sphere to exactly the target, closed and manifold, on the sphere") {
    Mesh sphere = test::icosphere(5, center, radius);
    EdgeCollapseResult r = collapseEdges(sphere.positions, indicesOf(sphere), 500, 1e9f);
    REQUIRE(r.indices.size() == 500 * 3);
    PolyMesh p = polyOf(sphere.positions, r.indices);
    PolyTopology t = test::checked(p);
    CHECK(t.closed());
    CHECK(t.manifold());
    std::vector<uint32_t> used = r.indices;
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    CHECK(used.size() == 500 / 2 + 2);  // Euler: V - E + F = 2, E = 3F/2
    for (uint32_t v : used) CHECK(std::fabs(glm::length(sphere.positions[v] - center) - radius) < 1e-5f * radius);
    CHECK(r.error > 0);
    CHECK(r.error < 0.1f * radius);
    Mesh tri = triangulate(p);
    CHECK(signedVolume(tri) > 0.95 * 4.0 / 3.0 * kPi * radius * radius * radius);
    // Deterministic.
    CHECK(collapseEdges(sphere.positions, indicesOf(sphere), 500, 1e9f).indices == r.indices);
  }
  SECTION("maxError stops the collapses") {
    Mesh sphere = test::icosphere(4, center, radius);
    EdgeCollapseResult r = collapseEdges(sphere.positions, indicesOf(sphere), 10, 1e-3f * radius);
    CHECK(r.indices.size() / 3 > 1000);
    CHECK(r.error <= 1e-3f * radius);
  }
  SECTION("a tetrahedron has no legal collapse") {
    Mesh tet = test::icosphere(0, center, radius);
    tet.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 3, 1}, {1, 3, 2}};
    tet.positions = {Vec3(0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)};
    CHECK(collapseEdges(tet.positions, indicesOf(tet), 0, 1e9f).indices == indicesOf(tet));
  }
  SECTION("an open grid keeps its border vertices and edges") {
    // A 9 x 9 vertex grid, slightly curved, 128 triangles, 32 boundary edges.
    std::vector<Vec3> pos;
    std::vector<uint32_t> idx;
    for (int y = 0; y < 9; ++y)
      for (int x = 0; x < 9; ++x) pos.push_back(Vec3(x, y, 0.01f * float((x - 4) * (x - 4) + (y - 4) * (y - 4))));
    for (uint32_t y = 0; y < 8; ++y)
      for (uint32_t x = 0; x < 8; ++x) {
        uint32_t a = y * 9 + x;
        idx.insert(idx.end(), {a, a + 1, a + 10, a, a + 10, a + 9});
      }
    EdgeCollapseResult r = collapseEdges(pos, idx, 1, 1e9f);
    PolyTopology t = test::checked(polyOf(pos, r.indices));
    CHECK(t.boundaryEdges == 32);
    CHECK(t.manifold());
    // 32 border vertices and one inner vertex left (2·1 + 32 - 2 faces): moving it onto
    // any border vertex would make a flat triangle along a side of the grid.
    CHECK(r.indices.size() / 3 == 32);
  }
}

TEST_CASE("collapseEdges on CGAL's free meshes", "[organisms]") {
  test::TempDir dir("collapse-meshes");
  std::optional<std::filesystem::path> meshes = test::freeMeshes(dir.path);
  if (!meshes) return;
  for (const char* name : {"mannequin-devil.off", "cactus.off", "fandisk.off"}) {
    Mesh m = triangulate(readPolyMesh(*meshes / name));
    PolyTopology before = test::checked(toPolyMesh(m));
    for (size_t target = 100; target < m.triangleCount(); target = target * 3 / 2) {
      INFO(name << " to " << target << " faces");
      EdgeCollapseResult r = collapseEdges(m.positions, indicesOf(m), target, 1e9f);
      PolyTopology after = test::checked(polyOf(m.positions, r.indices));
      CHECK(after.manifold());
      CHECK(after.boundaryEdges == before.boundaryEdges);
      CHECK(r.indices.size() / 3 <= std::max<size_t>(target + 1, 64));
    }
  }
}
