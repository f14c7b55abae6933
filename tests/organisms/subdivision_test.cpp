#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include "organisms/subdivision.h"
#include "tests/organisms/meshes.h"

using namespace sprig;
using namespace sprig::organisms;

namespace {

/// The cube [-1, 1]^3 as 12 triangles (two per face, outward), its 8 corners first.
ControlMesh triangulatedCube() {
  ControlMesh m;
  for (int i = 0; i < 8; ++i) m.positions.push_back(Vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) m.faceVertices.insert(m.faceVertices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  m.faceSizes.assign(12, 3);
  return m;
}

/// The cube's 12 edges (not the faces' diagonals).
std::vector<std::array<uint32_t, 2>> cubeEdges() {
  std::vector<std::array<uint32_t, 2>> out;
  for (uint32_t a = 0; a < 8; ++a)
    for (uint32_t bit = 1; bit < 8; bit <<= 1)
      if (!(a & bit)) out.push_back({a, a | bit});
  return out;
}

/// Positions of the finest level of sub from the control positions.
std::vector<Vec3> refined(const Subdivision& sub, std::vector<Vec3> p) {
  for (int l = 1; l <= sub.levels(); ++l) {
    std::vector<Vec3> fine(sub.vertexCount(l));
    sub.interpolate(l, p, fine);
    p = std::move(fine);
  }
  return p;
}

/// The axis (0, 1, 2) and side (+-1) of the cube face every vertex of triangle t lies on, or
/// axis -1.
std::pair<int, float> cubeFaceOf(const std::vector<Vec3>& p, const uint32_t* t) {
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f})
      if (std::all_of(t, t + 3, [&](uint32_t v) { return std::abs(p[v][axis] - side) < 1e-6f; })) return {axis, side};
  return {-1, 0.0f};
}

}  // namespace

TEST_CASE("Subdivision: Loop with the cube's edges creased keeps the cube", "[organisms][subdivision]") {
  const ControlMesh cube = triangulatedCube();
  SubdivisionOptions options;
  options.scheme = SubdivisionScheme::Loop;
  options.creases = cubeEdges();
  const Subdivision sub(cube, 2, options);
  const LevelTopology& fine = sub.topology(2);
  REQUIRE(fine.faceCount() == 12u * 16u);
  CHECK(std::all_of(fine.faceSizes.begin(), fine.faceSizes.end(), [](uint32_t n) { return n == 3; }));
  CHECK(sub.vertexCount(2) == 12u * 16u / 2u + 2u);  // a closed triangle mesh of genus 0
  for (uint32_t f = 0; f < fine.faceCount(); ++f) CHECK(sub.parentFace(1, sub.parentFace(2, f)) == f / 16);
  const std::vector<Vec3> p = refined(sub, cube.positions);
  // The corners, where three creases meet, stay (vertex v of every level is the control vertex v).
  for (uint32_t v = 0; v < 8; ++v) CHECK(p[v] == cube.positions[v]);
  // Every triangle lies on the face of the cube its control triangle lies on: faces flat, edges straight.
  for (uint32_t f = 0; f < fine.faceCount(); ++f) {
    const uint32_t parent = sub.parentFace(1, sub.parentFace(2, f));
    INFO("triangle " << f << " of control triangle " << parent);
    CHECK(cubeFaceOf(p, &fine.faceVertices[3 * f]) == cubeFaceOf(cube.positions, &cube.faceVertices[3 * parent]));
  }
  SECTION("without creases the corners round off") {
    SubdivisionOptions smooth;
    smooth.scheme = SubdivisionScheme::Loop;
    const std::vector<Vec3> q = refined(Subdivision(cube, 2, smooth), cube.positions);
    for (uint32_t v = 0; v < 8; ++v) CHECK(glm::length(q[v]) < 0.8f * glm::length(cube.positions[v]));
  }
}

TEST_CASE("Subdivision: Loop refines a smooth ball toward the sphere", "[organisms][subdivision]") {
  const Mesh ico = test::icosphere(0, Vec3(0.0f), 1.0f);
  ControlMesh m;
  m.positions = ico.positions;
  for (const auto& t : ico.triangles) m.faceVertices.insert(m.faceVertices.end(), {t.x, t.y, t.z});
  m.faceSizes.assign(ico.triangles.size(), 3);
  SubdivisionOptions options;
  options.scheme = SubdivisionScheme::Loop;
  // The largest fold between neighbouring triangles (degrees) and how far the vertices'
  // radii spread, relative to their mean, at a level.
  auto measure = [&](int levels) {
    const Subdivision sub(m, levels, options);
    const std::vector<Vec3> p = refined(sub, m.positions);
    const LevelTopology& t = sub.topology(levels);
    std::map<std::pair<uint32_t, uint32_t>, std::vector<Vec3>> edges;
    for (size_t f = 0; f < t.faceCount(); ++f) {
      const uint32_t* v = &t.faceVertices[3 * f];
      const Vec3 n = glm::normalize(glm::cross(p[v[1]] - p[v[0]], p[v[2]] - p[v[0]]));
      for (int k = 0; k < 3; ++k) edges[std::minmax(v[k], v[(k + 1) % 3])].push_back(n);
    }
    float fold = 0.0f;
    for (const auto& [e, n] : edges) fold = std::max(fold, glm::degrees(std::acos(std::clamp(glm::dot(n[0], n[1]), -1.0f, 1.0f))));
    float lo = 1e9f, hi = 0.0f, sum = 0.0f;
    for (const Vec3& v : p) lo = std::min(lo, glm::length(v)), hi = std::max(hi, glm::length(v)), sum += glm::length(v);
    return std::pair{fold, (hi - lo) / (sum / float(p.size()))};
  };
  const auto [fold0, spread0] = measure(0);
  const auto [fold2, spread2] = measure(2);
  const auto [fold4, spread4] = measure(4);
  INFO("largest fold " << fold0 << " " << fold2 << " " << fold4 << " degrees, radius spread " << spread2 << " " << spread4);
  CHECK(fold0 == Approx(41.8f).margin(0.1f));  // the icosahedron's dihedral angle, 138.2°
  CHECK(fold2 < 0.35f * fold0);  // about halved per level
  CHECK(fold4 < 0.35f * fold2);
  CHECK(spread4 < 0.02f);  // the limit surface is round to within 2% (not a sphere: Loop's is not)
}

