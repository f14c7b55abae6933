#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>

#include "core/polymesh.h"
#include "organisms/simplify.h"
#include "tests/organisms/meshes.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {


}  // namespace

TEST_CASE("simplifyMesh", "[organisms]") {
  const Vec3 center(1, 2, 3);
  const float radius = 2.5f;
  Mesh sphere = test::unwelded(test::icosphere(5, center, radius));
  REQUIRE(sphere.triangleCount() == 20480);
  REQUIRE(sphere.vertexCount() == 61440);

  SECTION("a fine sphere to about 500 closed, manifold faces on the sphere") {
    SimplifiedMesh s = simplifyMesh(sphere, 500);
    CHECK(s.report.inputTriangles == 20480);
    CHECK(s.report.weldedVertices == 10242);
    CHECK(s.report.faces == s.mesh.faceCount());
    CHECK(s.report.vertices == s.mesh.positions.size());
    CHECK(s.mesh.faceCount() >= 400);
    CHECK(s.mesh.faceCount() <= 600);
    CHECK(s.report.relativeError > 0);
    CHECK(s.report.relativeError <= 0.1f);
    CHECK(s.report.absoluteError == Approx(s.report.relativeError * 2 * radius).epsilon(1e-3));
    PolyTopology t = test::checked(s.mesh);
    CHECK(t.closed());
    CHECK(t.manifold());
    // A closed genus-0 triangle mesh: V - E + F = 2 with E = 3F/2.
    CHECK(s.mesh.positions.size() == s.mesh.faceCount() / 2 + 2);
    for (const Vec3& p : s.mesh.positions) CHECK(std::fabs(glm::length(p - center) - radius) <= 0.02f * radius);
    Mesh tri = triangulate(s.mesh);
    double sphereVolume = 4.0 / 3.0 * kPi * radius * radius * radius;
    CHECK(signedVolume(tri) > 0.95 * sphereVolume);
    CHECK(signedVolume(tri) < sphereVolume);
  }
  SECTION("the same mesh gives the same bytes") {
    PolyMesh a = simplifyToFaceCount(sphere, 500), b = simplifyToFaceCount(sphere, 500);
    REQUIRE(a.positions.size() == b.positions.size());
    REQUIRE(a.faceVertices.size() == b.faceVertices.size());
    CHECK(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vec3)) == 0);
    CHECK(a.faceVertices == b.faceVertices);
    CHECK(a.faceSizes == b.faceSizes);
  }
  SECTION("maxRelativeError stops early") {
    SimplifiedMesh s = simplifyMesh(sphere, 500, 1e-4f);
    CHECK(s.mesh.faceCount() > 2000);
    CHECK(s.report.relativeError <= 1e-4f);
    CHECK(test::checked(s.mesh).closed());
  }
  SECTION("an open mesh keeps its border; colors are kept") {
    // The upper half of the sphere (every triangle with a vertex above the centre).
    Mesh full = test::icosphere(5, center, radius), cap;
    cap.positions = full.positions;
    for (const Vec3& p : cap.positions) cap.colors.push_back(Vec3((p.y - center.y) / radius, 0.5f, 0.25f));
    for (const auto& t : full.triangles)
      if (full.positions[t.x].y > center.y || full.positions[t.y].y > center.y || full.positions[t.z].y > center.y)
        cap.triangles.push_back(t);
    PolyTopology before = test::checked(toPolyMesh(cap));
    REQUIRE(before.boundaryEdges > 0);
    SimplifiedMesh s = simplifyMesh(cap, 300);
    PolyTopology after = test::checked(s.mesh);
    CHECK(after.boundaryEdges == before.boundaryEdges);
    CHECK(after.manifold());
    CHECK(s.mesh.faceCount() < cap.triangleCount() / 4);
    REQUIRE(s.mesh.colors.size() == s.mesh.positions.size());
    for (size_t i = 0; i < s.mesh.positions.size(); ++i)
      CHECK(s.mesh.colors[i].x == Approx((s.mesh.positions[i].y - center.y) / radius).margin(1e-5));
  }
  SECTION("a target above the mesh's size keeps every welded triangle") {
    SimplifiedMesh s = simplifyMesh(sphere, 1'000'000);
    CHECK(s.mesh.faceCount() == 20480);
    CHECK(s.mesh.positions.size() == 10242);
    CHECK(s.report.relativeError == 0);
  }
  SECTION("an empty mesh gives an empty mesh") {
    SimplifiedMesh s = simplifyMesh(Mesh{}, 100);
    CHECK(s.mesh.faceCount() == 0);
    CHECK(s.mesh.positions.empty());
  }
  SECTION("bad input") {
    Mesh bad = test::icosphere(0, center, radius);
    bad.triangles[3].y = 99;
    CHECK_THROWS_WITH(simplifyMesh(bad, 10), "simplifyMesh: a triangle index is out of range (12 vertices)");
    bad = test::icosphere(0, center, radius);
    bad.positions[4].z = std::nanf("");
    CHECK_THROWS_WITH(simplifyMesh(bad, 10), "simplifyMesh: vertex 4 has a position that is not finite");
  }
}

