#include <catch2/catch.hpp>

#include "core/image.h"
#include "core/parallel.h"
#include "model/model.h"
#include "model/solid_kind.h"
#include "model/species.h"
#include "tests/model/species_error.h"

#include <array>
#include <cmath>
#include <variant>

using namespace sprig;

namespace {

// A layered ball on a coarse grid: a few thousand tetrahedra, built in well under a second.
const char* kBall = R"(kind: solid
solid:
  grid: {cell: 0.2}
  volume:
    distance_field: {sphere: {radius: 0.7}}
    layers:
      - interior_layer: {material: chocolate, thickness: fill}
      - exterior_layer: {material: white_chocolate, thickness: 0.2}
render:
  ground: false
  background: color
  sky_filter: false
  samples: 2
)";

size_t triangleCount(const std::vector<Mesh>& parts) {
  size_t n = 0;
  for (const Mesh& m : parts) n += m.triangleCount();
  return n;
}

Image renderBall(const SpeciesRender& look, int threads) {
  ThreadLimit limit(threads);
  SpeciesModel model(parseSpecies(kBall, "ball.yaml"));
  RenderJob job;
  job.width = 64;
  job.height = 48;
  job.progress = false;
  return renderModel(model, look, job);
}

float luminance(const Image& im, int x, int y) {
  const Vec4 p = im.at(x, y);
  return 0.2126f * p.x + 0.7152f * p.y + 0.0722f * p.z;
}

}  // namespace

TEST_CASE("wireframeCurves: one segment per distinct edge of the visible triangles", "[model][solid]") {
  const Species s = parseSpecies(kBall, "ball.yaml");
  SpeciesModel model(s);
  ModelFigures fig;
  model.buildMesh(model.finalStage(), 0, false, &fig);

  SECTION("a closed surface: every edge is shared by two triangles, so E = 3T/2 (the whole ball and its cut-away)") {
    // The visible interface of the ball (outer shell only) and of the ball cut by z = 0 (the
    // hemisphere and the disc of the cut, where the tetrahedra's faces show): both closed
    // 2-manifolds whose parts meet along the material boundaries on the cut.
    SpeciesRender look = s.render;
    for (const bool cut : {false, true}) {
      look.section = cut ? std::optional<Vec4>(Vec4(0, 0, 1, 0)) : std::nullopt;
      look.wireframe = WireframeSpec{};
      const BuiltStage built = model.build(model.finalStage(), GeometryMode::Exact, look);
      std::vector<Mesh> meshes;
      const CurveSet* curves = nullptr;
      for (const auto& part : built.geometry.parts) {
        if (const auto* m = std::get_if<render::MeshPart>(&part)) meshes.push_back(m->mesh);
        if (const auto* c = std::get_if<render::CurvesPart>(&part)) curves = &c->curves;
      }
      REQUIRE(curves);
      INFO("cut " << cut);
      CHECK(meshes.size() == (cut ? 2u : 1u));  // white chocolate, and chocolate on the cut
      const size_t t = triangleCount(meshes);
      REQUIRE(t % 2 == 0);
      CHECK(curves->segments.size() == 3 * t / 2);
      CHECK(curves->vertices.size() == 2 * curves->segments.size());
      CHECK(curves->flags == std::vector<uint8_t>(curves->segments.size(), 0));
      // Segments are distinct and sorted by their ends.
      auto key = [&](size_t i) {
        const Vec4 a = curves->vertices[2 * i], b = curves->vertices[2 * i + 1];
        return std::array<float, 6>{a.x, a.y, a.z, b.x, b.y, b.z};
      };
      for (size_t i = 0; i + 1 < curves->segments.size(); ++i) REQUIRE(key(i) < key(i + 1));
    }
  }

  SECTION("the radius is the pixel width at each end's depth") {
    CHECK(wireframeCurves({}, [](const Vec3&) { return 1.0f; }).empty());
    Mesh tri;
    tri.positions = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
    tri.triangles = {{0, 1, 2}, {2, 1, 0}};  // the same triangle twice: three edges
    const CurveSet c = wireframeCurves({tri, tri}, [](const Vec3& p) { return 0.01f + p.x; });
    REQUIRE(c.segments.size() == 3);
    CHECK(c.vertices[0] == Vec4(0, 0, 0, 0.01f));
    CHECK(c.vertices[1] == Vec4(0, 1, 0, 0.01f));
    CHECK(c.vertices[3] == Vec4(1, 0, 0, 1.01f));
  }
}

