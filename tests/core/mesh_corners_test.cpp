#include <catch2/catch.hpp>

#include <cmath>

#include "core/mesh_corners.h"

using namespace sprig;

namespace {

// A sheet folded along the y axis: vertices x ∈ {−1, 0, 1}, y ∈ {0, 1}, z = h·|x|. The
// left half's winding normal is (h, 0, 1)/√(1+h²), the right half's (−h, 0, 1)/√(1+h²):
// more than 90° apart exactly when h > 1. The fold line's vertices get the average (0,0,1).
Mesh fold(float h) {
  Mesh m;
  for (int y = 0; y < 2; ++y)
    for (int x = -1; x <= 1; ++x) m.positions.push_back(Vec3(float(x), float(y), h * std::abs(float(x))));
  // vertex (x, y) -> (x + 1) + 3y
  m.triangles = {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}};
  m.normals.assign(6, Vec3(0, 0, 1));
  return m;
}

Vec3 winding(const Mesh& m, size_t t) {
  const auto& tri = m.triangles[t];
  return glm::normalize(glm::cross(m.positions[tri.y] - m.positions[tri.x], m.positions[tri.z] - m.positions[tri.x]));
}

}  // namespace

TEST_CASE("splitCreaseNormals", "[core]") {
  SECTION("a fold sharper than 90 degrees splits the two fold vertices, each side its face normal") {
    const Mesh m = fold(2.0f);  // normals 126.87° apart: acos((1 − 4)/5)
    const CreaseNormals c = splitCreaseNormals(m);
    CHECK(c.splitVertices == 2);
    CHECK(c.extraNormals == 2);
    REQUIRE(c.normals.values.size() == 8);
    REQUIRE(c.normals.index.size() == 12);
    const Vec3 left = Vec3(2, 0, 1) / std::sqrt(5.0f), right = Vec3(-2, 0, 1) / std::sqrt(5.0f);
    for (size_t t = 0; t < 4; ++t) {
      const Vec3 expected = t < 2 ? left : right;
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = m.triangles[t][k];
        const Vec3 n = c.normals.values[c.normals.index[t * 3 + size_t(k)]];
        CHECK(glm::dot(n, winding(m, t)) > 0);  // within 90° of its face
        if (v == 1 || v == 4) {  // the fold line: the side's own normal
          CHECK(n.x == Approx(expected.x));
          CHECK(n.z == Approx(expected.z));
        } else {  // elsewhere the mesh's own normal is kept
          CHECK(n == Vec3(0, 0, 1));
        }
      }
    }
    const Mesh u = unweld(m, c.normals, {});
    CHECK(u.vertexCount() == 8);
    CHECK(u.triangleCount() == 4);
    for (size_t t = 0; t < 4; ++t)
      for (int k = 0; k < 3; ++k) CHECK(glm::dot(u.normals[u.triangles[t][k]], winding(u, t)) > 0);
  }
  SECTION("a fold of less than 90 degrees and a cube's right angles split nothing") {
    const Mesh m = fold(0.9f);  // acos((1 − 0.81)/1.81) = 84°
    const CreaseNormals c = splitCreaseNormals(m);
    CHECK(c.splitVertices == 0);
    CHECK(c.normals.values == m.normals);
    Mesh cube;
    for (int i = 0; i < 8; ++i) cube.positions.push_back(Vec3(float(i & 1), float((i >> 1) & 1), float(i >> 2)));
    cube.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                      {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    CHECK(splitCreaseNormals(cube).splitVertices == 0);
    CHECK(unweld(cube, splitCreaseNormals(cube).normals, {}).vertexCount() == 8);
  }
  SECTION("a thin wedge: every vertex is on a crease and gets two normals") {
    // Prism over the triangle (0,0), (1,−t), (1,t), t = tan 15°, from z = 0 to 1: the two
    // long sides meet at 30° (normals 150° apart), each meets the back at 75° (105° apart),
    // the caps are at exactly 90° to all (dot 0: on the side of whichever face came first).
    // Each vertex has two faces more than 90° apart and a cap: two sides.
    const float t = std::tan(15.0f * 3.14159265f / 180.0f);
    Mesh w;
    for (int z = 0; z < 2; ++z) {
      w.positions.push_back(Vec3(0, 0, z));
      w.positions.push_back(Vec3(1, -t, z));
      w.positions.push_back(Vec3(1, t, z));
    }
    w.triangles = {{0, 2, 1}, {3, 4, 5}, {0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}, {2, 0, 3}, {2, 3, 5}};
    const CreaseNormals c = splitCreaseNormals(w);
    CHECK(c.splitVertices == 6);
    CHECK(c.extraNormals == 6);
    const Mesh u = unweld(w, c.normals, {});
    CHECK(u.vertexCount() == 12);
    for (size_t f = 0; f < u.triangleCount(); ++f)
      for (int k = 0; k < 3; ++k) CHECK(glm::dot(u.normals[u.triangles[f][k]], winding(u, f)) > 0);
  }
}

TEST_CASE("cornerUvs", "[core]") {
  // A strip of two triangles whose u crosses the seam at 1 → 0, and one triangle far away in v.
  Mesh m;
  m.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0), Vec3(2, 0, 0)};
  m.uvs = {Vec2(0.9f, 0.0f), Vec2(0.1f, 0.0f), Vec2(0.9f, 0.1f), Vec2(0.1f, 0.1f), Vec2(0.2f, 0.9f)};
  m.triangles = {{0, 1, 2}, {1, 3, 2}, {1, 4, 3}};
  SECTION("without repetition nothing changes") {
    const CornerTable<Vec2> c = cornerUvs(m, {});
    CHECK(c.values == m.uvs);
    CHECK(c.index == std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 1, 4, 3});
  }
  SECTION("repeating u: the corners past the seam get u + 1, one value per shifted vertex") {
    UvSeamOptions o;
    o.repeatU = true;
    const CornerTable<Vec2> c = cornerUvs(m, o);
    REQUIRE(c.values.size() == 7);  // vertices 1 and 3 shifted, each once
    CHECK(c.values[5] == Vec2(1.1f, 0.0f));
    CHECK(c.values[6] == Vec2(1.1f, 0.1f));
    CHECK(c.index == std::vector<uint32_t>{0, 5, 2, 5, 6, 2, 1, 4, 3});  // the third triangle spans 0.1: unchanged
    const Mesh u = unweld(m, {}, c);
    CHECK(u.vertexCount() == 7);  // 1 and 3 are used with both u and u + 1
  }
  SECTION("continuous uvs (they run on across the repeats): repeating axes shift nothing") {
    UvSeamOptions o;
    o.repeatU = o.repeatV = true;
    o.continuous = true;
    const CornerTable<Vec2> c = cornerUvs(m, o);
    CHECK(c.values == m.uvs);
    CHECK(c.index == std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 1, 4, 3});
  }
  SECTION("a triangle spanning more than maxSpan takes its first corner's uv") {
    UvSeamOptions o;
    o.maxSpan = Vec2(10.0f, 0.5f);
    const CornerTable<Vec2> c = cornerUvs(m, o);
    CHECK(c.values.size() == 5);
    CHECK(c.index == std::vector<uint32_t>{0, 1, 2, 1, 3, 2, 1, 1, 1});
  }
}
