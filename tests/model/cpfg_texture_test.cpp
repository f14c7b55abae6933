// cpfg textures (`texture:` lines of a view file, `@Tx(n)`): texture coordinates on surface
// files, the colours the renderer gives the textured surfaces, and their export.
#include <catch2/catch.hpp>
#include <tiny_gltf.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/mesh_io.h"
#include "core/srgb.h"
#include "lsystem/skeleton.h"
#include "lsystem/turtle.h"
#include "model/growth.h"
#include "model/model.h"
#include "model/species.h"
#include "model/tree_kind.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/paths.h"

using namespace sprig;
namespace fs = std::filesystem;

namespace {

fs::path textureObject() { return fs::path(SPRIG_SOURCE_DIR) / "tests/assets/cpfg/texture"; }
fs::path cutoutObject() { return textureObject() / "cutout"; }
fs::path cylinderObject() { return textureObject() / "cylinder"; }
fs::path mipmapObject() { return textureObject() / "mipmap"; }

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

/// The skeleton of the species' last step.
lsystem::Skeleton finalSkeleton(const Species& s) {
  GrowthEngine engine(s);
  return engine.skeletonAt(engine.lastStep());
}

/// Adds the skeleton's preview in the species' style to the scene and commits it.
void addPreview(render::Scene& scene, const lsystem::Skeleton& sk, const Species& s) {
  scene.add(skeletonPreview(sk, s.render.style));
  scene.commit();
}

/// A cpfg object in a fresh folder `name` under the temporary directory: the files named in
/// copies copied from the folder `from`, and plant.v and plant.l holding view and lsystem.
fs::path writeObject(const std::string& name, const fs::path& from, std::initializer_list<const char*> copies,
                     const std::string& view, const std::string& lsystem) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  for (const char* f : copies) fs::copy_file(from / f, dir / f);
  writeFileAtomic(dir / "plant.v", view);
  writeFileAtomic(dir / "plant.l", lsystem);
  return dir;
}

/// The colour a camera at the given depth in front of p (looking along +Z, 90 degrees over
/// 16 x 16 pixels, which sets the texel footprint) sees at p.
Vec3 colorSeenFrom(const Species& s, const lsystem::Skeleton& sk, const Vec3& p, float depth) {
  render::Camera camera;
  camera.position = p - Vec3(0, 0, depth);
  camera.target = p;
  camera.fovYDeg = 90.0f;
  render::Scene scene;
  scene.setPixelFootprint(camera, 16, 16, 0.0f);  // no thin-curve widening; the pixel still counts
  addPreview(scene, sk, s);
  auto hit = scene.intersect(camera.position, Vec3(0, 0, 1), 0.0f, 100.0f);
  REQUIRE(hit);
  CHECK(hit->t == Approx(depth));
  return hit->color;
}

/// The preview of the skeleton rendered through the camera at 64 x 48 pixels, 2 samples per
/// pixel, on the given number of threads.
Image renderPreview(const Species& s, const lsystem::Skeleton& sk, const render::Camera& camera, int threads) {
  render::Scene scene;
  scene.setPixelFootprint(camera, 64, 48);
  addPreview(scene, sk, s);
  render::RenderSettings rs;
  rs.width = 64;
  rs.height = 48;
  rs.spp = 2;
  rs.threads = threads;
  return render::renderImage(scene, camera, rs);
}

}  // namespace

TEST_CASE("cpfg textures on surface files", "[model][cpfg]") {
  const Species s = loadSpecies(textureObject());
  REQUIRE(s.render.style.cpfgTextures);
  const auto& textures = *s.render.style.cpfgTextures;
  REQUIRE(textures.size() == 2);
  CHECK(textures[0].decal);
  CHECK_FALSE(textures[0].perSurface);
  CHECK_FALSE(textures[0].magLinear);
  CHECK_FALSE(textures[0].minLinear);
  CHECK_FALSE(textures[1].magLinear);
  CHECK(textures[1].minLinear);
  CHECK_FALSE(textures[1].decal);
  CHECK(textures[1].perSurface);
  REQUIRE(textures[0].image->width == 2);
  REQUIRE(textures[0].image->height == 1);
  // s below 1/2 is the left texel (red), above it the right one (blue); t does not matter.
  CHECK(textures[0].sample(0.25, 0.5) == Vec4(1, 0, 0, 1));
  CHECK(textures[0].sample(0.75, 0.5) == Vec4(0, 0, 1, 1));
  CHECK(textures[0].sample(1.25, -3.5) == Vec4(1, 0, 0, 1));  // repeats

  const lsystem::Skeleton sk = finalSkeleton(s);
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
  addPreview(scene, sk, s);
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
      skeletonPreview(finalSkeleton(s), s.render.style);  // draws the textures
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
  // An image that cannot be read is an error when an organ with its texture is drawn (cpfg
  // reads images only to draw), at the view file's line.
  CHECK(errorOf("texture: F: missing.png\n", "~a") == "no error");
  CHECK(errorOf("texture: F: missing.png\n", "[@Tx(1)]~a") == "no error");
  CHECK(errorOf("texture: F: missing.png\n", "[@Tx(1)~a]~a") ==
        "plant.v:2:13: cannot find file '" + (dir / "missing.png").string() + "'");
  CHECK(errorOf("texture: F: missing.png\n", "@Tx(1)F") ==
        "plant.v:2:13: cannot find file '" + (dir / "missing.png").string() + "'");
  // A file that is no image: the image reader's reason.
  writeFileAtomic(dir / "bad.png", "not a png");
  CHECK(errorOf("texture: F: bad.png\n", "~a") == "no error");
  CHECK(errorOf("texture: F: bad.png\n", "@Tx(1)~a").rfind("plant.v:2:13: cannot read the texture image '" + (dir / "bad.png").string() + "': ", 0) == 0);
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(2)~a") ==
        "cpfg's '@Tx(2)' names no texture: the view file has 1 'texture:' line");
  CHECK(errorOf("", "@Tx(1)~a") == "cpfg's '@Tx(1)' names no texture: the view file has no 'texture:' line");
  CHECK(errorOf("texture: F: halves.png E: b\n", "~a") == "no error");
  CHECK(errorOf("texture: F: halves.png L: m\n", "~a") == "no error");
  CHECK(errorOf("texture: F: halves.png E: x\n", "~a") ==
        "plant.v:2:27: a texture mode 'E:' is m (modulate), d (decal) or b (blend), got 'x'");
  CHECK(errorOf("texture: F: halves.png L: mx\n", "~a") ==
        "plant.v:2:27: a texture filter 'L:' is n (nearest) or l (linear), or m, mn, ml, mnn, mnl, mln, mll (mipmaps), got 'mx'");
  CHECK(errorOf("texture: F: halves.png H: m\n", "~a") ==
        "plant.v:2:27: a texture filter 'H:' is n (nearest) or l (linear), got 'm'");
  CHECK(errorOf("texture: F: halves.png Q: 1\n", "~a") ==
        "plant.v:2:24: unknown texture option 'Q' (cpfg's are F: image, H: and L: filters, E: mode, S, R: ratio)");
  CHECK(errorOf("texture: H: l\n", "~a") == "plant.v:2:10: a texture needs its image: 'texture: F: NAME.png'");
  CHECK(errorOf("texture: F: ../halves.png\n", "~a").find("is outside the object's folder") != std::string::npos);
  CHECK(errorOf("surface: b flat.s 3 2\n", "~b") ==
        "plant.v:2:21: the surface's texture 2 names no texture: the view file has 0 'texture:' lines");
  // Cylinders, generalized cylinders (with the circle or a contour) and polygons are textured.
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(1)F") == "no error");
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(1){.f+f}") == "no error");
  CHECK(errorOf("texture: F: halves.png\n", "@Tx(1)@Gs f @Gc(2) f @Ge(2)") == "no error");
  fs::remove_all(dir);
}

