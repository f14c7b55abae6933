#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"
#include "core/rng.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/render/test_scenes.h"
#include "textures/registry.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;

namespace {

/// A small branch: a trunk cone, two side cones blended in, and a bud.
blobtree::CompiledBlob branchBlob() {
  blobtree::BlobTree t;
  std::vector<blobtree::NodeId> parts;
  parts.push_back(t.cone(Vec3(0, 0, 0), Vec3(0, 1.2f, 0), 0.16f, 0.11f));
  parts.push_back(t.cone(Vec3(0, 1.2f, 0), Vec3(0.5f, 1.8f, 0.1f), 0.10f, 0.06f));
  parts.push_back(t.cone(Vec3(0, 1.2f, 0), Vec3(-0.3f, 2.0f, -0.2f), 0.09f, 0.05f));
  parts.push_back(t.point(Vec3(0.5f, 1.8f, 0.1f), 0.1f));
  return blobtree::compile(t, t.blend(parts));
}

/// A ray from 4 units away in a random direction toward a random point of box.
std::pair<Vec3, Vec3> rayIntoBox(Rng& rng, const Box3& box) {
  const Vec3 target = box.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * box.size();
  const Vec3 origin = target + 4.0f * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
  return {origin, glm::normalize(target - origin)};
}

}  // namespace

TEST_CASE("Scene::addImplicit", "[render]") {
  blobtree::BlobTree t;
  auto sphere = t.point(Vec3(0), 1.0f);
  blobtree::CompiledBlob blob = blobtree::compile(t, sphere);
  Scene scene;
  uint32_t id = scene.addImplicit(blob, scene.addMaterial(Material{}));
  scene.commit();
  CHECK(scene.stats().implicitCells > 0);
  // Bounds hug the surface (cells reach up to a cell beyond it; intervals shrink them).
  CHECK(scene.bounds().lo.x == Approx(-1.0f).margin(0.03));
  CHECK(scene.bounds().hi.y == Approx(1.0f).margin(0.03));
  CHECK(scene.bounds().lo.x <= -1.0f);
  CHECK(scene.bounds().hi.z >= 1.0f);

  SECTION("exact hits on the sphere") {
    for (Vec3 dir : {Vec3(0, 0, -1), glm::normalize(Vec3(-1, -0.5f, -2))}) {
      Vec3 origin = -6.0f * dir;
      auto hit = scene.intersect(origin, dir, 0, 100);
      REQUIRE(hit);
      CHECK(hit->geometry == id);
      CHECK(hit->t == Approx(5.0).margin(1e-4));
      CHECK(glm::length(hit->position) == Approx(1.0).margin(1e-4));
      CHECK(glm::dot(hit->normal, -dir) == Approx(1.0).margin(1e-3));
    }
    CHECK(scene.occluded(Vec3(0, 0, 6), Vec3(0, 0, -1), 0, 100));
    CHECK_FALSE(scene.occluded(Vec3(0, 0, 6), Vec3(0, 0, -1), 0, 4.9f));
    CHECK_FALSE(scene.occluded(Vec3(1.05f, 0, 6), Vec3(0, 0, -1), 0, 100));
  }
  SECTION("silhouette matches the analytic projection") {
    // Radius R at distance D projects to a disc of radius (H/2) tan(asin(R/D)) / tan(fov/2).
    Camera cam = orbitCamera(Vec3(0), 20, 10, 6.0, 30.0);
    Image img = renderImage(scene, cam, silhouetteSettings(200, 200, 16));
    double area = alphaArea(img);
    double expected = 100.0 * std::tan(std::asin(1.0 / 6.0)) / std::tan(radians(15.0));
    CHECK(std::sqrt(area / kPi) == Approx(expected).margin(0.25));
    // Per pixel: the silhouette is the analytic circle (centered: the camera looks at the
    // sphere). The separable tent filter reads samples up to one pixel away on each axis (a
    // square footprint, √2 on the diagonal), so pixels whose centers lie more than that
    // inside the circle are fully covered and those more than that outside are empty.
    const double reach = std::sqrt(2.0);
    int edge = 0;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x) {
        double d = std::hypot(x + 0.5 - 100.0, y + 0.5 - 100.0);
        float a = img.at(x, y).a;
        if (d < expected - reach) CHECK(a > 0.9999f);
        else if (d > expected + reach) CHECK(a < 1e-4f);
        else edge += a > 0.0f && a < 1.0f;
      }
    CHECK(edge > 100);  // the antialiased rim lies in that band
  }
}

