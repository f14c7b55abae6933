// Dual marching cubes (PolygonizeOptions::Mesher::DualMarchingCubes): the patches of single
// cells, then whole meshes against the marching-tetrahedra reference.
#include <catch2/catch.hpp>

#include <cstring>
#include <set>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/detail/dual_patches.h"
#include "blobtree/polygonize.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "tests/blobtree/mesh_checks.h"

using namespace sprig;
using namespace sprig::blobtree;
using sprig::test::euler;
using sprig::test::requireClosedManifold;

namespace {

PolygonizeOptions dual(float cell = 0.0f) {
  PolygonizeOptions o;
  o.mesher = PolygonizeOptions::Mesher::DualMarchingCubes;
  o.cellSize = cell;
  return o;
}

// Corner values +v inside / -1 outside from a mask.
detail::CellPatches patchesOf(unsigned mask, float v = 1.0f) {
  float f[8];
  for (int c = 0; c < 8; ++c) f[c] = (mask >> c) & 1 ? v : -1.0f;
  return detail::cellPatches(f);
}

int crossingEdges(unsigned mask) {
  int n = 0;
  for (int e = 0; e < 12; ++e) {
    int a = detail::lowCorner(e), b = a | (1 << detail::edgeAxis(e));
    n += ((mask >> a) & 1) != ((mask >> b) & 1);
  }
  return n;
}

}  // namespace

TEST_CASE("dual mesher: the patches of one cell", "[blobtree]") {
  SECTION("edge numbering: every edge joins two corners one axis apart, each edge once") {
    std::set<std::pair<int, int>> seen;
    for (int e = 0; e < 12; ++e) {
      int a = detail::lowCorner(e), b = a | (1 << detail::edgeAxis(e));
      CHECK((a & (1 << detail::edgeAxis(e))) == 0);
      CHECK(detail::edgeOf(a, b) == e);
      CHECK(detail::edgeOf(b, a) == e);
      seen.insert({a, b});
    }
    CHECK(seen.size() == 12);
  }
  SECTION("every crossing edge is in exactly one patch, no other edge is") {
    for (unsigned m = 0; m < 256; ++m)
      for (float v : {1.0f, 3.0f}) {
        detail::CellPatches p = patchesOf(m, v);
        int n = 0;
        for (int e = 0; e < 12; ++e) {
          int a = detail::lowCorner(e), b = a | (1 << detail::edgeAxis(e));
          bool x = ((m >> a) & 1) != ((m >> b) & 1);
          CHECK((p.patch[size_t(e)] >= 0) == x);
          if (x) CHECK(p.patch[size_t(e)] < p.count);
          n += x;
        }
        CHECK(n == crossingEdges(m));
        CHECK((p.count == 0) == (m == 0 || m == 255));
      }
  }
  SECTION("the marching-cubes cases") {
    CHECK(patchesOf(0x01).count == 1);  // one corner: a triangle
    CHECK(patchesOf(0x03).count == 1);  // one edge: a quad
    CHECK(patchesOf(0x0f).count == 1);  // one face: a plane
    CHECK(patchesOf(0x81).count == 2);  // opposite corners of the cube: two triangles
    // Corners 0 and 3 are diagonal on the face z = 0. With values +1/-1 the face's saddle
    // is 0 (outside): the inside corners stay apart, two patches. With +3 inside the
    // saddle is (9 - 1) / (6 + 2) = 1 > 0: one band of six edges around the joined corners.
    CHECK(patchesOf(0x09, 1.0f).count == 2);
    detail::CellPatches joined = patchesOf(0x09, 3.0f);
    CHECK(joined.count == 1);
    int band = 0;
    for (int e = 0; e < 12; ++e) band += joined.patch[size_t(e)] == 0;
    CHECK(band == 6);
    // Inside corners 0, 3, 5, 6 (every face ambiguous, every saddle 0): four corner triangles.
    CHECK(patchesOf(0x69).count == 4);
  }
}