namespace {

/// tests/assets/cpfg/texture/cutout derived and previewed, its textures and organs checked
/// on the way: [@Tx(1)~a] [^(90)f(2)&(90)~a] +(90)f(5)-(90) [@Tx(2)~a] F(1) draws the cut-out
/// square at z = 0, x in [-3, 0]; the untextured one 2 behind it (z = 2); the decal one at x
/// in [-8, -5].
struct CutoutScene {
  /// cutout.png: 5 x 1 red texels of alpha 255, 0, 128, 26, 25 (of 255).
  static constexpr float alpha[] = {1.0f, 0.0f, 128 / 255.0f, 26 / 255.0f, 25 / 255.0f};
  const Species s = loadSpecies(cutoutObject());
  const lsystem::Skeleton sk = finalSkeleton(s);
  render::Scene scene;
  const Vec3 red{1, 0, 0}, leaf = s.render.style.leaf.baseColor;

  CutoutScene() {
    REQUIRE(s.render.style.cpfgTextures);
    const auto& textures = *s.render.style.cpfgTextures;
    REQUIRE(textures.size() == 2);
    CHECK(textures[0].cutsOut());        // modulate: the texel's alpha is the fragment's
    CHECK_FALSE(textures[1].cutsOut());  // decal: the fragment is opaque
    for (int k = 0; k < 5; ++k) CHECK(textures[0].sample((k + 0.5) / 5, 0.5).a == Approx(alpha[k]).margin(1e-6));
    REQUIRE(sk.organs.size() == 3);
    CHECK(sk.organs[0].texture == 0);
    CHECK(sk.organs[1].texture == -1);
    CHECK(sk.organs[2].texture == 1);
    CHECK(sk.organs[1].points[0].z == Approx(2.0));
    addPreview(scene, sk, s);
  }

  /// Per patch, s runs along y: texel k covers y in [0.6 k, 0.6 (k + 1)], centre 0.3 + 0.6 k.
  static float texelY(int k) { return 0.3f + 0.6f * static_cast<float>(k); }

  /// The first hit beyond tnear of a ray along +Z through (x, y).
  auto ray(float x, float y, float tnear = 0.0f) const {
    return scene.intersect(Vec3(x, y, -10), Vec3(0, 0, 1), tnear, 100.0f);
  }
};

}  // namespace

TEST_CASE_METHOD(CutoutScene, "cpfg cut-out textures: camera rays and shadows are cut by the alpha test", "[model][cpfg]") {
  SECTION("camera rays: the opaque texel hits the leaf, the cut ones the square behind") {
    for (float x : {-0.4f, -1.5f, -2.6f}) {
      INFO("x " << x);
      auto opaque = ray(x, texelY(0));
      REQUIRE(opaque);
      CHECK(opaque->t == Approx(10.0f));
      CHECK(opaque->opacity == 1.0f);
      checkColor(opaque->color, red * leaf);
      for (int k : {1, 4}) {  // alpha 0 and 25/255 (at or below cpfg's 0.1): left out
        INFO("texel " << k);
        auto through = ray(x, texelY(k));
        REQUIRE(through);
        CHECK(through->t == Approx(12.0f));
        checkColor(through->color, leaf);
      }
      for (int k : {2, 3}) {  // alpha 128/255 and 26/255: drawn, covering that much
        INFO("texel " << k);
        auto part = ray(x, texelY(k));
        REQUIRE(part);
        CHECK(part->t == Approx(10.0f));
        CHECK(part->opacity == Approx(alpha[k]).margin(1e-6));
        CHECK(part->behind > part->t);
        CHECK(part->behind < 10.01f);
        CHECK(glm::length(part->color - red * leaf) < 0.02f);  // 8-bit premultiplied red, unassociated
        auto behind = ray(x, texelY(k), part->behind);  // what the renderer blends it over
        REQUIRE(behind);
        CHECK(behind->t == Approx(12.0f));
      }
    }
  }

  SECTION("shadows: a light beyond the cut-out square is blocked by its opaque texels only") {
    // From between the squares (z = 1) toward the light at -Z.
    auto blocked = [&](float x, float y) { return scene.occluded(Vec3(x, y, 1), Vec3(0, 0, -1), 0.0f, 100.0f); };
    for (float x : {-0.4f, -1.5f, -2.6f}) {
      CHECK(blocked(x, texelY(0)));
      CHECK_FALSE(blocked(x, texelY(1)));
      CHECK_FALSE(blocked(x, texelY(4)));
      CHECK_FALSE(blocked(x, 3.5f));  // beside the square
    }
    // Partly covering texels block that fraction of the rays (a hash of each ray): 20 x 20
    // rays over the inner part of each texel.
    for (int k : {2, 3}) {
      int count = 0;
      for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j)
          count += blocked(-0.1f - 2.8f * static_cast<float>(i) / 19.0f, 0.6f * static_cast<float>(k) + 0.05f + 0.5f * static_cast<float>(j) / 19.0f);
      INFO("texel " << k << ": " << count << " of 400 blocked");
      CHECK(std::abs(count / 400.0 - alpha[k]) < 0.06);
    }
  }
}

