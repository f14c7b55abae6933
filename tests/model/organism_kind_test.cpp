#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>

#include "core/mesh.h"
#include "core/mesh_io.h"
#include "core/parallel.h"
#include "model/model.h"
#include "model/organism_kind.h"
#include "model/species.h"
#include "organisms/base_mesh.h"
#include "organisms/multires.h"
#include "tests/model/self_intersection.h"
#include "tests/model/species_error.h"
#include "tests/scratch_dir.h"
#include "tests/paths.h"

using namespace sprig;

namespace {

std::string errorOf(const std::string& text) { return test::speciesError(text, "org.yaml"); }

const OrganismSpec& specOf(const Species& s) { return dynamic_cast<const OrganismSpec&>(*s.spec); }

/// The text of an organism on a cube sphere of radius 1 (quads per face edge, 3 levels) whose
/// blend plane x = 0 gives the +x half (alpha 1) the blend keys blendKeys (lines indented by
/// four spaces, each ending in a newline).
std::string halfBlendedSphere(int quads, const std::string& blendKeys) {
  return "kind: organism\norganism:\n  base: {cube_sphere: {radius: 1, quads: " + std::to_string(quads) +
         "}}\n  levels: 3\n  blend:\n    detail: []\n    alpha: {plane: {normal: [1, 0, 0], offset: 0, width: 0}}\n" +
         blendKeys;
}

/// Each vertex away from the blend plane x = 0 (where the limit surface moves a little) has
/// the value plusX on the +x side, minusX on the other.
void checkHalves(const std::vector<Vec3>& positions, const std::vector<Vec3>& values, const Vec3& plusX,
                 const Vec3& minusX) {
  for (size_t v = 0; v < positions.size(); ++v) {
    if (std::abs(positions[v].x) < 0.05f) continue;
    INFO("vertex at x = " << positions[v].x);
    REQUIRE(values[v] == (positions[v].x > 0 ? plusX : minusX));
  }
}

}  // namespace

TEST_CASE("kind: organism reads its keys", "[model][organism]") {
  const Species s = parseSpecies(R"(kind: organism
organism:
  base: {cube_sphere: {radius: 1, quads: 2}}
  levels: 3
  detail:
    - rock: {amplitude: 0.05, levels: [1, 3]}
    - tentacle: {length: 0.05, spin_deg: 90, seeds: {control_vertices: true}}
  modify:
    - {center: [0, 1, 0], radius: 0.3, gains: [1, 0, 1, 2]}
)", "org.yaml");
  const OrganismSpec& o = specOf(s);
  CHECK(o.base.faceCount() == 24);
  CHECK(o.levels == 3);
  CHECK(o.detail.size() == 2);
  CHECK(o.detail[0]->name() == "rock");
  CHECK(o.animated);       // the tentacle spins
  CHECK(o.frames == 24);   // animated organisms default to 24 stages
  REQUIRE(o.modifications.size() == 1);
  CHECK(o.modifications[0].gains.size() == 4);

  SECTION("the mesh is closed with 2 triangles per finest quad and one colour per vertex") {
    const Mesh m = buildOrganismMesh(o, 1.0, Vec3(0.5f));
    CHECK(m.triangleCount() == 2u * 24u * 64u);
    CHECK(m.colors.size() == m.vertexCount());
    CHECK(m.normals.size() == m.vertexCount());
    const MeshTopology topo = analyzeTopology(m);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    CHECK(signedVolume(m) > 0);
  }
  SECTION("same bytes at 1 and 2 threads") {
    Mesh a, b;
    {
      ThreadLimit limit(1);
      a = buildOrganismMesh(o, 0.5, Vec3(0.5f));
    }
    {
      ThreadLimit limit(2);
      b = buildOrganismMesh(o, 0.5, Vec3(0.5f));
    }
    REQUIRE(a.vertexCount() == b.vertexCount());
    CHECK(std::memcmp(a.positions.data(), b.positions.data(), a.vertexCount() * sizeof(Vec3)) == 0);
    CHECK(std::memcmp(a.normals.data(), b.normals.data(), a.vertexCount() * sizeof(Vec3)) == 0);
  }
  SECTION("stages are times") {
    SpeciesModel model(s);
    CHECK(model.finalStage().time == 1.0);
    CHECK(model.stageFromIndex(0).time == 0.0);
    CHECK(model.stageFromIndex(23).time == 1.0);
    CHECK_THROWS_AS(model.stageFromIndex(24), UsageError);
  }
}