// A polygonized part painted by textures needs its vertices' attributes; a mesh without
// them is refused rather than drawn in the base colour.
TEST_CASE("Scene::addPolygonized: textures without the vertices' attributes are an error", "[render]") {
  blobtree::CompiledBlob blob = branchBlob();
  blobtree::PolygonizeOptions po;
  po.cellSize = 0.05f;
  const blobtree::PolygonizeResult plain = blobtree::polygonizeDetailed(blob, po);
  po.vertexData = blobtree::PolygonizeOptions::VertexData::Blend;
  const blobtree::PolygonizeResult blended = blobtree::polygonizeDetailed(blob, po);
  REQUIRE(plain.attributes.empty());
  Scene untextured, textured;
  CHECK_NOTHROW(untextured.addPolygonized(plain, untextured.addMaterial(Material{})));
  textured.addTexture([](Vec2, const Vec3&) { return Vec3(1, 0, 0); });
  const uint32_t m = textured.addMaterial(Material{});
  CHECK_THROWS_AS(textured.addPolygonized(plain, m), std::invalid_argument);
  CHECK_NOTHROW(textured.addPolygonized(blended, m));
}

TEST_CASE("render::exact and mesh modes agree", "[render]") {
  blobtree::CompiledBlob blob = branchBlob();
  blobtree::PolygonizeOptions po;
  po.cellSize = 0.01f;
  blobtree::PolygonizeResult poly = blobtree::polygonizeDetailed(blob, po);
  REQUIRE(poly.mesh.triangleCount() > 1000);

  Scene exact, mesh;
  exact.addImplicit(blob, exact.addMaterial(Material{}));
  mesh.addPolygonized(poly, mesh.addMaterial(Material{}));
  exact.commit();
  mesh.commit();
  Camera cam = frameBounds(exact.bounds(), ViewSpec{}, 1.0);
  RenderSettings rs = quietSettings(120, 120);
  rs.background = Background::Transparent;
  rs.ground = false;
  Image a = renderImage(exact, cam, rs);
  Image b = renderImage(mesh, cam, rs);

  // Interior pixels: fully covered in both images over the whole 3x3 neighbourhood.
  auto covered = [&](int x, int y) {
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        int u = std::clamp(x + dx, 0, 119), v = std::clamp(y + dy, 0, 119);
        if (a.at(u, v).a < 1.0f || b.at(u, v).a < 1.0f) return false;
      }
    return true;
  };
  int interior = 0, large = 0;
  double sum = 0;
  for (int y = 0; y < 120; ++y)
    for (int x = 0; x < 120; ++x) {
      if (!covered(x, y)) continue;
      Vec4 d = glm::abs(a.at(x, y) - b.at(x, y));
      float m = std::max({d.r, d.g, d.b});
      sum += m;
      large += m > 0.05f;
      ++interior;
    }
  REQUIRE(interior > 500);
  CHECK(sum / interior < 0.01);
  CHECK(large < interior / 50);
  // Coverage agrees too: total alpha within 2%.
  double ca = 0, cb = 0;
  for (size_t i = 3; i < a.pixels.size(); i += 4) {
    ca += a.pixels[i];
    cb += b.pixels[i];
  }
  CHECK(ca == Approx(cb).epsilon(0.02));
}