TEST_CASE_METHOD(CutoutScene, "cpfg cut-out textures: decal blending and the glTF export", "[model][cpfg]") {
  SECTION("decal: the texels' alpha blends the colours, nothing is cut out") {
    for (int k = 0; k < 5; ++k) {
      INFO("texel " << k);
      auto hit = ray(-6.5f, texelY(k));
      REQUIRE(hit);
      CHECK(hit->t == Approx(10.0f));
      CHECK(hit->opacity == 1.0f);
      CHECK(glm::length(hit->color - glm::mix(leaf, red, alpha[k])) < 0.02f);
    }
  }

  SECTION("export: glTF alphaMode MASK at 0.1, the image's alpha kept, the samplers nearest") {
    SpeciesModel model(s, ModelOptions{});
    std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
    std::vector<ExportPart> textured;
    for (ExportPart& p : parts)
      if (p.name.rfind("textured_leaves_", 0) == 0) textured.push_back(std::move(p));
    REQUIRE(textured.size() == 2);  // modulate (cut out), decal (opaque)
    CHECK(textured[0].material.alphaCutoff == 0.1f);
    CHECK(textured[1].material.alphaCutoff < 0.0f);
    const Image& img = textured[0].material.texture->image;
    REQUIRE(img.width == 5);
    for (int k = 0; k < 5; ++k) CHECK(img.at(k, 0).a == Approx(alpha[k]).margin(1e-6));
    const fs::path dir = fs::temp_directory_path() / "sprig-cpfg-cutout-test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const fs::path file = dir / "cutout.glb";
    writeParts(textured, file);
    tinygltf::Model gltf;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    REQUIRE(loader.LoadBinaryFromFile(&gltf, &err, &warn, file.string()));
    REQUIRE(gltf.materials.size() == 2);
    CHECK(gltf.materials[0].alphaMode == "MASK");
    CHECK(gltf.materials[0].alphaCutoff == Approx(0.1));
    CHECK(gltf.materials[1].alphaMode == "OPAQUE");
    for (const tinygltf::Sampler& sampler : gltf.samplers) {  // H: n, L: n (cpfg's defaults)
      CHECK(sampler.magFilter == TINYGLTF_TEXTURE_FILTER_NEAREST);
      CHECK(sampler.minFilter == TINYGLTF_TEXTURE_FILTER_NEAREST);
    }
    const tinygltf::Image& png = gltf.images[size_t(gltf.textures[size_t(gltf.materials[0].pbrMetallicRoughness.baseColorTexture.index)].source)];
    REQUIRE(png.width == 5);
    REQUIRE(png.component == 4);
    const int alpha8[] = {255, 0, 128, 26, 25};
    for (int k = 0; k < 5; ++k) CHECK(int(png.image[size_t(4 * k + 3)]) == alpha8[k]);
    fs::remove_all(dir);
  }
}

TEST_CASE("cpfg texture filters: magnification or minification by the texel footprint", "[model][cpfg]") {
  const Species s = loadSpecies(textureObject());
  const auto& textures = *s.render.style.cpfgTextures;
  // Texture 2 is H: n, L: l. At s = 3/8 (a quarter texel left of the boundary between the red
  // and the blue texel centres at 1/4 and 3/4): nearest is red, bilinear 3/4 red + 1/4 blue.
  const Vec4 red(1, 0, 0, 1), mixed(0.75f, 0, 0.25f, 1);
  CHECK(textures[1].sample(0.375, 0.5, false) == red);
  CHECK(textures[1].sample(0.375, 0.5, true) == mixed);
  CHECK(textures[0].sample(0.375, 0.5, true) == red);  // texture 1: L: n

  const lsystem::Skeleton sk = finalSkeleton(s);
  const Vec3 leaf = s.render.style.leaf.baseColor;
  // The second square (texture 2, per surface): s = -x / 3 over x in [-3, 0], t = (y - 4) / 3.
  // A camera straight in front of p = (-9/8, 5.5, 0) at depth d, 90 degrees over 16 pixels:
  // a pixel is d / 8 wide there, 2/3 texel along s (2 texels over 3 units), 1/3 along t, so
  // GL's footprint is rho = d / 12: magnified nearer than 12, minified beyond.
  const Vec3 p(-1.125f, 5.5f, 0.0f);
  checkColor(colorSeenFrom(s, sk, p, 6.0f), Vec3(red) * leaf);     // rho 0.5
  checkColor(colorSeenFrom(s, sk, p, 11.8f), Vec3(red) * leaf);    // rho 0.983
  checkColor(colorSeenFrom(s, sk, p, 12.2f), Vec3(mixed) * leaf);  // rho 1.017
  checkColor(colorSeenFrom(s, sk, p, 40.0f), Vec3(mixed) * leaf);
  // Without a camera every lookup magnifies.
  render::Scene plain;
  addPreview(plain, sk, s);
  auto hit = plain.intersect(p - Vec3(0, 0, 40), Vec3(0, 0, 1), 0.0f, 100.0f);
  REQUIRE(hit);
  checkColor(hit->color, Vec3(red) * leaf);
}

