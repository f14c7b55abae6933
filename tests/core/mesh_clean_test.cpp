#include <catch2/catch.hpp>

#include "core/mesh_clean.h"
#include "tests/core/cube_mesh.h"

using namespace sprig;

namespace {

// The unit cube scaled by s and moved by d; inverted = wound (and its normals) inward.
Mesh movedCube(float s, Vec3 d, bool inverted = false) {
  Mesh m = test::cube(true);
  for (auto& p : m.positions) p = s * p + d;
  if (inverted) {
    for (auto& t : m.triangles) std::swap(t.y, t.z);
    for (auto& n : m.normals) n = -n;
  }
  return m;
}

}  // namespace

TEST_CASE("cleanMesh", "[core]") {
  SECTION("a speck outside and a void inside go, a part above the fraction stays") {
    Mesh m = movedCube(1, Vec3(0));                    // volume 1
    m.append(movedCube(0.01f, Vec3(3, 0, 0)));         // speck, 1e-6
    m.append(movedCube(0.01f, Vec3(0.5f), true));      // void inside, -1e-6
    m.append(movedCube(0.1f, Vec3(-2, 0, 0)));         // 1e-3: kept at the default 1e-4
    size_t count = 0;
    triangleComponents(m, &count);
    REQUIRE(count == 4);
    const MeshCleanReport r = cleanMesh(m);
    CHECK(r.componentsBefore == 4);
    CHECK(r.componentsAfter == 2);
    CHECK(r.specks == 1);
    CHECK(r.voids == 1);
    CHECK(r.removedTriangles == 24);
    CHECK(r.modelVolume == Approx(1.001).epsilon(1e-6));
    CHECK(m.vertexCount() == 16);
    CHECK(m.normals.size() == 16);
    CHECK(m.colors.size() == 16);
    CHECK(m.materials.size() == 24);
    const MeshTopology topo = analyzeTopology(m);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    CHECK(signedVolume(m) == Approx(1.001).epsilon(1e-6));
    // The kept small cube's vertices follow the big one's (order kept, indices remapped).
    CHECK(m.positions[8] == Vec3(-2, 0, 0));
  }
  SECTION("a fraction of 0 keeps every component") {
    Mesh m = movedCube(1, Vec3(0));
    m.append(movedCube(0.01f, Vec3(3, 0, 0)));
    MeshCleanOptions o;
    o.minVolumeFraction = 0;
    const MeshCleanReport r = cleanMesh(m, o);
    CHECK(r.componentsAfter == 2);
    CHECK(m.triangleCount() == 24);
  }
  SECTION("a raised fraction removes the larger part too") {
    Mesh m = movedCube(1, Vec3(0));
    m.append(movedCube(0.1f, Vec3(-2, 0, 0)));
    MeshCleanOptions o;
    o.minVolumeFraction = 2e-3;  // 1e-3 / 1.001 of the volume is below it
    CHECK(cleanMesh(m, o).specks == 1);
    CHECK(m.triangleCount() == 12);
  }
  SECTION("a vertex normal against the winding is replaced by its triangles' normal") {
    Mesh m = movedCube(1, Vec3(0));
    CHECK(facesAgainstWinding(m) == 0);
    m.normals[0] = -m.normals[0];
    // Vertex 0 is in two triangles of each of three faces.
    CHECK(facesAgainstWinding(m) == 6);
    const MeshCleanReport r = cleanMesh(m);
    CHECK(r.facesAgainstBefore == 6);
    CHECK(r.fixedNormals == 1);
    CHECK(r.facesAgainstAfter == 0);
    // Its three faces' area-weighted normals (two triangles each, equal areas) sum along -(1,1,1).
    CHECK(m.normals[0].x == Approx(-1 / std::sqrt(3.0)));
    CHECK(m.normals[0].y == Approx(-1 / std::sqrt(3.0)));
    CHECK(m.normals[0].z == Approx(-1 / std::sqrt(3.0)));
    CHECK(m.normals[1] == movedCube(1, Vec3(0)).normals[1]);
  }
}

TEST_CASE("removeDegenerateTriangles", "[core]") {
  // A closed cube (12 triangles) and five degenerate triangles among them: two with a
  // repeated corner ({0,0,1}, {2,3,3}), three of zero area with distinct corners (vertex 8
  // at vertex 0's position, vertex 9 halfway along the edge from 0 to 1, and three corners
  // on one line), each with a material id.
  Mesh mesh = test::cube(true);
  mesh.positions.push_back(mesh.positions[0]);                                  // 8
  mesh.positions.push_back(0.5f * (mesh.positions[0] + mesh.positions[1]));     // 9
  const std::vector<glm::uvec3> bad = {{0, 0, 1}, {0, 8, 5}, {2, 3, 3}, {0, 9, 1}, {9, 1, 0}};
  std::vector<glm::uvec3> triangles;
  std::vector<uint32_t> materials;
  for (size_t t = 0; t < 12; ++t) {
    triangles.push_back(mesh.triangles[t]), materials.push_back(mesh.materials[t]);
    if (t % 3 == 0) triangles.push_back(bad[t / 3]), materials.push_back(99);
  }
  triangles.push_back(bad[4]), materials.push_back(99);
  mesh.triangles = triangles;
  mesh.materials = materials;
  REQUIRE(mesh.triangleCount() == 17);
  const Mesh cube = test::cube(true);
  std::vector<size_t> kept;
  const DegenerateReport r = removeDegenerateTriangles(mesh, &kept);
  CHECK(r.repeatedIndex == 2);
  CHECK(r.zeroArea == 3);
  CHECK(r.total() == 5);
  // The cube's twelve remain, in order, with their materials; kept names their old places.
  REQUIRE(mesh.triangleCount() == 12);
  REQUIRE(kept.size() == 12);
  for (size_t t = 0; t < 12; ++t) {
    CHECK(mesh.triangles[t] == cube.triangles[t]);
    CHECK(mesh.materials[t] == cube.materials[t]);
    CHECK(triangles[kept[t]] == cube.triangles[t]);
  }
  CHECK(mesh.vertexCount() == 10);  // vertices stay
  CHECK(analyzeTopology(mesh).closed());
  // A second pass finds nothing.
  CHECK(removeDegenerateTriangles(mesh).total() == 0);
  CHECK(mesh.triangleCount() == 12);
}
