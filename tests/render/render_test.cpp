#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "core/image.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/core/cube_mesh.h"
#include "tests/render/test_scenes.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;
using sprig::test::scratchDir;
namespace fs = std::filesystem;

namespace {

}  // namespace

TEST_CASE("frameBounds", "[render]") {
  Box3 box{Vec3(-1, 0, -0.5f), Vec3(2, 5, 0.5f)};
  for (double az : {0.0, 30.0, 135.0}) {
    for (double aspect : {0.75, 1.5}) {
      ViewSpec view;
      view.azimuthDeg = az;
      view.elevationDeg = 20;
      view.margin = 0.1;
      Camera cam = frameBounds(box, view, aspect);
      int h = 400, w = static_cast<int>(std::lround(400 * aspect));
      float lo = 1e9f, hi = -1e9f, top = 1e9f, bottom = -1e9f;
      for (int i = 0; i < 8; ++i) {
        Vec3 p((i & 1) ? box.hi.x : box.lo.x, (i & 2) ? box.hi.y : box.lo.y, (i & 4) ? box.hi.z : box.lo.z);
        Vec2 f;
        REQUIRE(cam.project(p, w, h, f));
        lo = std::min(lo, f.x);
        hi = std::max(hi, f.x);
        top = std::min(top, f.y);
        bottom = std::max(bottom, f.y);
      }
      // Every corner lies inside the frame less the margin (5% of the width/height each side)...
      CHECK(lo >= 0.05f * w - 0.5f);
      CHECK(hi <= 0.95f * w + 0.5f);
      CHECK(top >= 0.05f * h - 0.5f);
      CHECK(bottom <= 0.95f * h + 0.5f);
      // ...and the fit is tight on at least one axis, centered on both.
      bool tightX = std::abs(lo - 0.05f * w) < 1.0f && std::abs(hi - 0.95f * w) < 1.0f;
      bool tightY = std::abs(top - 0.05f * h) < 1.0f && std::abs(bottom - 0.95f * h) < 1.0f;
      CHECK((tightX || tightY));
      CHECK(std::abs((lo + hi) - w) < 1.0f);
      CHECK(std::abs((top + bottom) - h) < 1.0f);
    }
  }
  SECTION("framing depends only on the box") {
    Camera a = frameBounds(box, ViewSpec{}, 1.0), b = frameBounds(box, ViewSpec{}, 1.0);
    CHECK(a.position == b.position);
    CHECK(a.target == b.target);
  }
}


TEST_CASE("frameBounds and cameraProblem: degenerate boxes and cameras", "[render]") {
  const float inf = std::numeric_limits<float>::infinity();
  SECTION("a point box is framed by a camera apart from its target, with finite rays") {
    for (const Vec3 p : {Vec3(1, 1, 1), Vec3(0), Vec3(-3e14f, 2e14f, 1e3f)}) {
      INFO("point " << p.x << ", " << p.y << ", " << p.z);
      const Camera cam = frameBounds(Box3{p, p}, ViewSpec{}, 1.0);
      CHECK(cameraProblem(cam).empty());
      CHECK(glm::length(cam.position - p) > 0);
      const Ray ray = cam.generateRay(3.5f, 7.5f, 16, 16);
      CHECK(std::isfinite(ray.direction.x + ray.direction.y + ray.direction.z));
    }
  }
  SECTION("a box that is not finite or beyond 1e15 is refused") {
    CHECK_THROWS_AS(frameBounds(Box3{Vec3(0), Vec3(inf, 1, 1)}, ViewSpec{}, 1.0), std::invalid_argument);
    CHECK_THROWS_AS(frameBounds(Box3{Vec3(0), Vec3(2e15f, 1, 1)}, ViewSpec{}, 1.0), std::invalid_argument);
    CHECK_FALSE(boxInRenderRange(Box3{Vec3(std::nanf("")), Vec3(1)}));
    CHECK(boxInRenderRange(Box3{}));  // empty: frames the unit cube
  }
  SECTION("cameraProblem names what is wrong") {
    Camera c;
    c.position = c.target = Vec3(1, 2, 3);
    CHECK(cameraProblem(c) == "the camera's target is its position (no view direction)");
    c.position = Vec3(inf, 0, 0);
    CHECK(cameraProblem(c) == "the camera's position is not finite or lies beyond 1e15");
    c.position = Vec3(0, 0, 5);
    c.fovYDeg = 180;
    CHECK(cameraProblem(c) == "the camera's field of view is outside (0, 180) degrees");
  }
}

TEST_CASE("Scene: rays Embree cannot trace miss", "[render]") {
  Scene scene;
  scene.addMesh(sprig::test::cube(false), scene.addMaterial({}));
  scene.commit();
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  // A valid ray hits the unit cube...
  REQUIRE(scene.intersect(Vec3(0.5f, 0.5f, 5), Vec3(0, 0, -1), 0, inf));
  CHECK(scene.occluded(Vec3(0.5f, 0.5f, 5), Vec3(0, 0, -1), 0, inf));
  // ...and rays Embree would assert on are answered as misses.
  CHECK_FALSE(scene.intersect(Vec3(nan, 0.5f, 5), Vec3(0, 0, -1), 0, inf));
  CHECK_FALSE(scene.intersect(Vec3(0.5f, 0.5f, 5), Vec3(nan), 0, inf));
  CHECK_FALSE(scene.intersect(Vec3(0.5f, 0.5f, 1e19f), Vec3(0, 0, -1), 0, inf));
  CHECK_FALSE(scene.intersect(Vec3(0.5f, 0.5f, 5), Vec3(0, 0, -1), nan, inf));
  CHECK_FALSE(scene.occluded(Vec3(0.5f, 0.5f, 5), Vec3(0, 0, -1), 0, nan));
  CHECK_FALSE(scene.occluded(Vec3(0.5f, 0.5f, 5), Vec3(0, 0, inf), 0, 10));
  SECTION("renderImage refuses a camera on its target before tracing") {
    Camera c;
    c.position = c.target = Vec3(0.5f);
    CHECK_THROWS_WITH(renderImage(scene, c, quietSettings(8, 8)), "render: the camera's target is its position (no view direction)");
  }
}