TEST_CASE("cpfg textures on polygons", "[model][cpfg]") {
  const fs::path dir = writeObject("sprig-cpfg-polygon-texture-test", textureObject(), {"halves.png"},
                                   "angle increment: 90\ntexture: F: halves.png E: d\n",
                                   "lsystem: 1\nderivation length: 0\naxiom: @Tx(1){.f+f}\nendlsystem\n");
  const Species s = loadSpecies(dir);
  const lsystem::Skeleton sk = finalSkeleton(s);
  // Points (0,0,0), (0,1,0), (-1,1,0); the first point's frame has H = +Y and -L = +X, so
  // t = y over [0, 1] and s = x over [-1, 0] (irisGL.c PolygonToMesh): a fan of 1 triangle.
  REQUIRE(sk.organs.size() == 1);
  const lsystem::Organ& o = sk.organs[0];
  CHECK(o.kind == lsystem::Organ::Kind::Polygon);
  CHECK(o.texture == 0);
  CHECK(o.triangles == std::vector<uint32_t>{0, 1, 2});
  REQUIRE(o.uvs.size() == 3);
  CHECK(o.uvs[0] == Vec2(1, 0));
  CHECK(o.uvs[1] == Vec2(1, 1));
  CHECK(o.uvs[2] == Vec2(0, 1));
  REQUIRE(o.normals.size() == 3);
  CHECK(std::abs(o.normals[0].z) == Approx(1.0));
  render::Scene scene;
  addPreview(scene, sk, s);
  // Decal halves.png: red for s below 1/2 (x < -1/2), blue above; drawn once (not also as
  // an untextured polygon: no other hit behind the first).
  checkColor(colorAt(scene, -0.6f, 0.9f), Vec3(1, 0, 0));
  checkColor(colorAt(scene, -0.25f, 0.75f), Vec3(0, 0, 1));
  CHECK_FALSE(scene.intersect(Vec3(-0.6f, 0.9f, -10), Vec3(0, 0, 1), 10.001f, 100.0f));
  fs::remove_all(dir);
}

TEST_CASE("cpfg cut-out textures render the same bytes at 1 and 2 threads", "[model][cpfg]") {
  // Shadow and sky rays through partly covering texels are decided by a hash of the ray.
  const Species s = loadSpecies(cutoutObject());
  const lsystem::Skeleton sk = finalSkeleton(s);
  render::Camera camera;
  camera.position = Vec3(-4, 1.5f, -12);
  camera.target = Vec3(-4, 1.5f, 0);
  CHECK(renderPreview(s, sk, camera, 1).pixels == renderPreview(s, sk, camera, 2).pixels);
}

namespace {

/// The colour seen by a ray toward the point c of a tube's axis, coming from the direction
/// d = cos b L + sin b U' (U' is cpfg's up vector, -U): from 10 units out along d. The
/// tube's radius is r (32 sides: the hit lies within 0.5% of it).
Vec3 colorToward(const render::Scene& scene, const Vec3& c, const Vec3& left, const Vec3& upCpfg, double bDeg, float r) {
  const double b = bDeg * 3.14159265358979323846 / 180.0;
  const Vec3 d = static_cast<float>(std::cos(b)) * left + static_cast<float>(std::sin(b)) * upCpfg;
  INFO("ray toward (" << c.x << ", " << c.y << ", " << c.z << ") from angle " << bDeg);
  auto hit = scene.intersect(c + 10.0f * d, -d, 0.0f, 100.0f);
  REQUIRE(hit);
  CHECK(hit->t == Approx(10.0f - r).margin(0.005f * r));
  return hit->color;
}

/// colorToward for a tube of radius 1 along +Y through (x0, 0, 0) in the turtle's starting
/// frame (L = -X, U' = -Z), at height y.
Vec3 colorAround(const render::Scene& scene, float x0, float y, double bDeg) {
  return colorToward(scene, Vec3(x0, y, 0), Vec3(-1, 0, 0), Vec3(0, 0, -1), bDeg, 1.0f);
}

}  // namespace