TEST_CASE("Subdivision: a face-varying channel is linear and keeps its seams", "[organisms][subdivision]") {
  // Each cube face its own four values (a seam along every cube edge), each value the face's
  // number: linear interpolation keeps a face's number on all its children.
  ControlMesh cube = triangulatedCube();
  SubdivisionOptions options;
  options.scheme = SubdivisionScheme::Loop;
  options.creases = cubeEdges();
  std::vector<float> values;
  for (uint32_t f = 0; f < 12; ++f)
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t quad = f / 2, corner = f % 2 == 0 ? k : (k == 0 ? 0 : k + 1);  // triangles 0,1,2 and 0,2,3 of the quad
      options.faceVaryingIndices.push_back(4 * quad + corner);
    }
  options.faceVaryingCount = 24;
  for (int v = 0; v < 24; ++v) values.push_back(float(v / 4));
  const Subdivision sub(cube, 2, options);
  CHECK(sub.topology(0).faceVaryingCount == 24u);
  CHECK(sub.topology(2).faceVaryingCount == 6u * 25u);  // each face a 5 x 5 grid of its own
  for (int l = 1; l <= 2; ++l) {
    std::vector<float> fine(sub.topology(l).faceVaryingCount);
    sub.interpolate(l, Primvar::FaceVarying, values, fine, 1);
    values = std::move(fine);
  }
  const LevelTopology& fine = sub.topology(2);
  for (size_t i = 0; i < fine.faceVaryingIndices.size(); ++i) {
    const uint32_t f = uint32_t(i / 3), quad = sub.parentFace(1, sub.parentFace(2, f)) / 2;
    CHECK(values[fine.faceVaryingIndices[i]] == float(quad));
  }
  // Varying data is linear: a vertex keeps its value, an edge point (one per control edge,
  // 12 cube edges and 6 diagonals) takes its ends' mean.
  std::vector<float> x;
  for (const Vec3& p : cube.positions) x.insert(x.end(), {p.x, p.y, p.z});
  std::vector<float> x1(3 * sub.vertexCount(1));
  REQUIRE(sub.vertexCount(1) == 8u + 18u);
  sub.interpolate(1, Primvar::Varying, x, x1, 3);
  auto at = [](const std::vector<float>& v, size_t i) { return Vec3(v[3 * i], v[3 * i + 1], v[3 * i + 2]); };
  for (size_t v = 0; v < 8; ++v) CHECK(at(x1, v) == cube.positions[v]);
  std::set<std::pair<uint32_t, uint32_t>> edges;
  for (size_t f = 0; f < 12; ++f)
    for (size_t k = 0; k < 3; ++k)
      edges.insert(std::minmax(cube.faceVertices[3 * f + k], cube.faceVertices[3 * f + (k + 1) % 3]));
  std::set<std::pair<uint32_t, uint32_t>> hit;
  for (size_t v = 8; v < sub.vertexCount(1); ++v)
    for (const auto& [a, b] : edges)
      if (at(x1, v) == 0.5f * (cube.positions[a] + cube.positions[b])) hit.insert({a, b});
  CHECK(hit == edges);
}

TEST_CASE("Subdivision: Loop refuses polygons and creases that are not edges", "[organisms][subdivision]") {
  ControlMesh quad;
  quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  quad.faceSizes = {4};
  quad.faceVertices = {0, 1, 2, 3};
  SubdivisionOptions loop;
  loop.scheme = SubdivisionScheme::Loop;
  CHECK_THROWS_AS(Subdivision(quad, 1, loop), std::invalid_argument);
  SubdivisionOptions diagonal;
  diagonal.creases = {{0, 2}};
  CHECK_THROWS_WITH(Subdivision(quad, 1, diagonal), Catch::Contains("not an edge"));
  SubdivisionOptions fvar;
  fvar.faceVaryingIndices = {0, 1, 2};
  fvar.faceVaryingCount = 3;
  CHECK_THROWS_WITH(Subdivision(quad, 1, fvar), Catch::Contains("face-varying"));
}
