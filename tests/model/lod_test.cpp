#include <catch2/catch.hpp>

#include <tiny_gltf.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "core/parallel.h"
#include "model/leaf_cards.h"
#include "model/lod.h"
#include "model/mesh_parts.h"
#include "model/model.h"
#include "model/species.h"
#include "tests/model/read_glb.h"
#include "tests/organisms/meshes.h"
#include "tests/paths.h"

using namespace sprig;
using test::readGlb;
namespace fs = std::filesystem;

namespace {

// The attributes the test parts carry at a position: a vertex that remains after
// simplification must still have exactly these (collapses move no vertex).
Vec2 uvAt(const Vec3& p) { return {p.x * 0.5f + 0.5f, p.y * 0.25f + 0.5f}; }
Vec3 colorAt(const Vec3& p) { return glm::abs(p) * 0.5f + Vec3(0.1f); }

// A closed "wood" sphere of 20,480 triangles with normals, uvs and colours; "leaves": 400
// unit-area squares (2 triangles each) of one colour each, double-sided and scattered, with
// an atlas of their colours.
std::vector<ExportPart> testParts() {
  ExportPart wood{"wood", test::icosphere(5, Vec3(0.0f), 1.0f), PartMaterial{"wood", Vec3(0.3f, 0.2f, 0.1f), 0.7f, false}};
  for (const Vec3& p : wood.mesh.positions) {
    wood.mesh.normals.push_back(glm::normalize(p));
    wood.mesh.uvs.push_back(uvAt(p));
    wood.mesh.colors.push_back(colorAt(p));
  }
  ExportPart leaves{"leaves", Mesh{}, PartMaterial{"leaves", Vec3(0.1f, 0.4f, 0.05f), 0.5f, true}, true};
  for (int i = 0; i < 400; ++i) {
    const Vec3 o(float(i % 20) * 2.0f, 3.0f, float(i / 20) * 2.0f);
    const auto b = uint32_t(leaves.mesh.positions.size());
    for (Vec3 d : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1)}) {
      leaves.mesh.positions.push_back(o + d);
      leaves.mesh.normals.push_back(Vec3(0, 1, 0));
      leaves.mesh.colors.push_back(Vec3(0.05f + 0.001f * float(i), 0.3f, 0.05f));
    }
    leaves.mesh.triangles.push_back({b, b + 2, b + 1});
    leaves.mesh.triangles.push_back({b, b + 3, b + 2});
  }
  REQUIRE(atlasVertexColors(leaves) > 0);
  return {wood, leaves};
}

double area(const Mesh& m) {
  double a = 0;
  for (const glm::uvec3& t : m.triangles)
    a += 0.5 * glm::length(glm::cross(glm::dvec3(m.positions[t.y] - m.positions[t.x]), glm::dvec3(m.positions[t.z] - m.positions[t.x])));
  return a;
}

struct TempDir {
  fs::path path = fs::temp_directory_path() / ("sprig_lod_test_" + std::to_string(getpid()));
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
};

// Where point p, projected along card quad's normal, falls on the card (cards: 4 vertices a
// quad, corners -u-v, +u-v, +u+v, -u+v): (s, t) across its sides in [0, 1], and its uv.
struct CardPoint {
  double s, t;
  Vec2 uv;
};
CardPoint cardPoint(const Mesh& cards, size_t quad, const glm::dvec3& p) {
  const size_t q = 4 * quad;
  const glm::dvec3 q0(cards.positions[q]), du = glm::dvec3(cards.positions[q + 1]) - q0,
      dv = glm::dvec3(cards.positions[q + 3]) - q0;
  const double s = glm::dot(p - q0, du) / glm::dot(du, du), t = glm::dot(p - q0, dv) / glm::dot(dv, dv);
  return {s, t, cards.uvs[q] + float(s) * (cards.uvs[q + 1] - cards.uvs[q]) + float(t) * (cards.uvs[q + 3] - cards.uvs[q])};
}

// Triangles of a glTF node's mesh.
size_t nodeTriangles(const tinygltf::Model& m, int node) {
  size_t n = 0;
  for (const tinygltf::Primitive& p : m.meshes[size_t(m.nodes[size_t(node)].mesh)].primitives)
    n += m.accessors[size_t(p.indices)].count / 3;
  return n;
}

}  // namespace

