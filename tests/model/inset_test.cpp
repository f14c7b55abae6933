#include "model/model.h"

#include <catch2/catch.hpp>

#include <string>

#include "tests/model/final_stage_job.h"
#include "tests/model/species_error.h"

using namespace sprig;
using test::finalStageJob;

namespace {

/// A blob sphere of radius 0.5 centred at (0, 0.5, 0), 60 x 40 pictures, and an extra
/// `render:` entry.
std::string sphere(const std::string& extra = "") {
  return "kind: blob\nblob: {point: {center: [0, 0.5, 0], radius: 1.1}}\n"
         "render: {width: 60, height: 40, samples: 1, color: [0.8, 0.3, 0.2], view: {azimuth: 0, elevation: 10}" +
         extra + "}\n";
}

const std::string kInset = ", inset: {fraction: 0.5, view: {azimuth: 90, elevation: 30, margin: 0.02}, "
                           "close_up: {point: [0, 0.9, 0], size: 0.3}, sun: {azimuth: 60, elevation: 20}}";

}  // namespace

TEST_CASE("render.inset: the inset's look is the species' with its own camera and light", "[model]") {
  const Species a = parseSpecies(sphere(kInset), "a.yaml");
  REQUIRE(a.render.inset);
  const InsetSpec& inset = *a.render.inset;
  CHECK(inset.fraction == 0.5);
  CHECK(inset.look.view.azimuthDeg == 90);
  CHECK(inset.look.view.elevationDeg == 30);
  CHECK(inset.look.image.sunAzimuthDeg == 60);
  CHECK(inset.look.image.sunElevationDeg == 20);
  REQUIRE(inset.look.closeUp);
  CHECK(*inset.look.closeUp->point == Vec3(0, 0.9f, 0));
  // Everything else is the picture's: size, samples, colour; no inset or pair of its own.
  CHECK(inset.look.image.width == 60);
  CHECK(inset.look.image.spp == 1);
  CHECK(inset.look.surface.baseColor == Vec3(0.8f, 0.3f, 0.2f));
  CHECK(!inset.look.inset);
  CHECK(!inset.look.pair);
  CHECK(!a.render.closeUp);  // the picture keeps its own framing
  CHECK(a.render.view.azimuthDeg == 0);
  CHECK(a.render.image.sunElevationDeg != 20);
  // Keys of the picture alone are errors inside the inset, and so is a fraction out of range.
  CHECK(test::speciesError(sphere(", inset: {width: 20}"), "b.yaml").find("width") != std::string::npos);
  CHECK(test::speciesError(sphere(", inset: {fraction: 0.9}"), "b.yaml").find("fraction") != std::string::npos);
  CHECK(test::speciesError(sphere(", inset: {close_up: {size: 0.3}}"), "b.yaml").find("exactly one target") != std::string::npos);
  CHECK(test::speciesError(sphere(kInset), "b.yaml").empty());
}

TEST_CASE("renderPicture: render.inset draws a close-up over the lower right corner", "[model]") {
  const Species a = parseSpecies(sphere(kInset), "a.yaml");
  SpeciesModel model(a);
  const RenderJob job = finalStageJob(model);
  const Image picture = renderPicture(model, a.render, job);
  SpeciesRender plain = a.render;
  plain.inset.reset();
  const Image whole = renderModel(model, plain, job);
  const Image detail = renderInset(model, a.render, job, 60, 40);
  const InsetPlace p = insetPlace(*a.render.inset, 60, 40);
  REQUIRE(p.x == 30);
  REQUIRE(p.y == 20);
  REQUIRE(p.width == 30);
  REQUIRE(p.height == 20);
  REQUIRE(p.rule == 2);
  REQUIRE(detail.width == 30);
  REQUIRE(detail.height == 20);
  REQUIRE(picture.width == 60);
  REQUIRE(picture.height == 40);
  bool insetDiffers = false;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) {
      const bool in = x >= p.x && y >= p.y;
      if (!in) {
        REQUIRE(picture.at(x, y) == whole.at(x, y));
      } else if (x < p.x + p.rule || y < p.y + p.rule) {
        REQUIRE(picture.at(x, y) == Vec4(1.0f));  // the white rule along the top and left edges
      } else {
        REQUIRE(picture.at(x, y) == detail.at(x - p.x, y - p.y));
        insetDiffers = insetDiffers || picture.at(x, y) != whole.at(x, y);
      }
    }
  CHECK(insetDiffers);
  // The inset is the close-up of the inset's look (its camera, not the picture's), traced in
  // cells sized for the picture's camera.
  RenderJob closeUp = job;
  closeUp.width = 30;
  closeUp.height = 20;
  const Image ownCells = renderModel(model, a.render.inset->look, closeUp);
  double largest = 0;
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 30; ++x)
      for (int c = 0; c < 3; ++c) largest = std::max(largest, double(std::abs(ownCells.at(x, y)[c] - detail.at(x, y)[c])));
  CHECK(largest < 0.02);  // the same surface, whatever the cells
}

TEST_CASE("RenderJob::cellCamera sizes implicit cells for another camera's pixel", "[model]") {
  const Species a = parseSpecies(sphere(), "a.yaml");
  SpeciesModel model(a);
  SpeciesRender look = a.render;
  look.closeUp = CloseUpSpec{Vec3(0, 0.9f, 0), -1, -1, 0.1, {}};
  RenderJob job = finalStageJob(model);
  ModelFigures near, far;
  const Image nearImage = renderModel(model, look, job, &near);
  job.cellCamera = render::Camera{Vec3(0, 0.5f, 200), Vec3(0, 0.5f, 0), Vec3(0, 1, 0), 35};
  job.cellHeight = 40;
  const Image farImage = renderModel(model, look, job, &far);
  CHECK(far.cells < near.cells);  // coarser cells: the distant camera's pixel is wider
  REQUIRE(farImage.pixels.size() == nearImage.pixels.size());
  for (size_t i = 0; i < farImage.pixels.size(); ++i) REQUIRE(farImage.pixels[i] == Approx(nearImage.pixels[i]).margin(0.02));
}