TEST_CASE("simplifyToError keeps the input's per-vertex data", "[organisms]") {
  const Vec3 center(1, 2, 3);
  const float radius = 2.5f;
  Mesh sphere = test::unwelded(test::icosphere(5, center, radius));
  // Field normals, a uv and a colour that are functions of the vertex's position, so the
  // kept vertex's values can be checked against its position.
  sphere.normals.clear();
  sphere.uvs.clear();
  sphere.colors.clear();
  for (const Vec3& p : sphere.positions) {
    const Vec3 n = glm::normalize(p - center);
    sphere.normals.push_back(n);
    sphere.uvs.push_back(Vec2(p.x, p.z));
    sphere.colors.push_back(0.5f * (n + 1.0f));
  }
  SimplifyReport report;
  std::vector<uint32_t> source;
  const float bound = 1e-3f;
  Mesh s = simplifyToError(sphere, bound, &report, &source);
  // The icosphere's level-5 facets deviate from the sphere by about R(1 - cos(edge/2)),
  // 2.5e-4 of its diameter, so a bound of 1e-3 allows collapses but not down to a handful.
  CHECK(s.triangleCount() < sphere.triangleCount() / 4);
  CHECK(s.triangleCount() > 200);
  CHECK(report.relativeError <= bound);
  CHECK(report.faces == s.triangleCount());
  MeshTopology t = analyzeTopology(s);
  CHECK(t.closed());
  CHECK(t.manifold());
  CHECK(signedVolume(s) > 0);
  REQUIRE(source.size() == s.vertexCount());
  REQUIRE(s.normals.size() == s.vertexCount());
  REQUIRE(s.uvs.size() == s.vertexCount());
  REQUIRE(s.colors.size() == s.vertexCount());
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    CHECK(s.positions[v] == sphere.positions[source[v]]);  // collapses move no vertex
    CHECK(s.normals[v] == glm::normalize(s.positions[v] - center));
    CHECK(s.uvs[v] == Vec2(s.positions[v].x, s.positions[v].z));
  }
  // Every triangle's centroid within the bound (of the 5-unit extent) plus the flat
  // facets' own sag of the sphere.
  for (const auto& tri : s.triangles) {
    const Vec3 c = (s.positions[tri.x] + s.positions[tri.y] + s.positions[tri.z]) / 3.0f;
    CHECK(radius - glm::length(c - center) <= 4 * bound * 2 * radius);
  }
}

TEST_CASE("simplifyMesh where meshoptimizer pinches", "[organisms]") {
  test::TempDir dir("simplify-meshes");
  std::optional<std::filesystem::path> meshes = test::freeMeshes(dir.path);
  if (!meshes) return;
  Mesh m = triangulate(readPolyMesh(*meshes / "mannequin-devil.off"));
  // meshoptimizer 0.18 leaves an edge of four faces at this target; the link-checked
  // collapses replace its result.
  SimplifiedMesh s = simplifyMesh(m, 677);
  CHECK(s.report.linkChecked);
  CHECK(s.mesh.faceCount() <= 677);  // a collapse removes two faces
  CHECK(s.mesh.faceCount() >= 676);
  PolyTopology t = test::checked(s.mesh);
  CHECK(t.manifold());
  CHECK(t.boundaryEdges == 64);
  CHECK(s.report.relativeError > 0);
  CHECK(s.report.relativeError < 0.1f);
  // And at the sphere's 500, meshoptimizer's own result stands.
  CHECK(!simplifyMesh(test::icosphere(5, Vec3(0), 1), 500).report.linkChecked);
}

TEST_CASE("dropFoldedPairs removes a triangle and its reverse, nothing else", "[organisms]") {
  // An octahedron, then on its first face the same triangle again and its reverse.
  std::vector<unsigned int> octa = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  std::vector<unsigned int> folded = octa;
  folded.insert(folded.end(), {2, 4, 0, 4, 2, 0});  // (0, 2, 4) rotated, and reversed
  CHECK(dropFoldedPairs(folded) == 1);
  REQUIRE(folded.size() == octa.size());
  Mesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.triangles.resize(8);
  std::memcpy(m.triangles.data(), folded.data(), folded.size() * sizeof(unsigned int));
  const MeshTopology t = analyzeTopology(m);
  CHECK(t.closed());
  CHECK(t.manifold());
  CHECK(t.inconsistentEdges == 0);
  // A copy with the same orientation is not a fold; a lone reversed pair goes whole.
  std::vector<unsigned int> twice = {0, 1, 2, 1, 2, 0};
  CHECK(dropFoldedPairs(twice) == 0);
  CHECK(twice.size() == 6);
  std::vector<unsigned int> pillow = {0, 1, 2, 2, 1, 0, 3, 4, 5};
  CHECK(dropFoldedPairs(pillow) == 1);
  CHECK(pillow == std::vector<unsigned int>{3, 4, 5});
}

TEST_CASE("simplifyMesh without the link check leaves no folded pair", "[organisms]") {
  test::TempDir dir("simplify-folds");
  std::optional<std::filesystem::path> meshes = test::freeMeshes(dir.path);
  if (!meshes) return;
  Mesh m = triangulate(readPolyMesh(*meshes / "mannequin-devil.off"));
  size_t folds = 0;
  for (size_t target : {50, 80, 120, 200, 300, 500, 677, 800, 1200, 2000, 3000, 5000}) {
    INFO("target " << target);
    SimplifiedMesh s = simplifyMesh(m, target, 1e-1f, false);
    folds += s.report.foldedPairs;
    std::vector<unsigned int> indices(s.mesh.faceVertices.begin(), s.mesh.faceVertices.end());
    CHECK(dropFoldedPairs(indices) == 0);  // (a pinch, an edge of four faces, may remain)
  }
  // meshoptimizer 0.18 folds at some of these targets: the removal is what is tested.
  CHECK(folds > 0);
}