TEST_CASE("buildLodChain", "[model][lod]") {
  const std::vector<ExportPart> parts = testParts();
  REQUIRE(partTriangles(parts) == 20480 + 800);

  SECTION("LOD0 within the budget, then a quarter per level, the same parts with their attributes") {
    Vec3 moved(1.0f);
    const std::vector<LodLevel> levels = buildLodChain(parts, 8000, &moved);
    // LOD0 stands on the ground at the origin, every level moved with it.
    CHECK(glm::length(groundOffset(levels[0].parts)) < 1e-6f);
    CHECK(glm::length(moved - groundOffset(parts)) < 0.05f);
    // 8000 -> about 2000 -> about 500 (stops: a quarter of it would be below 500), then the
    // crown level (the model has leaves).
    REQUIRE(levels.size() == 4);
    CHECK(levels[0].triangles <= 8000);
    CHECK(levels[0].triangles >= 7000);
    for (size_t k = 1; k < levels.size(); ++k) {
      CHECK(levels[k].triangles < levels[k - 1].triangles);
      CHECK(double(levels[k].triangles) <= kLodMaxKeep * double(levels[k - 1].triangles));
    }
    CHECK(levels[0].screenCoverage == 0.25);
    CHECK(levels[1].screenCoverage == 0.0625);
    CHECK(levels[2].screenCoverage == 0.015625);
    CHECK(levels[3].screenCoverage == 0.0);
    for (size_t k = 0; k < levels.size(); ++k) {
      const LodLevel& level = levels[k];
      REQUIRE(level.parts.size() == 2);
      CHECK(level.parts[0].name == "wood");
      CHECK(level.parts[1].name == "leaves");
      CHECK(level.triangles == partTriangles(level.parts));
      const Mesh& w = level.parts[0].mesh;
      REQUIRE(w.triangles.size() > 0);
      REQUIRE(w.normals.size() == w.positions.size());
      REQUIRE(w.uvs.size() == w.positions.size());
      REQUIRE(w.colors.size() == w.positions.size());
      // Every vertex keeps its own attributes (a neighbour's differ by about 1e-2).
      size_t own = 0;
      for (size_t v = 0; v < w.positions.size(); ++v) {
        const Vec3 p = w.positions[v] - moved;
        own += glm::length(w.uvs[v] - uvAt(p)) < 1e-5f && glm::length(w.colors[v] - colorAt(p)) < 1e-5f &&
               glm::length(w.normals[v] - glm::normalize(p)) < 1e-5f;
      }
      CHECK(own == w.positions.size());
      // Its colours vary and it had no texture (as a part above the atlas budget): each
      // level bakes them into an atlas.
      REQUIRE(level.parts[0].material.texture);
      CHECK(level.parts[0].material.texture->atlas.index.size() == w.triangles.size() * 3);
      // The sphere stays closed: every edge in two triangles.
      CHECK(analyzeTopology(w).boundaryEdges == 0);
      // Leaves: all 400 kept at LOD0 (they fit in half the budget), then a quarter per level,
      // grown so that they cover the same area; their atlas baked again per level. The last
      // two levels' leaves are cards (the next test cases).
      const ExportPart& l = level.parts[1];
      if (k + 2 >= levels.size()) continue;
      CHECK(area(l.mesh) == Approx(400.0).epsilon(1e-4));
      REQUIRE(l.material.texture);
      CHECK(l.material.texture->atlas.index.size() == l.mesh.triangles.size() * 3);
      CHECK(l.material.doubleSided);
    }
    CHECK(levels[0].parts[1].mesh.triangles.size() == 800);
    CHECK(levels[1].parts[1].mesh.triangles.size() == 200);
    CHECK(levels[2].parts[1].mesh.triangles.size() == 50);  // 25 cards
    CHECK(levels[3].parts[1].mesh.triangles.size() == 12);  // 2 clusters of 3 crown cards
  }
  SECTION("a model within the budget is LOD0 unchanged") {
    std::vector<ExportPart> placed = parts;
    finishExportParts(placed);
    const std::vector<LodLevel> levels = buildLodChain(placed, 30000);
    // 21,280 -> about 5,320 -> about 1,330 (a quarter of it would be below 500), then the crown.
    REQUIRE(levels.size() == 4);
    CHECK(levels[0].triangles == 21280);
    CHECK(levels[0].parts[0].mesh.positions == placed[0].mesh.positions);
    CHECK(levels[0].parts[1].material.texture == placed[1].material.texture);
    CHECK(levels[2].triangles < levels[1].triangles);
    CHECK(levels[1].triangles < levels[0].triangles);
  }
  SECTION("the same parts give the same levels") {
    const std::vector<LodLevel> a = buildLodChain(parts, 8000), b = buildLodChain(parts, 8000);
    REQUIRE(a.size() == b.size());
    for (size_t k = 0; k < a.size(); ++k) {
      CHECK(a[k].parts[0].mesh.triangles == b[k].parts[0].mesh.triangles);
      CHECK(a[k].parts[1].mesh.positions == b[k].parts[1].mesh.positions);
    }
  }
}

