// cpfg textures (`texture:` lines of a view file, `@Tx(n)`): texture coordinates on surface
// files, the colours the renderer gives the textured surfaces, and their export.
#include <catch2/catch.hpp>

#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/mesh_io.h"
#include "lsystem/skeleton.h"
#include "model/growth.h"
#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/scene.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

fs::path textureObject() { return fs::path(SPRIG_SOURCE_DIR) / "tests/assets/cpfg/texture"; }

/// The colour the scene's surface shows at (x, y) seen along +Z (the flat squares face -Z).
Vec3 colorAt(const render::Scene& scene, float x, float y) {
  INFO("ray at (" << x << ", " << y << ")");
  auto hit = scene.intersect(Vec3(x, y, -10), Vec3(0, 0, 1), 0.0f, 100.0f);
  REQUIRE(hit);
  CHECK(hit->t == Approx(10.0f));
  return hit->color;
}

void checkColor(const Vec3& got, const Vec3& want) {
  INFO("got (" << got.x << ", " << got.y << ", " << got.z << "), expected (" << want.x << ", " << want.y << ", " << want.z << ")");
  CHECK(glm::length(got - want) < 1e-6f);
}

}  // namespace

TEST_CASE("cpfg textures on surface files", "[model][cpfg]") {
  const Species s = loadSpecies(textureObject());
  REQUIRE(s.render.style.cpfgTextures);
  const auto& textures = *s.render.style.cpfgTextures;
  REQUIRE(textures.size() == 2);
  CHECK(textures[0].decal);
  CHECK_FALSE(textures[0].perSurface);
  CHECK_FALSE(textures[0].linear);
  CHECK_FALSE(textures[1].decal);
  CHECK(textures[1].perSurface);
  REQUIRE(textures[0].image->width == 2);
  REQUIRE(textures[0].image->height == 1);
  // s below 1/2 is the left texel (red), above it the right one (blue); t does not matter.
  CHECK(textures[0].sample(0.25, 0.5) == Vec4(1, 0, 0, 1));
  CHECK(textures[0].sample(0.75, 0.5) == Vec4(0, 0, 1, 1));
  CHECK(textures[0].sample(1.25, -3.5) == Vec4(1, 0, 0, 1));  // repeats

  GrowthEngine engine(s);
  const lsystem::Skeleton sk = engine.skeletonAt(engine.lastStep());
  // [@Tx(1)~a] f(4) [@Tx(2)~a] f(4) ~a f(4) ~b F(1): four squares, 3 x 3 vertices each.
  REQUIRE(sk.organs.size() == 4);
  const int wantTexture[] = {0, 1, -1, 0};  // the bracket ends @Tx(2); b's line names texture 1
  for (size_t k = 0; k < 4; ++k) {
    INFO("organ " << k);
    CHECK(sk.organs[k].texture == wantTexture[k]);
    REQUIRE(sk.organs[k].points.size() == 9);
    CHECK(sk.organs[k].uvs.size() == (wantTexture[k] >= 0 ? 9u : 0u));
  }
  // flat.s at size 3 is the square (3t, 3s, 0) of the surface frame, vertex k = 3 si + ti at
  // (s, t) = (si / 2, ti / 2). Per patch the texture coordinates are (s, t); per surface
  // (texture 2, `S`) they are x and y over the square's bounds: (t, s).
  for (int si = 0; si <= 2; ++si)
    for (int ti = 0; ti <= 2; ++ti) {
      const size_t k = static_cast<size_t>(3 * si + ti);
      CHECK(sk.organs[0].uvs[k] == Vec2(si / 2.0f, ti / 2.0f));
      CHECK(sk.organs[1].uvs[k] == Vec2(ti / 2.0f, si / 2.0f));
      CHECK(sk.organs[3].uvs[k] == Vec2(si / 2.0f, ti / 2.0f));
      // Placed at the turtle (H = +Y, L = -X): surface x goes to -X, y to +Y.
      CHECK(sk.organs[0].points[k].x == Approx(-3.0 * ti / 2.0));
      CHECK(sk.organs[0].points[k].y == Approx(3.0 * si / 2.0));
    }

  // The preview: each square's colour where a ray meets it. Squares start at y = 0, 4, 8 and
  // 15 (the third moves the turtle to its end point, 3 along H, before f(4)).
  render::Scene scene;
  scene.add(skeletonPreview(sk, s.render.style));
  scene.commit();
  const Vec3 red(1, 0, 0), blue(0, 0, 1), leaf = s.render.style.leaf.baseColor;
  // Texture 1, decal, per patch: s runs along y: red below y = 1.5, blue above, at any x.
  checkColor(colorAt(scene, -0.75f, 0.75f), red);
  checkColor(colorAt(scene, -2.25f, 0.75f), red);
  checkColor(colorAt(scene, -0.75f, 2.25f), blue);
  checkColor(colorAt(scene, -2.25f, 2.25f), blue);
  // Texture 2, modulate, per surface: s runs along surface x (world -X), times the leaf colour.
  checkColor(colorAt(scene, -0.75f, 4.75f), red * leaf);
  checkColor(colorAt(scene, -0.75f, 6.25f), red * leaf);
  checkColor(colorAt(scene, -2.25f, 4.75f), blue * leaf);
  checkColor(colorAt(scene, -2.25f, 6.25f), blue * leaf);
  // No texture: the leaf colour.
  checkColor(colorAt(scene, -0.75f, 8.75f), leaf);
  checkColor(colorAt(scene, -2.25f, 10.25f), leaf);
  // Surface b, texture 1 from its view file line.
  checkColor(colorAt(scene, -1.5f, 15.75f), red);
  checkColor(colorAt(scene, -1.5f, 17.25f), blue);

  // The export: one part per texture and colour, each with its uvs and the texture baked.
  SpeciesModel model(s, ModelOptions{});
  const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
  std::vector<const ExportPart*> textured;
  for (const ExportPart& p : parts)
    if (p.name.rfind("textured_leaves_", 0) == 0) textured.push_back(&p);
  REQUIRE(textured.size() == 2);  // texture 1 (squares 1 and 4) and texture 2 (square 2)
  CHECK(textured[0]->mesh.triangleCount() == 16);
  CHECK(textured[1]->mesh.triangleCount() == 8);
  for (const ExportPart* p : textured) {
    REQUIRE(p->material.texture);
    CHECK(p->mesh.uvs.size() == p->mesh.positions.size());
    const Image& img = p->material.texture->image;
    REQUIRE(img.width == 2);
    REQUIRE(img.height == 1);
    const Vec3 tint = p == textured[0] ? Vec3(1.0f) : leaf;
    checkColor(Vec3(img.at(0, 0)), red * tint);
    checkColor(Vec3(img.at(1, 0)), blue * tint);
  }
  // The untextured square stays among the leaves.
  bool leaves = false;
  for (const ExportPart& p : parts) leaves = leaves || (p.name == "leaves" && p.mesh.triangleCount() == 8);
  CHECK(leaves);
}

