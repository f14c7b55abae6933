#include <catch2/catch.hpp>

#include <filesystem>

#include "model/tree_kind.h"
#include "model/growth.h"
#include "model/model.h"
#include "blobtree/polygonize.h"
#include "core/atomic_file.h"
#include "core/mesh_clean.h"
#include "core/mesh_io.h"
#include "core/parallel.h"
#include "tests/paths.h"

using namespace sprig;
using organisms::JunctionModel;
using organisms::TipStyle;

TEST_CASE("readTreeOptions", "[model]") {
  SECTION("defaults from an empty section") {
    auto o = parseTreeOptions("{}", "t.yaml");
    CHECK(o.junctions == JunctionModel::Smooth);
    CHECK(o.deltaA == 1.75);
    CHECK(o.deltaAMulti == 2.75);
    CHECK(o.tips == TipStyle::Taper);
    CHECK(o.bends.angleDeg == 0.0);
  }
  SECTION("every group of keys") {
    auto o = parseTreeOptions(R"(junctions: pcm
delta_a: 1.7
branch_offset: false
tips: hemisphere
seed: 9
prune: {orders: [1, 2], below_height: 2.5, probability: 1, cut_fraction: 0.3}
scars: {internodes: [4, 7], style: knob, stub_length: 2, negative_radius: 0.6}
bends: {angle: 15, order_scale: 0.8, randomness: 0.3, trunk: true}
bark: {enabled: false, v_scale: 3}
leaves: {scale: 1.5}
)", "t.yaml");
    CHECK(o.junctions == JunctionModel::Pcm);
    CHECK(o.deltaA == 1.7);
    CHECK_FALSE(o.branchOffset);
    CHECK(o.tips == TipStyle::Hemisphere);
    CHECK(o.seed == 9);
    CHECK(o.prune.select.orders == std::vector<int>{1, 2});
    CHECK(o.prune.select.belowHeight == 2.5);
    CHECK(o.prune.select.probability == 1.0);
    CHECK(o.prune.cutFraction == 0.3);
    CHECK(o.scars.select.internodes == std::vector<int>{4, 7});
    CHECK(o.scars.style == organisms::ScarStyle::Knob);
    CHECK(o.scars.stubLength == 2.0);
    CHECK(o.scars.negativeRadius == 0.6);
    CHECK(o.bends.angleDeg == 15.0);
    CHECK(o.bends.trunk);
    CHECK_FALSE(o.bark.enabled);
    CHECK(o.bark.vScale == 3.0);
    CHECK(o.leaves.scale == 1.5);
  }
  SECTION("errors carry positions and did-you-mean, all at once") {
    try {
      parseTreeOptions("junctions: pcmm\ndelta_aa: 2\nbends: {angel: 3}\n", "t.yaml");
      FAIL("no throw");
    } catch (const InputError& e) {
      const std::string msg = e.what();
      CHECK(msg.find("t.yaml:1:12: error:") != std::string::npos);
      CHECK(msg.find("t.yaml:2:1: error: unknown key 'delta_aa' in tree (did you mean 'delta_a'?)") != std::string::npos);
      CHECK(msg.find("unknown key 'angel' in bends (did you mean 'angle'?)") != std::string::npos);
    }
  }
  SECTION("ranges") {
    CHECK_THROWS_AS(parseTreeOptions("prune: {probability: 2}", "t.yaml"), InputError);
    CHECK_THROWS_AS(parseTreeOptions("bends: {angle: 100}", "t.yaml"), InputError);
  }
}

namespace {

// Grows a tree species at `steps`, polygonizes its wood on a fixed grid and returns the
// bytes of the PLY file written from that mesh.
std::string treePlyBytes(const std::string& speciesFile, int steps, const std::filesystem::path& out) {
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;  // ctest runs in the build folder; the grammar is ../grammars
  const Species species =
      loadSpecies(std::filesystem::path(SPRIG_SOURCE_DIR) / "species" / speciesFile, policy);
  GrowthOptions grow;
  grow.extra.derivationLength = steps;
  GrowthEngine engine(species, grow);
  const lsystem::Skeleton skeleton = engine.skeletonAt(engine.lastStep());
  const TreeSurface model = buildTreeSurface(skeleton, treeSpec(species).surface.value_or(organisms::TreeOptions{}));
  blobtree::PolygonizeOptions po;
  po.cellSize = 0.02f;
  const Mesh mesh = blobtree::polygonize(*model.compiled, po);
  REQUIRE(mesh.triangleCount() > 1000);
  writePly(mesh, out);
  return readFile(out);
}

}  // namespace