TEST_CASE("buildLodChain: the far level's leaves are alpha-tested cards with their leaves' images", "[model][lod]") {
  const std::vector<ExportPart> parts = testParts();
  Vec3 moved(0.0f);
  const std::vector<LodLevel> levels = buildLodChain(parts, 8000, &moved);
  REQUIRE(levels.size() == 4);
  // The wood is still there, closed, and as before a quarter of the level before.
  const Mesh& wood = levels[2].parts[0].mesh;
  CHECK(wood.triangles.size() > 100);
  CHECK(analyzeTopology(wood).boundaryEdges == 0);
  // The far level kept 50 leaf triangles: 25 cards of 4 vertices and 2 triangles each.
  const ExportPart& cards = levels[2].parts[1];
  CHECK(cards.name == "leaves");
  REQUIRE(cards.mesh.triangles.size() == 50);
  REQUIRE(cards.mesh.positions.size() == 100);
  REQUIRE(cards.mesh.uvs.size() == 100);
  REQUIRE(cards.mesh.normals.size() == 100);
  CHECK(cards.mesh.colors.empty());
  for (size_t t = 0; t < 50; ++t) {
    const glm::uvec3& tri = cards.mesh.triangles[t];
    CHECK(tri.x == uint32_t(t / 2 * 4));  // each card its own four vertices
    CHECK(std::max({tri.x, tri.y, tri.z}) < uint32_t(t / 2 * 4 + 4));
  }
  // Cut out (glTF MASK) with the leaves' own image: 5 x 5 cells of 16 texels, not an atlas.
  CHECK(cards.material.alphaCutoff == kLeafCardAlphaCutoff);
  CHECK(cards.material.doubleSided);
  REQUIRE(cards.material.texture);
  CHECK_FALSE(cards.material.texture->isAtlas());
  const Image& im = cards.material.texture->pixels();
  CHECK(im.width == 80);
  CHECK(im.height == 80);
  // Card i is leaf 16i + 15 (evenly spread), a unit square grown 4 times (25 leaves cover
  // the 400 leaves' area): its centre and normal are the leaf's, its 14 x 14 inner texels
  // opaque in the leaf's colour, its rim transparent.
  size_t opaque = 0;
  for (size_t i = 0; i < 25; ++i) {
    const size_t j = 16 * i + 15;
    const Vec3 centre(float(j % 20) * 2.0f + 0.5f, 3.0f, float(j / 20) * 2.0f + 0.5f);
    Vec3 mean(0.0f);
    for (size_t v = 4 * i; v < 4 * i + 4; ++v) {
      mean += 0.25f * (cards.mesh.positions[v] - moved);
      CHECK(glm::length(cards.mesh.normals[v] - Vec3(0, 1, 0)) < 1e-5f);
    }
    CHECK(glm::length(mean - centre) < 1e-4f);
    CHECK(glm::length(cards.mesh.positions[4 * i] - cards.mesh.positions[4 * i + 2]) ==
          Approx(4.0 * std::sqrt(2.0) * 16 / 14).epsilon(1e-4));
    const int x0 = int(i % 5) * 16, y0 = int(i / 5) * 16;
    const Vec4 c = im.at(x0 + 8, y0 + 8);
    CHECK(c.r == Approx(0.05 + 0.001 * double(j)).margin(1e-5));
    CHECK(c.a == 1.0f);
    CHECK(im.at(x0, y0 + 8).a == 0.0f);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) opaque += im.at(x0 + x, y0 + y).a == 1.0f;
  }
  CHECK(opaque == 25 * 14 * 14);
}

TEST_CASE("buildLodChain: the last level is the crown, all the leaves on crown cards, the wood a quarter", "[model][lod]") {
  const std::vector<ExportPart> parts = testParts();
  Vec3 moved(0.0f);
  const std::vector<LodLevel> levels = buildLodChain(parts, 8000, &moved);
  REQUIRE(levels.size() == 4);
  const Mesh& wood = levels[3].parts[0].mesh;
  const double quarter = double(levels[2].parts[0].mesh.triangles.size()) * kLodRatio;
  CHECK(double(wood.triangles.size()) <= quarter + 1);
  CHECK(double(wood.triangles.size()) >= 0.75 * quarter);
  CHECK(analyzeTopology(wood).boundaryEdges == 0);
  // ⌊50 / 4 / 6⌋ = 2 clusters of the 20 x 20 leaves (x and z in [0, 39]), 3 cards each.
  const ExportPart& crown = levels[3].parts[1];
  CHECK(crown.name == "leaves");
  REQUIRE(crown.mesh.triangles.size() == 2 * kCrownCardsPerCluster * 2);
  CHECK(crown.mesh.positions.size() == 2 * kCrownCardsPerCluster * 4);
  CHECK(crown.material.alphaCutoff == kLeafCardAlphaCutoff);
  REQUIRE(crown.material.texture);
  CHECK(crown.material.texture->pixels().width == 3 * kCrownCardTexels);  // 6 cells, 3 a row
  CHECK(crown.material.texture->pixels().height == 2 * kCrownCardTexels);
  // Every leaf is on the three cards of one cluster: its centre, projected along each
  // card's normal, falls inside it (more than a rim texel in).
  size_t inside = 0;
  for (size_t j = 0; j < 400; ++j) {
    const glm::dvec3 p(float(j % 20) * 2.0f + 0.5f + moved.x, 3.0f + moved.y, float(j / 20) * 2.0f + 0.5f + moved.z);
    size_t clusters = 0;
    for (size_t c = 0; c < 2; ++c) {
      size_t in = 0;
      for (size_t k = 0; k < kCrownCardsPerCluster; ++k) {
        const CardPoint a = cardPoint(crown.mesh, c * kCrownCardsPerCluster + k, p);
        in += a.s > 1.0 / kCrownCardTexels && a.s < 1 - 1.0 / kCrownCardTexels && a.t > 1.0 / kCrownCardTexels &&
              a.t < 1 - 1.0 / kCrownCardTexels;
      }
      clusters += in == kCrownCardsPerCluster;
    }
    inside += clusters >= 1;
  }
  CHECK(inside == 400);
}

