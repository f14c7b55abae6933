// The bark keys of kind: blob species: the same table as tree species' tree.bark
// (model/bark_keys.h), so peeling and braided bark, their colours and the branch bark ridge
// (on PCM seams and as arcs over branches) reach blob species too.

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "core/image.h"
#include "model/blob_kind.h"
#include "model/model.h"
#include "model/schema.h"
#include "model/species.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"

using namespace sprig;

namespace {

// A blob species: one vertical segment (radius 0.4, y in [-1, 1]) wearing the bark `bark`.
std::string barkSpecies(const std::string& bark) {
  return "kind: blob\n"
         "textures:\n"
         "  - bark: {furrows: 12, seed: 2" + bark + "}\n"
         "blob:\n"
         "  segment: {a: [0, -1, 0], b: [0, 1, 0], radius: 0.4, texture: {id: 0}}\n";
}

// The species rendered exactly, 64 x 96 at 1 sample, on a transparent background with no ground.
Image renderSpecies(const std::string& text) {
  Species species = parseSpecies(text, "bark.yaml");
  SpeciesModel model(species);
  render::Scene scene;
  model.addToScene(scene, model.finalStage(), GeometryMode::Exact, species.render);
  scene.commit();
  render::RenderSettings rs;
  rs.width = 64;
  rs.height = 96;
  rs.spp = 1;
  rs.threads = 2;
  rs.progress = false;
  rs.ground = false;
  rs.background = render::Background::Transparent;
  return render::renderImage(scene, render::orbitCamera(Vec3(0), 0, 0, 4.0, 40.0), rs);
}

// Over the pixels both images cover fully: the mean colour of each and the share of pixels
// whose luminance differs by more than 5%.
struct Compare {
  Vec3 meanA{0.0f}, meanB{0.0f};
  double changed = 0;
  size_t pixels = 0;
};
Compare compare(const Image& a, const Image& b) {
  Compare c;
  size_t changed = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const Vec4 pa = a.at(x, y), pb = b.at(x, y);
      if (pa.a < 1.0f || pb.a < 1.0f) continue;
      c.meanA += Vec3(pa);
      c.meanB += Vec3(pb);
      const float la = pa.r + pa.g + pa.b, lb = pb.r + pb.g + pb.b;
      if (std::abs(la - lb) > 0.05f * std::max(la, lb)) ++changed;
      ++c.pixels;
    }
  if (c.pixels > 0) {
    c.meanA /= float(c.pixels);
    c.meanB /= float(c.pixels);
    c.changed = double(changed) / double(c.pixels);
  }
  return c;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("blob bark: the keys of tree.bark", "[model]") {
  const Image plain = renderSpecies(barkSpecies(""));
  SECTION("peel 0 is the default: the same pixels") {
    CHECK(renderSpecies(barkSpecies(", peel: 0")).pixels == plain.pixels);
  }
  SECTION("peel covers the bark with grey-brown patches") {
    // Default colours: ridges (0.20, 0.14, 0.09), B/R 0.45; old bark (0.36, 0.31, 0.26),
    // B/R 0.72, covering about peel·(0.4 + 0.6·maturity) = 80% of the surface.
    const Compare c = compare(plain, renderSpecies(barkSpecies(", peel: 0.8")));
    INFO("pixels " << c.pixels << ", changed " << c.changed << ", mean " << c.meanA.r << " " << c.meanA.b << " -> "
                   << c.meanB.r << " " << c.meanB.b);
    REQUIRE(c.pixels > 1000);
    CHECK(c.changed > 0.5);
    CHECK(c.meanB.b / c.meanB.r > c.meanA.b / c.meanA.r + 0.1);
    CHECK(c.meanB.r > 1.3f * c.meanA.r);  // old bark is the paler
    // peel_color sets the patches' colour: pure red patches leave hardly any blue.
    const Compare red = compare(plain, renderSpecies(barkSpecies(", peel: 0.8, peel_color: [0.5, 0, 0]")));
    CHECK(red.meanB.b < 0.6f * c.meanB.b);
    // peel_frequency changes the patches' size.
    CHECK(compare(renderSpecies(barkSpecies(", peel: 0.8")), renderSpecies(barkSpecies(", peel: 0.8, peel_frequency: 12")))
              .changed > 0.2);
  }
  SECTION("braid interlaces the furrows") {
    CHECK(compare(plain, renderSpecies(barkSpecies(", braid: 3"))).changed > 0.2);
  }
}

TEST_CASE("blob bark: errors and the schema", "[model]") {
  SECTION("ranges are the tree's") {
    try {
      parseSpecies(barkSpecies(", peel: 1.5, ridge_arc_spread: 0"), "bark.yaml");
      FAIL("no error");
    } catch (const InputError& e) {
      const std::string what = e.what();
      CHECK(what.find("bark.yaml:3:40: error: 'peel' is 1.5, out of range [0, 1]") != std::string::npos);
      CHECK(what.find("'ridge_arc_spread' is 0, out of range [0.1, 20]") != std::string::npos);
    }
  }
  SECTION("the ridge shades the whole blob: one bark texture sets it") {
    try {
      parseSpecies("kind: blob\ntextures:\n  - bark: {ridge_arc: 0.5}\n  - bark: {ridge_darkening: 0.5}\n"
                   "blob:\n  point: {radius: 1, texture: {id: 0}}\n",
                   "two.yaml");
      FAIL("no error");
    } catch (const InputError& e) {
      CHECK(std::string(e.what()).find("two.yaml:4:11: error: the branch bark ridge keys") != std::string::npos);
    }
  }
  SECTION("sprig schema lists the bark keys for trees and for blobs' bark textures") {
    const std::string schema = speciesSchemaJson();
    for (const char* key : {"\"peel\"", "\"peel_frequency\"", "\"peel_color\"", "\"braid\"", "\"ridge_arc\"",
                            "\"ridge_arc_spread\"", "\"ridge_darkening\"", "\"lenticel_frequency\""}) {
      INFO(key);
      CHECK(count(schema, key) == 2);  // tree.bark and the blob's texture definition
    }
    CHECK(count(schema, "\"tile_v\"") == 1);  // a blob texture's own key
  }
}

TEST_CASE("blobRidgeArcs", "[model]") {
  auto arcsOf = [](const std::string& blob) {
    DiagnosticList diags;
    auto file = YamlFile::parse("kind: blob\nblob:\n" + blob, "arcs.yaml", diags);
    REQUIRE(file);
    MapReader top(file->rootNode(), diags, "species file");
    top.requiredString("kind");
    std::optional<BlobSpecies> s = readBlobSpecies(top, diags);
    top.finish();
    diags.throwIfErrors();
    REQUIRE(s);
    return blobRidgeArcs(s->tree, s->root);
  };
  SECTION("a junction: basal part, leader and one lateral") {
    const auto arcs = arcsOf(
        "  blend:\n"
        "    - cone: {a: [0, 0, 0], b: [0, 1, 0], radius_a: 0.25, radius_b: 0.2}\n"
        "    - cone: {a: [0, 1, 0], b: [0.1, 2, 0], radius_a: 0.18, radius_b: 0.1}\n"
        "    - cone: {a: [0, 1, 0], b: [0, 1, -1], radius_a: 0.07, radius_b: 0.05}\n");
    REQUIRE(arcs.size() == 1);
    CHECK(arcs[0].point == Vec3(0, 1, 0));
    CHECK(glm::length(arcs[0].branchAxis - Vec3(0, 0, -1)) < 1e-6f);
    CHECK(glm::length(arcs[0].parentAxis - glm::normalize(Vec3(0.1f, 1, 0))) < 1e-6f);
    CHECK(arcs[0].parentRadius == Approx(0.2));  // the larger of the basal's end and the leader's start
    CHECK(arcs[0].branchRadius == Approx(0.07));
  }
  SECTION("a branch out of the side of a segment, moved by a transform") {
    const auto arcs = arcsOf(
        "  translate:\n"
        "    offset: [1, 0, 0]\n"
        "    child:\n"
        "      blend:\n"
        "        - segment: {a: [0, 0, 0], b: [0, 2, 0], radius: 0.3}\n"
        "        - segment: {a: [0, 0.5, 0], b: [1, 0.5, 0], radius: 0.1}\n");
    REQUIRE(arcs.size() == 1);
    CHECK(arcs[0].point == Vec3(1, 0.5f, 0));
    CHECK(arcs[0].parentAxis == Vec3(0, 1, 0));
    CHECK(arcs[0].parentRadius == Approx(0.3));
  }
  SECTION("a fork with no basal part, cutters and lone parts have no arcs") {
    CHECK(arcsOf("  blend:\n"
                 "    - segment: {a: [0, 0, 0], b: [1, 1, 0], radius: 0.1}\n"
                 "    - segment: {a: [0, 0, 0], b: [-1, 1, 0], radius: 0.1}\n")
              .empty());
    CHECK(arcsOf("  difference:\n"
                 "    - segment: {a: [0, 0, 0], b: [0, 2, 0], radius: 0.3}\n"
                 "    - segment: {a: [0, 1, 0], b: [1, 1, 0], radius: 0.1}\n")
              .empty());
  }
}

TEST_CASE("blob bark: the branch bark ridge arc over a blob's branch", "[model]") {
  // A trunk of two cones (radius 0.2) and a horizontal lateral (radius 0.07) toward -z at
  // y = 1. The arc's apex stands 1/sin 90° + rise = 1.6 branch radii above the point where
  // the lateral's axis leaves the trunk: y = 1.112 on the trunk's front; it darkens the
  // bark there by up to ridge_arc = 0.85 and leaves the bark below the lateral and on the
  // back exactly as it is.
  auto species = [](const std::string& arc) {
    return "kind: blob\n"
           "textures:\n"
           "  - bark: {furrows: 8, seed: 1" + arc + "}\n"
           "blob:\n"
           "  blend:\n"
           "    - cone: {a: [0, 0, 0], b: [0, 1, 0], radius_a: 0.2, radius_b: 0.2, texture: {id: 0}}\n"
           "    - cone: {a: [0, 1, 0], b: [0, 2, 0], radius_a: 0.2, radius_b: 0.2, texture: {id: 0}}\n"
           "    - cone: {a: [0, 1, 0], b: [0, 1, -1], radius_a: 0.07, radius_b: 0.06, texture: {id: 0}}\n";
  };
  struct Lit {
    Species species;
    SpeciesModel model;
    render::Scene scene;
    explicit Lit(const std::string& text) : species(parseSpecies(text, "arc.yaml")), model(species) {
      model.addToScene(scene, model.finalStage(), GeometryMode::Exact, species.render);
      scene.commit();
    }
    Vec3 colorAt(Vec3 from, Vec3 dir) const {
      auto hit = scene.intersect(from, dir, 0.0f, 100.0f);
      REQUIRE(hit);
      return hit->color;
    }
  };
  const Lit plain(species("")), arc(species(", ridge_arc: 0.85, ridge_arc_width: 0.5"));
  const Vec3 front(0, 0, 1), back(0, 0, -1);
  // Up the trunk's front over the lateral (the sum blend bulges it: hits at z -0.33 to -0.25):
  // one dark band, centred on the apex and about 2·width·r_B = 0.07 wide, the bark unchanged
  // below and above it.
  float darkest = 1.0f, darkestY = 0.0f;
  for (int i = 0; i <= 14; ++i) {
    const float y = 1.08f + 0.005f * float(i);
    const float ratio = arc.colorAt(Vec3(0, y, -5), front).r / plain.colorAt(Vec3(0, y, -5), front).r;
    if (ratio < darkest) darkest = ratio, darkestY = y;
  }
  CHECK(darkest < 0.45f);
  CHECK(std::abs(darkestY - 1.117f) < 0.012f);
  for (float y : {1.07f, 1.16f, 1.3f, 0.8f}) {
    CAPTURE(y);
    CHECK(arc.colorAt(Vec3(0, y, -5), front) == plain.colorAt(Vec3(0, y, -5), front));
  }
  CHECK(arc.colorAt(Vec3(0, 1.12f, 5), back) == plain.colorAt(Vec3(0, 1.12f, 5), back));
}

TEST_CASE("blob bark: ridge_arc_height raises the arc over a blob's branch", "[model]") {
  // The blob of the test above: the arc's apex on the trunk's front at y = 1.112 (the sum
  // blend bulges the trunk there beyond its radius 0.2). With ridge_arc_height 0.3 the
  // surface there comes 0.3·r_B = 0.021 nearer a ray from the front; below the lateral, on
  // the back and far above the arc nothing moves.
  auto species = [](const std::string& arc) {
    return "kind: blob\n"
           "textures:\n"
           "  - bark: {furrows: 8, seed: 1" + arc + "}\n"
           "blob:\n"
           "  blend:\n"
           "    - cone: {a: [0, 0, 0], b: [0, 1, 0], radius_a: 0.2, radius_b: 0.2, texture: {id: 0}}\n"
           "    - cone: {a: [0, 1, 0], b: [0, 2, 0], radius_a: 0.2, radius_b: 0.2, texture: {id: 0}}\n"
           "    - cone: {a: [0, 1, 0], b: [0, 1, -1], radius_a: 0.07, radius_b: 0.06, texture: {id: 0}}\n";
  };
  auto hitDistance = [](const Species& s, Vec3 from, Vec3 dir) {
    SpeciesModel model(s);
    render::Scene scene;
    model.addToScene(scene, model.finalStage(), GeometryMode::Exact, s.render);
    scene.commit();
    auto hit = scene.intersect(from, dir, 0.0f, 100.0f);
    REQUIRE(hit);
    return glm::length(hit->position - from);
  };
  const Species plain = parseSpecies(species(", ridge_arc: 0.5, ridge_arc_width: 0.5"), "plain.yaml");
  const Species raised = parseSpecies(species(", ridge_arc: 0.5, ridge_arc_width: 0.5, ridge_arc_height: 0.3"), "raised.yaml");
  const Vec3 front(0, 0, 1), back(0, 0, -1);
  const float rise = hitDistance(plain, Vec3(0, 1.112f, -5), front) - hitDistance(raised, Vec3(0, 1.112f, -5), front);
  INFO("raise at the apex " << rise);
  CHECK(rise == Approx(0.3 * 0.07).margin(0.15 * 0.3 * 0.07));
  for (float y : {0.8f, 0.9f, 1.3f})
    CHECK(hitDistance(plain, Vec3(0, y, -5), front) == hitDistance(raised, Vec3(0, y, -5), front));
  CHECK(hitDistance(plain, Vec3(0, 1.112f, 5), back) == hitDistance(raised, Vec3(0, 1.112f, 5), back));
}
