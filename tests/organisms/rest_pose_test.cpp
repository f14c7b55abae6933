#include "organisms/rest_pose.h"

#include <catch2/catch.hpp>

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "meshes.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

/// A closed, outward-wound box of half extents h centred at c (12 triangles).
Mesh boxMesh(const Vec3& c, const Vec3& h) {
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back(c + Vec3((i & 1) ? h.x : -h.x, (i & 2) ? h.y : -h.y, (i & 4) ? h.z : -h.z));
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({uint32_t(q[0]), uint32_t(q[1]), uint32_t(q[2])});
    m.triangles.push_back({uint32_t(q[0]), uint32_t(q[2]), uint32_t(q[3])});
  }
  return m;
}

DVec3 tilted(double degFromZ) {
  const double a = degFromZ * 3.14159265358979323846 / 180.0;
  return {std::sin(a), 0.0, std::cos(a)};
}

}  // namespace

TEST_CASE("volumeCentroid: the centre of mass of a closed mesh", "[rest]") {
  const Mesh box = boxMesh(Vec3(1, 2, 3), Vec3(2, 1, 0.5f));
  REQUIRE(signedVolume(box) == Approx(8.0 * 2 * 1 * 0.5));
  const DVec3 c = volumeCentroid(box);
  CHECK(c.x == Approx(1.0).margin(1e-9));
  CHECK(c.y == Approx(2.0).margin(1e-9));
  CHECK(c.z == Approx(3.0).margin(1e-9));
  // A sphere away from the origin: its centre.
  const DVec3 s = volumeCentroid(test::icosphere(3, Vec3(-1, 0.5f, 2), 0.7f));
  CHECK(glm::length(s - DVec3(-1, 0.5, 2)) < 1e-5);
}

TEST_CASE("restingUp: a box rolls onto the face its centre of mass falls towards", "[rest]") {
  // Half extents 2, 1, 0.5 along x, y, z: h(u) = 2|ux| + |uy| + 0.5|uz| (the box's support
  // function about its centre). In the xz plane, put down at φ from +z, it has
  // dh/dφ = 2 cos φ − 0.5 sin φ: it rolls back to +z below φ = atan 4 = 75.96° and over to +x beyond.
  const Mesh box = boxMesh(Vec3(0.0f), Vec3(2, 1, 0.5f));
  const DVec3 c = volumeCentroid(box);
  SECTION("put down 50 degrees from its broad face: lies on it") {
    const DVec3 up = restingUp(box.positions, c, tilted(50));
    CHECK(std::abs(up.z) > 1 - 1e-6);
    CHECK(restingHeight(box.positions, c, up) == Approx(0.5).margin(1e-5));
  }
  SECTION("put down 80 degrees from it: tips over onto its narrow end") {
    const DVec3 up = restingUp(box.positions, c, tilted(80));
    CHECK(std::abs(up.x) > 1 - 1e-6);
    CHECK(restingHeight(box.positions, c, up) == Approx(2.0).margin(1e-5));
  }
  SECTION("put down aslant in every direction: still comes to rest on the broad face") {
    const DVec3 up = restingUp(box.positions, c, glm::normalize(DVec3(0.4, -0.5, 1.0)));
    CHECK(up.z > 1 - 1e-6);
  }
}

TEST_CASE("uprightRotation: up to +y, forward to +x, a proper rotation", "[rest]") {
  const DVec3 up = glm::normalize(DVec3(0.3, 0.2, 0.9));
  const DVec3 forward(0.0, -1.0, 0.2);
  const glm::dmat3 r = uprightRotation(up, forward);
  CHECK(glm::determinant(r) == Approx(1.0));
  const DVec3 y = r * up;
  CHECK(glm::length(y - DVec3(0, 1, 0)) < 1e-12);
  const DVec3 f = r * forward;
  CHECK(f.x > 0);
  CHECK(std::abs(f.z) < 1e-12);
  // Forward along up: any horizontal direction, still a rotation.
  CHECK(glm::determinant(uprightRotation(up, up)) == Approx(1.0));
}