TEST_CASE("buildLodChain reduces the parts side by side to the same levels at any thread count", "[model][lod]") {
  const std::vector<ExportPart> parts = testParts();
  auto chain = [&](int threads) {
    const ThreadLimit limit(threads);
    return buildLodChain(parts, 8000);
  };
  const std::vector<LodLevel> one = chain(1), two = chain(2);
  REQUIRE(one.size() == 4);
  REQUIRE(two.size() == one.size());
  for (size_t k = 0; k < one.size(); ++k) {
    CHECK(two[k].triangles == one[k].triangles);
    REQUIRE(two[k].parts.size() == 2);
    for (size_t i = 0; i < 2; ++i) {
      const Mesh &a = one[k].parts[i].mesh, &b = two[k].parts[i].mesh;
      CHECK(b.triangles == a.triangles);
      CHECK(b.positions == a.positions);
      CHECK(b.normals == a.normals);
      CHECK(b.colors == a.colors);
    }
    // The maps', atlases' and cards' texels too.
    for (size_t i = 0; i < 2; ++i) {
      const PartTexture* ta = one[k].parts[i].material.texture.get();
      const PartTexture* tb = two[k].parts[i].material.texture.get();
      REQUIRE((ta == nullptr) == (tb == nullptr));
      if (!ta) continue;
      CHECK(tb->pixels().pixels == ta->pixels().pixels);
      CHECK(tb->image8.values == ta->image8.values);
      CHECK(ta->pixels().pixels.size() + ta->image8.values.size() > 0);
    }
  }
}