TEST_CASE("cpfg textures on cylinders and generalized cylinders", "[model][cpfg]") {
  const Species s = loadSpecies(cylinderObject());
  const lsystem::Skeleton sk = finalSkeleton(s);
  const double pi = 3.14159265358979323846;
  // Every segment is a textured tube (no internode): F(4), two generalized-cylinder
  // segments, then F(2), the branch's +F(1), F(1) at width 1, and F(1) after f(1).
  CHECK(sk.internodes.empty());
  REQUIRE(sk.organs.size() == 7);
  const char* names[] = {lsystem::kTexturedCylinderName, lsystem::kTexturedGcName, lsystem::kTexturedGcName,
                         lsystem::kTexturedCylinderName, lsystem::kTexturedCylinderName, lsystem::kTexturedCylinderName,
                         lsystem::kTexturedCylinderName};
  // t accumulates along the branch by length / (pi d) * 2 (textures.c): d = 2 gives
  // length / pi; the generalized cylinder starts at the turtle's t (4 / pi) and adds its
  // length (3 per segment, straight); the side branch starts at its parent's t, and so does
  // the continuation after ']'; !(1) doubles the rate, and the move f(1) adds to t too.
  const double t0[] = {0, 4, 7, 10, 12, 12, 16}, t1[] = {4, 7, 10, 12, 13, 14, 18};
  for (size_t k = 0; k < 7; ++k) {
    INFO("organ " << k);
    const lsystem::Organ& o = sk.organs[k];
    CHECK(o.name == names[k]);
    CHECK(o.texture == 0);
    CHECK(o.kind == lsystem::Organ::Kind::Surface);
    // 8 sides (cpfg's default) times 4: 33 points per ring (the seam twice), 2 rings for F,
    // 4 + 1 rings for a generalized-cylinder segment @Gc(3)/@Ge(3) (3 pieces).
    const size_t rings = std::string(names[k]) == lsystem::kTexturedCylinderName ? 2 : 4;
    REQUIRE(o.points.size() == 33 * rings);
    REQUIRE(o.uvs.size() == o.points.size());
    CHECK(o.triangles.size() == 3 * 2 * 32 * (rings - 1));
    CHECK(o.uvs.front().y == Approx(t0[k] / pi));
    CHECK(o.uvs.back().y == Approx(t1[k] / pi));
    for (size_t m = 0; m <= 32; ++m) {
      INFO("point " << m);
      // F: s = m / 32 from the seam along L; a generalized cylinder: s = 1 - m / 32 (general.c).
      const float sWant = rings == 2 ? m / 32.0f : 1.0f - m / 32.0f;
      CHECK(o.uvs[m].x == Approx(sWant));
      CHECK(o.uvs[m].y == Approx(t0[k] / pi));
      CHECK(o.uvs[o.uvs.size() - 33 + m].x == Approx(sWant));
    }
  }
  // The F at width 1 has radius 1/2; the others radius 1.
  CHECK(glm::length(sk.organs[5].points[0] - sk.organs[5].position) == Approx(0.5));
  CHECK(glm::length(sk.organs[3].points[0] - sk.organs[3].position) == Approx(1.0));
  // The F's seam (s = 0) is along L (-X), a quarter turn (s = 1/4) toward cpfg's up (-Z).
  CHECK(sk.organs[0].points[0].x == Approx(-1.0));
  CHECK(sk.organs[0].points[8].z == Approx(-1.0));
  // The generalized cylinder's seam is along cpfg's up (-Z), s = 1/4 along L (-X).
  CHECK(sk.organs[1].points[0].z == Approx(-1.0));
  CHECK(sk.organs[1].points[24].x == Approx(10.0 - 1.0));

  // The renderer's colours (decal: the texel itself) where rays meet the tubes. F(4) at the
  // origin: s = b / 360 at angle b from L toward U' (red, green, blue, white quarters), t =
  // y / pi (bottom row below 1/2, top row above, repeating).
  render::Scene scene;
  addPreview(scene, sk, s);
  const Vec3 red(1, 0, 0), green(0, 1, 0), blue(0, 0, 1), white(1), cyan(0, 1, 1), magenta(1, 0, 1), yellow(1, 1, 0);
  checkColor(colorAround(scene, 0, 0.5f, 40), red);  // t = 0.16
  checkColor(colorAround(scene, 0, 0.5f, 130), green);
  checkColor(colorAround(scene, 0, 0.5f, 220), blue);
  checkColor(colorAround(scene, 0, 0.5f, 310), white);
  checkColor(colorAround(scene, 0, 2.0f, 40), cyan);  // t = 0.64
  checkColor(colorAround(scene, 0, 2.0f, 130), magenta);
  checkColor(colorAround(scene, 0, 2.0f, 220), yellow);
  checkColor(colorAround(scene, 0, 3.5f, 130), green);  // t = 1.11: the image again
  // The generalized cylinder at x = 10: s = 1 - b' / 360 with b' from U' toward -L, so at
  // angle b from L toward U' s = (90 - b) / 360 (mod 1): the same bisector at 45 degrees,
  // mirrored; t = (4 + y) / pi.
  checkColor(colorAround(scene, 10, 0.5f, 40), red);    // s = 0.014, t = 1.43
  checkColor(colorAround(scene, 10, 0.5f, 310), green);  // s = 0.361
  checkColor(colorAround(scene, 10, 0.5f, 220), blue);   // s = 0.611
  checkColor(colorAround(scene, 10, 0.5f, 130), white);  // s = 0.861
  checkColor(colorAround(scene, 10, 2.0f, 310), magenta);  // t = 1.91
  checkColor(colorAround(scene, 10, 4.5f, 310), magenta);  // second segment, t = 2.71
  checkColor(colorAround(scene, 10, 5.5f, 310), green);    // t = 3.02

  // The same tubes in the exact and mesh modes (no internode, so no BlobTree: the
  // preview's parts).
  SpeciesModel model(s, ModelOptions{});
  for (GeometryMode mode : {GeometryMode::Exact, GeometryMode::Mesh}) {
    render::Scene other;
    model.addToScene(other, model.finalStage(), mode, s.render);
    other.commit();
    checkColor(colorAround(other, 0, 0.5f, 40), red);
    checkColor(colorAround(other, 10, 2.0f, 310), magenta);
  }

  // The export: one textured wood part (one texture, one colour) holding every tube, its
  // uvs the organs' (s in [0, 1], t from 0 to 18 / pi), double sided, the image baked.
  const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
  REQUIRE(parts.size() == 1);
  CHECK(parts[0].name == "textured_wood_0");
  CHECK(parts[0].mesh.triangleCount() == 64 * 5 + 3 * 64 * 2);
  REQUIRE(parts[0].mesh.uvs.size() == parts[0].mesh.positions.size());
  Vec2 lo(1e9f), hi(-1e9f);
  for (const Vec2& uv : parts[0].mesh.uvs) {
    lo = glm::min(lo, uv);
    hi = glm::max(hi, uv);
  }
  CHECK(lo.x == 0.0f);
  CHECK(hi.x == 1.0f);
  CHECK(lo.y == 0.0f);
  CHECK(hi.y == Approx(18 / pi));
  REQUIRE(parts[0].material.texture);
  CHECK(parts[0].material.texture->image.width == 4);
  CHECK(parts[0].material.texture->image.height == 2);
  CHECK(parts[0].material.alphaCutoff < 0);
}