TEST_CASE("tree species: same file and seed, same mesh bytes", "[model]") {
  // PCM junctions, random bends and a leaf-less poplar: every seeded choice of the
  // builder is on the way from the species file to the PLY bytes.
  const auto dir = std::filesystem::temp_directory_path() / "sprig_tree_determinism";
  std::filesystem::create_directories(dir);
  const std::string a = treePlyBytes("tree_poplar_pcm.yaml", 5, dir / "a.ply");
  const std::string b = treePlyBytes("tree_poplar_pcm.yaml", 5, dir / "b.ply");
  std::string one, two;
  {
    ThreadLimit limit(1);
    one = treePlyBytes("tree_poplar_pcm.yaml", 5, dir / "one.ply");
  }
  {
    ThreadLimit limit(2);
    two = treePlyBytes("tree_poplar_pcm.yaml", 5, dir / "two.ply");
  }
  CHECK(a.size() > 10000);
  CHECK(a == b);
  CHECK(one == a);
  CHECK(two == a);
  std::filesystem::remove_all(dir);
}

TEST_CASE("tree species: Fig. 13's five-branch PCM junction meshes to one closed part", "[model]") {
  // Three of the five branches interpenetrate near the branching point; the wood is one
  // closed, outward piece before any cleaning (it was three: two voids inside the junction,
  // too large for the cleaning's volume fraction).
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  const Species species =
      loadSpecies(std::filesystem::path(SPRIG_SOURCE_DIR) / "species" / "fig_tree_13_pcm_higher.yaml", policy);
  SpeciesModel model(species, ModelOptions{});
  ModelFigures fig;
  const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false, {}, &fig);
  REQUIRE(parts.size() == 1);
  const Mesh& wood = parts[0].mesh;
  CHECK(parts[0].name == "wood");
  CHECK(wood.triangleCount() > 10000);
  CHECK(fig.clean.componentsBefore == 1);
  size_t pieces = 0;
  triangleComponents(wood, &pieces);
  CHECK(pieces == 1);
  const MeshTopology topo = analyzeTopology(wood);
  CHECK(topo.closed());
  CHECK(topo.manifold());
  CHECK(topo.inconsistentEdges == 0);
  CHECK(signedVolume(wood) > 0);
}

namespace {

/// A vlab object of tests/assets/cpfg loaded as the CLI loads it without --root (the
/// object's folder is its own library root), whatever the current folder.
Species loadCpfgObject(const char* name) {
  PathPolicy policy;
  policy.root.clear();
  return loadSpecies(std::filesystem::path(SPRIG_SOURCE_DIR) / "tests/assets/cpfg" / name, policy);
}

}  // namespace

TEST_CASE("cpfg colour map of a vlab object", "[model][cpfg]") {
  SECTION("tests/assets/cpfg/colormap: the specifications' -m plant.map, entry i for colour index i") {
    const Species s = loadCpfgObject("colormap");
    REQUIRE(s.render.style.palette.size() == 256);
    CHECK(s.render.style.palette[1] == Vec3(1.0f, 1.0f, 0.0f));
    CHECK(s.render.style.palette[2] == Vec3(250 / 255.0f, 0.0f, 0.0f));
    CHECK(s.render.style.palette[3] == Vec3(0.0f, 249 / 255.0f, 0.0f));
    CHECK(s.render.style.palette[200] == Vec3(200 / 255.0f));
    // The spheres carry colour indices 1, 2, 3 (`;(1)`, then `;` adds the increment 1).
    GrowthEngine engine(s);
    const lsystem::Skeleton sk = engine.skeletonAt(engine.lastStep());
    REQUIRE(sk.organs.size() == 3);
    for (int k = 0; k < 3; ++k) CHECK(sk.organs[static_cast<size_t>(k)].color == k + 1);
  }
  SECTION("a colour map of another size is an error at the file") {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sprig-cpfg-colormap-test";
    std::filesystem::create_directories(dir);
    writeFileAtomic(dir / "plant.l", "axiom: F\n");
    writeFileAtomic(dir / "plant.map", std::string(10, '\0'));
    try {
      loadSpecies(dir);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message == "a cpfg colour map holds 256 entries of 3 bytes (768 bytes), this file has 10");
    }
    std::filesystem::remove_all(dir);
  }
}

