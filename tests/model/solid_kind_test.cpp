#include <catch2/catch.hpp>

#include "core/atomic_file.h"
#include "core/mesh.h"
#include "model/model.h"
#include "model/solid_kind.h"
#include "model/species.h"
#include "solids/solid.h"
#include "tests/model/species_error.h"
#include "tests/scratch_dir.h"

using namespace sprig;

namespace {

std::string errorOf(const std::string& text) { return test::speciesError(text, "solid.yaml"); }

const char* kStriped = R"(kind: solid
materials:
  striped: {select: "x > 0", choices: [white_chocolate, chocolate]}
  my_clay: {base: fired_clay, density: 2000, color: [0.5, 0.3, 0.2]}
solid:
  grid: {cell: 0.1}
  precedence:
    - volume:
        distance_field: {sphere: {center: [0.4, 0, 0], radius: 0.3}}
        layers:
          - interior_layer: {material: my_clay, thickness: fill}
    - volume:
        distance_field: {transform: {distance_field: {box: {size: [1, 1, 1]}}, scale: 1, rotate: {axis: [0, 1, 0], angle_deg: 10}}}
        layers:
          - interior_layer: {material: striped, thickness: fill}
          - exterior_layer: {material: nothing, thickness: 0.1}
          - exterior_layer: {material: foil, thickness: 0.1}
)";

}  // namespace

TEST_CASE("kind: solid reads the paper's language", "[model][solid]") {
  const Species s = parseSpecies(kStriped, "solid.yaml");
  const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
  REQUIRE(spec.solid.volumes.size() == 2);
  CHECK(spec.grid.cell == 0.1);
  // Box: striped inside, nothing 0..0.1 (claims, no tetrahedra), foil 0.1..0.2.
  CHECK(spec.solid.volumes[1].boundaries == std::vector<double>{0.0, 0.1, 0.2});
  CHECK(spec.solid.volumes[1].regions[1] == solids::kNothing);
  CHECK(spec.solid.materials.materials[0].name == "my_clay");
  CHECK(spec.solid.materials.materials[0].density == 2000);

  SECTION("the model renders the visible interface in the materials' colours and writes tetrahedra") {
    SpeciesModel model(s);
    CHECK(model.volumeMeshExtensions() == std::vector<std::string>{".msh", ".vtu", ".mesh"});
    ModelFigures fig;
    const Mesh m = model.buildMesh(model.finalStage(), 0, false, &fig);
    CHECK(fig.primitives > 1000);  // tetrahedra
    // The foil shell (outer and inner surface) plus the box and the sphere's protruding cap.
    CHECK(m.colors.size() == m.positions.size());
    sprig::test::TempDir dir("solid-kind");
    const std::string line = model.writeVolumeMesh(model.finalStage(), dir.path / "s.msh", false);
    CHECK(line.find("tetrahedra") != std::string::npos);
    const std::string text = readFile(dir.path / "s.msh");
    CHECK(text.find("\"my_clay\"") != std::string::npos);
    CHECK(text.find("\"foil\"") != std::string::npos);
    CHECK(text.find("\"white_chocolate\"") != std::string::npos);
    CHECK(text.find("\"chocolate\"") != std::string::npos);
  }
}

TEST_CASE("kind: solid reports every mistake at its file:line:col", "[model][solid]") {
  const std::string head = "kind: solid\nsolid:\n  volume:\n    distance_field: {sphere: {radius: 1}}\n    layers:\n";
  CHECK(errorOf(head + "      - interior_layer: {material: chocolate, thikness: fill}\n")
            .find("solid.yaml:6:47: error: unknown key 'thikness' in interior_layer (did you mean 'thickness'?)") != std::string::npos);
  CHECK(errorOf(head + "      - exterior_layer: {material: chocolate, thickness: fill}\n")
            .find("solid.yaml:6:58: error: 'thickness: fill' is for interior layers") != std::string::npos);
  CHECK(errorOf(head + "      - exterior_layer: {material: chocolate, thickness: -1}\n")
            .find("'thickness' must be positive") != std::string::npos);
  CHECK(errorOf(head + "      - middle_layer: {material: chocolate}\n").find("unknown layer 'middle_layer'") != std::string::npos);
  CHECK(errorOf("kind: solid\nsolid:\n  volume:\n    distance_field: {from_volume_surface: {}}\n    layers: []\n")
            .find("solid.yaml:4:22: error: 'from_volume_surface' is not supported by this version of Sprig") != std::string::npos);
  CHECK(errorOf("kind: solid\nsolid:\n  volume:\n    distance_field: {ground_plane: {}}\n    layers:\n"
                "      - interior_layer: {material: dirt, thickness: 1}\n")
            .find("a volume has no bounds (a ground plane)") != std::string::npos);
  CHECK(errorOf("kind: solid\nmaterials:\n  chocolate: {density: 3}\nsolid:\n  volume:\n    distance_field: {sphere: {}}\n"
                "    layers: [{interior_layer: {material: chocolate, thickness: fill}}]\n")
            .find("solid.yaml:3:3: error: 'chocolate' is a built-in material") != std::string::npos);
  CHECK(errorOf("kind: solid\nsolid: {}\n").find("missing required key 'volume' or 'precedence' in solid") != std::string::npos);
}
