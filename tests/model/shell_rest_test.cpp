#include "model/model.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>

#include "blobtree/polygonize.h"
#include "model/shell_kind.h"
#include "render/scene.h"

using namespace sprig;

namespace {

/// Three whorls of the Murex generating surface (point and canal) with varices, small and
/// quick to build; `rest` is the render key's value.
std::string restingShell(const std::string& rest) {
  return R"(kind: shell
render: {width: 48, height: 32, samples: 1, rest: )" + rest + R"(}
shell:
  whorls: 3
  generating: murex
  varices: {spines: [[[-40, 0.8], [0, 1.2], [40, 0.8]]], lip: false}
  opening: {inner_scale: 0.8}
)";
}

const ShellSpec& shellOf(const Species& s) { return dynamic_cast<const ShellSpec&>(*s.spec); }

/// The lowest y of the blob's surface: its polygonization's vertices, which lie on the
/// surface, at cells of diagonal / 600.
float lowestSurfaceY(const blobtree::CompiledBlob& blob) {
  blobtree::PolygonizeOptions po;
  po.cellSize = glm::length(blob.bounds().size()) / 600.0f;
  const Mesh m = blobtree::polygonize(blob, po);
  REQUIRE(!m.positions.empty());
  float lo = m.positions.front().y;
  for (const Vec3& p : m.positions) lo = std::min(lo, p.y);
  return lo;
}

}  // namespace

TEST_CASE("render.rest: a shell lies on the ground, touching it", "[model][rest]") {
  const Species lying = parseSpecies(restingShell("aperture_up"), "lying.yaml");
  const Species standing = parseSpecies(restingShell("as_built"), "standing.yaml");
  REQUIRE(lying.render.rest == RestPose::ApertureUp);
  REQUIRE(standing.render.rest == RestPose::None);
  const ShellSpec& spec = shellOf(lying);
  const ShellBuild asBuilt = buildShell(spec);
  const glm::dmat4 pose = shellRestingPose(asBuilt, true);
  const ShellBuild rested = buildShell(spec, std::nullopt, pose);
  const float diagonal = glm::length(asBuilt.blob->bounds().size());

  SECTION("the pose is a rigid turn that lays the shell's axis down") {
    const glm::dmat3 turn(pose);
    CHECK(glm::determinant(turn) == Approx(1.0));
    // The axis (world y as built) ends up nearer the ground plane than upright.
    const DVec3 axis = turn * DVec3(0, 1, 0);
    CHECK(std::abs(axis.y) < 0.7);
    // The aperture (the spiral's tangent at the lip) faces up rather than down.
    const organisms::ShellModel& m = rested.model;
    const DVec3 lip(m.worldFromShell * glm::dvec4(m.spiral.point(m.endDeg), 1.0));
    const DVec3 ahead(m.worldFromShell * glm::dvec4(m.spiral.point(m.endDeg + 1.0), 1.0));
    CHECK(glm::normalize(ahead - lip).y > 0.0);
  }
  SECTION("the picture's ground is at the rested surface's lowest point") {
    SpeciesModel model(lying);
    render::Scene scene;
    model.addToScene(scene, model.finalStage(), GeometryMode::Exact, lying.render);
    const float ground = restingFrame(model.frameBox(), scene.bounds(), true).lo.y;
    const float lowest = lowestSurfaceY(*rested.blob);
    // The ground touches the lowest point: within 0.2% of the shell's diagonal of it.
    CHECK(std::abs(lowest - ground) < 0.002f * diagonal);
  }
  SECTION("the pose is for pictures: the model's own mesh is the one built as is") {
    SpeciesModel a(lying), b(standing);
    const Mesh ma = a.buildMesh(a.finalStage(), 0.05f, false);
    const Mesh mb = b.buildMesh(b.finalStage(), 0.05f, false);
    REQUIRE(ma.positions.size() == mb.positions.size());
    CHECK(ma.positions == mb.positions);
  }
}

TEST_CASE("render.rest: only shells rest on their side", "[model][rest]") {
  CHECK_THROWS_WITH(parseSpecies("kind: blob\nblob: {point: {center: [0, 0, 0], radius: 1}}\nrender: {rest: aperture_up}\n", "b.yaml"),
                    Catch::Contains("'render.rest' sets a shell down on its side; a blob species has no aperture"));
}