TEST_CASE("cpfg textured cylinders beside untextured wood: parts and export", "[model][cpfg]") {
  // An untextured trunk, a textured branch (modulate: texel times the wood colour), and the
  // trunk again after ']' (untextured: the bracket ended the texture).
  const fs::path dir =
      writeObject("sprig-cpfg-cylinder-texture-test", cylinderObject(), {"quadrants.png"},
                  "angle increment: 45\nline style: cylinder\ntexture: F: quadrants.png R: 2\n",
                  "lsystem: 1\nderivation length: 0\naxiom: !(0.5)F(2)[+@Tx(1)F(1)F(1)]F(2)\nendlsystem\n");
  const Species s = loadSpecies(dir);
  const lsystem::Skeleton sk = finalSkeleton(s);
  CHECK(sk.internodes.size() == 2);
  REQUIRE(sk.organs.size() == 2);
  // R: 2 halves the rate: 1 / (pi 0.5) * 2 / 2 = 2 / pi per unit length.
  const double pi = 3.14159265358979323846;
  CHECK(sk.organs[0].uvs.back().y == Approx(2 / pi));
  CHECK(sk.organs[1].uvs.front().y == Approx(2 / pi));
  CHECK(sk.organs[1].uvs.back().y == Approx(4 / pi));
  // Rays at the branch, 1/2 along its first segment (t = 1 / pi): angle 40 (s = 0.11) is
  // red, 130 green, times the wood colour, in every mode (the trunk a BlobTree in the
  // exact and mesh modes, the textured branch a mesh beside it).
  const Vec3 wood = s.render.style.wood.baseColor;
  const Vec3 h(-std::sqrt(0.5f), std::sqrt(0.5f), 0), left(-std::sqrt(0.5f), -std::sqrt(0.5f), 0), upCpfg(0, 0, -1);
  SpeciesModel model(s, ModelOptions{});
  for (GeometryMode mode : {GeometryMode::Skeleton, GeometryMode::Exact, GeometryMode::Mesh}) {
    INFO("mode " << static_cast<int>(mode));
    render::Scene scene;
    model.addToScene(scene, model.finalStage(), mode, s.render);
    scene.commit();
    checkColor(colorToward(scene, Vec3(0, 2, 0) + 0.5f * h, left, upCpfg, 40, 0.25f), Vec3(1, 0, 0) * wood);
    checkColor(colorToward(scene, Vec3(0, 2, 0) + 0.5f * h, left, upCpfg, 130, 0.25f), Vec3(0, 1, 0) * wood);
  }
  const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
  std::vector<std::string> names;
  for (const ExportPart& p : parts) names.push_back(p.name);
  REQUIRE(names.size() == 2);
  CHECK(names[0] == "wood");
  CHECK(names[1] == "textured_wood_1");
  // The baked image: each texel times the wood colour (modulate); top row of the image is
  // the texture's upper row (t above 1/2): cyan first.
  const Image& img = parts[1].material.texture->image;
  CHECK(glm::length(Vec3(img.at(0, 1)) - Vec3(1, 0, 0) * wood) < 1e-6f);
  CHECK(glm::length(Vec3(img.at(0, 0)) - Vec3(0, 1, 1) * wood) < 1e-6f);
  // glb written and read back: two meshes, the textured one with TEXCOORD_0 (s, 1 - t) over
  // s in [0, 1] and t in [0, 4 / pi].
  const fs::path glb = dir / "plant.glb";
  writeParts(parts, glb);
  tinygltf::Model m;
  tinygltf::TinyGLTF loader;
  std::string err, warn;
  REQUIRE(loader.LoadBinaryFromFile(&m, &err, &warn, glb.string()));
  REQUIRE(m.meshes.size() == 2);
  const tinygltf::Primitive& prim = m.meshes[1].primitives[0];
  REQUIRE(prim.attributes.count("TEXCOORD_0"));
  const tinygltf::Accessor& uv = m.accessors[static_cast<size_t>(prim.attributes.at("TEXCOORD_0"))];
  REQUIRE(uv.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT);
  REQUIRE(uv.type == TINYGLTF_TYPE_VEC2);
  const tinygltf::BufferView& view = m.bufferViews[static_cast<size_t>(uv.bufferView)];
  const size_t stride = view.byteStride ? view.byteStride : 2 * sizeof(float);
  Vec2 lo(1e9f), hi(-1e9f);
  for (size_t k = 0; k < uv.count; ++k) {
    Vec2 v;
    std::memcpy(&v, m.buffers[static_cast<size_t>(view.buffer)].data.data() + view.byteOffset + uv.byteOffset + k * stride, sizeof v);
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  CHECK(uv.count == parts[1].mesh.positions.size());
  CHECK(lo.x == 0.0f);
  CHECK(hi.x == 1.0f);
  CHECK(lo.y == Approx(1 - 4 / pi));  // glTF's v runs down the image: 1 - t
  CHECK(hi.y == 1.0f);
  const int texIndex = m.materials[static_cast<size_t>(prim.material)].pbrMetallicRoughness.baseColorTexture.index;
  REQUIRE(texIndex >= 0);
  // t runs on along the branch (beyond 1): the sampler repeats both ways, as GL_REPEAT.
  const tinygltf::Sampler& sampler = m.samplers[static_cast<size_t>(m.textures[static_cast<size_t>(texIndex)].sampler)];
  CHECK(sampler.wrapS == TINYGLTF_TEXTURE_WRAP_REPEAT);
  CHECK(sampler.wrapT == TINYGLTF_TEXTURE_WRAP_REPEAT);
  fs::remove_all(dir);
}

TEST_CASE("cpfg textured cylinders render the same bytes at 1 and 2 threads", "[model][cpfg]") {
  const Species s = loadSpecies(cylinderObject());
  const lsystem::Skeleton sk = finalSkeleton(s);
  render::Camera camera;
  camera.position = Vec3(10, 4, -30);
  camera.target = Vec3(10, 4, 0);
  const Image a = renderPreview(s, sk, camera, 1);
  CHECK(a.pixels == renderPreview(s, sk, camera, 2).pixels);
}

TEST_CASE("cpfg cut-out textures on cylinders", "[model][cpfg]") {
  // cutout.png: five red texels along s of alpha 255, 0, 128, 26 and 25, modulated, on an F
  // of diameter 2 (radius 1) up +Y: texel k covers s in [k/5, (k+1)/5), s = b / 360 at angle
  // b from L (-X) toward cpfg's up (-Z); a ray through the axis meets the far wall at b + 180.
  const fs::path dir = writeObject("sprig-cpfg-cylinder-cutout-test", cutoutObject(), {"cutout.png"},
                                   "line style: cylinder\ntexture: F: cutout.png E: m\n",
                                   "lsystem: 1\nderivation length: 0\naxiom: !(2)@Tx(1)F(1)\nendlsystem\n");
  const Species s = loadSpecies(dir);
  const lsystem::Skeleton sk = finalSkeleton(s);
  render::Scene scene;
  addPreview(scene, sk, s);
  const Vec3 wood = s.render.style.wood.baseColor;
  // A ray toward (0, 0.5, 0) on the axis from angle b: d = cos b L + sin b U'.
  auto fromAngle = [](double bDeg) {
    const double b = bDeg * 3.14159265358979323846 / 180.0;
    return Vec3(static_cast<float>(-std::cos(b)), 0.0f, static_cast<float>(-std::sin(b)));
  };
  auto rayAt = [&](double bDeg) {
    const Vec3 d = fromAngle(bDeg);
    return scene.intersect(Vec3(0, 0.5f, 0) + 10.0f * d, -d, 0.0f, 100.0f);
  };
  // b = 36: s = 0.1, the opaque texel: red times the wood colour, opaque, on the near wall.
  auto opaque = rayAt(36);
  REQUIRE(opaque);
  CHECK(opaque->t == Approx(9.0f).margin(0.005f));
  CHECK(opaque->opacity == 1.0f);
  checkColor(opaque->color, Vec3(1, 0, 0) * wood);
  // b = 112: s = 0.31 (alpha 0) near, s = 0.81 (alpha 25/255, at or below 0.1) far: both cut
  // out, the ray passes through the tube.
  CHECK_FALSE(rayAt(112));
  // b = 150: s = 0.42 (alpha 128/255): the near wall covers half, blended over what lies behind.
  auto half = rayAt(150);
  REQUIRE(half);
  CHECK(half->t == Approx(9.0f).margin(0.005f));
  CHECK(half->opacity == Approx(128.0f / 255.0f).margin(1e-3f));
  // Shadow rays are cut the same way: blocked by the opaque texel, not through the cut ones.
  auto occludedAt = [&](double bDeg) {
    const Vec3 d = fromAngle(bDeg);
    return scene.occluded(Vec3(0, 0.5f, 0) + 10.0f * d, -d, 0.0f, 100.0f);
  };
  CHECK(occludedAt(36));
  CHECK_FALSE(occludedAt(112));
  fs::remove_all(dir);
}

namespace {

/// The linear colour of 8-bit sRGB-encoded values e (0..1 each).
Vec4 fromSrgb(float r, float g, float b, float a = 1.0f) { return Vec4(srgbToLinear(r), srgbToLinear(g), srgbToLinear(b), a); }

void checkTexel(const Vec4& got, const Vec4& want, float tolerance = 1e-5f) {
  INFO("got (" << got.r << ", " << got.g << ", " << got.b << ", " << got.a << "), expected (" << want.r << ", " << want.g
               << ", " << want.b << ", " << want.a << ")");
  CHECK(glm::length(got - want) < tolerance);
}

}  // namespace

TEST_CASE("cpfg mipmapped textures: the level of log2 of the texel footprint", "[model][cpfg]") {
  const Species s = loadSpecies(mipmapObject());
  REQUIRE(s.render.style.cpfgTextures);
  const auto& textures = *s.render.style.cpfgTextures;
  REQUIRE(textures.size() == 5);
  const lsystem::CpfgTexture& trilinear = textures[0];
  const lsystem::CpfgTexture& nearest = textures[1];
  CHECK(trilinear.mipmap);
  CHECK(trilinear.minLinear);  // L: m is GL_LINEAR_MIPMAP_LINEAR (textures.c)
  CHECK(trilinear.mipLinear);
  CHECK(nearest.mipmap);
  CHECK_FALSE(nearest.minLinear);  // L: mnn is GL_NEAREST_MIPMAP_NEAREST
  CHECK_FALSE(nearest.mipLinear);
  CHECK_FALSE(textures[2].mipmap);
  // quads.png (4 x 4): levels 2 x 2 and 1 x 1, each texel the mean of four in sRGB values.
  REQUIRE(trilinear.levels.size() == 2);
  CHECK(trilinear.levels[0]->width == 2);
  CHECK(trilinear.levels[0]->height == 2);
  CHECK(trilinear.levels[1]->width == 1);
  CHECK(trilinear.levels[1]->height == 1);
  const Vec4 red(1, 0, 0, 1), blue(0, 0, 1, 1), green(0, 1, 0, 1), white(1, 1, 1, 1);
  const Vec4 purple = fromSrgb(0.5f, 0.0f, 0.5f);          // level 1, top left: R B / B R
  const Vec4 mean = fromSrgb(0.375f, 0.5f, 0.625f);        // level 2: purple, green, white, blue
  checkTexel(trilinear.levels[0]->at(0, 0), purple);
  checkTexel(trilinear.levels[0]->at(1, 0), green);
  checkTexel(trilinear.levels[0]->at(0, 1), white);
  checkTexel(trilinear.levels[0]->at(1, 1), blue);
  checkTexel(trilinear.levels[1]->at(0, 0), mean);

  SECTION("GL_LINEAR_MIPMAP_LINEAR: lambda = log2 rho, levels floor(lambda) and the next mixed by its fraction") {
    // (1/8, 7/8) is the top-left texel (R); (1/4, 3/4) the centre of level 1's top-left texel.
    checkTexel(trilinear.sampleFootprint(0.125, 0.875, 0.0), red);   // no footprint: magnified
    checkTexel(trilinear.sampleFootprint(0.125, 0.875, 0.5), red);   // lambda -1: magnified, H: n
    checkTexel(trilinear.sampleFootprint(0.125, 0.875, 1.0), red);   // lambda 0: still magnified (c = 0)
    checkTexel(trilinear.sampleFootprint(0.25, 0.75, 2.0), purple);  // lambda 1: level 1 at its texel's centre
    checkTexel(trilinear.sampleFootprint(0.25, 0.75, 4.0), mean);    // lambda 2: the last level
    checkTexel(trilinear.sampleFootprint(0.25, 0.75, 1000.0), mean);  // clamped to the last level
    checkTexel(trilinear.sampleFootprint(0.25, 0.75, 2.0 * std::sqrt(2.0)), 0.5f * (purple + mean));  // lambda 1.5
    // Bilinear within level 1: halfway between its purple and green texels.
    checkTexel(trilinear.sampleFootprint(0.5, 0.75, 2.0), 0.5f * (purple + green));
    // Between levels 0 and 1 at lambda 0.5: level 0 bilinear at (1/4, 3/4) is the mean of
    // R B / B R in linear values, level 1 the mean in sRGB values.
    const Vec4 linearMean = 0.5f * (red + blue);
    checkTexel(trilinear.sampleFootprint(0.25, 0.75, std::sqrt(2.0)), 0.5f * (linearMean + purple));
  }
  SECTION("GL_NEAREST_MIPMAP_NEAREST: level ceil(lambda + 1/2) - 1, nearest texel") {
    checkTexel(nearest.sampleFootprint(0.125, 0.875, std::pow(2.0, 0.4)), red);       // lambda 0.4: level 0
    checkTexel(nearest.sampleFootprint(0.125, 0.875, std::pow(2.0, 1.4)), purple);    // lambda 1.4: level 1
    checkTexel(nearest.sampleFootprint(0.125, 0.875, std::pow(2.0, 1.6)), mean);      // lambda 1.6: level 2
    checkTexel(nearest.sampleFootprint(0.625, 0.875, std::pow(2.0, 1.4)), green);
  }
  SECTION("an image whose sides are not powers of two is scaled to the nearest ones first (GLU)") {
    const lsystem::CpfgTexture& odd = textures[4];  // cutout.png, 5 x 1
    CHECK(odd.image->width == 4);
    CHECK(odd.image->height == 1);
    REQUIRE(odd.levels.size() == 2);
    CHECK(odd.levels[0]->width == 2);
    CHECK(odd.levels[1]->width == 1);
    CHECK(odd.levels[1]->height == 1);
  }
  SECTION("the renderer's footprint picks the level: a camera in front of the square at depth d sees rho = d / 6") {
    const lsystem::Skeleton sk = finalSkeleton(s);
    const Vec3 leaf = s.render.style.leaf.baseColor;
    // Square 1 (per surface): s = -x / 3 over x in [-3, 0], t = y / 3. 90 degrees over 16
    // pixels: a pixel is d / 8 wide at depth d, 4/3 texels per unit, so rho = d / 6.
    checkColor(colorSeenFrom(s, sk, Vec3(-0.375f, 2.625f, 0), 3.0f), Vec3(red) * leaf);  // rho 0.5: level 0
    const Vec3 atLevel1 = colorSeenFrom(s, sk, Vec3(-0.75f, 2.25f, 0), 12.0f);           // rho 2
    CHECK(glm::length(atLevel1 - Vec3(purple) * leaf) < 1e-4f);
    // rho 4 (log2 of the computed footprint may fall a hair below 2: level 1 then weighs ~1e-6)
    CHECK(glm::length(colorSeenFrom(s, sk, Vec3(-0.75f, 2.25f, 0), 24.0f) - Vec3(mean) * leaf) < 1e-4f);
  }
  SECTION("export: the glTF sampler minifies with LINEAR_MIPMAP_LINEAR") {
    SpeciesModel model(s, ModelOptions{});
    const std::vector<ExportPart> parts = model.exportParts(model.finalStage(), 0.0f, false);
    int textured = 0, mipmapped = 0;
    for (const ExportPart& part : parts) {
      if (part.name.rfind("textured_leaves_", 0) != 0) continue;  // not the wood's bark
      REQUIRE(part.material.texture);
      ++textured;
      if (part.material.texture->minFilter == PartTexture::Filter::Default) ++mipmapped;
    }
    CHECK(textured == 3);   // textures 1, 3 and 4 (texture 2 and 5 are drawn nowhere)
    CHECK(mipmapped == 1);  // texture 1
  }
}

TEST_CASE("cpfg blended textures (E: b): the colour times one minus the texel", "[model][cpfg]") {
  const Species s = loadSpecies(mipmapObject());
  const auto& textures = *s.render.style.cpfgTextures;
  const lsystem::CpfgTexture& blend = textures[2];
  const lsystem::CpfgTexture& cut = textures[3];
  CHECK(blend.blend);
  CHECK_FALSE(blend.decal);
  CHECK_FALSE(blend.cutsOut());  // opaque texels
  CHECK(cut.cutsOut());          // GL_BLEND keeps the texel's alpha: alpha-tested as modulate
  // C = Cf (1 - Ct) + Cc Ct with cpfg's environment colour Cc GL's default (0, 0, 0, 0); A = Af At.
  const Vec3 base(0.2f, 0.6f, 0.8f);
  checkTexel(blend.combine(Vec4(1, 0, 0, 1), base), Vec4(0, 0.6f, 0.8f, 1));
  checkTexel(blend.combine(Vec4(0.25f, 0.5f, 1, 0.5f), base), Vec4(0.15f, 0.3f, 0, 0.5f));
  checkTexel(blend.fragment(0.875, 0.875, base), Vec4(0.2f, 0, 0.8f, 1));  // green texel
  checkTexel(blend.fragment(0.125, 0.125, base), Vec4(0, 0, 0, 1));        // white texel: black

  const lsystem::Skeleton sk = finalSkeleton(s);
  render::Scene scene;
  addPreview(scene, sk, s);
  const Vec3 leaf = s.render.style.leaf.baseColor;
  // Square 2 (texture 3, per surface) at y in [4, 7]: s = -x / 3, t = (y - 4) / 3.
  checkColor(colorAt(scene, -0.375f, 6.625f), leaf * Vec3(0, 1, 1));   // red texel
  checkColor(colorAt(scene, -2.625f, 6.625f), leaf * Vec3(1, 0, 1));   // green texel
  checkColor(colorAt(scene, -0.375f, 4.375f), Vec3(0));                // white texel
  // Square 3 (texture 4, per patch) at y in [8, 11]: s along y, texel k at y = 8.3 + 0.6 k.
  auto ray = [&](float x, float y) { return scene.intersect(Vec3(x, y, -10), Vec3(0, 0, 1), 0.0f, 100.0f); };
  auto opaque = ray(-1.5f, 8.3f);
  REQUIRE(opaque);
  CHECK(opaque->t == Approx(10.0f));
  checkColor(opaque->color, leaf * Vec3(0, 1, 1));
  CHECK_FALSE(ray(-1.5f, 8.9f));  // alpha 0: cut out, nothing behind
  CHECK_FALSE(ray(-1.5f, 10.7f));  // alpha 25/255: cut out
  auto part = ray(-1.5f, 9.5f);  // alpha 128/255: drawn, covering that much
  REQUIRE(part);
  CHECK(part->opacity == Approx(128 / 255.0f).margin(1e-6));
}
