#include <catch2/catch.hpp>

#include "core/image.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
#include "tests/render/test_scenes.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;

namespace {

/// One white sphere of radius 1 at the origin seen from +Z, lit by the rim light alone.
Image rimOnly(float strength, double azimuthDeg, double elevationDeg, bool occluder = false) {
  Scene scene;
  SphereSet s;
  s.spheres = {Vec4(0, 0, 0, 1)};
  // Beside and behind the sphere, between it and a rim light at azimuth 120, out of the picture's middle.
  if (occluder) s.spheres.push_back(Vec4(3.46f, 0, -2, 1.2f));
  s.colors = std::vector<Vec3>(s.spheres.size(), Vec3(1));
  scene.addSpheres(s, scene.addMaterial(Material{Vec3(1), 1.0f, 0.0f}));
  scene.commit();
  RenderSettings rs = quietSettings(41, 41);
  rs.spp = 1;
  rs.sun = false;
  rs.skyStrength = 0;
  rs.ground = false;
  rs.background = Background::Color;
  rs.backgroundColor = Vec3(0);
  rs.filter = Filter::Box;
  rs.skyFilter = false;
  rs.rimStrength = strength;
  rs.rimAzimuthDeg = azimuthDeg;
  rs.rimElevationDeg = elevationDeg;
  const Camera cam = orbitCamera(Vec3(0), 0, 0, 6, 30);
  return renderImage(scene, cam, rs);
}

}  // namespace

/// The brightest red within r pixels of the picture's centre (the sphere's disc is about 12.9 pixels wide).
float brightestWithin(const Image& img, int r) {
  float best = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if ((x - 20) * (x - 20) + (y - 20) * (y - 20) < r * r) best = std::max(best, img.at(x, y).r);
  return best;
}

TEST_CASE("RenderSettings::rim: a light from behind lights the silhouette only", "[render]") {
  // From azimuth 120 (behind the sphere, to the camera's right) the rim lights the points
  // whose normals turn more than 30 degrees from the camera toward the right: a crescent.
  const Image off = rimOnly(0, 120, 0);
  const Image rim = rimOnly(1, 120, 0);
  CHECK(rim.at(20, 20).r == 0.0f);  // facing the camera, away from the light
  CHECK(brightestWithin(off, 13) == 0.0f);
  float right = 0, left = 0;
  for (int x = 0; x < 41; ++x) (x > 20 ? right : left) = std::max(x > 20 ? right : left, rim.at(x, 20).r);
  CHECK(right > 0.5f);
  CHECK(left == 0.0f);
  // The azimuth is relative to the camera: 0 puts the light at the camera, lighting the centre.
  CHECK(rimOnly(1, 0, 0).at(20, 20).r > 0.9f);
  // Elevation lifts it: from above and behind, the top of the sphere is lit, the bottom not.
  const Image high = rimOnly(1, 180, 60);
  CHECK(high.at(20, 9).r > 0.2f);
  CHECK(high.at(20, 31).r == 0.0f);
  // It casts shadows: a sphere between the lit crescent and the light darkens it.
  CHECK(brightestWithin(rimOnly(1, 120, 0, true), 11) < 0.5f * brightestWithin(rim, 11));
}
