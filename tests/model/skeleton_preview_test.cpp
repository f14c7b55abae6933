// Skeleton previews (model/tree_kind.h, organisms/skeleton_geometry.h) rendered through render/.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/image.h"
#include "lsystem/skeleton.h"
#include "model/tree_kind.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/render/test_scenes.h"
#include "tests/scratch_dir.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;
namespace fs = std::filesystem;
using sprig::test::scratchDir;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A sphere organ at position with radius (world units).
inline lsystem::Organ sphereOrgan(DVec3 position, double radius) {
  lsystem::Organ ball;
  ball.kind = lsystem::Organ::Kind::Sphere;
  ball.position = position;
  ball.radius = radius;
  return ball;
}

/// A Y-shaped skeleton: a two-internode trunk and one branch.
lsystem::Skeleton smallTree() {
  lsystem::Skeleton s;
  auto add = [&](DVec3 a, DVec3 b, double r0, double r1, int parent) {
    lsystem::Internode n;
    n.start = a;
    n.end = b;
    n.baseRadius = r0;
    n.tipRadius = r1;
    n.parent = parent;
    s.internodes.push_back(n);
  };
  add({0, 0, 0}, {0, 1, 0}, 0.12, 0.1, -1);
  add({0, 1, 0}, {0, 2, 0}, 0.1, 0.06, 0);
  add({0, 1, 0}, {0.6, 1.6, 0}, 0.05, 0.03, 0);
  lsystem::Organ leaf;
  leaf.points = {{0.6, 1.6, 0}, {0.9, 1.7, 0.1}, {0.8, 2.0, 0}};
  s.organs.push_back(leaf);
  s.organs.push_back(sphereOrgan({0, 2.1, 0}, 0.1));
  return s;
}

/// The skeleton preview of s (model/tree_kind.h) added to scene; returns the geometry ids.
std::vector<uint32_t> addSkeleton(Scene& scene, const lsystem::Skeleton& s) {
  return scene.add(skeletonPreview(s, SkeletonStyle{}));
}

}  // namespace

TEST_CASE("skeletonPreview", "[model]") {
  Scene scene;
  lsystem::Skeleton tree = smallTree();
  auto ids = addSkeleton(scene, tree);
  scene.commit();
  CHECK(ids.size() == 3);  // curves, leaf triangles, spheres
  CHECK(scene.stats().curveSegments == 3);
  CHECK(scene.stats().triangles == 1);
  CHECK(scene.stats().spheres == 1);
  Box3 b = scene.bounds();
  CHECK(b.lo.y == Approx(-0.12f));
  CHECK(b.hi.y == Approx(2.2f));

  SECTION("a ray hits the tapered trunk at its radius") {
    // At height 0.5 the trunk radius is 0.11 (linear from 0.12 to 0.1).
    auto hit = scene.intersect(Vec3(0, 0.5f, 5), Vec3(0, 0, -1), 0, 100);
    REQUIRE(hit);
    CHECK(hit->t == Approx(5.0 - 0.11).margin(2e-3));
    CHECK(hit->normal.z == Approx(1.0).margin(0.02));
    CHECK(hit->geometry == ids[0]);
  }
  SECTION("the sphere organ and the leaf are hit") {
    auto s = scene.intersect(Vec3(0, 2.1f, 5), Vec3(0, 0, -1), 0, 100);
    REQUIRE(s);
    CHECK(s->t == Approx(4.9).margin(1e-3));
    CHECK(s->geometry == ids[2]);
    auto l = scene.intersect(Vec3(0.75f, 1.75f, 5), Vec3(0, 0, -1), 0, 100);
    REQUIRE(l);
    CHECK(l->geometry == ids[1]);
    CHECK(std::abs(l->normal.z) > 0.9f);
  }
  SECTION("occlusion") {
    CHECK(scene.occluded(Vec3(0, 0.5f, 5), Vec3(0, 0, -1), 0, 100));
    CHECK_FALSE(scene.occluded(Vec3(0, 0.5f, 5), Vec3(0, 0, -1), 0, 4));
    CHECK_FALSE(scene.occluded(Vec3(3, 0.5f, 5), Vec3(0, 0, -1), 0, 100));
  }
}

