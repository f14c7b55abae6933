// The `textures:` list of kind: blob species: image and procedural textures in id order,
// primitives' texture ids, located errors (missing images, unknown kinds and keys), and
// the textures reaching the rendered colors through SpeciesModel.

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>

#include "model/model.h"
#include "model/species.h"
#include "model/blob_kind.h"
#include "blobtree/compiled.h"
#include "render/scene.h"
#include "textures/procedural.h"
#include "textures/registry.h"
#include "tests/scratch_dir.h"
#include "tests/paths.h"

using namespace sprig;
namespace fs = std::filesystem;
using test::TempDir;

namespace {

void write(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// A uniform 8x4 PNG of the sRGB-exact linear color c.
void writeUniformPng(const fs::path& p, Vec3 c) {
  writeImage(Image(8, 4, Vec4(c, 1.0f)), p, ImageEncoding::TextureMap);
}

// The InputError of loading `text` as species.yaml in dir (with the dir as library root).
std::string loadError(const TempDir& dir, const std::string& text) {
  write(dir.path / "species.yaml", text);
  PathPolicy policy;
  policy.root = dir.path;
  try {
    loadBlobSpecies(dir.path / "species.yaml", policy);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

bool near(Vec3 a, Vec3 b, float tol) { return glm::all(glm::lessThanEqual(glm::abs(a - b), Vec3(tol))); }

}  // namespace

TEST_CASE("readBlobSpecies::textures", "[model]") {
  TempDir dir("blob-textures-test");
  fs::create_directory(dir.path / "maps");
  const Vec3 pink(0.8f, 0.2f, 0.4f);
  writeUniformPng(dir.path / "maps" / "pink.png", pink);
  write(dir.path / "species.yaml",
        "kind: blob\n"
        "textures:\n"
        "  - image: maps/pink.png\n"
        "  - stripes: {frequency: 5, spiral: true, seed: 3}\n"
        "  - color: [0.1, 0.2, 0.3]\n"
        "blob:\n"
        "  blend:\n"
        "    - segment: {a: [0, 0, 0], b: [0, 1, 0], radius: 0.3, texture: {id: 2}}\n"
        "    - point: {center: [3, 0, 0], radius: 0.5, texture: {id: 0, v_scale: 2}}\n"
        "    - point: {center: [-3, 0, 0], radius: 0.5}\n");
  PathPolicy policy;
  policy.root = dir.path;
  BlobSpecies s = loadBlobSpecies(dir.path / "species.yaml", policy);
  REQUIRE(s.textures);
  const textures::TextureRegistry& reg = *s.textures;
  REQUIRE(reg.size() == 3);

  SECTION("entries are registered in list order with their options") {
    REQUIRE(std::holds_alternative<textures::ImageTexture>(reg.get(0)));
    const auto& image = std::get<textures::ImageTexture>(reg.get(0));
    CHECK(image.width() == 8);
    CHECK(image.height() == 4);
    CHECK(fs::equivalent(image.path(), dir.path / "maps" / "pink.png"));
    REQUIRE(std::holds_alternative<textures::StripesTexture>(reg.get(1)));
    const auto& stripes = std::get<textures::StripesTexture>(reg.get(1)).options();
    CHECK(stripes.frequency == 5.0);
    CHECK(stripes.spiral);
    CHECK(stripes.seed == 3);
    CHECK(stripes.duty == textures::StripesOptions{}.duty);  // unset options keep their defaults
    REQUIRE(std::holds_alternative<textures::ConstantTexture>(reg.get(2)));
    CHECK(reg.color(2, Vec2(0.3f, 0.7f)) == Vec3(0.1f, 0.2f, 0.3f));
  }
  SECTION("the image is looked up through the texture system") {
    // 8-bit sRGB quantization: within half a code value, about 0.004 in linear light here.
    CHECK(near(reg.color(0, Vec2(0.3f, 0.6f)), pink, 0.005f));
  }
  SECTION("primitives carry the ids they name; no texture key means kNoTexture") {
    blobtree::CompiledBlob blob = blobtree::compile(s.tree, s.root);
    blobtree::Sample seg = blob.sample(Vec3(0.0f, 0.5f, 0.25f));
    REQUIRE(seg.attributes.textureCount == 1);
    CHECK(seg.attributes.textureIds[0] == 2);
    blobtree::Sample right = blob.sample(Vec3(3.0f, 0.0f, 0.4f));
    REQUIRE(right.attributes.textureCount == 1);
    CHECK(right.attributes.textureIds[0] == 0);
    blobtree::Sample left = blob.sample(Vec3(-3.0f, 0.0f, 0.4f));
    REQUIRE(left.attributes.textureCount == 1);
    CHECK(left.attributes.textureIds[0] == kNoTexture);
  }
}

TEST_CASE("readBlobSpecies::texture errors", "[model]") {
  TempDir dir("blob-textures-test");
  const std::string blob = "blob:\n  point: {radius: 1, texture: {id: 0}}\n";
  // Each case: the species text before `blob`, and what the error of loading it must contain.
  auto checkErrors = [&](std::initializer_list<std::pair<std::string, std::string>> cases) {
    for (const auto& [text, message] : cases) {
      CAPTURE(text);
      CHECK(loadError(dir, text + blob).find(message) != std::string::npos);
    }
  };

  SECTION("a missing image names the file at the path's line:col") {
    std::string e = loadError(dir, "kind: blob\ntextures:\n  - image: maps/missing.png\n" + blob);
    const std::string file = (dir.path / "species.yaml").string();
    const std::string resolved = (dir.path / "maps" / "missing.png").string();
    CHECK(e.find(file + ":3:12: error: cannot find file '" + resolved + "'") != std::string::npos);
    CHECK(e.find("  - image: maps/missing.png") != std::string::npos);  // the source line is shown
  }
  SECTION("a file that is no image is unreadable") {
    write(dir.path / "notes.png", "not an image");
    std::string e = loadError(dir, "kind: blob\ntextures:\n  - {image: notes.png}\n" + blob);
    CHECK(e.find(":3:13: error: cannot read texture '") != std::string::npos);
  }
  SECTION("a folder is not an image") {
    fs::create_directory(dir.path / "maps");
    std::string e = loadError(dir, "kind: blob\ntextures:\n  - image: maps\n" + blob);
    CHECK(e.find(":3:12: error: '" + (dir.path / "maps").string() + "' is a folder, not a regular file") != std::string::npos);
  }
  SECTION("image paths obey the path policy") {
    checkErrors({
        {"kind: blob\ntextures:\n  - image: ../outside.png\n",
         ":3:12: error: refusing path '../outside.png': it leaves the library root"},
        {"kind: blob\ntextures:\n  - image: https://example.com/a.png\n",
         ":3:12: error: refusing URI 'https://example.com/a.png'"},
    });
  }
  SECTION("unknown texture kinds and options get did-you-mean") {
    checkErrors({
        {"kind: blob\ntextures:\n  - strpes: {}\n",
         ":3:5: error: unknown texture kind 'strpes' (did you mean 'stripes'?)"},
        {"kind: blob\ntextures:\n  - spots: {frequncy: 4}\n",
         ":3:13: error: unknown key 'frequncy' in spots (did you mean 'frequency'?)"},
    });
  }
  SECTION("wrong types and ranges are located") {
    checkErrors({
        {"kind: blob\ntextures:\n  - bark: {furrows: many}\n",
         ":3:21: error: 'furrows' must be an integer, got 'many'"},
        {"kind: blob\ntextures:\n  - stripes: {duty: 2}\n",
         ":3:21: error: 'duty' is 2, out of range [0, 1]"},
        {"kind: blob\ntextures: {image: a.png}\n",
         ":2:11: error: 'textures' must be a sequence"},
        {"kind: blob\ntextures:\n  - image: {file: a.png}\n",
         ":3:12: error: 'image' must be a file name"},
        {"kind: blob\ntextures:\n  - color: [0.1, 0.2, 0.3]\n    noise: {}\n",
         ":3:5: error: a texture must be a map with one key naming its kind"},
    });
  }
  SECTION("texture ids must name an entry of the list") {
    std::string e = loadError(dir, "kind: blob\ntextures:\n  - color: [1, 0, 0]\n"
                                   "blob:\n  point: {radius: 1, texture: {id: 1}}\n");
    CHECK(e.find(":5:36: error: 'id' is 1, out of range [0, 0]") != std::string::npos);
    e = loadError(dir, "kind: blob\nblob:\n  point: {radius: 1, texture: {id: 0}}\n");
    CHECK(e.find(":3:36: error: texture id 0 names no texture: the species has no 'textures:' list") !=
          std::string::npos);
    e = loadError(dir, "kind: blob\ntextures:\n  - color: [1, 0, 0]\nblob:\n  point: {radius: 1, texture: {u_scale: 2}}\n");
    CHECK(e.find(":5:31: error: missing required key 'id' in texture") != std::string::npos);
  }
}

TEST_CASE("SpeciesModel::addToScene blob textures", "[model]") {
  // Two blended spheres, red and blue: pure colors outside the blend, and by symmetry an
  // equal mix on the mirror plane x = 0 (colors blend by field weight).
  const std::string text =
      "kind: blob\n"
      "textures: [{color: [1, 0, 0]}, {color: [0, 0, 1]}]\n"
      "blob:\n"
      "  blend:\n"
      "    - point: {center: [-0.5, 0, 0], radius: 0.6, texture: {id: 0}}\n"
      "    - point: {center: [0.5, 0, 0], radius: 0.6, texture: {id: 1}}\n";
  Species species = parseSpecies(text, "two.yaml");
  SpeciesModel model(species);
  for (GeometryMode mode : {GeometryMode::Exact, GeometryMode::Mesh}) {
    CAPTURE(geometryModeName(mode));
    render::Scene scene;
    model.addToScene(scene, model.finalStage(), mode, species.render);
    scene.commit();
    const Vec3 down(0, 0, -1);
    auto red = scene.intersect(Vec3(-0.95f, 0.0f, 5.0f), down, 0.0f, 100.0f);
    auto blue = scene.intersect(Vec3(0.95f, 0.0f, 5.0f), down, 0.0f, 100.0f);
    auto mid = scene.intersect(Vec3(0.0f, 0.0f, 5.0f), down, 0.0f, 100.0f);
    REQUIRE(red);
    REQUIRE(blue);
    REQUIRE(mid);
    const float tol = mode == GeometryMode::Exact ? 1e-4f : 0.02f;
    CHECK(near(red->color, Vec3(1, 0, 0), tol));
    CHECK(near(blue->color, Vec3(0, 0, 1), tol));
    CHECK(near(mid->color, Vec3(0.5f, 0.0f, 0.5f), mode == GeometryMode::Exact ? 1e-3f : 0.05f));
  }
}

TEST_CASE("SpeciesModel::missing blob texture", "[model]") {
  // The error comes from loading the species (every section is read at load time), before
  // any model is built or anything is rendered or written.
  TempDir dir("blob-textures-test");
  write(dir.path / "s.yaml",
        "kind: blob\ntextures:\n  - image: gone.png\nblob:\n  point: {radius: 1, texture: {id: 0}}\n");
  PathPolicy policy;
  policy.root = dir.path;
  try {
    Species species = loadSpecies(dir.path / "s.yaml", policy);
    FAIL("no error for a missing texture");
  } catch (const InputError& e) {
    REQUIRE(e.diagnostics().size() == 1);
    CHECK(e.diagnostics()[0].loc.line == 3);
    CHECK(e.diagnostics()[0].loc.col == 12);
    CHECK(std::string(e.what()).find("cannot find file '" + (dir.path / "gone.png").string() + "'") != std::string::npos);
  }
}

TEST_CASE("species/blob_textured.yaml", "[model]") {
  PathPolicy policy;
  policy.root = SPRIG_SOURCE_DIR;
  Species species = loadSpecies(fs::path(SPRIG_SOURCE_DIR) / "species" / "blob_textured.yaml", policy);
  SpeciesModel model(species);
  BlobSpecies blob = loadBlobSpecies(fs::path(SPRIG_SOURCE_DIR) / "species" / "blob_textured.yaml", policy);
  REQUIRE(blob.textures);
  REQUIRE(blob.textures->size() == 2);
  CHECK(std::holds_alternative<textures::ImageTexture>(blob.textures->get(0)));
  CHECK_FALSE(std::holds_alternative<textures::ImageTexture>(blob.textures->get(1)));
}