TEST_CASE("render.wireframe: dark lines over the solid only, the same bytes at 1 and 2 threads", "[model][solid]") {
  SpeciesRender plain = parseSpecies(kBall, "ball.yaml").render;
  plain.section = Vec4(0, 0, 1, 0);
  SpeciesRender wired = plain;
  wired.wireframe = WireframeSpec{};
  const Image a = renderBall(plain, 2);
  const Image b = renderBall(wired, 1);
  const Image c = renderBall(wired, 2);
  CHECK(b.pixels == c.pixels);
  // Background pixels of the plain render (the flat background colour) whose 5 x 5
  // neighbourhood holds no model pixel are unchanged; model pixels darken on the lines.
  const Vec4 bg = a.at(0, 0);
  auto isBackground = [&](int x, int y) { return a.at(x, y) == bg; };
  size_t model = 0, darker = 0, brighter = 0, farChanged = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      bool far = true;
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int u = std::clamp(x + dx, 0, a.width - 1), v = std::clamp(y + dy, 0, a.height - 1);
          far = far && isBackground(u, v);
        }
      if (far) {
        farChanged += a.at(x, y) != b.at(x, y);
        continue;
      }
      if (isBackground(x, y)) continue;
      ++model;
      const float la = luminance(a, x, y), lb = luminance(b, x, y);
      darker += lb < 0.8f * la;
      brighter += lb > 1.05f * la + 1e-3f;
    }
  INFO("model " << model << " darker " << darker << " brighter " << brighter);
  CHECK(farChanged == 0);
  CHECK(model > 500);
  CHECK(darker > model / 10);
  CHECK(brighter < model / 50);
}

TEST_CASE("render.wireframe and render.section: read with their defaults, refused on other kinds, errors at file:line:col", "[model][solid]") {
  const std::string head = "kind: solid\nsolid:\n  volume: {distance_field: {sphere: {}}, layers: [{interior_layer: {material: nut, thickness: fill}}]}\n";
  const Species s = parseSpecies(head + "render:\n  wireframe: {color: [0.1, 0.2, 0.3], width: 2}\n", "solid.yaml");
  REQUIRE(s.render.wireframe);
  CHECK(s.render.wireframe->color == Vec3(0.1f, 0.2f, 0.3f));
  CHECK(s.render.wireframe->widthPixels == 2);
  const Species d = parseSpecies(head + "render:\n  wireframe: {}\n", "solid.yaml");
  REQUIRE(d.render.wireframe);
  CHECK(d.render.wireframe->widthPixels == 1);
  CHECK(!parseSpecies(head, "solid.yaml").render.wireframe);
  auto errorOf = [](const std::string& text) { return test::speciesError(text, "solid.yaml"); };
  CHECK(errorOf(head + "render:\n  wireframe: {width: 0}\n").find("solid.yaml:5:22: error: 'width' is 0, out of range [0.1, 16]") !=
        std::string::npos);
  CHECK(errorOf(head + "render:\n  wireframe: {colour: [0, 0, 0]}\n")
            .find("solid.yaml:5:15: error: unknown key 'colour' in render.wireframe (did you mean 'color'?)") != std::string::npos);
  CHECK(errorOf("kind: blob\nblob: {segment: {a: [0, -1, 0], b: [0, 1, 0], radius: 0.4}}\nrender:\n  wireframe: {}\n")
            .find("solid.yaml:4:3: error: 'render.wireframe' draws the edges of a solid's tetrahedra; a blob species has none") !=
        std::string::npos);
  const Species cut = parseSpecies(head + "render:\n  section: {normal: [1, 0, 0], offset: -0.25}\n", "solid.yaml");
  CHECK(cut.render.section == std::optional<Vec4>(Vec4(1, 0, 0, -0.25f)));
  CHECK(parseSpecies(head + "render:\n  section: {}\n", "solid.yaml").render.section == std::optional<Vec4>(Vec4(0, 0, 1, 0)));
  CHECK(errorOf(head + "render:\n  section: {normal: [0, 0, 0]}\n")
            .find("solid.yaml:5:12: error: render.section: 'normal' is zero (the plane has no side to remove)") != std::string::npos);
  CHECK(errorOf("kind: blob\nblob: {segment: {a: [0, -1, 0], b: [0, 1, 0], radius: 0.4}}\nrender:\n  section: {}\n")
            .find("solid.yaml:4:3: error: 'render.section' cuts a solid open; a blob species has no inside to show") != std::string::npos);
}