TEST_CASE("render::blended textures", "[render]") {
  // Two blended spheres with different textures: the color varies continuously through the
  // neck, a field-weighted mix of the two.
  blobtree::BlobTree t;
  blobtree::TextureAttr red, blue;
  red.textureId = 0;
  blue.textureId = 1;
  std::vector<blobtree::NodeId> parts{t.point(Vec3(-0.6f, 0, 0), 0.6f, red), t.point(Vec3(0.6f, 0, 0), 0.6f, blue)};
  blobtree::CompiledBlob blob = blobtree::compile(t, t.blend(parts));
  Scene scene;
  scene.addTexture([](Vec2, const Vec3&) { return Vec3(1, 0, 0); });
  scene.addTexture([](Vec2, const Vec3&) { return Vec3(0, 0, 1); });
  scene.addImplicit(blob, scene.addMaterial(Material{}));
  scene.commit();
  float previous = -1;
  for (int i = 0; i <= 20; ++i) {
    float x = -1.0f + 0.1f * static_cast<float>(i);
    auto hit = scene.intersect(Vec3(x, 0, 5), Vec3(0, 0, -1), 0, 100);
    REQUIRE(hit);
    CHECK(hit->color.r + hit->color.b == Approx(1.0f).margin(1e-4));
    CHECK(hit->color.b >= previous - 1e-4f);  // monotone from red to blue
    if (i > 0) CHECK(hit->color.b - previous < 0.35f);  // no jump
    previous = hit->color.b;
  }
  auto mid = scene.intersect(Vec3(0, 0, 5), Vec3(0, 0, -1), 0, 100);
  REQUIRE(mid);
  CHECK(mid->color.r == Approx(0.5f).margin(0.01));
}

TEST_CASE("render::exact mode determinism", "[render]") {
  Scene scene;
  scene.addImplicit(branchBlob(), scene.addMaterial(Material{}));
  scene.commit();
  Camera cam = frameBounds(scene.bounds(), ViewSpec{}, 1.0);
  RenderSettings rs = quietSettings(64, 64);
  rs.threads = 2;
  Image a = renderImage(scene, cam, rs);
  Image again = renderImage(scene, cam, rs);
  rs.threads = 1;
  Image b = renderImage(scene, cam, rs);
  CHECK(a.pixels == again.pixels);
  CHECK(a.pixels == b.pixels);
  // A second scene built from the same blob (surface cells, Embree BVH) renders the same too.
  Scene rebuilt;
  rebuilt.addImplicit(branchBlob(), rebuilt.addMaterial(Material{}));
  rebuilt.commit();
  rs.threads = 2;
  CHECK(renderImage(rebuilt, cam, rs).pixels == a.pixels);
}

TEST_CASE("Scene::addImplicit pruned tapes", "[render]") {
  // Each cell traced with its pruned tape (the default) gives the image of the whole tape:
  // the branch's blend has too few children for a point grid, so the pruned tapes sum the
  // same terms in the same order and the pixels are the same bits.
  Image images[2];
  size_t tapes[2] = {};
  for (int pruned = 0; pruned < 2; ++pruned) {
    Scene scene;
    ImplicitOptions opt;
    opt.prunedTapes = pruned == 1;
    scene.addImplicit(branchBlob(), scene.addMaterial(Material{}), opt);
    scene.commit();
    tapes[pruned] = scene.stats().implicitTapes;
    if (pruned == 1) {
      REQUIRE(tapes[1] > 0);
      CHECK(tapes[1] < scene.stats().implicitCells / 4);
      // The whole tape has 5 nodes; most cells see one or two cones.
      CHECK(double(scene.stats().implicitTapeNodes) / double(scene.stats().implicitCells) < 2.5);
    }
    RenderSettings rs = quietSettings(96, 96);
    images[pruned] = renderImage(scene, frameBounds(scene.bounds(), ViewSpec{}, 1.0), rs);
  }
  CHECK(tapes[0] == 0);
  CHECK(images[0].pixels == images[1].pixels);
}

TEST_CASE("Scene::setPrunedTapes and the process default (sprig --full-tape)", "[render]") {
  // Pruned tapes are on by default; the scene switch and the process-wide default each turn
  // them off for implicit parts added afterwards, whatever the part's options say.
  auto tapesOf = [](Scene& scene) {
    scene.addImplicit(branchBlob(), scene.addMaterial(Material{}));
    scene.commit();
    return scene.stats().implicitTapes;
  };
  REQUIRE(Scene::prunedTapesDefault());
  Scene pruned;
  CHECK(tapesOf(pruned) > 0);
  Scene switched;
  switched.setPrunedTapes(false);
  CHECK(tapesOf(switched) == 0);
  Scene::setPrunedTapesDefault(false);
  Scene byDefault;
  Scene::setPrunedTapesDefault(true);
  CHECK(tapesOf(byDefault) == 0);
  Scene after;
  CHECK(tapesOf(after) > 0);
}

