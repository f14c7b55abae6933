#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <OpenImageIO/imageio.h>

#include "render/camera.h"
#include "render/image.h"
#include "render/renderer.h"
#include "render/scene.h"

using namespace sprig;
using namespace sprig::render;
namespace fs = std::filesystem;

namespace {

fs::path scratchDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("sprig-render-test-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

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

TEST_CASE("writeImage", "[render]") {
  Image img(8, 4, Vec4(0.5f, 0.25f, 1.0f, 1.0f));
  fs::path dir = scratchDir("write");
  SECTION("formats by extension") {
    writeImage(img, dir / "x.png");
    writeImage(img, dir / "x.JPG");
    writeImage(img, dir / "x.exr");
    CHECK(fs::file_size(dir / "x.png") > 0);
    CHECK(fs::file_size(dir / "x.JPG") > 0);
    CHECK(fs::file_size(dir / "x.exr") > 0);
    // Only the three images: no temporaries left behind.
    CHECK(std::distance(fs::directory_iterator(dir), fs::directory_iterator()) == 3);
  }
  SECTION("EXR keeps linear values") {
    writeImage(img, dir / "lin.exr");
    auto in = OIIO::ImageInput::open((dir / "lin.exr").string());
    REQUIRE(in);
    CHECK(in->spec().width == 8);
    CHECK(in->spec().nchannels == 4);
    std::vector<float> px(8 * 4 * 4);
    REQUIRE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, px.data()));
    in->close();
    CHECK(px[0] == 0.5f);
    CHECK(px[1] == 0.25f);
    CHECK(px[2] == 1.0f);
    CHECK(px[3] == 1.0f);
  }
  SECTION("sRGB encoding") {
    auto bytes = toSrgb8(img, 4);
    REQUIRE(bytes.size() == 8 * 4 * 4);
    CHECK(bytes[0] == 188);  // 0.5 linear -> 0.7354 sRGB
    CHECK(bytes[1] == 137);  // 0.25 -> 0.5371
    CHECK(bytes[2] == 255);
    CHECK(bytes[3] == 255);
  }
  SECTION("unknown extension fails and writes nothing") {
    CHECK_THROWS_AS(writeImage(img, dir / "x.bmpx"), std::invalid_argument);
    CHECK_THROWS_WITH(writeImage(img, dir / "x.tga"), Catch::Contains("unknown extension '.tga'"));
    CHECK(fs::is_empty(dir));
  }
  SECTION("missing folder fails and writes nothing") {
    CHECK_THROWS_AS(writeImage(img, dir / "nope" / "x.png"), std::runtime_error);
    CHECK(fs::is_empty(dir));
    CHECK_FALSE(fs::exists(dir / "nope"));
  }
  fs::remove_all(dir);
}