TEST_CASE("kind: organism reports its mistakes at file:line:col", "[model][organism]") {
  CHECK(errorOf("kind: organism\norganism:\n  base: {cube_sphere: {}}\n  detail:\n    - rok: {}\n")
            .find("org.yaml:5:7: error: unknown detail entry 'rok' (did you mean 'rock'?)") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  levels: 3\n  base: {cube_sphere: {}}\n  detail:\n    - rock: {levels: [1, 5]}\n")
            .find("org.yaml:6:22: error: level range [1, 5] lies outside the organism's levels 0..3") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {sphere: {}}\n")
            .find("org.yaml:3:10: error: unknown base 'sphere'") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {cube_sphere: {radius: 1}}\n  levels: 9\n")
            .find("org.yaml:4:11: error: 'levels' is 9, out of range [1, 8]") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {cube_sphere: {quads: 64}}\n  levels: 8\n")
            .find("more than the limit 16777216") != std::string::npos);
  // A profile expression's error points into the expression.
  const std::string e = errorOf(
      "kind: organism\norganism:\n  base: {revolution: {profile: \"0.3 + sin(t\", t: [0, 1]}}\n");
  CHECK(e.find("org.yaml:3:") != std::string::npos);
  CHECK(e.find("error:") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {revolution: {profile: \"0.3 - t\", t: [0, 1]}}\n")
            .find("must be finite and >= 0") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {plane: {}}\n  detail:\n    - rock: {output: scalar}\n")
            .find("needs a shader that uses the scalar") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {plane: {}}\n  detail:\n    - mushroom: {cap_radius: 0.5, footprint: 0.4}\n")
            .find("stalk_radius < cap_radius < footprint") != std::string::npos);
  CHECK(errorOf("kind: organism\norganism:\n  base: {plane: {}}\n  blend: {detail: []}\n")
            .find("missing required key 'alpha' in blend") != std::string::npos);
}

TEST_CASE("Organism blends colour by alpha and the planet shader colours by height", "[model][organism]") {
  const Species s = parseSpecies(halfBlendedSphere(2, "    color: [1, 0, 0]\n"), "org.yaml");
  const Mesh m = buildOrganismMesh(specOf(s), 1.0, Vec3(0, 0, 1));
  checkHalves(m.positions, m.colors, Vec3(1, 0, 0), Vec3(0, 0, 1));
}

TEST_CASE("The planet shader mixes toward the second planet's own bands by alpha", "[model][organism]") {
  const Species s = parseSpecies(R"(kind: organism
organism:
  base: {cube_sphere: {radius: 1, quads: 2}}
  detail:
    - rock: {output: scalar}
  shader:
    planet:
      mountain: 0.2
      snow: 0.4
      lowland: [0, 1, 0]
      second: {ocean: [1, 0, 1], lowland: [1, 0.5, 0], highland: [0.5, 0, 0]}
)", "planet.yaml");
  const PlanetShader& p = *specOf(s).planet;
  REQUIRE(p.second);
  // Bands the file does not give keep the first set's: ice is the default in both.
  CHECK(p.second->ice == p.bands.ice);
  CHECK(planetColor(p, 0.1f, 0.0f) == Vec3(0, 1, 0));
  CHECK(planetColor(p, 0.1f, 1.0f) == Vec3(1, 0.5f, 0));
  CHECK(planetColor(p, 0.1f, 0.5f) == Vec3(0.5f, 0.75f, 0));
  CHECK(planetColor(p, 0.3f, 1.0f) == Vec3(0.5f, 0, 0));
  // The sea darkens with depth in both sets alike: at h = -0.1, by 0.6 + 0.4 * 0 = 0.6.
  const Vec3 deep = planetColor(p, -0.1f, 1.0f);
  CHECK(deep.x == Approx(0.6f));
  CHECK(deep.z == Approx(0.6f));
  // Without `second`, alpha tints toward `tint` as before.
  PlanetShader tinted = p;
  tinted.second.reset();
  CHECK(planetColor(tinted, 0.1f, 1.0f) == glm::mix(Vec3(0, 1, 0), tinted.tint, tinted.tintStrength));
  CHECK(errorOf("kind: organism\norganism:\n  base: {plane: {}}\n  detail: [{rock: {output: scalar}}]\n"
                "  shader: {planet: {second: {sea: [0, 0, 1]}}}\n")
            .find("'sea'") != std::string::npos);
}

TEST_CASE("Organism mesh bases: flip turns an inward-wound mesh's details outward", "[model][organism]") {
  test::TempDir dir("organism_mesh_flip");
  // The cube of the test below with every face's corners reversed: wound inward.
  std::ofstream(dir.path / "inward.off") << "OFF\n8 6 0\n-1 -1 -1\n1 -1 -1\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n"
                                            "4 0 1 2 3\n4 4 7 6 5\n4 0 4 5 1\n4 2 6 7 3\n4 1 5 6 2\n4 0 3 7 4\n";
  const PathPolicy policy{dir.path, false};
  // A spur of length 0.5 at every control vertex (the cube's corners), at level 1.
  auto reach = [&](const std::string& flip, const std::string& detail) {
    const Species s = parseSpecies("kind: organism\norganism:\n  base: {mesh: {file: inward.off" + flip +
                                       "}}\n  levels: 2\n  detail: [" + detail + "]\n",
                                   (dir.path / "s.yaml").string(), policy);
    const Mesh m = buildOrganismMesh(specOf(s), 1.0, Vec3(0.5f));
    float far = 0;
    for (const Vec3& p : m.positions) far = std::max(far, glm::length(p));
    return far;
  };
  const std::string spurs = "{spur: {length: 0.5, seeds: {control_vertices: true}}}";
  const float plain = reach("", ""), inward = reach("", spurs), outward = reach(", flip: true", spurs);
  CHECK(reach(", flip: true", "") == plain);  // the surface itself is the same
  CHECK(inward < plain);                      // unflipped, the spurs point into the cube
  CHECK(outward > plain + 0.1f);              // flipped, they stand out of its corners
}

TEST_CASE("Organism bases from mesh files, and captured surfaces", "[model][organism]") {
  test::TempDir dir("organism_mesh_base");
  // A closed quad cube as OFF, and a finer sphere of radius 1.05 as OBJ (Sprig's writer).
  std::ofstream(dir.path / "cube.off") << "OFF\n8 6 0\n-1 -1 -1\n1 -1 -1\n1 1 -1\n-1 1 -1\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\n"
                                          "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";
  {
    const organisms::ControlMesh ball = organisms::cubeSphere(1.05f, 8);
    const organisms::Subdivision sub(ball, 1);
    writeObj(organisms::limitMesh(sub, organisms::referenceLevels(sub, ball.positions).back()), dir.path / "ball.obj");
  }
  const PathPolicy policy{dir.path, false};
  const std::string head = "kind: organism\norganism:\n  base: {mesh: {file: cube.off}}\n  levels: 4\n";
  const Species plain = parseSpecies(head, (dir.path / "a.yaml").string(), policy);
  CHECK(specOf(plain).base.faceCount() == 6);
  const Mesh cube = buildOrganismMesh(specOf(plain), 1.0, Vec3(0.5f));
  CHECK(analyzeTopology(cube).closed());
  // Captured onto the cube: the subdivided cube becomes the sphere of radius 1.05.
  const Species cap = parseSpecies(head + "  capture: {file: ball.obj, max_distance: 0.8}\n  detail: [{captured: {}}]\n",
                                   (dir.path / "b.yaml").string(), policy);
  CHECK(specOf(cap).captureMisses == 0);
  const Mesh ball = buildOrganismMesh(specOf(cap), 1.0, Vec3(0.5f));
  double worst = 0;
  for (const Vec3& p : ball.positions) worst = std::max(worst, std::abs(double(glm::length(p)) - 1.05));
  INFO("worst radius error " << worst);
  CHECK(worst < 0.04);  // the limit surface lies inside the reproduced control points on the sphere
  CHECK(errorOf("kind: organism\norganism:\n  base: {plane: {}}\n  detail: [{captured: {}}]\n")
            .find("'captured' detail needs a 'capture:' section") != std::string::npos);
}

TEST_CASE("Mushroom clouds do not self-intersect, on a plane and on the planet of Fig. 8b", "[model][organism]") {
  // A negative control first: two quads crossing each other are found.
  Mesh cross;
  cross.positions = {{-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}, {0, -1, -0.5f}, {0, 1, -0.5f}, {0, 1, 0.5f}, {0, -1, 0.5f}};
  cross.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  CHECK(test::selfIntersections(cross) > 0);

  const Species onPlane = parseSpecies(R"(kind: organism
organism:
  base: {plane: {size: 2, quads: 4}}
  levels: 6
  detail:
    - mushroom: {height: 0.5, cap_radius: 0.35, cap_top: 0.12, cap_under: 0.08, stalk_radius: 0.08, footprint: 0.6,
                 levels: [2, 6], seeds: {points: [[0, 0, 0]]}}
)", "plane.yaml");
  const Mesh plane = buildOrganismMesh(specOf(onPlane), 1.0, Vec3(0.5f));
  CHECK(plane.bounds().hi.y > 0.45f);  // the mushroom stands up
  CHECK(test::selfIntersections(plane) == 0);
  // Folds within the flat ground are coplanar overlaps the crossing test cannot see
  // reliably: every ground triangle must face up (a kink of the foot at the footprint's
  // edge once folded 136 of them).
  size_t groundFaces = 0, flipped = 0;
  for (const auto& t : plane.triangles) {
    const Vec3 a = plane.positions[t[0]], b = plane.positions[t[1]], c = plane.positions[t[2]];
    if (std::abs(a.y) > 1e-6f || std::abs(b.y) > 1e-6f || std::abs(c.y) > 1e-6f) continue;
    ++groundFaces;
    flipped += glm::cross(b - a, c - a).y <= 0;
  }
  CHECK(groundFaces > 10000);
  CHECK(flipped == 0);

  const Species planet = loadSpecies(std::string(SPRIG_SOURCE_DIR) + "/species/fig_org_08b_mushroom_planet.yaml");
  const Mesh m = buildOrganismMesh(specOf(planet), 1.0, Vec3(0.5f));
  CHECK(m.triangles.size() > 100000);
  CHECK(test::selfIntersections(m) == 0);
}

namespace {

/// An organism cube sphere whose blend plane x = 0 gives the +x half (alpha 1) the blend's
/// surface keys `blendKeys`, rendered 48 x 48 at 1 sample under a point-like white sun from
/// the camera's right, no sky, no ground, black background.
Image blendSurfaceImage(const std::string& blendKeys) {
  const Species s = parseSpecies(halfBlendedSphere(3, blendKeys) + R"(
render:
  color: [0.5, 0.5, 0.5]
  roughness: 0.6
  specular: 0.5
)", "org.yaml");
  SpeciesModel model(s);
  render::Scene scene;
  model.addToScene(scene, model.finalStage(), GeometryMode::Exact, s.render);
  scene.commit();
  render::RenderSettings rs;
  rs.width = rs.height = 48;
  rs.spp = 1;
  rs.threads = 2;
  rs.progress = false;
  rs.ground = false;
  rs.background = render::Background::Color;
  rs.backgroundColor = Vec3(0);
  rs.filter = render::Filter::Box;
  rs.skyFilter = false;
  rs.skyStrength = 0;
  rs.fillStrength = 0;
  rs.sunColor = Vec3(1);
  rs.sunStrength = 1;
  rs.sunAngleDeg = 0;
  rs.sunAzimuthDeg = 0;
  rs.sunElevationDeg = 0;
  return render::renderImage(scene, render::orbitCamera(Vec3(0), 0, 0, 5, 30), rs);
}

/// The largest red over the image columns [x0, x1).
float maxRed(const Image& img, int x0, int x1) {
  float best = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = x0; x < x1; ++x) best = std::max(best, img.at(x, y).r);
  return best;
}

}  // namespace