TEST_CASE("Scene::addImplicit batched tracing", "[render]") {
  // The Embree scene (the tracer over each surface cell) and CompiledBlob::intersect (the
  // same tracer over whole rays, empty space skipped by interval bounds, no cells) find the
  // same first hits.
  blobtree::CompiledBlob blob = branchBlob();
  Scene batched;
  ImplicitOptions opt;
  batched.addImplicit(blob, batched.addMaterial(Material{}), opt);
  batched.commit();
  const uint64_t seed = 20261122;
  INFO("seed " << seed);
  Rng rng(seed);
  Box3 b = blob.bounds();
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    Vec3 target = b.lo + Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * b.size() * 0.6f + 0.2f * b.size();
    Vec3 origin = target + 4.0f * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
    Vec3 dir = glm::normalize(target - origin);
    auto a = batched.intersect(origin, dir, 0, 100);
    auto r = blob.intersect(blobtree::Ray{origin, dir}, 0, 100);
    REQUIRE(a.has_value() == r.has_value());
    CHECK(batched.occluded(origin, dir, 0, 100) == a.has_value());
    if (!a) continue;
    ++hits;
    CHECK(a->t == Approx(r->t).margin(1e-4));
    CHECK(std::abs(blob.value(a->position) - 0.5f) < 1e-3f);
    CHECK(glm::dot(a->normal, r->normal) > 0.999f);
  }
  CHECK(hits > 50);
}

TEST_CASE("Scene::addTextures", "[render]") {
  // Registry textures color blob primitives by id; two models side by side in one scene.
  auto registry = std::make_shared<textures::TextureRegistry>();
  registry->add(textures::ConstantTexture{Vec3(0.8f, 0.1f, 0.1f)});
  registry->add(textures::ConstantTexture{Vec3(0.1f, 0.7f, 0.2f)});
  blobtree::BlobTree t;
  blobtree::TextureAttr green;
  green.textureId = 1;
  blobtree::CompiledBlob left = blobtree::compile(t, t.point(Vec3(-2, 0, 0), 1.0f));
  blobtree::CompiledBlob right = blobtree::compile(t, t.point(Vec3(2, 0, 0), 1.0f, green));
  Scene scene;
  CHECK(scene.addTextures(registry) == 0);
  uint32_t m = scene.addMaterial(Material{});
  uint32_t a = scene.addImplicit(left, m), b = scene.addImplicit(right, m);
  scene.commit();
  auto hl = scene.intersect(Vec3(-2, 0, 5), Vec3(0, 0, -1), 0, 100);
  auto hr = scene.intersect(Vec3(2, 0, 5), Vec3(0, 0, -1), 0, 100);
  REQUIRE(hl);
  REQUIRE(hr);
  CHECK(hl->geometry == a);
  CHECK(hr->geometry == b);
  CHECK(hl->color.r == Approx(0.8f));
  CHECK(hr->color.g == Approx(0.7f));
  CHECK(scene.bounds().lo.x < -2.9f);
  CHECK(scene.bounds().hi.x > 2.9f);
}

TEST_CASE("Scene::addImplicit far from the camera", "[render]") {
  // The root tolerance scales with the model (a unit sphere: about 1e-4), but at t = 1e5
  // floats are 0.0078 apart: the tracer must stop at the float spacing instead of
  // subdividing forever (a one-internode tree framed for its grown stage did hang).
  blobtree::BlobTree t;
  blobtree::CompiledBlob blob = blobtree::compile(t, t.point(Vec3(0), 1.0f));
  Scene scene;
  scene.addImplicit(blob, scene.addMaterial(Material{}));
  scene.commit();
  for (float dist : {1.0e4f, 1.0e5f, 1.0e6f}) {
    INFO("distance " << dist);
    Vec3 dir = glm::normalize(Vec3(0.3f, -0.2f, -1.0f));
    auto hit = scene.intersect(-dist * dir, dir, 0, 2.0f * dist);
    REQUIRE(hit);
    CHECK(hit->t == Approx(dist - 1.0f).margin(dist * 4e-6f));
    CHECK(scene.occluded(-dist * dir, dir, 0, 2.0f * dist));
  }
}

