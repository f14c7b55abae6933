#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/image.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/scene.h"
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