TEST_CASE("dual mesher: a face whose diagonal corners both cells join is decided by them", "[blobtree]") {
  // Cell A below, B above, sharing A's top face z = 1 (corners 4 5 6 7 of A, 0 1 2 3 of B).
  // Its inside corners 4 and 7 (A's codes) are diagonal, and joined through A (4-0-1-3-7)
  // and through B (0-4-5-7-3 in B's codes). With values +1/-1 the saddle is 0 and the
  // decider would separate them: A's one patch and B's one patch would then share both
  // segments of the face, an edge of four quads. The decision joins them instead.
  float fA[8], fB[8];
  for (int c = 0; c < 8; ++c) {
    fA[c] = (c == 0 || c == 1 || c == 3 || c == 4 || c == 7) ? 1.0f : -1.0f;
    fB[c] = (c == 0 || c == 3 || c == 4 || c == 5 || c == 7) ? 1.0f : -1.0f;
  }
  CHECK(detail::cornersJoined(fA, 4, 7, true));
  CHECK(detail::cornersJoined(fB, 0, 3, true));
  CHECK_FALSE(detail::cornersJoined(fA, 5, 6, false));
  CHECK(detail::forcedFaceDecision(fA, fB, 2, 1) == 1);
  CHECK(detail::forcedFaceDecision(fB, fA, 2, 0) == 1);  // both cells take the same decision
  // Undecided, A's patch holds both segments of the face (around 4 and around 7).
  detail::CellPatches loose = detail::cellPatches(fA);
  CHECK(loose.patch[size_t(detail::edgeOf(4, 5))] == loose.patch[size_t(detail::edgeOf(6, 7))]);
  // Only B joined: nothing is forced.
  fB[5] = -1.0f;
  CHECK(detail::forcedFaceDecision(fA, fB, 2, 1) == -1);
}

TEST_CASE("dual mesher: closed 2-manifold meshes, a third of the triangles", "[blobtree]") {
  SECTION("sphere: genus 0, volume within 1%, vertices on the surface, fewer triangles") {
    BlobTree tree;
    CompiledBlob blob = compile(tree, tree.point(Vec3(0.3f, -0.2f, 0.1f), 1.0f));
    PolygonizeResult d = polygonizeDetailed(blob, dual());
    PolygonizeResult t = polygonizeDetailed(blob);
    requireClosedManifold(d.mesh);
    CHECK(euler(d.mesh) == 2);
    double exact = 4.0 / 3.0 * kPi;
    CHECK(signedVolume(d.mesh) == Approx(exact).epsilon(0.01));
    INFO("dual " << d.mesh.triangleCount() << " tets " << t.mesh.triangleCount());
    CHECK(d.mesh.triangleCount() < t.mesh.triangleCount() / 2);
    float worst = 0.0f;
    for (const auto& p : d.mesh.positions) worst = std::max(worst, std::fabs(glm::length(p - Vec3(0.3f, -0.2f, 0.1f)) - 1.0f));
    CHECK(worst < 1e-3f);
    for (size_t i = 0; i < d.mesh.vertexCount(); ++i)
      CHECK(glm::dot(d.mesh.normals[i], glm::normalize(d.mesh.positions[i] - Vec3(0.3f, -0.2f, 0.1f))) > 0.99f);
  }
  SECTION("torus: genus 1") {
    BlobTree tree;
    Mesh m = polygonize(compile(tree, tree.torus(Vec3(0), glm::normalize(Vec3(0.2f, 1, 0.1f)), 1.0f, 0.3f)), dual());
    requireClosedManifold(m);
    CHECK(euler(m) == 0);
    CHECK(signedVolume(m) == Approx(2.0 * kPi * kPi * 0.3 * 0.3).epsilon(0.01));
  }
  SECTION("two spheres: two components; a cut ball stays closed") {
    BlobTree tree;
    std::vector<NodeId> kids = {tree.point(Vec3(-2, 0, 0), 0.5f), tree.point(Vec3(2, 0, 0), 0.5f)};
    Mesh two = polygonize(compile(tree, tree.blend(kids)), dual());
    requireClosedManifold(two);
    CHECK(euler(two) == 4);
    BlobTree t2;
    Mesh cut = polygonize(compile(t2, t2.difference(t2.point(Vec3(0), 1.0f), t2.box(Vec3(0), Vec3(2, 2, 2)))), dual());
    requireClosedManifold(cut);
    CHECK(euler(cut) == 2);
    CHECK(signedVolume(cut) == Approx(7.0 / 8.0 * 4.0 / 3.0 * kPi).epsilon(0.03));
  }
}