TEST_CASE("render::sphere silhouette", "[render]") {
  // A sphere organ of radius R at distance D from the camera, on the optical axis,
  // projects to a disc of radius (H/2) tan(asin(R/D)) / tan(fov/2) pixels.
  lsystem::Skeleton s;
  s.organs.push_back(sphereOrgan({0, 0, 0}, 1.0));
  Scene scene;
  addSkeleton(scene, s);
  scene.commit();
  Camera cam = orbitCamera(Vec3(0), 20, 10, 6.0, 30.0);
  Image img = renderImage(scene, cam, silhouetteSettings(200, 200, 16));
  double area = alphaArea(img);
  double expected = 100.0 * std::tan(std::asin(1.0 / 6.0)) / std::tan(radians(15.0));
  CHECK(std::sqrt(area / kPi) == Approx(expected).margin(0.25));
  CHECK(img.at(100, 100).a == 1.0f);
  CHECK(img.at(2, 2).a == 0.0f);
}

TEST_CASE("render::determinism", "[render]") {
  Scene scene;
  addSkeleton(scene, smallTree());
  scene.commit();
  ViewSpec view;
  RenderSettings rs;
  rs.width = 96;
  rs.height = 80;
  rs.spp = 4;
  rs.progress = false;
  Camera cam = frameBounds(scene.bounds(), view, 96.0 / 80.0);
  rs.threads = 2;
  RenderStats stats;
  Image a = renderImage(scene, cam, rs, &stats);
  Image b = renderImage(scene, cam, rs);
  rs.threads = 1;
  Image c = renderImage(scene, cam, rs);
  CHECK(a.pixels == b.pixels);
  CHECK(a.pixels == c.pixels);
  CHECK(stats.cameraRays >= 96u * 80u * 4u);
  CHECK(stats.shadowRays > 0);
  CHECK(stats.skyRays > 0);
  CHECK(stats.raysPerSecond() > 0);

  fs::path dir = scratchDir("render-determinism");
  writeImage(a, dir / "a.png");
  writeImage(c, dir / "c.png");
  CHECK(slurp(dir / "a.png") == slurp(dir / "c.png"));
  CHECK(slurp(dir / "a.png").size() > 100);
  fs::remove_all(dir);
}

TEST_CASE("render::shadows", "[render]") {
  // A sphere floating above the ground with the sun overhead shades the ground below it.
  lsystem::Skeleton s;
  s.organs.push_back(sphereOrgan({0, 2, 0}, 1.0));
  Scene scene;
  addSkeleton(scene, s);
  scene.commit();
  Camera cam = orbitCamera(Vec3(0, 1, 0), 0, 30, 8.0, 40.0);
  RenderSettings rs;
  rs.width = rs.height = 120;
  rs.spp = 4;
  rs.progress = false;
  rs.groundAtModelBase = false;
  rs.groundHeight = 0.0f;
  rs.sunElevationDeg = 90.0;
  Vec2 under, aside;
  REQUIRE(cam.project(Vec3(0, 0, 0), rs.width, rs.height, under));
  REQUIRE(cam.project(Vec3(3.5f, 0, 0), rs.width, rs.height, aside));
  Image lit = renderImage(scene, cam, rs);
  rs.shadows = false;
  Image unlit = renderImage(scene, cam, rs);
  auto lum = [](const Image& im, Vec2 f) {
    Vec4 v = im.at(static_cast<int>(f.x), static_cast<int>(f.y));
    return 0.2126f * v.r + 0.7152f * v.g + 0.0722f * v.b;
  };
  CHECK(lum(lit, under) < 0.5f * lum(unlit, under));
  CHECK(lum(lit, aside) == Approx(lum(unlit, aside)).epsilon(0.02));
}