TEST_CASE("writeLevels", "[model][lod]") {
  TempDir dir;
  const std::vector<LodLevel> levels = buildLodChain(testParts(), 8000);
  REQUIRE(levels.size() == 4);
  SECTION("glb: LOD0 in the scene, each part's lower levels through MSFT_lod; one file per level") {
    const fs::path file = dir.path / "model.glb";
    writeLevels(levels, file);
    CHECK(lodPath(file, 1) == dir.path / "model_lod1.glb");
    const tinygltf::Model m = readGlb(file);
    CHECK(m.extensionsUsed == std::vector<std::string>{"MSFT_lod"});
    CHECK(m.extensionsRequired.empty());
    REQUIRE(m.scenes.size() == 1);
    REQUIRE(m.scenes[0].nodes.size() == 2);
    REQUIRE(m.nodes.size() == 8);
    for (size_t i = 0; i < 2; ++i) {
      const tinygltf::Node& top = m.nodes[size_t(m.scenes[0].nodes[i])];
      CHECK(top.name == levels[0].parts[i].name);
      CHECK(nodeTriangles(m, m.scenes[0].nodes[i]) == levels[0].parts[i].mesh.triangles.size());
      REQUIRE(top.extensions.count("MSFT_lod") == 1);
      const tinygltf::Value& ids = top.extensions.at("MSFT_lod").Get("ids");
      REQUIRE(ids.ArrayLen() == 3);
      const tinygltf::Value& coverage = top.extras.Get("MSFT_screencoverage");
      REQUIRE(coverage.ArrayLen() == 4);
      for (size_t k = 0; k < 4; ++k) CHECK(coverage.Get(int(k)).GetNumberAsDouble() == levels[k].screenCoverage);
      for (size_t k = 1; k < 4; ++k) {
        const int id = ids.Get(int(k - 1)).GetNumberAsInt();
        CHECK(m.nodes[size_t(id)].name == levels[0].parts[i].name + "_lod" + std::to_string(k));
        CHECK(nodeTriangles(m, id) == levels[k].parts[i].mesh.triangles.size());
        // The material keeps the part's name.
        const int mat = m.meshes[size_t(m.nodes[size_t(id)].mesh)].primitives[0].material;
        CHECK(m.materials[size_t(mat)].name == levels[0].parts[i].name);
      }
    }
    // Each level's own file (LOD0's too): the parts by their own names, that level's triangles.
    for (size_t k = 0; k < 4; ++k) {
      const tinygltf::Model f = readGlb(lodPath(file, k));
      CHECK(f.extensionsUsed.empty());
      REQUIRE(f.nodes.size() == 2);
      for (size_t i = 0; i < 2; ++i) {
        CHECK(f.nodes[i].name == levels[k].parts[i].name);
        CHECK(nodeTriangles(f, int(i)) == levels[k].parts[i].mesh.triangles.size());
      }
    }
    CHECK_FALSE(fs::exists(lodPath(file, 4)));
  }
  SECTION("OBJ: LOD0 in the file, every further level in its own OBJ, MTL and images") {
    const fs::path file = dir.path / "model.obj";
    writeLevels(levels, file);
    for (const char* name : {"model.obj", "model.mtl", "model_leaves.png", "model_lod1.obj", "model_lod1.mtl",
                             "model_lod1_leaves.png", "model_lod2.obj", "model_lod2.mtl", "model_lod2_leaves.png",
                             "model_lod3.obj", "model_lod3.mtl", "model_lod3_leaves.png"})
      CHECK(fs::exists(dir.path / name));
    CHECK_FALSE(fs::exists(dir.path / "model_lod0.obj"));  // the OBJ itself is LOD0
  }
  SECTION("a failure leaves no file of the call behind") {
    fs::create_directories(dir.path / "taken.glb" / "x");  // the file itself cannot be written
    CHECK_THROWS(writeLevels(levels, dir.path / "taken.glb"));
    CHECK_FALSE(fs::exists(dir.path / "taken_lod0.glb"));
    CHECK_FALSE(fs::exists(dir.path / "taken_lod1.glb"));
    CHECK_FALSE(fs::exists(dir.path / "taken_lod2.glb"));
    CHECK_FALSE(fs::exists(dir.path / "taken_lod3.glb"));
  }
  SECTION("each texture image is encoded once for all the files, to the same bytes") {
    // The level of leaf cards: wood (an atlas and a normal map) and the cards' RGBA image.
    const std::vector<ExportPart>& far = levels[2].parts;
    REQUIRE(far[0].material.normalTexture);
    writeParts(far, dir.path / "alone.glb");
    {
      PngReuse reuse;
      writeParts(far, dir.path / "a.glb");
      CHECK(reuse.encoded() == 3);
      writeParts(far, dir.path / "b.glb");
      CHECK(reuse.encoded() == 3);
    }
    CHECK(readFile(dir.path / "a.glb") == readFile(dir.path / "alone.glb"));
    CHECK(readFile(dir.path / "b.glb") == readFile(dir.path / "alone.glb"));
    // writeLevels: OUT.glb holds the very images of the levels' own files.
    writeLevels(levels, dir.path / "all.glb");
    const tinygltf::Model all = readGlb(dir.path / "all.glb"), two = readGlb(dir.path / "all_lod2.glb");
    const auto png = [](const tinygltf::Model& m, const tinygltf::Image& im) {
      const tinygltf::BufferView& v = m.bufferViews.at(size_t(im.bufferView));
      const std::vector<unsigned char>& b = m.buffers.at(size_t(v.buffer)).data;
      return std::string(b.begin() + long(v.byteOffset), b.begin() + long(v.byteOffset + v.byteLength));
    };
    REQUIRE(two.images.size() == 3);
    for (const tinygltf::Image& im : two.images) {
      size_t same = 0;
      for (const tinygltf::Image& a : all.images) same += a.name == im.name && png(all, a) == png(two, im);
      CHECK(same == 1);
    }
  }
  SECTION("one level writes what writeParts writes") {
    writeLevels({levels[2]}, dir.path / "one.glb");
    writeParts(levels[2].parts, dir.path / "two.glb");
    CHECK(readFile(dir.path / "one.glb") == readFile(dir.path / "two.glb"));
    CHECK_FALSE(fs::exists(dir.path / "one_lod0.glb"));
    CHECK_FALSE(fs::exists(dir.path / "one_lod1.glb"));
  }
}