TEST_CASE("PixelScale::nearestPixel and pixelCellSize", "[render]") {
  PixelScale px;
  px.eye = Vec3(0, 0, 5);
  px.forward = Vec3(0, 0, -1);
  px.pixelPerDepth = 0.01f;
  const Box3 box{Vec3(-1), Vec3(1)};
  SECTION("the pixel at the nearest corner") {
    // The nearest face is z = 1, at depth 4.
    CHECK(px.nearestPixel(box) == Approx(0.04f));
    CHECK(pixelCellSize(0.01f, px, box) == Approx(kCellPixels * 0.04f));
    CHECK(pixelCellSize(0.01f, px, box, 1.0f) == Approx(0.04f));
  }
  SECTION("never finer than the model's own cell") {
    CHECK(pixelCellSize(0.5f, px, box) == 0.5f);
    CHECK(pixelCellSize(0.0f, px, box) == 0.0f);
  }
  SECTION("a camera inside the box, or the box behind it: the rule does not bind") {
    px.eye = Vec3(0, 0, 0.5f);
    CHECK(px.nearestPixel(box) == 0.0f);
    CHECK(pixelCellSize(0.01f, px, box) == 0.01f);
    px.eye = Vec3(0, 0, -5);
    CHECK(px.nearestPixel(box) == 0.0f);
    CHECK(px.nearestPixel(Box3{}) == 0.0f);
  }
  SECTION("a tilted view: the corner nearest along the view") {
    px.eye = Vec3(4, 0, 4);
    px.forward = glm::normalize(Vec3(-1, 0, -1));
    CHECK(px.nearestPixel(box) == Approx(0.01f * glm::dot(Vec3(1, 1, 1) - px.eye, px.forward)));
  }
}

TEST_CASE("Scene::addImplicit follows the pixels", "[render]") {
  // The model's own cells (no camera), a large image (the rule does not bind: the same
  // cells, the same bytes) and a thumbnail (cells of at least kCellPixels pixels).
  const blobtree::CompiledBlob blob = branchBlob();
  const Camera cam = frameBounds(blob.bounds(), ViewSpec{}, 1.0);
  struct Built {
    size_t cells = 0;
    float edge = 0;
    Image image;
  };
  auto build = [&](int imageSize) {
    Scene scene;
    if (imageSize > 0) scene.setPixelFootprint(cam, imageSize, imageSize, 0.0f);
    scene.addImplicit(blob, scene.addMaterial(Material{}));
    scene.commit();
    Built b;
    b.cells = scene.stats().implicitCells;
    b.edge = scene.stats().implicitCellSize;
    b.image = renderImage(scene, cam, quietSettings(64, 64));
    return b;
  };
  const Built own = build(0), large = build(4096), thumb = build(32);
  const float ownEdge = own.edge;
  REQUIRE(own.cells > 1000);
  // 4096 pixels: the pixel at the box's nearest corner is far below the model's cell.
  REQUIRE(kCellPixels * cam.pixelScale(4096).nearestPixel(blob.bounds()) < ownEdge);
  CHECK(large.cells == own.cells);
  CHECK(large.edge == ownEdge);
  CHECK(large.image.pixels == own.image.pixels);
  // A 32-pixel thumbnail: the requested edge is kCellPixels pixels at the nearest corner;
  // surfaceCells rounds it down to the root cube over a power of two (at most 2x).
  const float wanted = kCellPixels * cam.pixelScale(32).nearestPixel(blob.bounds());
  REQUIRE(wanted > 2.0f * ownEdge);
  CHECK(thumb.edge <= wanted);
  CHECK(thumb.edge > 0.5f * wanted);
  CHECK(thumb.cells * 3 < own.cells);
  CHECK(thumb.cells <= size_t(32 * 32));  // no more cells than the thumbnail has pixels
  // The same surface (rendered at 64x64 both ways): only hits within the root tolerance differ.
  double diff = 0;
  for (size_t i = 0; i < own.image.pixels.size(); ++i)
    diff = std::max(diff, double(std::abs(thumb.image.pixels[i] - own.image.pixels[i])));
  CHECK(diff < 0.02);
}