TEST_CASE("Organism blends roughness, specular and metallic by alpha", "[model][organism]") {
  const Species s = parseSpecies(halfBlendedSphere(2, "    roughness: 1\n    metallic: 0.8\n") +
                                     "render: {roughness: 0.3, specular: 0.2}\n",
                                 "org.yaml");
  const OrganismSpec& o = specOf(s);
  CHECK(o.blendRoughness == 1.0f);
  CHECK(!o.blendSpecular);
  CHECK(o.blendMetallic == 0.8f);
  const OrganismSurface surface = buildOrganismSurface(o, organisms::Subdivision(o.base, o.levels), 1.0);
  const std::vector<Vec3> values = organismSurfaces(o, surface, Vec3(0.3f, 0.2f, 0.0f));
  REQUIRE(values.size() == surface.mesh.vertexCount());
  // The specular the blend leaves out is the render's on both sides.
  checkHalves(surface.mesh.positions, values, Vec3(1.0f, 0.2f, 0.8f), Vec3(0.3f, 0.2f, 0.0f));
  // The export: glTF's factors are per material, so the alpha > 1/2 side is its own part.
  SpeciesModel model(s);
  const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
  REQUIRE(parts.size() == 2);
  CHECK(parts[0].name == "organism");
  CHECK(parts[0].material.roughness == 0.3f);
  CHECK(parts[0].material.metallic == 0.0f);
  CHECK(parts[1].name == "organism_blend");
  CHECK(parts[1].material.roughness == 1.0f);
  CHECK(parts[1].material.metallic == 0.8f);
  CHECK(parts[0].mesh.triangleCount() + parts[1].mesh.triangleCount() == buildOrganismMesh(o, 1.0, Vec3(0.5f)).triangleCount());
  CHECK(std::none_of(parts[1].mesh.positions.begin(), parts[1].mesh.positions.end(), [](const Vec3& p) { return p.x < -0.3f; }));
  // No surface key in the blend: no per-vertex values (the material applies everywhere).
  const Species plain = parseSpecies(
      "kind: organism\norganism:\n  base: {cube_sphere: {}}\n  levels: 2\n  blend:\n    detail: []\n"
      "    alpha: {plane: {normal: [1, 0, 0]}}\n", "org.yaml");
  const OrganismSpec& p = specOf(plain);
  CHECK(organismSurfaces(p, buildOrganismSurface(p, organisms::Subdivision(p.base, p.levels), 1.0), Vec3(0.5f)).empty());
}

TEST_CASE("An organism's blend with roughness 1 has no highlight on its side", "[model][organism][render]") {
  // The sun stands at the camera, so the broad highlight (roughness 0.6) sits at the
  // sphere's centre, where the plane x = 0 cuts it in two. The halves are compared 6 pixels
  // and more from the seam (triangles across it interpolate the two surfaces). Without
  // blend keys both halves have the highlight; diffuse alone stays at or below 0.5.
  const Image plain = blendSurfaceImage("");
  const Image rough = blendSurfaceImage("    roughness: 1\n");
  CHECK(maxRed(plain, 0, 18) > 0.9f);
  CHECK(maxRed(plain, 30, 48) > 0.9f);
  const float roughLeft = maxRed(rough, 0, 18), roughRight = maxRed(rough, 30, 48);
  CHECK(std::max(roughLeft, roughRight) > 0.9f);     // the render's side keeps its highlight
  CHECK(std::min(roughLeft, roughRight) <= 0.501f);  // the blend's side is diffuse alone
}