TEST_CASE("cpfg materials file of a vlab object", "[model][cpfg]") {
  SECTION("tests/assets/cpfg/materials: the specifications' -M materials.mat, material i's diffuse colour for colour index i") {
    const Species s = loadCpfgObject("materials");
    REQUIRE(s.render.style.palette.size() == 256);
    // Record 1: diffuse bytes e4 c5 ff (Lilac's petal purple); record 2: 88 b2 46 (green).
    CHECK(s.render.style.palette[1] == Vec3(0xe4 / 255.0f, 0xc5 / 255.0f, 0xff / 255.0f));
    CHECK(s.render.style.palette[2] == Vec3(0x88 / 255.0f, 0xb2 / 255.0f, 0x46 / 255.0f));
    // No record names 3 or 0: cpfg's default material, diffuse white.
    CHECK(s.render.style.palette[3] == Vec3(1.0f));
    CHECK(s.render.style.palette[0] == Vec3(1.0f));
    // Material 1's transparency byte 0x99 is said, not silently dropped.
    int transparencyNotes = 0;
    for (const Diagnostic& d : s.notes)
      if (d.message == "material 1 has transparency 0.60: Sprig draws it opaque") ++transparencyNotes;
    CHECK(transparencyNotes == 1);
    GrowthEngine engine(s);
    const lsystem::Skeleton sk = engine.skeletonAt(engine.lastStep());
    REQUIRE(sk.organs.size() == 3);
    for (int k = 0; k < 3; ++k) CHECK(sk.organs[static_cast<size_t>(k)].color == k + 1);
  }
  SECTION("a materials file that is not whole records is an error at the file") {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sprig-cpfg-materials-test";
    std::filesystem::create_directories(dir);
    writeFileAtomic(dir / "plant.l", "axiom: F\n");
    writeFileAtomic(dir / "plant.mat", std::string(16, '\0'));
    try {
      loadSpecies(dir);
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(e.diagnostics().front().message ==
            "a cpfg materials file holds records of 15 bytes (colour index, transparency, ambient, diffuse, emissive, "
            "specular, shininess), this file has 16 bytes");
    }
    std::filesystem::remove_all(dir);
  }
}

TEST_CASE("cpfg background scene of a vlab object", "[model][cpfg][background]") {
  // tests/assets/cpfg/background: 5 materials, 5,002 triangles (lsystem/cpfg_background.h).
  SECTION("without a colour map or materials file: not drawn, as cpfg draws none in index mode; a note") {
    const Species s = loadCpfgObject("background");
    CHECK_FALSE(s.render.style.cpfgBackground);
    int notes = 0;
    for (const Diagnostic& d : s.notes) notes += d.message.rfind("the background scene is not drawn", 0) == 0;
    CHECK(notes == 1);
  }
  SECTION("with a colour map: one mesh part drawn with the plant, each triangle in its material's diffuse colour") {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "sprig-cpfg-background-test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    for (const char* f : {"plant.l", "plant.v", "background.dat"})
      std::filesystem::copy_file(std::filesystem::path(SPRIG_SOURCE_DIR) / "tests/assets/cpfg/background" / f, dir / f);
    writeFileAtomic(dir / "plant.map", std::string(768, '\x80'));
    const Species s = loadSpecies(dir);
    REQUIRE(s.render.style.cpfgBackground);
    const render::MeshPart& part = *s.render.style.cpfgBackground;
    REQUIRE(part.mesh.triangleCount() == 5002);
    REQUIRE(part.triangleColors.size() == 5002);
    CHECK(part.triangleColors.front() == Vec3(0.5f, 0.2f, 0.2f));  // the first material's diffuse
    CHECK(part.triangleColors.back() == Vec3(0.2f, 0.4f, 0.5f));   // the last's
    SpeciesModel model(s);
    const BuiltStage built = model.build(model.finalStage(), GeometryMode::Skeleton, s.render);
    size_t found = 0;
    for (const render::GeometryPart& p : built.geometry.parts)
      if (const auto* m = std::get_if<render::MeshPart>(&p)) found += m->mesh.triangleCount() == 5002;
    CHECK(found == 1);
    std::filesystem::remove_all(dir);
  }
}