TEST_CASE("Scene::servesCamera: implicit cells sized alike by another camera", "[render]") {
  const blobtree::CompiledBlob blob = branchBlob();
  ViewSpec turned;
  turned.azimuthDeg += 90.0;
  const Camera cam = frameBounds(blob.bounds(), ViewSpec{}, 1.0), side = frameBounds(blob.bounds(), turned, 1.0);
  Camera far = cam;
  far.position = cam.target + 3.0f * (cam.position - cam.target);
  auto built = [&](int imageSize, auto check) {
    Scene scene;
    scene.setPixelFootprint(cam, imageSize, imageSize, 0.0f);
    scene.addImplicit(blob, scene.addMaterial(Material{}));
    scene.commit();
    check(scene);
  };
  // 4096 pixels: the model's own cell binds for either camera: one scene serves both.
  built(4096, [&](const Scene& scene) {
    CHECK(scene.servesCamera(cam, 4096, 4096));
    CHECK(scene.servesCamera(side, 4096, 4096));
  });
  // 32 pixels: the pixel binds; three times farther gives coarser cells: another scene.
  built(32, [&](const Scene& scene) {
    CHECK(scene.servesCamera(cam, 32, 32));
    CHECK_FALSE(scene.servesCamera(far, 32, 32));
    CHECK_FALSE(scene.servesCamera(cam, 8, 8));
  });
  // Curves widened to the footprint follow the camera: no other camera is served.
  Scene curves;
  curves.setPixelFootprint(cam, 32, 32);
  CurveSet c;
  c.vertices = {Vec4(0, 0, 0, 0.001f), Vec4(0, 1, 0, 0.001f)};
  c.segments = {0};
  c.flags = {0};
  curves.addCurves(c, curves.addMaterial(Material{}));
  curves.commit();
  CHECK_FALSE(curves.servesCamera(cam, 32, 32));
}

TEST_CASE("Scene::addImplicit sub-cell bounds", "[render]") {
  // ImplicitOptions::subCells narrows the tracer's bounds once a cell has been traced
  // SubCellBounds::kWarmTraces times; the hits are the same to the bit. Coarse cells and
  // many rays, so that most cells pass the threshold.
  blobtree::CompiledBlob blob = branchBlob();
  ImplicitOptions off, on;
  off.cellSize = on.cellSize = 0.4f;
  off.subCells = 0;
  on.subCells = 4;
  Scene a, b;
  a.addImplicit(blob, a.addMaterial(Material{}), off);
  b.addImplicit(blob, b.addMaterial(Material{}), on);
  a.commit();
  b.commit();
  const uint64_t seed = 20261206;
  INFO("seed " << seed);
  Rng rng(seed);
  const Box3 box = blob.bounds();
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const auto [origin, dir] = rayIntoBox(rng, box);
    const auto ha = a.intersect(origin, dir, 0, 100), hb = b.intersect(origin, dir, 0, 100);
    REQUIRE(ha.has_value() == hb.has_value());
    CHECK(a.occluded(origin, dir, 0, 100) == b.occluded(origin, dir, 0, 100));
    if (!ha) continue;
    ++hits;
    CHECK(ha->t == hb->t);
    CHECK(ha->normal == hb->normal);
  }
  CHECK(hits > 2000);
  ImplicitOptions bad;
  bad.subCells = 9;
  Scene c;
  CHECK_THROWS_AS(c.addImplicit(blob, c.addMaterial(Material{}), bad), std::invalid_argument);
}

