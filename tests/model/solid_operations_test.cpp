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