TEST_CASE("Levels of detail of a shipped tree", "[model][lod]") {
  // The PCM junction of Fig. 12 (11,044 triangles of wood): LOD0 at a budget of 4,000.
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  const Species species = loadSpecies(std::string(SPRIG_SOURCE_DIR) + "/species/fig_tree_12_pcm_offset.yaml", policy);
  SpeciesModel model(species);
  CHECK(model.lodBudget() == 300000);
  std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
  finishExportParts(parts);
  const size_t full = partTriangles(parts);
  CHECK(full == 11044);  // as polygonized: no vertices share a position, so no sliver has zero area
  CHECK(lodLevels(parts, 0).size() == 1);
  CHECK(lodLevels(parts, 0)[0].triangles == full);
  const std::vector<LodLevel> levels = lodLevels(parts, 4000);
  REQUIRE(levels.size() == 2);
  CHECK(levels[0].triangles <= 4000);
  CHECK(levels[1].triangles < levels[0].triangles);
  for (const LodLevel& l : levels) {
    REQUIRE(l.parts.size() == parts.size());
    CHECK(l.parts[0].name == "wood");
    CHECK(analyzeTopology(l.parts[0].mesh).boundaryEdges == 0);
  }
  SECTION("levels polygonize the wood at the coarser cell that gives about the triangles asked for") {
    ModelFigures fig;
    std::vector<ExportPart> coarse = model.exportParts(model.finalStage(), 0.0f, false, {}, &fig, 2500);
    const size_t n = coarse[0].mesh.triangles.size();
    INFO("auto cell " << fig.autoCell << ", lod cell " << fig.lodCell << ", triangles " << n);
    CHECK(fig.lodCell > fig.autoCell);
    CHECK(fig.lodCell <= fig.ceilingCell);
    CHECK(fig.ceilingCell <= kLodProbeCells * fig.autoCell);
    CHECK(n >= 1800);
    CHECK(n <= 3500);
    CHECK(analyzeTopology(coarse[0].mesh).boundaryEdges == 0);
    // More than the automatic cell gives: the automatic cell, the same mesh.
    std::vector<ExportPart> same = model.exportParts(model.finalStage(), 0.0f, false, {}, &fig, 50000);
    CHECK(fig.lodCell == fig.autoCell);
    CHECK(same[0].mesh.positions == model.exportParts(model.finalStage(), 0.0f, false)[0].mesh.positions);
  }
}

TEST_CASE("Levels of detail of a shipped shell bake the full mesh's atlases only when written", "[model][lod]") {
  // shell_turret's whorl has growth lines: its atlas is the renderer's colours
  // (atlasBlobPart), deferred until a written file uses it (at cell 0.4: 820 triangles,
  // the whole shell one part; its bake, 210,000 texels, is the test's cost, 3-7 s). Levels of detail bake
  // their own atlases from the colours of the vertices that remain, so with LOD0 below
  // the full mesh the full parts' atlases are never baked; with --lod none they are.
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  const Species species = loadSpecies(std::string(SPRIG_SOURCE_DIR) + "/species/shell_turret.yaml", policy);
  SpeciesModel model(species);
  std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.4f, false);
  finishExportParts(parts);
  std::vector<std::shared_ptr<const PartTexture>> atlases;
  for (const ExportPart& p : parts)
    if (p.material.texture && p.material.texture->isAtlas()) atlases.push_back(p.material.texture);
  REQUIRE(parts.size() == 1);
  REQUIRE(atlases.size() == 1);  // the whorl's
  for (const auto& tex : atlases) {
    REQUIRE(tex->deferred != nullptr);
    CHECK_FALSE(tex->deferred->baked());
    CHECK(tex->image.pixels.empty());
  }
  const size_t full = partTriangles(parts);
  TempDir dir;
  const std::vector<LodLevel> levels = lodLevels(parts, full / 2);
  CHECK(full == 820);
  REQUIRE(!levels.empty());
  CHECK(levels[0].triangles <= full / 2);
  const fs::path out = dir.path / "turret.glb";
  writeLevels(levels, out);
  for (const auto& tex : atlases) CHECK_FALSE(tex->deferred->baked());
  for (const LodLevel& level : levels)
    for (const ExportPart& p : level.parts) {
      INFO(p.name);
      REQUIRE(p.material.texture != nullptr);  // each level's own atlas, baked now
      CHECK(p.material.texture->isAtlas());
      CHECK(p.material.texture->deferred == nullptr);
      CHECK(p.material.texture->width() > 0);  // 8-bit (image8) where the level got detail maps
    }
  writeLevels(lodLevels(parts, 0), dir.path / "full.glb");
  for (const auto& tex : atlases) {
    REQUIRE(tex->deferred->baked());
    CHECK(tex->pixels().width == atlasLayout(tex->atlas.values.size() / 3).width());
  }
  CHECK(readGlb(dir.path / "full.glb").images.size() == 1);
}

