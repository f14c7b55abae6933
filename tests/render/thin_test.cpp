// Thin geometry keeps its coverage: curves and cones narrower than a pixel are drawn at a
// minimum width with opacity true width / drawn width (Scene::setPixelFootprint).

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/render/test_scenes.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;

namespace {

constexpr int kW = 240, kH = 40;
constexpr float kFov = 35.0f;
constexpr float kDepth = 10.0f;

Camera frontCamera() {
  Camera c;
  c.position = Vec3(0, 0, kDepth);
  c.target = Vec3(0);
  c.fovYDeg = kFov;
  return c;
}

/// World size of one pixel at the cylinder's depth.
float pixelSize() { return 2.0f * kDepth * std::tan(0.5f * static_cast<float>(radians(kFov))) / kH; }

/// A long, slightly tilted cylinder of diameter `pixels` pixels (it crosses a few rows, so
/// point sampling alone breaks it into dots).
constexpr float kHalfLength = 15.0f, kRise = 0.2f;
CurveSet thinCylinder(float pixels) {
  const float r = 0.5f * pixels * pixelSize();
  CurveSet c;
  c.vertices = {Vec4(-kHalfLength, -kRise, 0, r), Vec4(kHalfLength, kRise, 0, r)};
  c.segments = {0};
  c.flags = {0};
  return c;
}

struct Coverage {
  double mean = 0, cv = 0;
};

/// Mean and coefficient of variation of the alpha column sums over the cylinder's inner
/// columns (8 pixels clear of its ends).
Coverage columnCoverage(const Image& img) {
  Camera cam = frontCamera();
  Vec2 a, b;
  cam.project(Vec3(-kHalfLength, 0, 0), kW, kH, a);
  cam.project(Vec3(kHalfLength, 0, 0), kW, kH, b);
  std::vector<double> sums;
  for (int x = static_cast<int>(a.x) + 8; x < static_cast<int>(b.x) - 8; ++x) {
    double s = 0;
    for (int y = 0; y < img.height; ++y) s += img.at(x, y).a;
    sums.push_back(s);
  }
  double mean = 0;
  for (double s : sums) mean += s;
  mean /= static_cast<double>(sums.size());
  double var = 0;
  for (double s : sums) var += (s - mean) * (s - mean);
  var /= static_cast<double>(sums.size());
  return {mean, std::sqrt(var) / mean};
}

Image renderCurves(float pixels, float minPixels, int threads = 0) {
  Scene scene;
  scene.setPixelFootprint(frontCamera(), kW, kH, minPixels);
  scene.addCurves(thinCylinder(pixels), scene.addMaterial(Material{}));
  scene.commit();
  RenderSettings rs = silhouetteSettings(kW, kH, 4);
  rs.threads = threads;
  return renderImage(scene, frontCamera(), rs);
}

/// The cylinder as a BlobTree cone (exact mode) with its axis as thinAxes.
Image renderCone(float pixels, float minPixels) {
  const CurveSet axes = thinCylinder(pixels);
  blobtree::BlobTree t;
  const Vec4 a = axes.vertices[0], b = axes.vertices[1];
  auto blob = std::make_shared<const blobtree::CompiledBlob>(
      blobtree::compile(t, t.cone(Vec3(a), Vec3(b), a.w, b.w)));
  Scene scene;
  scene.setPixelFootprint(frontCamera(), kW, kH, minPixels);
  Geometry g;
  g.parts.push_back(ImplicitPart{blob, Material{}, {}, {}, axes});
  scene.add(g);
  scene.commit();
  return renderImage(scene, frontCamera(), silhouetteSettings(kW, kH, 4));
}

}  // namespace

TEST_CASE("thin curves keep their coverage along their length", "[render][thin]") {
  // A quarter-pixel cylinder: the column sums of alpha are its width, 0.25 px (the tilt
  // adds a factor 1/cos of 0.013 rad, negligible).
  const float width = 0.25f;
  const Coverage plain = columnCoverage(renderCurves(width, 0.0f));
  const Coverage widened = columnCoverage(renderCurves(width, Scene::kThinMinPixels));
  std::printf("thin curve 0.25 px: plain mean %.3f cv %.3f; widened mean %.3f cv %.3f\n", plain.mean, plain.cv, widened.mean, widened.cv);
  INFO("plain mean " << plain.mean << " cv " << plain.cv << "; widened mean " << widened.mean << " cv " << widened.cv);
  // Point-sampled, the cylinder breaks into dots: its column sums vary a lot.
  CHECK(plain.cv > 0.5);
  // Widened to 2 px with opacity 1/8, the coverage is nearly even and still the width.
  CHECK(widened.cv < 0.1);
  CHECK(widened.mean == Approx(width).epsilon(0.1));
  CHECK(plain.mean == Approx(width).epsilon(0.25));
}

TEST_CASE("thin BlobTree cones are drawn by their axes at the minimum width", "[render][thin]") {
  const float width = 0.25f;
  const Coverage exact = columnCoverage(renderCone(width, 0.0f));
  const Coverage widened = columnCoverage(renderCone(width, Scene::kThinMinPixels));
  std::printf("thin cone 0.25 px: exact mean %.3f cv %.3f; widened mean %.3f cv %.3f\n", exact.mean, exact.cv, widened.mean, widened.cv);
  INFO("exact mean " << exact.mean << " cv " << exact.cv << "; widened mean " << widened.mean << " cv " << widened.cv);
  CHECK(exact.cv > 0.5);
  CHECK(widened.cv < 0.1);
  // The cone itself inside the drawn tube is skipped: coverage is the width, not twice it.
  CHECK(widened.mean == Approx(width).epsilon(0.1));
}

TEST_CASE("curves wider than the minimum are drawn as they are", "[render][thin]") {
  // A 3-pixel cylinder: no radius is raised, so the footprint changes no byte.
  Scene a, b;
  b.setPixelFootprint(frontCamera(), kW, kH, Scene::kThinMinPixels);
  for (Scene* s : {&a, &b}) {
    CurveSet c = thinCylinder(3.0f);
    s->addCurves(c, s->addMaterial(Material{}));
    s->commit();
  }
  const RenderSettings rs = silhouetteSettings(kW, kH, 4);
  CHECK(renderImage(a, frontCamera(), rs).pixels == renderImage(b, frontCamera(), rs).pixels);
}

TEST_CASE("thin curves render the same bytes at 1 and 2 threads", "[render][thin]") {
  // Shadows through widened curves are decided by a hash of the ray: no thread dependence.
  CHECK(renderCurves(0.3f, 1.5f, 1).pixels == renderCurves(0.3f, 1.5f, 2).pixels);
}

TEST_CASE("the pixel footprint is fixed before geometry", "[render][thin]") {
  Scene s;
  s.addCurves(thinCylinder(1.0f), s.addMaterial(Material{}));
  CHECK_THROWS_AS(s.setPixelFootprint(frontCamera(), kW, kH), std::logic_error);
}