TEST_CASE("dual mesher: a branching blend of cones, deterministic at any thread count", "[blobtree]") {
  Rng rng(deriveSeed(1234, {7}));
  BlobTree tree;
  std::vector<NodeId> kids;
  Vec3 at(0);
  for (int i = 0; i < 60; ++i) {
    Vec3 next = at + Vec3(rng.uniform(-0.5f, 0.5f), rng.uniform(0.2f, 0.6f), rng.uniform(-0.5f, 0.5f));
    kids.push_back(tree.cone(at, next, rng.uniform(0.08f, 0.15f), rng.uniform(0.03f, 0.08f)));
    at = i % 10 == 9 ? Vec3(rng.uniform(-1.0f, 1.0f), 0, rng.uniform(-1.0f, 1.0f)) : next;
  }
  CompiledBlob blob = compile(tree, tree.blend(kids));
  Mesh one, two;
  {
    ThreadLimit limit(1);
    one = polygonize(blob, dual(0.02f));
  }
  {
    ThreadLimit limit(2);
    two = polygonize(blob, dual(0.02f));
  }
  REQUIRE(one.vertexCount() == two.vertexCount());
  REQUIRE(one.triangleCount() == two.triangleCount());
  CHECK(std::memcmp(one.positions.data(), two.positions.data(), one.vertexCount() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(one.triangles.data(), two.triangles.data(), one.triangleCount() * sizeof(glm::uvec3)) == 0);
  REQUIRE(one.normals.size() == one.vertexCount());
  REQUIRE(two.normals.size() == one.vertexCount());
  REQUIRE(one.uvs.size() == one.vertexCount());
  REQUIRE(two.uvs.size() == one.vertexCount());
  CHECK(std::memcmp(one.normals.data(), two.normals.data(), one.vertexCount() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(one.uvs.data(), two.uvs.data(), one.vertexCount() * sizeof(Vec2)) == 0);
  requireClosedManifold(one);
  PolygonizeOptions ref;
  ref.cellSize = 0.02f;
  Mesh tets = polygonize(blob, ref);
  INFO("dual " << one.triangleCount() << " tets " << tets.triangleCount());
  CHECK(euler(one) == euler(tets));
  CHECK(signedVolume(one) == Approx(signedVolume(tets)).epsilon(0.01));
  CHECK(one.triangleCount() < tets.triangleCount() / 2);
  // The patch vertices start from the mean of linearly interpolated edge crossings and are
  // moved onto F = 0.5 by Newton steps kept inside their cell: nearly all land there.
  std::vector<float> f(one.vertexCount());
  blob.values(one.positions, f);
  size_t off = 0;
  float worst = 0;
  for (float v : f) {
    off += std::fabs(v - 0.5f) > 1e-3f;
    worst = std::max(worst, std::fabs(v - 0.5f));
  }
  INFO("vertices off the surface by more than 1e-3 in F: " << off << " of " << f.size() << ", worst " << std::to_string(worst));
  CHECK(off * 200 < f.size());
  CHECK(worst < 0.05f);
}

TEST_CASE("dual mesher: batched Newton steps place the vertices of the scalar path", "[blobtree]") {
  // PolygonizeOptions::batchedNewton takes the scalar path's steps with F and ∇F from the
  // batched evaluator, equal to sample()'s up to the rounding of sums in a different child
  // order: the same mesh, vertices within 1e-4 of the cell (a step differing by rounding
  // near a clamp or a kink can end a few ulps elsewhere), exactly the same triangles.
  Rng rng(deriveSeed(1234, {19}));
  BlobTree tree;
  std::vector<NodeId> kids;
  Vec3 at(0);
  for (int i = 0; i < 40; ++i) {
    Vec3 next = at + Vec3(rng.uniform(-0.5f, 0.5f), rng.uniform(0.2f, 0.6f), rng.uniform(-0.5f, 0.5f));
    kids.push_back(tree.cone(at, next, rng.uniform(0.08f, 0.15f), rng.uniform(0.03f, 0.08f)));
    at = i % 10 == 9 ? Vec3(rng.uniform(-1.0f, 1.0f), 0, rng.uniform(-1.0f, 1.0f)) : next;
  }
  // A PCM contact and a bent, cut limb: the batched evaluator's other operators on the way.
  NodeId contact = tree.pcm(tree.point(Vec3(2, 0.5f, 0), 0.5f), tree.point(Vec3(2.6f, 0.5f, 0), 0.45f));
  NodeId bent = tree.bend(tree.segment(Vec3(-1, -1, 1), Vec3(1, -1, 1), 0.2f), Vec3(-1, -1, 1), Vec3(1, -1, 1), 0.4f, Vec3(0, 1, 0));
  kids.push_back(contact);
  kids.push_back(tree.difference(bent, tree.box(Vec3(0.5f, -2, 0), Vec3(2, 0, 2))));
  CompiledBlob blob = compile(tree, tree.blend(kids));
  const float cell = 0.03f;
  using VertexData = PolygonizeOptions::VertexData;
  for (VertexData data : {VertexData::Blend, VertexData::None}) {
    const bool attributes = data == VertexData::Blend;
    INFO("attributes " << attributes);
    PolygonizeOptions scalarOpt = dual(cell), batchedOpt = dual(cell);
    scalarOpt.batchedNewton = false;
    scalarOpt.vertexData = batchedOpt.vertexData = data;
    PolygonizeResult s = polygonizeDetailed(blob, scalarOpt), b = polygonizeDetailed(blob, batchedOpt);
    REQUIRE(s.mesh.vertexCount() == b.mesh.vertexCount());
    REQUIRE(s.mesh.triangleCount() == b.mesh.triangleCount());
    REQUIRE(b.mesh.vertexCount() > 10000);
    requireClosedManifold(b.mesh);
    float worst = 0.0f, worstNormal = 0.0f;
    size_t moved = 0;
    for (size_t i = 0; i < b.mesh.vertexCount(); ++i) {
      float d = glm::length(b.mesh.positions[i] - s.mesh.positions[i]);
      worst = std::max(worst, d);
      moved += d > 0.0f;
      worstNormal = std::max(worstNormal, glm::length(b.mesh.normals[i] - s.mesh.normals[i]));
    }
    INFO("vertices not bit-identical " << moved << " of " << b.mesh.vertexCount() << ", worst " << worst
                                       << ", worst normal difference " << worstNormal);
    CHECK(worst <= 1e-4f * cell);
    CHECK(worstNormal <= 1e-3f);
    // Triangles: the same quads split along the same diagonals except where the two
    // diagonals are equal to rounding (none in practice).
    size_t sameTriangles = 0;
    for (size_t i = 0; i < b.mesh.triangleCount(); ++i) sameTriangles += b.mesh.triangles[i] == s.mesh.triangles[i];
    CHECK(sameTriangles + 8 >= b.mesh.triangleCount());
    if (attributes) {
      REQUIRE(b.attributes.size() == s.attributes.size());
      for (size_t i = 0; i < b.mesh.vertexCount(); i += 97) CHECK(glm::length(b.mesh.uvs[i] - s.mesh.uvs[i]) <= 1e-3f);
    }
  }
}