TEST_CASE("Scene::addImplicit free sub-cells", "[render]") {
  // ImplicitOptions::freeSubCells proves sub-cells free of the surface, when the cells are
  // made (freeSubCellsEager 0: the cells free everywhere then left out) or when rays come
  // (a scene without an expectation), and skips spans that cross only free sub-cells: the
  // same hits, normals and shadows to the bit as tracing every cell, and the same bounds
  // (they come from every surface cell).
  blobtree::CompiledBlob blob = branchBlob();
  ImplicitOptions off, eager, lazy;
  off.freeSubCells = false;
  eager.freeSubCellsEager = 0.0f;
  lazy.freeSubCellsLazy = 1;
  Scene a, b, c;
  a.addImplicit(blob, a.addMaterial(Material{}), off);
  b.addImplicit(blob, b.addMaterial(Material{}), eager);
  c.addImplicit(blob, c.addMaterial(Material{}), lazy);
  a.commit();
  b.commit();
  c.commit();
  CHECK(a.stats().implicitFreeCells == 0);
  CHECK(b.stats().implicitFreeCells > b.stats().implicitCells / 20);
  CHECK(c.stats().implicitFreeCells == 0);
  CHECK(a.stats().implicitCells == b.stats().implicitCells);
  CHECK(a.bounds().lo == b.bounds().lo);
  CHECK(a.bounds().hi == b.bounds().hi);
  CHECK(a.bounds().lo == c.bounds().lo);
  CHECK(a.bounds().hi == c.bounds().hi);
  const uint64_t seed = 20261206;
  INFO("seed " << seed);
  Rng rng(seed);
  const Box3 box = blob.bounds();
  int hits = 0, shadowed = 0;
  for (int i = 0; i < 20000; ++i) {
    const auto [origin, dir] = rayIntoBox(rng, box);
    const auto ha = a.intersect(origin, dir, 0, 100), hb = b.intersect(origin, dir, 0, 100),
               hc = c.intersect(origin, dir, 0, 100);
    REQUIRE(ha.has_value() == hb.has_value());
    REQUIRE(ha.has_value() == hc.has_value());
    const bool occluded = a.occluded(origin, dir, 0, 100);
    CHECK(occluded == b.occluded(origin, dir, 0, 100));
    CHECK(occluded == c.occluded(origin, dir, 0, 100));
    shadowed += occluded;
    if (!ha) continue;
    ++hits;
    CHECK(ha->t == hb->t);
    CHECK(ha->normal == hb->normal);
    CHECK(ha->t == hc->t);
    CHECK(ha->normal == hc->normal);
    // A shadow ray leaving the hit, as the renderer casts them.
    const Vec3 p = ha->position + 1e-4f * ha->geometricNormal;
    const Vec3 away = glm::normalize(ha->geometricNormal + Vec3(rng.normal(), rng.normal(), rng.normal()));
    const bool shadow = a.occluded(p, away, 0, 100);
    CHECK(shadow == b.occluded(p, away, 0, 100));
    CHECK(shadow == c.occluded(p, away, 0, 100));
  }
  CHECK(hits > 2000);
  CHECK(shadowed > 2000);
}

TEST_CASE("Scene::setExpectedSamples: free sub-cells proved when made only where rays are many", "[render]") {
  // The cells are proved when made (and the wholly free ones left out) when the expected
  // camera samples per cell in view reach ImplicitOptions::freeSubCellsEager; otherwise,
  // and without an expectation, when rays come. The picture is the same bytes either way.
  const blobtree::CompiledBlob blob = branchBlob();
  const Camera cam = frameBounds(blob.bounds(), ViewSpec{}, 1.0);
  ImplicitOptions opt;
  opt.cellSize = 0.05f;
  opt.followPixels = false;
  auto built = [&](int size, int spp, bool expect, Image* image) {
    Scene scene;
    if (expect) scene.setExpectedSamples(cam, size, size, spp);
    scene.addImplicit(blob, scene.addMaterial(Material{}), opt);
    scene.commit();
    if (image) {
      RenderSettings rs;
      rs.width = rs.height = 48;
      rs.spp = 2;
      rs.progress = false;
      *image = renderImage(scene, cam, rs);
    }
    return scene.stats();
  };
  Image many, few, unknown;
  const SceneStats dense = built(1024, 16, true, &many);
  const SceneStats sparse = built(48, 2, true, &few);
  const SceneStats none = built(1024, 16, false, &unknown);
  REQUIRE(dense.implicitCells > 200);
  CHECK(dense.implicitFreeCells > dense.implicitCells / 20);
  CHECK(sparse.implicitFreeCells == 0);
  CHECK(none.implicitFreeCells == 0);
  CHECK(many.pixels == few.pixels);
  CHECK(many.pixels == unknown.pixels);
  Scene late;
  late.addImplicit(blob, late.addMaterial(Material{}), opt);
  CHECK_THROWS_AS(late.setExpectedSamples(cam, 8, 8, 1), std::logic_error);
}
