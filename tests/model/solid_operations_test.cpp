#include <catch2/catch.hpp>

#include "model/model.h"
#include "model/solid_kind.h"
#include "model/species.h"
#include "solids/solid.h"
#include "tests/model/species_error.h"

using namespace sprig;

namespace {

/// A ball of bronze under 0.12 of fired clay, with `operations` appended under `solid:`.
std::string mold(const std::string& operations) {
  return "kind: solid\n"
         "solid:\n"
         "  grid: {cell: 0.06}\n"
         "  volume:\n"
         "    distance_field: {sphere: {radius: 0.5}}\n"
         "    layers:\n"
         "      - interior_layer: {material: fired_clay, thickness: 0.12}\n"
         "      - interior_layer: {material: bronze, thickness: fill}\n" +
         (operations.empty() ? std::string() : "  operations:\n" + operations);
}

std::string errorOf(const std::string& text) { return test::speciesError(text, "ops.yaml"); }

size_t tetCount(const Species& s) {
  SpeciesModel model(s);
  ModelFigures fig;
  model.buildMesh(model.finalStage(), 0, false, &fig);
  return size_t(fig.primitives);
}

}  // namespace

TEST_CASE("solid operations: reading", "[model][solid]") {
  const Species s = parseSpecies(mold("    - hammer: {position: [0.5, 0, 0], orientation: [-1, 0, 0], magnitude: 1e7, size: 0.1, affects: [fired_clay], rounds: 2}\n"
                                      "    - displace: {moving: [bronze], offset: [0, 0.001, 0]}\n"),
                                 "ops.yaml");
  const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
  REQUIRE(spec.operations.size() == 2);
  CHECK(spec.operations[0].tool == "hammer");
  CHECK(spec.operations[0].loc.line == 10);
  const auto& h = std::get<solids::HammerOptions>(spec.operations[0].options);
  CHECK(h.position == DVec3(0.5, 0, 0));
  CHECK(h.magnitude == 1e7);
  CHECK(h.size == Approx(0.1));
  CHECK(h.rounds == 2);
  REQUIRE(h.affects.size() == 1);
  CHECK(spec.solid.materials.materials[h.affects[0]].name == "fired_clay");
  const auto& d = std::get<solids::DisplaceOptions>(spec.operations[1].options);
  REQUIRE(d.moving.size() == 1);
  CHECK(spec.solid.materials.materials[d.moving[0]].name == "bronze");
  CHECK(d.offset.y == Approx(0.001));
}

TEST_CASE("solid operations: a hammer blow removes clay from the built model", "[model][solid]") {
  const size_t whole = tetCount(parseSpecies(mold(""), "ops.yaml"));
  const size_t struck = tetCount(parseSpecies(
      mold("    - hammer: {position: [0.5, 0, 0], orientation: [-1, 0, 0], magnitude: 1e7, size: 0.1, affects: [fired_clay]}\n"),
      "ops.yaml"));
  INFO("tetrahedra: " << whole << " whole, " << struck << " after the blow");
  CHECK(whole > 1000);
  CHECK(struck < whole);
}

TEST_CASE("solid operations: mistakes at their file:line:col", "[model][solid]") {
  CHECK(errorOf(mold("    - hamer: {magnitude: 1}\n")).find("ops.yaml:10:7: error: unknown operation 'hamer'") != std::string::npos);
  CHECK(errorOf(mold("    - hamer: {magnitude: 1}\n")).find("did you mean 'hammer'?") != std::string::npos);
  CHECK(errorOf(mold("    - hammer: {magnitud: 1}\n"))
            .find("ops.yaml:10:16: error: unknown key 'magnitud' in hammer (did you mean 'magnitude'?)") != std::string::npos);
  CHECK(errorOf(mold("    - hammer: {magnitude: .nan}\n")).find("ops.yaml:10:27: error: 'magnitude' must be a finite number") !=
        std::string::npos);
  CHECK(errorOf(mold("    - hammer: {affects: [fired_cly]}\n"))
            .find("ops.yaml:10:26: error: unknown material 'fired_cly' (did you mean 'fired_clay'?)") != std::string::npos);
  CHECK(errorOf(mold("    - displace: {offset: [0, 1, 0]}\n")).find("missing required key 'moving' in displace") != std::string::npos);
  CHECK(errorOf(mold("    - displace: {moving: [bronze], stepz: 2}\n")).find("(did you mean 'steps'?)") != std::string::npos);
}

