#include <catch2/catch.hpp>

#include <cstring>
#include <algorithm>
#include <map>
#include <set>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/mesh_clean.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "tests/blobtree/mesh_checks.h"

using namespace sprig;
using namespace sprig::blobtree;
using sprig::test::euler;
using sprig::test::requireClosedManifold;

namespace {

// Largest |F − 0.5| over the mesh vertices.
float maxFieldError(const CompiledBlob& blob, const Mesh& m) {
  float worst = 0.0f;
  for (const auto& p : m.positions) worst = std::max(worst, std::fabs(blob.value(p) - kIso));
  return worst;
}

}  // namespace

TEST_CASE("polygonize::sphere", "[blobtree]") {
  BlobTree tree;
  NodeId s = tree.point(Vec3(0.3f, -0.2f, 0.1f), 1.0f);
  CompiledBlob blob = compile(tree, s);
  PolygonizeResult r = polygonizeDetailed(blob);
  const Mesh& m = r.mesh;
  requireClosedManifold(m);
  CHECK(euler(m) == 2);

  SECTION("volume within 1% of 4/3 pi r^3 at default settings, oriented outward") {
    double exact = 4.0 / 3.0 * kPi;
    double v = signedVolume(m);
    INFO("volume " << v << " exact " << exact << " cell " << r.cellSize);
    CHECK(v > 0.0);
    CHECK(std::fabs(v - exact) / exact < 0.01);
  }
  SECTION("vertices lie on the surface, normals point out") {
    CHECK(maxFieldError(blob, m) < 1e-4f);
    for (size_t i = 0; i < m.vertexCount(); ++i) {
      Vec3 radial = m.positions[i] - Vec3(0.3f, -0.2f, 0.1f);
      CHECK(std::fabs(glm::length(radial) - 1.0f) < 1e-4f);
      CHECK(glm::dot(m.normals[i], glm::normalize(radial)) > 0.999f);
    }
  }
  SECTION("only near-surface cells are visited") {
    CHECK(r.activeCells <= r.surfaceCells);
    // A dense grid over the bounds would sample (size/cell)^3 points.
    Vec3 size = blob.bounds().size();
    double dense = double(size.x / r.cellSize) * double(size.y / r.cellSize) * double(size.z / r.cellSize);
    CHECK(double(r.gridSamples) < 0.2 * dense);
  }
}

// Grid corners on the surface to within rounding: a ball of radius 1 about the origin at a
// cell of 1/16 (the grid's corners are multiples of 1/16, so (±1, 0, 0), (0, ±1, 0) and
// (0, 0, ±1) are corners on the sphere), and two such balls united (max) that touch at the
// origin, a corner: two sheets meet in one grid point, within the cells around it. The root
// search put the vertices of every grid edge from such a corner onto the corner, distinct
// vertices at one position; welded by position (as viewers, slicers and the simplifier
// weld) they pinched the surface: degenerate triangles and edges of four triangles. Such
// vertices now move 16 float spacings out along their edges, so no two share a position and
// the welded mesh is the closed, consistently oriented 2-manifold marching tetrahedra made.
TEST_CASE("polygonize: a surface through grid corners welds by position to a closed 2-manifold", "[blobtree]") {
  PolygonizeOptions options;
  options.cellSize = 1.0f / 16.0f;
  auto check = [&](const CompiledBlob& blob, long eulerWanted) {
    const PolygonizeResult r = polygonizeDetailed(blob, options);
    REQUIRE(r.cellSize == options.cellSize);
    CHECK(r.separatedVertices > 0);  // the configuration has vertices at one position
    requireClosedManifold(r.mesh);
    const Mesh welded = test::weldByPosition(r.mesh);
    CHECK(welded.vertexCount() == r.mesh.vertexCount());  // no two vertices share a position
    requireClosedManifold(welded);
    CHECK(euler(welded) == eulerWanted);
    CHECK(maxFieldError(blob, r.mesh) < 1e-4f);
  };
  SECTION("a ball through six corners") {
    BlobTree tree;
    check(compile(tree, tree.point(Vec3(0.0f), 1.0f)), 2);
  }
  SECTION("two balls touching at a corner") {
    BlobTree tree;
    const NodeId balls[] = {tree.point(Vec3(-1.0f, 0.0f, 0.0f), 1.0f), tree.point(Vec3(1.0f, 0.0f, 0.0f), 1.0f)};
    check(compile(tree, tree.unite(balls)), 4);
  }
}