TEST_CASE("leafCards takes a leaf's image and cut-out through its uvs", "[model][lod]") {
  // Three unit squares in the xz plane whose uvs are (x, z), textured by a 2 x 2 image whose
  // left column (s < 1/2) is cut out and whose right column is red; no vertex colours.
  ExportPart leaves{"textured_leaves_1", Mesh{}, PartMaterial{"textured_leaves_1", Vec3(0.2f, 0.5f, 0.1f), 0.5f, true}, true};
  for (int i = 0; i < 3; ++i) {
    const auto b = uint32_t(leaves.mesh.positions.size());
    for (Vec3 d : {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 0, 1), Vec3(0, 0, 1)}) {
      leaves.mesh.positions.push_back(Vec3(float(3 * i), 0.0f, 0.0f) + d);
      leaves.mesh.uvs.push_back(Vec2(d.x, d.z));
    }
    leaves.mesh.triangles.push_back({b, b + 2, b + 1});
    leaves.mesh.triangles.push_back({b, b + 3, b + 2});
  }
  auto tex = std::make_shared<PartTexture>();
  tex->image = Image(2, 2, Vec4(0.0f));
  tex->image.set(1, 0, Vec4(1, 0, 0, 1));
  tex->image.set(1, 1, Vec4(1, 0, 0, 1));
  leaves.material.texture = tex;
  leaves.material.alphaCutoff = 0.3f;
  const ExportPart cards = leafCards(leaves, 10);  // more cards than leaves: one a leaf
  REQUIRE(cards.mesh.triangles.size() == 6);
  CHECK(cards.mesh.positions.size() == 12);
  CHECK(cards.material.alphaCutoff == 0.3f);  // its own cut-out kept
  CHECK(cards.material.texture != leaves.material.texture);
  const Image& im = cards.material.texture->pixels();
  REQUIRE(im.width == 32);
  REQUIRE(im.height == 32);
  // The square's card: u along +z, v = n x u along +x, so the cell's upper rows are x > 1/2
  // (red, opaque) and its lower rows x < 1/2 (cut out).
  for (int cell = 0; cell < 3; ++cell) {
    const int x0 = (cell % 2) * 16, y0 = (cell / 2) * 16;
    CHECK(im.at(x0 + 8, y0 + 4).a == 1.0f);
    CHECK(im.at(x0 + 8, y0 + 4).r == 1.0f);
    CHECK(im.at(x0 + 8, y0 + 11).a == 0.0f);
    CHECK(im.at(x0 + 8, y0 + 0).a == 0.0f);  // the rim
  }
  CHECK(leafCards(leaves, 0).mesh.triangles.size() == 2);  // at least one card
}

namespace {

// 8 blobs of 3 x 3 x 3 square leaves (side 0.2, normal (0.2, 1, 0.1) normalized: about
// level, as a tree's leaves mostly are; one colour a blob), the
// blobs at the corners of a cube of side 10, blob by blob; each blob 1.2 long in x, 0.8 high
// and 0.6 deep.
ExportPart blobLeaves() {
  ExportPart leaves{"leaves", Mesh{}, PartMaterial{"leaves", Vec3(0.1f, 0.4f, 0.05f), 0.5f, true}, true};
  const glm::dvec3 n = glm::normalize(glm::dvec3(0.2, 1, 0.1));
  const glm::dvec3 e1 = glm::normalize(glm::cross(glm::dvec3(0, 1, 0), n)), e2 = glm::cross(n, e1);
  for (int b = 0; b < 8; ++b)
    for (int j = 0; j < 27; ++j) {
      const glm::dvec3 c(10.0 * (b & 1) + 0.6 * (j % 3), 10.0 * ((b >> 1) & 1) + 5.0 + 0.4 * (j / 3 % 3),
                         10.0 * (b >> 2) + 0.3 * (j / 9));
      const auto base = uint32_t(leaves.mesh.positions.size());
      for (glm::dvec2 d : {glm::dvec2(-1, -1), glm::dvec2(1, -1), glm::dvec2(1, 1), glm::dvec2(-1, 1)}) {
        leaves.mesh.positions.push_back(Vec3(c + 0.1 * d.x * e1 + 0.1 * d.y * e2));
        leaves.mesh.normals.push_back(Vec3(n));
        leaves.mesh.colors.push_back(Vec3(0.1f * float(b), 0.5f, 0.1f));
      }
      leaves.mesh.triangles.push_back({base, base + 1, base + 2});
      leaves.mesh.triangles.push_back({base, base + 2, base + 3});
    }
  return leaves;
}

}  // namespace

TEST_CASE("crownClusters puts every point in exactly one cluster", "[model][lod]") {
  const ExportPart leaves = blobLeaves();
  size_t count = 0, pieces = 0;
  const std::vector<uint32_t> piece = triangleComponents(leaves.mesh, pieces);
  REQUIRE(pieces == 216);
  const std::vector<glm::dvec3> centres = componentCentroids(leaves.mesh, piece, pieces);
  CHECK(glm::length(centres[0] - glm::dvec3(0, 5, 0)) < 1e-6);
  // 8 clusters: the 8 blobs (seeded at each blob's last leaf), numbered in the leaves' order.
  const std::vector<uint32_t> blob = crownClusters(centres, 8, count);
  CHECK(count == 8);
  REQUIRE(blob.size() == 216);
  for (size_t j = 0; j < 216; ++j) CHECK(blob[j] == j / 27);
  // Fewer: each cluster whole blobs; more clusters than points: one a point; none: one.
  const std::vector<uint32_t> four = crownClusters(centres, 4, count);
  CHECK(count == 4);
  for (size_t j = 0; j < 216; ++j) CHECK(four[j] == four[j / 27 * 27]);
  CHECK(crownClusters(std::vector<glm::dvec3>(centres.begin(), centres.begin() + 5), 9, count).size() == 5);
  CHECK(count == 5);
  const std::vector<uint32_t> one = crownClusters(centres, 0, count);
  CHECK(count == 1);
  CHECK(std::count(one.begin(), one.end(), 0u) == 216);
  CHECK(crownClusters({}, 3, count).empty());
  CHECK(count == 0);
}