TEST_CASE("solid operations: a failing operation is an error at its entry", "[model][solid]") {
  // Pushing the bronze core 5 m down through the clay, whose lowest vertices are held,
  // would invert tetrahedra: refused when the model is built, at the entry.
  const Species s = parseSpecies(mold("    - displace: {moving: [bronze], offset: [0, -5, 0]}\n"), "ops.yaml");
  SpeciesModel model(s);
  ModelFigures fig;
  try {
    model.buildMesh(model.finalStage(), 0, false, &fig);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()).find("ops.yaml:10:7: error: displace:") != std::string::npos);
  }
}

TEST_CASE("solid operations: polish and the particle tools are read with their defaults", "[model][solid]") {
  const Species s = parseSpecies(mold("    - polish: {position: [0.5, 0, 0], size: 0.2}\n"
                                      "    - dirt: {}\n"
                                      "    - wash: {particles: 50, seed: 4}\n"
                                      "    - erode: {}\n"
                                      "    - lichen: {color: [0.2, 0.3, 0.1]}\n"),
                                 "ops.yaml");
  const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
  REQUIRE(spec.operations.size() == 5);
  const auto& p = std::get<solids::PolishOptions>(spec.operations[0].options);
  REQUIRE(p.affects.size() == 1);
  CHECK(spec.solid.materials.materials[p.affects[0]].name == "fired_clay");
  REQUIRE(p.shiny >= 0);
  CHECK(spec.solid.materials.materials[size_t(p.shiny)].name == "shiny_bronze");
  CHECK(std::get<solids::DirtOptions>(spec.operations[1].options).color == Vec3(0.5f));
  const auto& w = std::get<solids::ParticleOptions>(spec.operations[2].options);
  CHECK(w.tool == solids::ParticleTool::Wash);
  CHECK(w.particles == 50);
  CHECK(w.seed == 4);
  CHECK(w.radius == 0.1);
  const auto& e = std::get<solids::ParticleOptions>(spec.operations[3].options);
  CHECK(e.tool == solids::ParticleTool::Erode);
  CHECK(e.particles == 2000);
  const auto& l = std::get<solids::ParticleOptions>(spec.operations[4].options);
  CHECK(l.particles == 40000);
  CHECK(l.color == Vec3(0.2f, 0.3f, 0.1f));
}

TEST_CASE("solid operations: stages play the list one operation at a time", "[model][solid]") {
  const Species s = parseSpecies(mold("    - polish: {position: [0.5, 0, 0], size: 0.2}\n"
                                      "    - polish: {position: [-0.5, 0, 0], size: 0.2}\n"),
                                 "ops.yaml");
  SpeciesModel model(s);
  CHECK(model.finalStage().step == 2);
  const std::vector<Stage> frames = model.animationFrames(6, 0, 2);
  REQUIRE(frames.size() == 3);
  size_t tets[3];
  for (int k = 0; k < 3; ++k) {
    ModelFigures fig;
    model.buildMesh(frames[size_t(k)], 0, false, &fig);
    tets[k] = size_t(fig.primitives);
  }
  CHECK(tets[0] == tetCount(parseSpecies(mold(""), "ops.yaml")));
  CHECK(tets[1] != tets[0]);
  CHECK(tets[2] != tets[1]);
  CHECK(tets[2] == tetCount(s));
  CHECK(model.stageName(frames[1]) == "after operation 1 of 2 (polish)");
}