TEST_CASE("polygonize::capsule", "[blobtree]") {
  BlobTree tree;
  float radius = 0.5f, length = 2.0f;
  NodeId c = tree.segment(Vec3(0, 0, 0), Vec3(0, length, 0), radius);
  CompiledBlob blob = compile(tree, c);
  Mesh m = polygonize(blob);
  requireClosedManifold(m);
  CHECK(euler(m) == 2);
  double exact = kPi * radius * radius * length + 4.0 / 3.0 * kPi * radius * radius * radius;
  double v = signedVolume(m);
  INFO("volume " << v << " exact " << exact);
  CHECK(std::fabs(v - exact) / exact < 0.01);
  CHECK(maxFieldError(blob, m) < 1e-4f);
}

TEST_CASE("polygonize::topology", "[blobtree]") {
  SECTION("a torus has genus 1") {
    BlobTree tree;
    NodeId t = tree.torus(Vec3(0), glm::normalize(Vec3(0.2f, 1, 0.1f)), 1.0f, 0.3f);
    Mesh m = polygonize(compile(tree, t));
    requireClosedManifold(m);
    CHECK(euler(m) == 0);
    double exact = 2.0 * kPi * kPi * 1.0 * 0.3 * 0.3;
    CHECK(signedVolume(m) == Approx(exact).epsilon(0.01));
  }
  SECTION("two separate spheres give two closed components") {
    BlobTree tree;
    std::vector<NodeId> kids = {tree.point(Vec3(-2, 0, 0), 0.5f), tree.point(Vec3(2, 0, 0), 0.5f)};
    Mesh m = polygonize(compile(tree, tree.blend(kids)));
    requireClosedManifold(m);
    CHECK(euler(m) == 4);
  }
  SECTION("CSG with a box cutter stays closed and manifold") {
    BlobTree tree;
    NodeId ball = tree.point(Vec3(0), 1.0f);
    NodeId cut = tree.box(Vec3(0, 0, 0), Vec3(2, 2, 2));
    Mesh m = polygonize(compile(tree, tree.difference(ball, cut)));
    requireClosedManifold(m);
    CHECK(euler(m) == 2);
    double exact = 7.0 / 8.0 * 4.0 / 3.0 * kPi;
    CHECK(signedVolume(m) == Approx(exact).epsilon(0.02));
  }
  SECTION("an empty blob gives an empty mesh") {
    CompiledBlob empty;
    CHECK(polygonize(empty).triangleCount() == 0);
  }
}

TEST_CASE("polygonize::thin twig survives", "[blobtree]") {
  // A twig of radius 0.01 reaching across a model of size 10, on a small knob.
  BlobTree tree;
  std::vector<NodeId> kids = {tree.point(Vec3(0), 0.05f), tree.segment(Vec3(0), Vec3(9.8f, 0, 0), 0.01f)};
  CompiledBlob blob = compile(tree, tree.blend(kids));
  PolygonizeResult r = polygonizeDetailed(blob);
  const Mesh& m = r.mesh;
  INFO("cell " << r.cellSize << " triangles " << m.triangleCount());
  CHECK(r.cellSize <= 0.005f);
  requireClosedManifold(m);
  CHECK(euler(m) == 2);  // one piece: the twig is not broken anywhere
  CHECK(m.bounds().hi.x == Approx(9.81f).margin(2e-3));
  // Along its whole length the twig's cross-section radius stays close to 0.01.
  for (const auto& p : m.positions)
    if (p.x > 1.0f && p.x < 9.7f) CHECK(std::hypot(p.y, p.z) == Approx(0.01f).margin(1e-3));
}