TEST_CASE("crownCards paints each cluster's leaves on its crossed cards", "[model][lod]") {
  const ExportPart leaves = blobLeaves();
  const ExportPart crown = crownCards(leaves, 8);
  // 8 clusters of 3 cards: 24 quads of their own 4 vertices; 24 cells of 64 texels, 5 a row.
  REQUIRE(crown.mesh.triangles.size() == 48);
  REQUIRE(crown.mesh.positions.size() == 96);
  REQUIRE(crown.mesh.uvs.size() == 96);
  REQUIRE(crown.mesh.normals.size() == 96);
  CHECK(crown.mesh.colors.empty());
  for (size_t t = 0; t < 48; ++t) CHECK(crown.mesh.triangles[t].x == uint32_t(t / 2 * 4));
  CHECK(crown.material.alphaCutoff == kLeafCardAlphaCutoff);
  CHECK(crown.material.doubleSided);
  REQUIRE(crown.material.texture);
  const Image& im = crown.material.texture->pixels();
  REQUIRE(im.width == 5 * kCrownCardTexels);
  REQUIRE(im.height == 5 * kCrownCardTexels);
  // Cluster c's cards: mutually perpendicular, each 35.3 degrees above the horizontal, the
  // first's horizontal direction along x (the blob is longest in x).
  for (size_t c = 0; c < 8; ++c) {
    const Vec3 n[3] = {crown.mesh.normals[c * 12], crown.mesh.normals[c * 12 + 4], crown.mesh.normals[c * 12 + 8]};
    for (int k = 0; k < 3; ++k) {
      CHECK(n[k].y == Approx(std::sqrt(1.0 / 3.0)).margin(1e-6));
      CHECK(std::abs(glm::dot(n[k], n[(k + 1) % 3])) < 1e-6f);
    }
    CHECK(std::abs(n[0].x) > 0.99f * std::sqrt(2.0f / 3.0f));
  }
  // Every leaf (blob c's leaves are cluster c) is drawn on each of its cluster's three
  // cards: its centre, projected along the card's normal, falls on a texel at or above the
  // cut-off, in the card's own cell.
  size_t drawn = 0;
  for (size_t j = 0; j < 216; ++j) {
    glm::dvec3 p(0.0);
    for (size_t v = 4 * j; v < 4 * j + 4; ++v) p += 0.25 * glm::dvec3(leaves.mesh.positions[v]);
    for (size_t k = 0; k < 3; ++k) {
      const size_t card = j / 27 * 3 + k;
      const Vec2 uv = cardPoint(crown.mesh, card, p).uv;
      const int x = int(std::floor(uv.x * float(im.width))), y = int(std::floor((1.0f - uv.y) * float(im.height)));
      const int x0 = int(card % 5) * kCrownCardTexels, y0 = int(card / 5) * kCrownCardTexels;
      CHECK(x > x0);
      CHECK(x < x0 + kCrownCardTexels - 1);
      CHECK(y > y0);
      CHECK(y < y0 + kCrownCardTexels - 1);
      drawn += im.at(x, y).a >= kLeafCardAlphaCutoff && std::abs(im.at(x, y).r - 0.1f * float(j / 27)) < 1e-5f;
    }
  }
  CHECK(drawn == 216 * 3);
  // Each cell: its rim transparent, and leaves with gaps between them, not a sheet.
  for (size_t card = 0; card < 24; ++card) {
    const int x0 = int(card % 5) * kCrownCardTexels, y0 = int(card / 5) * kCrownCardTexels;
    size_t opaque = 0, rim = 0;
    for (int y = 0; y < kCrownCardTexels; ++y)
      for (int x = 0; x < kCrownCardTexels; ++x) {
        const bool edge = x == 0 || y == 0 || x == kCrownCardTexels - 1 || y == kCrownCardTexels - 1;
        const float a = im.at(x0 + x, y0 + y).a;
        (edge ? rim : opaque) += edge ? a > 0.0f : a >= kLeafCardAlphaCutoff;
      }
    INFO("card " << card << ": " << opaque << " opaque texels");
    CHECK(rim == 0);
    CHECK(opaque > 400);
    CHECK(opaque < 62 * 62 * 9 / 10);
  }
  // The same cards at any thread count.
  const auto with = [&](int threads) {
    const ThreadLimit limit(threads);
    return crownCards(leaves, 8);
  };
  const ExportPart one = with(1), two = with(2);
  CHECK(one.mesh.positions == crown.mesh.positions);
  CHECK(two.mesh.positions == crown.mesh.positions);
  CHECK(one.mesh.uvs == two.mesh.uvs);
  CHECK(one.material.texture->pixels().pixels == im.pixels);
  CHECK(two.material.texture->pixels().pixels == im.pixels);
  CHECK(crownCards(ExportPart{}, 3).mesh.triangles.empty());
}
