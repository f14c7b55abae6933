#include "model/model.h"

#include <catch2/catch.hpp>

#include <fstream>
#include <string>

#include "tests/model/final_stage_job.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using test::finalStageJob;

namespace {

/// A blob sphere of radius 0.5 centred at (x, 0.5, 0).
std::string sphere(float x, const std::string& extra = "") {
  return "kind: blob\nblob: {point: {center: [" + std::to_string(x) +
         ", 0.5, 0], radius: 1.1}}\nrender: {width: 48, height: 24, samples: 1, view: {azimuth: 0, elevation: 10}" + extra +
         "}\n";
}

}  // namespace

TEST_CASE("renderPair: two panels side by side seen by one camera", "[model]") {
  const Species a = parseSpecies(sphere(0), "a.yaml");
  const Species b = parseSpecies(sphere(1.5f), "b.yaml");
  SpeciesModel ma(a), mb(b);
  SECTION("a species paired with itself: both halves are the same picture") {
    SpeciesModel again(a);
    const Image img = renderPair(ma, again, a.render, finalStageJob(ma));
    REQUIRE(img.width == 48);
    REQUIRE(img.height == 24);
    REQUIRE(pairDividerHalfWidth(24) == 1);
    for (int y = 0; y < 24; ++y)
      for (int x = 1; x < 23; ++x) REQUIRE(img.at(x, y) == img.at(24 + x, y));
  }
  SECTION("a white rule covers the panels' facing columns, one a side and one more per 512 pixels") {
    const Image img = renderPair(ma, mb, a.render, finalStageJob(ma));
    for (int y = 0; y < 24; ++y) {
      CHECK(img.at(23, y) == Vec4(1.0f));
      CHECK(img.at(24, y) == Vec4(1.0f));
      CHECK(img.at(22, y) != Vec4(1.0f));  // sky or ground
      CHECK(img.at(25, y) != Vec4(1.0f));
    }
    CHECK(pairDividerHalfWidth(255) == 1);
    CHECK(pairDividerHalfWidth(256) == 1);
    CHECK(pairDividerHalfWidth(512) == 2);
  }
  SECTION("each panel is its species rendered through the pair's camera, which frames both") {
    const render::Camera cam = pairCamera(ma, mb, a.render, 48, 24);
    const Image img = renderPair(ma, mb, a.render, finalStageJob(ma));
    RenderJob panel = finalStageJob(ma);
    panel.width = 24;
    panel.height = 24;
    panel.camera = cam;
    Box3 both = ma.frameBox();  // the ground fades around both species' frame boxes
    both.extend(mb.frameBox());
    panel.frame = both;
    const Image left = renderModel(ma, a.render, panel);
    const Image right = renderModel(mb, a.render, panel);
    bool differ = false;
    for (int y = 0; y < 24; ++y)
      for (int x = 0; x < 24; ++x) {
        if (x < 23) REQUIRE(img.at(x, y) == left.at(x, y));  // but for the rule's columns 23 and 24
        if (x > 0) REQUIRE(img.at(24 + x, y) == right.at(x, y));
        differ = differ || left.at(x, y) != right.at(x, y);
      }
    CHECK(differ);
    // One camera for both: the shared point (0.75, 0.5, 0) between the spheres is at the
    // panel's centre column, the left sphere's centre left of it, the right one's right.
    Vec2 mid, l, r;
    REQUIRE(cam.project(Vec3(0.75f, 0.5f, 0), 24, 24, mid));
    REQUIRE(cam.project(Vec3(0, 0.5f, 0), 24, 24, l));
    REQUIRE(cam.project(Vec3(1.5f, 0.5f, 0), 24, 24, r));
    CHECK(mid.x == Approx(12).margin(0.01));
    CHECK(l.x < 12);
    CHECK(r.x > 12);
    CHECK(l.x > 0);
    CHECK(r.x < 24);
    // Not a's own camera, which frames a alone.
    RenderJob alone = panel;
    alone.camera.reset();
    alone.frame.reset();
    CHECK(renderModel(ma, a.render, alone).pixels != left.pixels);
  }
}

TEST_CASE("renderPicture: render.pair loads the other species file", "[model]") {
  test::TempDir dir("pair");
  std::ofstream(dir.path / "a.yaml") << sphere(0, ", pair: b.yaml");
  std::ofstream(dir.path / "b.yaml") << sphere(1.5f);
  PathPolicy policy;
  policy.root = dir.path;
  const Species a = loadSpecies(dir.path / "a.yaml", policy);
  REQUIRE(a.render.pair);
  SpeciesModel ma(a);
  SpeciesModel mb(loadSpecies(dir.path / "b.yaml", policy));
  const RenderJob job = finalStageJob(ma);
  CHECK(renderPicture(ma, a.render, job).pixels == renderPair(ma, mb, a.render, job).pixels);
  SpeciesRender single = a.render;
  single.pair.reset();
  CHECK(renderPicture(ma, single, job).width == 48);  // one panel, the whole width
}