TEST_CASE("polygonize::deterministic", "[blobtree]") {
  Rng rng(deriveSeed(1234, {7}));
  BlobTree tree;
  std::vector<NodeId> kids;
  Vec3 at(0);
  for (int i = 0; i < 40; ++i) {
    Vec3 next = at + Vec3(rng.uniform(-0.5f, 0.5f), rng.uniform(0.2f, 0.6f), rng.uniform(-0.5f, 0.5f));
    kids.push_back(tree.cone(at, next, rng.uniform(0.08f, 0.15f), rng.uniform(0.05f, 0.08f)));
    at = i % 10 == 9 ? Vec3(rng.uniform(-1.0f, 1.0f), 0, rng.uniform(-1.0f, 1.0f)) : next;
  }
  CompiledBlob blob = compile(tree, tree.blend(kids));
  PolygonizeOptions opt;
  opt.cellSize = 0.04f;
  CHECK(polygonizeDetailed(blob, opt).cellSize == 0.04f);  // cells of exactly the requested edge
  Mesh one, two;
  {
    ThreadLimit limit(1);
    one = polygonize(blob, opt);
  }
  {
    ThreadLimit limit(2);
    two = polygonize(blob, opt);
  }
  REQUIRE(one.vertexCount() == two.vertexCount());
  REQUIRE(one.triangleCount() == two.triangleCount());
  CHECK(std::memcmp(one.positions.data(), two.positions.data(), one.vertexCount() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(one.normals.data(), two.normals.data(), one.vertexCount() * sizeof(Vec3)) == 0);
  CHECK(std::memcmp(one.triangles.data(), two.triangles.data(), one.triangleCount() * sizeof(glm::uvec3)) == 0);
  requireClosedManifold(one);
  CHECK(signedVolume(one) > 0.0);
}

TEST_CASE("polygonize::automatic cell size keeps thin limbs whole", "[blobtree]") {
  // A sphere of radius 0.5 with a twig: a cylinder of radius 0.02 leaving it along an
  // oblique axis, then a cone tapering from 0.02 to 0.005. The smallest feature is the
  // cone's tip (0.005); the thinnest limb is the cylinder (and the cone's thick end), 0.02.
  BlobTree tree;
  const Vec3 d = glm::normalize(Vec3(1.0f, 1.3f, 0.7f));
  std::vector<NodeId> kids = {tree.point(Vec3(0), 0.5f), tree.segment(0.4f * d, 1.4f * d, 0.02f),
                              tree.cone(1.4f * d, 1.7f * d, 0.02f, 0.005f)};
  CompiledBlob blob = compile(tree, tree.blend(kids));
  CHECK(blob.smallestFeature() == Approx(0.005f));
  CHECK(blob.thinnestLimb() == Approx(0.02f));
  const float diag = glm::length(blob.bounds().size());
  PolygonizeOptions opt;
  opt.maxDivisions = 80.0f;  // a floor of diag / 80, over twice the twig's radius
  opt.limbMaxDivisions = 1000.0f;
  REQUIRE(diag / 80.0f > 2.0f * 0.02f);
  REQUIRE(diag / 1000.0f < 0.02f);
  REQUIRE(diag / 150.0f > 1.1f * 0.02f);
  // How far along d the mesh reaches, and its pieces.
  auto measure = [&](const Mesh& m) {
    float reach = 0.0f;
    for (const Vec3& p : m.positions) reach = std::max(reach, glm::dot(p, d));
    size_t pieces = 0;
    triangleComponents(m, &pieces);
    return std::pair<float, size_t>(reach, pieces);
  };
  // The limb term lowers the floor to 1.1 x the limb's radius: one piece reaching the
  // cylinder's end.
  CHECK(resolveCellSize(blob, opt) == Approx(1.1f * 0.02f));
  const auto [reach, pieces] = measure(polygonize(blob, opt));
  CHECK(pieces == 1);
  CHECK(reach > 1.4f);
  // Without it the twig at diag / 80 falls apart or is lost short of its end.
  opt.limbFraction = 0.0f;
  CHECK(resolveCellSize(blob, opt) == Approx(diag / 80.0f));
  const auto [reachOld, piecesOld] = measure(polygonize(blob, opt));
  CHECK((piecesOld > 1 || reachOld < 1.2f));
  // limbMaxDivisions bounds the limb term: a limb that would need cells finer than
  // diag / limbMaxDivisions leaves the floor alone.
  opt.limbFraction = 1.1f;
  opt.limbMaxDivisions = 150.0f;
  CHECK(resolveCellSize(blob, opt) == Approx(diag / 80.0f));
  opt.limbMaxDivisions = 1000.0f;
  opt.limbFraction = 1.5f;
  CHECK(resolveCellSize(blob, opt) == Approx(1.5f * 0.02f));
}

TEST_CASE("polygonize::automatic cell size bounds", "[blobtree]") {
  // A sphere of radius 1 with a speck of radius 0.01: the feature rule asks for 0.005.
  BlobTree tree;
  std::vector<NodeId> kids = {tree.point(Vec3(0), 1.0f), tree.point(Vec3(1.5f, 0, 0), 0.01f)};
  CompiledBlob blob = compile(tree, tree.blend(kids));
  const float diag = glm::length(blob.bounds().size());
  PolygonizeOptions opt;
  opt.maxDivisions = 100.0f;  // the floor binds: diag / 100 is about 0.03
  opt.limbFraction = 0.0f;    // (the speck is a whole primitive: the limb term would resolve it)
  PolygonizeResult r = polygonizeDetailed(blob, opt);
  CHECK(r.cellSize == Approx(diag / 100.0f).epsilon(1e-6));
  CHECK(r.mesh.triangleCount() > 0);
  opt.cellSize = 0.02f;  // an explicit cell is never clamped
  CHECK(polygonizeDetailed(blob, opt).cellSize == 0.02f);
  opt.cellSize = 0.0f;
  opt.maxDivisions = 0.0f;  // no floor: half the smallest radius
  CHECK(resolveCellSize(blob, opt) == Approx(0.005f));
  CHECK(resolveCellSize(blob) == Approx(0.005f));  // the default floor (diag / 2500) is finer
}

// PolygonizeOptions::vertexData keeps per vertex what the caller asks for and changes
// nothing else: the same positions, normals and triangles; uvs with Uvs and Blend (the
// same ones); the blended attributes only with Blend, their uv the vertex's.
TEST_CASE("polygonizeDetailed: vertexData decides what each vertex keeps, and only that", "[blobtree]") {
  BlobTree tree;
  TextureAttr bark;
  bark.textureId = 3;
  const std::vector<NodeId> parts{tree.cone(Vec3(0), Vec3(0, 2, 0), 0.4f, 0.25f, bark), tree.point(Vec3(0.3f, 1.0f, 0), 0.5f)};
  CompiledBlob blob = compile(tree, tree.blend(parts));
  using VertexData = PolygonizeOptions::VertexData;
  for (auto mesher : {PolygonizeOptions::Mesher::MarchingTetrahedra, PolygonizeOptions::Mesher::DualMarchingCubes}) {
    INFO("dual " << (mesher == PolygonizeOptions::Mesher::DualMarchingCubes));
    PolygonizeOptions o;
    o.mesher = mesher;
    o.cellSize = 0.05f;
    std::map<VertexData, PolygonizeResult> r;
    for (VertexData d : {VertexData::None, VertexData::Uvs, VertexData::Blend}) {
      o.vertexData = d;
      r[d] = polygonizeDetailed(blob, o);
    }
    const Mesh& m = r[VertexData::Blend].mesh;
    REQUIRE(m.vertexCount() > 1000);
    CHECK(PolygonizeOptions{}.vertexData == VertexData::Uvs);
    for (VertexData d : {VertexData::None, VertexData::Uvs}) {
      CHECK(r[d].mesh.positions == m.positions);
      CHECK(r[d].mesh.normals == m.normals);
      CHECK(r[d].mesh.triangles == m.triangles);
    }
    CHECK(r[VertexData::None].mesh.uvs.empty());
    CHECK(r[VertexData::Uvs].mesh.uvs == m.uvs);
    REQUIRE(m.uvs.size() == m.vertexCount());
    CHECK(r[VertexData::None].attributes.empty());
    CHECK(r[VertexData::Uvs].attributes.empty());
    const std::vector<Attributes>& a = r[VertexData::Blend].attributes;
    REQUIRE(a.size() == m.vertexCount());
    size_t textured = 0;
    for (size_t v = 0; v < a.size(); ++v) {
      CHECK(a[v].uv == m.uvs[v]);
      textured += a[v].textureCount > 0 && a[v].textureIds[0] == 3;
    }
    CHECK(textured > a.size() / 4);  // the cone's texture reaches the vertices on the cone
  }
}