TEST_CASE("cpfg texture errors", "[model][cpfg]") {
  const fs::path dir = fs::temp_directory_path() / "sprig-cpfg-texture-test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* f : {"flat.s", "halves.png"}) fs::copy_file(textureObject() / f, dir / f);
  auto errorOf = [&](const std::string& view, const std::string& axiom) {
    writeFileAtomic(dir / "plant.v", "surface: a flat.s 3\n" + view);
    writeFileAtomic(dir / "plant.l", "lsystem: 1\nderivation length: 0\naxiom: " + axiom + "\nendlsystem\n");
    try {
      const Species s = loadSpecies(dir);
      GrowthEngine engine(s);
      engine.skeletonAt(engine.lastStep());
    } catch (const InputError& e) {
      const Diagnostic& d = e.diagnostics().front();
      return (d.loc.line ? fs::path(d.loc.file).filename().string() + ":" + std::to_string(d.loc.line) + ":" +
                               std::to_string(d.loc.col) + ": "
                         : std::string()) +
             d.message;
    }
    return std::string("no error");
  };
  CHECK(errorOf("texture: F: halves.png\n", "[@Tx(1)~a]F") == "no error");
  CHECK(errorOf("texture: F: missing.png\n", "~a") ==
        "plant.v:2:13: cannot read the texture image '" + (dir / "missing.png").string() + "': no such file");
  // A file that is no image: the image reader's reason.
  writeFileAtomic(dir / "bad.png", "not a png");
  CHECK(errorOf("texture: F: bad.png\n", "~a").rfind("plant.v:2:13: cannot read the texture image '" + (dir / "bad.png").string() + "': ", 0) == 0);
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(2)~a") ==
        "cpfg's '@Tx(2)' names no texture: the view file has 1 'texture:' line");
  CHECK(errorOf("", "@Tx(1)~a") == "cpfg's '@Tx(1)' names no texture: the view file has no 'texture:' line");
  CHECK(errorOf("texture: F: halves.png E: b\n", "~a") ==
        "plant.v:2:27: the texture mode 'E: b' (blend) is not supported (use m, modulate, or d, decal)");
  CHECK(errorOf("texture: F: halves.png L: m\n", "~a") ==
        "plant.v:2:27: the mipmapped minification filter 'L: m' is not supported (use n or l)");
  CHECK(errorOf("texture: F: halves.png Q: 1\n", "~a") ==
        "plant.v:2:24: unknown texture option 'Q' (cpfg's are F: image, H: and L: filters, E: mode, S, R: ratio)");
  CHECK(errorOf("texture: H: l\n", "~a") == "plant.v:2:10: a texture needs its image: 'texture: F: NAME.png'");
  CHECK(errorOf("texture: F: ../halves.png\n", "~a").find("is outside the object's folder") != std::string::npos);
  CHECK(errorOf("surface: b flat.s 3 2\n", "~b") ==
        "plant.v:2:21: the surface's texture 2 names no texture: the view file has 0 'texture:' lines");
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(1)F") ==
        "cpfg's texture '@Tx(1)' on an 'F' segment (a cylinder) is not supported: Sprig textures surfaces ('~X') only; "
        "end the texture with '@Tx' or close its branch before drawing it");
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(1){.f.+f.}").find("on a polygon '{ }' is not supported") !=
        std::string::npos);
  fs::remove_all(dir);
}
