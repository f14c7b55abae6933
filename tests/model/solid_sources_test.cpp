// The distance-field sources of solids read from species files: extrude_2d (an image mask
// extruded) and species (another Sprig species as a field).
#include <catch2/catch.hpp>

#include <fstream>

#include "core/image.h"
#include "core/mesh.h"
#include "core/mesh_clean.h"
#include "model/model.h"
#include "model/solid_kind.h"
#include "model/species.h"
#include "solids/solid.h"
#include "tests/scratch_dir.h"
#include "tests/paths.h"

using namespace sprig;

namespace {

void writeText(const std::filesystem::path& path, const std::string& text) { std::ofstream(path) << text; }

std::string loadError(const std::filesystem::path& path, const PathPolicy& policy) {
  try {
    loadSpecies(path, policy);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

float at(const solids::FieldPtr& f, Vec3 p) { return f->sample({p}, 0.02, 1.0)[0]; }

/// The visible interface of m as a mesh (for its topology).
Mesh interfaceMesh(const solids::TetMesh& m) {
  Mesh out;
  for (const DVec3& p : m.positions) out.positions.push_back(Vec3(p));
  for (const auto& t : solids::visibleInterface(m)) out.triangles.push_back({t.v[0], t.v[1], t.v[2]});
  return out;
}

}  // namespace

TEST_CASE("kind: solid reads extrude_2d of a PNG", "[model][solid]") {
  test::TempDir dir("extrude2d");
  // 100 x 100 pixels over 2 x 2 world units (0.02 per pixel): a black square of 40 x 40
  // pixels (0.8 x 0.8 world) centred, on white. Written with OpenImageIO (core/image).
  Image img(100, 100, Vec4(1, 1, 1, 1));
  for (int y = 30; y < 70; ++y)
    for (int x = 30; x < 70; ++x) img.set(x, y, Vec4(0, 0, 0, 1));
  writeImage(img, dir.path / "square.png");
  writeText(dir.path / "s.yaml", R"(kind: solid
solid:
  grid: {cell: 0.05}
  volume:
    distance_field: {extrude_2d: {file: square.png, size: [2, 2], center: [0.5, 0], height: [-0.25, 0.25]}}
    layers: [{interior_layer: {material: wood, thickness: fill}}]
)");
  PathPolicy policy;
  policy.root = dir.path;
  const Species s = loadSpecies(dir.path / "s.yaml", policy);
  const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
  REQUIRE(spec.solid.volumes.size() == 1);
  const solids::FieldPtr f = spec.solid.volumes[0].field;
  const double px = 0.02;
  // The square is 0.8 wide about (u, v) = (0.5, 0): x in [0.1, 0.9], z in [-0.4, 0.4].
  CHECK(at(f, Vec3(0.5, 0, 0)) == Approx(-0.25).margin(1e-4));  // the slab ends are nearer than the sides
  CHECK(at(f, Vec3(0.5, 0.25, 0)) == Approx(0).margin(1e-4));
  CHECK(at(f, Vec3(0.5, 0.6, 0)) == Approx(0.35).margin(1e-4));
  CHECK(at(f, Vec3(0.15, 0, 0)) == Approx(-0.05).margin(px));   // 0.05 from the side x = 0.1
  CHECK(at(f, Vec3(-0.3, 0, 0)) == Approx(0.4).margin(px));     // 0.4 beyond that side
  CHECK(at(f, Vec3(0.5, 0, 0.7)) == Approx(0.3).margin(px));
  CHECK(at(f, Vec3(1.3, 0.65, 0.7)) == Approx(std::sqrt(0.4 * 0.4 + 0.3 * 0.3 + 0.4 * 0.4)).margin(px));  // the corner
  CHECK(at(f, Vec3(-3, 0, 0)) > 0);
  const auto b = f->bounds();
  REQUIRE(b);
  CHECK(b->lo.x == Approx(-0.5));
  CHECK(b->hi.x == Approx(1.5));
  CHECK(b->lo.y == Approx(-0.25));

  SECTION("the solid meshes: tetrahedra, and a closed visible interface") {
    const solids::TetMesh m = solids::meshSolid(spec.solid, spec.grid);
    CHECK(m.tets.size() > 0);
    CHECK(analyzeTopology(interfaceMesh(m)).closed());
    double v = 0;
    for (size_t t = 0; t < m.tets.size(); ++t) v += m.volume(t);
    CHECK(v == Approx(0.8 * 0.8 * 0.5).epsilon(0.05));
  }
  SECTION("threshold picks the dark pixels") {
    writeText(dir.path / "t.yaml", R"(kind: solid
solid:
  grid: {cell: 0.05}
  volume:
    distance_field: {extrude_2d: {file: square.png, size: [2, 2], threshold: 0}}
    layers: [{interior_layer: {material: wood, thickness: fill}}]
)");
    // No pixel is darker than 0: the region is empty, so the field is positive everywhere.
    const Species t = loadSpecies(dir.path / "t.yaml", policy);
    CHECK(at(dynamic_cast<const SolidSpec&>(*t.spec).solid.volumes[0].field, Vec3(0, 0.5, 0)) > 0);
  }
}

TEST_CASE("kind: solid reads another species as a distance field", "[model][solid]") {
  test::TempDir dir("species-field");
  PathPolicy policy;
  policy.allowOutside = true;
  const std::string bulge = std::string(SPRIG_SOURCE_DIR) + "/species/blob_bulge_fig9.yaml";
  writeText(dir.path / "s.yaml", "kind: solid\nsolid:\n  grid: {cell: 0.06}\n  volume:\n    distance_field: {species: {file: " +
                                     bulge + "}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
  const Species s = loadSpecies(dir.path / "s.yaml", policy);
  const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
  const solids::FieldPtr f = spec.solid.volumes[0].field;
  // blob_bulge_fig9: segments of iso radius 0.2 along x = -1 and x = 1, y from 0 to 2.
  std::vector<Vec3> pts = {Vec3(-1, 0.5, 0), Vec3(1, 1.5, 0), Vec3(0, 1, 0), Vec3(-1, 0.5, 0.5)};
  const std::vector<float> d = f->sample(pts, 0.03, 0.4);  // values beyond the band 0.4 are clamped to it
  CHECK(d[0] < -0.1f);
  CHECK(d[1] < -0.1f);
  CHECK(d[2] > 0.35f);
  CHECK(d[3] == Approx(0.3).margin(0.03));

  SECTION("the solid meshes: tetrahedra, and a closed visible interface") {
    const solids::TetMesh m = solids::meshSolid(spec.solid, spec.grid);
    CHECK(m.tets.size() > 0);
    CHECK(analyzeTopology(interfaceMesh(m)).closed());
  }
  SECTION("errors name the file key") {
    writeText(dir.path / "loop.yaml", "kind: solid\nsolid:\n  volume:\n    distance_field: {species: {file: loop.yaml}}\n"
                                      "    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
    CHECK(loadError(dir.path / "loop.yaml", policy).find("loop.yaml:4:38: error: species files refer to each other in a cycle: "
                                                         "loop.yaml -> loop.yaml") != std::string::npos);
    const std::string sphere = std::string(SPRIG_SOURCE_DIR) + "/species/solid_layered_sphere.yaml";
    writeText(dir.path / "solid.yaml", "kind: solid\nsolid:\n  volume:\n    distance_field: {species: {file: " + sphere +
                                           "}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
    CHECK(loadError(dir.path / "solid.yaml", policy).find("solid.yaml:4:38: error:") != std::string::npos);
    CHECK(loadError(dir.path / "solid.yaml", policy).find("a solid species is not a distance field") != std::string::npos);
    writeText(dir.path / "seed.yaml", "kind: solid\nsolid:\n  volume:\n    distance_field: {species: {file: " + bulge +
                                          ", seed: 3}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
    CHECK(loadError(dir.path / "seed.yaml", policy).find("'seed' replaces a tree's derivation seed") != std::string::npos);
    PathPolicy strict;
    strict.root = dir.path;
    CHECK(loadError(dir.path / "s.yaml", strict).find("s.yaml:5:38: error:") != std::string::npos);  // absolute path refused
  }
}

// A species field takes the species' surface cleaned as `sprig mesh` cleans it, the same
// surface an organism's species base takes (SpeciesModel::cleanSurface): a ball of radius
// 0.45 meshes with a speck beside it (a ball of radius 0.02, 8.8e-5 of the volume, below
// the cleaning's 1e-4), which the solid does not see.
TEST_CASE("kind: solid's species field leaves out the species' specks", "[model][solid]") {
  test::TempDir dir("species-field-speck");
  PathPolicy policy;
  policy.allowOutside = true;
  writeText(dir.path / "speck.yaml", "kind: blob\nblob:\n  union:\n    - {point: {center: [0, 0, 0], radius: 0.45}}\n"
                                     "    - {point: {center: [1, 0, 0], radius: 0.02}}\nmesh: {cell: 0.01}\n");
  SpeciesModel base(loadSpecies(dir.path / "speck.yaml", policy));
  size_t raw = 0, cleaned = 0;
  triangleComponents(base.buildMesh(base.finalStage(), 0.0f, false), &raw);
  MeshCleanReport report;
  triangleComponents(base.cleanSurface({}, &report), &cleaned);
  CHECK(raw == 2);
  CHECK(cleaned == 1);
  CHECK(report.specks == 1);
  CHECK(report.voids == 0);

  writeText(dir.path / "s.yaml", "kind: solid\nsolid:\n  grid: {cell: 0.1}\n  volume:\n    distance_field: {species: {file: speck.yaml}}\n"
                                 "    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
  const Species s = loadSpecies(dir.path / "s.yaml", policy);
  const solids::FieldPtr f = dynamic_cast<const SolidSpec&>(*s.spec).solid.volumes[0].field;
  const std::vector<float> d = f->sample({Vec3(1, 0, 0), Vec3(0, 0, 0), Vec3(0.75, 0, 0)}, 0.02, 0.6);
  CHECK(d[0] == Approx(0.55).margin(0.02));  // the speck's centre: outside, 0.55 from the ball
  CHECK(d[1] == Approx(-0.45).margin(0.02));
  CHECK(d[2] == Approx(0.3).margin(0.02));
}

// A wall thinner than the grid's cell (a plate 0.018 thick, tilted against the grid of cell
// 0.05) meshes to a lace of 64 fragments holding 5% of its volume: only the nodes within
// 0.009 of its mid-plane are inside. Grown by an offset of 0.044 (0.88 of the cell, above the
// lattice's covering radius √3/2 cell: every point of the plate then has a node inside
// within the offset), it is 0.106 thick and meshes to one closed piece, the plate dilated by
// a ball of radius 0.044.
TEST_CASE("kind: solid's surface_mesh offset keeps a wall thinner than the cell whole", "[model][solid]") {
  test::TempDir dir("thin-wall");
  const Vec3 n = glm::normalize(Vec3(1, 2, 3));
  const Vec3 u = glm::normalize(glm::cross(n, Vec3(0, 0, 1)));
  const Vec3 v = glm::cross(u, n);  // (u, n, v) right-handed: the cube's faces stay outward
  const float half[3] = {0.4f, 0.009f, 0.4f};
  {
    std::ofstream obj(dir.path / "plate.obj");
    for (int k = 0; k < 8; ++k) {
      const Vec3 p = float((k & 1) ? 1 : -1) * half[0] * u + float((k & 2) ? 1 : -1) * half[1] * n +
                     float((k & 4) ? 1 : -1) * half[2] * v + Vec3(0.013f, -0.021f, 0.007f);
      obj << "v " << p.x << " " << p.y << " " << p.z << "\n";
    }
    obj << "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
  }
  auto mesh = [&](const std::string& offset) {
    writeText(dir.path / "s.yaml", "kind: solid\nsolid:\n  grid: {cell: 0.05}\n  volume:\n    distance_field: {surface_mesh: {file: plate.obj" +
                                       offset + "}}\n    layers: [{interior_layer: {material: wood, thickness: fill}}]\n");
    PathPolicy policy;
    policy.allowOutside = true;
    const Species s = loadSpecies(dir.path / "s.yaml", policy);
    const auto& spec = dynamic_cast<const SolidSpec&>(*s.spec);
    return std::make_pair(spec.solid.volumes[0].field, solids::meshSolid(spec.solid, spec.grid));
  };
  auto pieces = [](const solids::TetMesh& m) {
    const solids::BoundarySurface b = solids::boundarySurface(m);
    Mesh out;
    for (const DVec3& p : b.positions) out.positions.push_back(Vec3(p));
    for (const auto& t : b.triangles) out.triangles.push_back({t.v[0], t.v[1], t.v[2]});
    size_t count = 0;
    triangleComponents(out, &count);
    const MeshTopology topo = analyzeTopology(out);
    CHECK(topo.closed());
    CHECK(topo.manifold());
    return count;
  };
  auto volume = [](const solids::TetMesh& m) {
    double sum = 0;
    for (size_t t = 0; t < m.tets.size(); ++t) sum += m.volume(t);
    return sum;
  };

  const auto [thin, thinMesh] = mesh("");
  const size_t before = pieces(thinMesh);
  CHECK(before == 64);
  CHECK(volume(thinMesh) < 0.06 * 0.8 * 0.8 * 0.018);

  const auto [grown, grownMesh] = mesh(", offset: 0.044");
  const Vec3 c(0.013f, -0.021f, 0.007f);
  const std::vector<float> d = grown->sample({c, c + 0.1f * n, c + 0.5f * u}, 0.01, 0.2);
  CHECK(d[0] == Approx(-0.009 - 0.044).margin(1e-3));  // the plate's mid-plane
  CHECK(d[1] == Approx(0.1 - 0.009 - 0.044).margin(1e-3));
  CHECK(d[2] == Approx(0.1 - 0.044).margin(1e-3));  // beyond the rim
  CHECK(pieces(grownMesh) == 1);
  // The plate (a, b, t) dilated by a ball of radius o: abt + 2o(ab + bt + ta) + πo²(a + b + t) + 4πo³/3.
  // Its faces are planes, which the linear tetrahedra hold exactly; its rounded rim, of a
  // radius below the cell, they cut by chords, so the mesh holds a little less.
  const double a = 0.8, b = 0.8, t = 0.018, o = 0.044;
  const double exact = a * b * t + 2 * o * (a * b + b * t + t * a) + M_PI * o * o * (a + b + t) + 4 * M_PI * o * o * o / 3;
  INFO("volume " << volume(grownMesh) << " of " << exact);
  CHECK(volume(grownMesh) < exact);
  CHECK(volume(grownMesh) > 0.95 * exact);
}