TEST_CASE("terminatorLift: Hanika's shadow-terminator offset", "[render]") {
  // An equilateral triangle whose corners lie on a sphere of radius R about c, at height
  // h above c, with the sphere's radial normals: at the centroid every corner's tangent
  // plane lies above the point by (R² − h²)/R along its normal, so the lift is
  // (R² − h²)/R times the mean normal, h/R·ẑ: h·(R² − h²)/R² straight up.
  const float R = 1.0f, h = 0.8f, r = std::sqrt(R * R - h * h);
  std::array<Vec3, 3> corners, normals;
  for (int i = 0; i < 3; ++i) {
    const float a = float(2.0 * M_PI * i / 3.0);
    corners[i] = Vec3(r * std::cos(a), r * std::sin(a), h);
    normals[i] = corners[i] / R;
  }
  const Vec3 third(1.0f / 3.0f);
  const Vec3 lift = render::terminatorLift(corners, normals, third);
  CHECK(lift.x == Approx(0.0f).margin(1e-6));
  CHECK(lift.y == Approx(0.0f).margin(1e-6));
  CHECK(lift.z == Approx(h * (R * R - h * h) / (R * R)).epsilon(1e-5));
  // Nothing moves at a corner, nor where the normals are the flat face's own.
  CHECK(glm::length(render::terminatorLift(corners, normals, Vec3(1, 0, 0))) < 1e-6f);
  const std::array<Vec3, 3> flat{Vec3(0, 0, 1), Vec3(0, 0, 1), Vec3(0, 0, 1)};
  CHECK(glm::length(render::terminatorLift(corners, flat, third)) == 0.0f);
  // Normals leaning inward (a saddle or a concave dent): the point lies above every
  // tangent plane and stays where it is.
  std::array<Vec3, 3> inward;
  for (int i = 0; i < 3; ++i) inward[i] = glm::normalize(Vec3(-corners[i].x, -corners[i].y, h));
  CHECK(glm::length(render::terminatorLift(corners, inward, third)) == 0.0f);
}

TEST_CASE("renderImage traces each pixel once; a tent filter reads the neighbouring tiles' samples", "[render]") {
  Scene scene;
  addSpheres(scene);
  const Camera cam = frameBounds(Box3{Vec3(-1.2f, 0, -1.2f), Vec3(2.2f, 2, 1.2f)}, ViewSpec{}, 1.4);
  RenderSettings rs = quietSettings(70, 50);  // 3 x 2 tiles of 32, the last row and column partial
  rs.threads = 2;
  rs.edgeSamples = 0;  // spp samples per pixel: the count below
  rs.refineSamples = 0;
  RenderStats stats;
  const Image narrow = renderImage(scene, cam, rs, &stats);
  CHECK(stats.cameraRays == 70u * 50u * static_cast<uint64_t>(rs.spp));
  SECTION("a filter reaching two tiles away: the same bytes at 1 and 2 threads, and a blur") {
    rs.filterRadius = 40.5f;  // reads 40 pixels around: every tile here reads every other
    rs.edgeSamples = 4;
    RenderStats two, one;
    const Image a = renderImage(scene, cam, rs, &two);
    rs.threads = 1;
    const Image b = renderImage(scene, cam, rs, &one);
    CHECK(a.pixels == b.pixels);
    CHECK(two.cameraRays == one.cameraRays);
    CHECK(two.cameraRays > stats.cameraRays);
    CHECK((two.cameraRays - stats.cameraRays) % 4 == 0);
    // Neighbouring pixels of the wide filter differ far less than the narrow one's.
    auto variation = [](const Image& img) {
      double sum = 0;
      for (int y = 0; y < img.height; ++y)
        for (int x = 1; x < img.width; ++x) sum += std::abs(img.at(x, y).r - img.at(x - 1, y).r);
      return sum;
    };
    CHECK(variation(a) < 0.25 * variation(narrow));
  }
  SECTION("the same bytes with any tile size: one tile, tiles the filter crosses, tiles of one pixel") {
    rs.edgeSamples = 4;
    for (float radius : {1.0f, 2.5f}) {
      rs.filterRadius = radius;
      rs.tileSize = 4096;
      const Image whole = renderImage(scene, cam, rs);
      for (int tile : {32, 7, 3, 1}) {
        rs.tileSize = tile;
        INFO("radius " << radius << ", tiles of " << tile);
        CHECK(renderImage(scene, cam, rs).pixels == whole.pixels);
      }
    }
    rs.tileSize = 0;
    CHECK_THROWS_WITH(renderImage(scene, cam, rs), Catch::Contains("tile size"));
  }
}
