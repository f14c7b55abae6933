#include "model/model.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>

#include "species_error.h"

using namespace sprig;

namespace {

/// Fig. 12's junction: a trunk of radius 0.15 and two branches of 0.12 (`!` sets the width)
/// meeting at P = (0, 1, 0).
std::string junctionTree(const std::string& closeUp) {
  return R"(kind: tree
grammar: |
  lsystem: p
  derivation length: 0
  axiom: !(0.3)F(1)[+(30)!(0.24)F(1)][-(30)!(0.24)F(1)]
  endlsystem
turtle: {width_scale: 1, angle: 30}
render:
  width: 48
  height: 32
  samples: 1
  view: {azimuth: 20, elevation: 10, margin: 0.1}
  close_up: )" + closeUp + R"(
tree: {junctions: pcm, bark: {enabled: false}}
)";
}

/// The film rectangle [lo, hi] the eight corners of box project to.
void projectedRect(const render::Camera& cam, const Box3& box, int w, int h, Vec2& lo, Vec2& hi) {
  lo = Vec2(1e30f);
  hi = Vec2(-1e30f);
  for (int i = 0; i < 8; ++i) {
    const Vec3 p((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
    Vec2 film;
    REQUIRE(cam.project(p, w, h, film));
    lo = glm::min(lo, film);
    hi = glm::max(hi, film);
  }
}

/// The target's projected box lies inside the frame less its margin and touches that margin
/// on both sides of one axis (it fills the frame), centred.
void checkFills(const render::Camera& cam, const Box3& target, int w, int h, double margin) {
  Vec2 lo, hi;
  projectedRect(cam, target, w, h, lo, hi);
  const float mx = float(0.5 * margin * w), my = float(0.5 * margin * h), tol = 0.05f;
  CHECK(lo.x >= mx - tol);
  CHECK(hi.x <= w - mx + tol);
  CHECK(lo.y >= my - tol);
  CHECK(hi.y <= h - my + tol);
  const bool fillsX = lo.x < mx + tol && hi.x > w - mx - tol;
  const bool fillsY = lo.y < my + tol && hi.y > h - my - tol;
  CHECK((fillsX || fillsY));
  CHECK(lo.x + hi.x == Approx(w).margin(0.1));
  CHECK(lo.y + hi.y == Approx(h).margin(0.1));
}

}  // namespace

TEST_CASE("speciesCamera: a close-up frames its target", "[model]") {
  const int w = 48, h = 32;
  SECTION("a point with a size: a square of that side across the view fills the shorter side") {
    const Species s = parseSpecies(junctionTree("{point: [0.2, 1, 0], size: 0.5}"), "close.yaml");
    SpeciesModel model(s);
    const Vec3 p(0.2f, 1, 0);
    const Box3 box = model.closeUpBox(*s.render.closeUp);
    CHECK(box.lo == p);
    CHECK(box.hi == p);
    const render::Camera cam = speciesCamera(model, s.render, model.frameBox(), w, h);
    const render::CameraBasis b = cam.basis();
    Vec2 top, bottom, left, right;
    REQUIRE(cam.project(p + 0.25f * b.up, w, h, top));
    REQUIRE(cam.project(p - 0.25f * b.up, w, h, bottom));
    REQUIRE(cam.project(p - 0.25f * b.right, w, h, left));
    REQUIRE(cam.project(p + 0.25f * b.right, w, h, right));
    CHECK(top.y == Approx(0.05 * h).margin(0.01));  // the margin's 10% of the half-frame
    CHECK(bottom.y == Approx(0.95 * h).margin(0.01));
    CHECK(right.x - left.x == Approx(0.9 * h).margin(0.01));  // square pixels
    CHECK(left.x + right.x == Approx(w).margin(0.01));
    // Looking along the view's direction.
    const Vec3 toViewer = glm::normalize(cam.position - cam.target);
    CHECK(glm::length(toViewer - render::directionFromAngles(20, 10)) < 1e-5f);
  }
  SECTION("a junction: the base of internode 1, four radii of the larger internode across") {
    const Species s = parseSpecies(junctionTree("{junction: 1}"), "close.yaml");
    SpeciesModel model(s);
    const Box3 box = model.closeUpBox(*s.render.closeUp);
    CHECK(box.center().x == Approx(0).margin(1e-6));
    CHECK(box.center().y == Approx(1).margin(1e-6));
    CHECK(box.center().z == Approx(0).margin(1e-6));
    CHECK(box.size().x == Approx(4 * 0.15).epsilon(1e-5));  // the trunk's radius at P
    const render::Camera cam = speciesCamera(model, s.render, model.frameBox(), w, h);
    checkFills(cam, box, w, h, 0.1);
    // A close-up: the whole tree does not fit the frame.
    Vec2 lo, hi;
    projectedRect(cam, model.frameBox(), w, h, lo, hi);
    CHECK((lo.y < 0 || hi.y > h));
    // The same camera without the close-up is the whole tree's.
    SpeciesRender whole = s.render;
    whole.closeUp.reset();
    CHECK(speciesCamera(model, whole, model.frameBox(), w, h).position != cam.position);
  }
  SECTION("an internode: its box with its radius") {
    const Species s = parseSpecies(junctionTree("{internode: 0}"), "close.yaml");
    SpeciesModel model(s);
    const Box3 box = model.closeUpBox(*s.render.closeUp);
    CHECK(box.lo.y == Approx(-0.15).margin(1e-5));
    CHECK(box.hi.y == Approx(1.15).margin(1e-5));
    CHECK(box.hi.x == Approx(0.15).margin(1e-5));
    checkFills(speciesCamera(model, s.render, model.frameBox(), w, h), box, w, h, 0.1);
  }
}

TEST_CASE("renderModel: a close-up renders through speciesCamera", "[model]") {
  const Species s = parseSpecies(junctionTree("{junction: 2}"), "close.yaml");
  SpeciesModel model(s);
  RenderJob job;
  job.width = 24;
  job.height = 16;
  job.samples = 1;
  job.progress = false;
  job.stage = model.finalStage();
  const Image closeUp = renderModel(model, s.render, job);
  job.camera = speciesCamera(model, s.render, model.frameBox(), 24, 16);
  CHECK(renderModel(model, s.render, job).pixels == closeUp.pixels);
  SpeciesRender whole = s.render;
  whole.closeUp.reset();
  job.camera.reset();
  CHECK(renderModel(model, whole, job).pixels != closeUp.pixels);
}

TEST_CASE("render.close_up: errors", "[model]") {
  using test::speciesError;
  CHECK(speciesError(junctionTree("{}"), "c.yaml")
            .find("c.yaml:13:13: error: render.close_up: give exactly one target: 'point', 'internode' or 'junction'\n") == 0);
  CHECK(speciesError(junctionTree("{point: [0, 1, 0]}"), "c.yaml")
            .find("c.yaml:13:13: error: render.close_up: a 'point' needs a 'size' above 0 (the world extent to frame)\n") == 0);
  CHECK(speciesError(junctionTree("{junction: 1, internode: 1}"), "c.yaml").find("exactly one target") != std::string::npos);
  CHECK(speciesError(junctionTree("{junction: -1}"), "c.yaml").find("c.yaml:13:24: error:") == 0);
  const Species s = parseSpecies(junctionTree("{junction: 3}"), "c.yaml");
  SpeciesModel model(s);
  try {
    model.closeUpBox(*s.render.closeUp);
    FAIL("junction 3 of 3 internodes was accepted");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("c.yaml:13:13: error: render.close_up: junction 3 is beyond the tree's 3 internodes (0..2)") == 0);
  }
  CHECK(speciesError("kind: blob\nblob: {point: {center: [0, 0, 0], radius: 1}}\nrender:\n  close_up: {internode: 0}\n", "b.yaml")
            .find("b.yaml:4:3: error: 'render.close_up' names an internode or a junction of a tree") == 0);
  CHECK(speciesError("kind: blob\nblob: {point: {center: [0, 0, 0], radius: 1}}\nrender:\n  camera: {distance: 3}\n  close_up: {point: [0, 0, 0], size: 1}\n",
                     "b.yaml")
            .find("give either 'camera' or 'close_up'") != std::string::npos);
}
