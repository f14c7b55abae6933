#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>

#include "core/diagnostics.h"
#include "core/image.h"
#include "render/camera.h"
#include "render/labels.h"
#include "render/scene.h"

using namespace sprig;
using namespace sprig::render;

namespace {

constexpr const char* kFont = "/usr/share/fonts/truetype/dejavu/DejaVuSansMono-Bold.ttf";

/// The box of the pixels that differ between a and b (x0 > x1 when none do), and their count.
struct Changed {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1, count = 0;
};
Changed changed(const Image& a, const Image& b) {
  Changed c;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (a.at(x, y) != b.at(x, y)) {
        c.x0 = std::min(c.x0, x), c.y0 = std::min(c.y0, y), c.x1 = std::max(c.x1, x), c.y1 = std::max(c.y1, y);
        ++c.count;
      }
  return c;
}

}  // namespace

TEST_CASE("drawLabels", "[render]") {
  REQUIRE(std::filesystem::exists(kFont));  // Debian's fonts-dejavu-core (scripts/install-deps.sh)
  Camera camera;
  camera.position = Vec3(0, 0, 10);
  camera.target = Vec3(0);
  const Image grey(96, 64, Vec4(0.2f, 0.2f, 0.2f, 1));
  TextLabel l;
  l.position = Vec3(-0.5f, -0.3f, 0);
  l.text = "47";
  l.color = Vec3(1, 1, 0);
  l.fontFile = kFont;
  l.sizePixels = 16;
  Vec2 at;
  REQUIRE(camera.project(l.position, grey.width, grey.height, at));
  const int px = static_cast<int>(std::floor(at.x)), py = static_cast<int>(std::floor(at.y));
  SECTION("the text's pixels lie right of and above the projected point, its baseline there, and nowhere else") {
    Image img = grey;
    drawLabels(img, {l}, camera);
    const Changed c = changed(grey, img);
    INFO("projected at " << px << ", " << py << "; changed " << c.x0 << ".." << c.x1 << " x " << c.y0 << ".." << c.y1);
    CHECK(c.count > 20);  // two bold digits
    CHECK(c.x0 >= px - 1);
    CHECK(c.x0 <= px + 3);           // the first glyph starts at the point
    CHECK(c.x1 <= px + 2 * 10 + 2);  // two monospace cells of 16 px (about 9.6 px each)
    CHECK(c.y1 <= py + 1);           // digits sit on the baseline
    CHECK(c.y1 >= py - 1);
    CHECK(c.y0 >= py - 16);          // no taller than the em
    CHECK(c.y0 <= py - 9);           // digits are about 3/4 of it
    // The fully covered pixels hold the label's colour exactly (sRGB 255, 255, 0).
    int solid = 0;
    for (int y = c.y0; y <= c.y1; ++y)
      for (int x = c.x0; x <= c.x1; ++x) {
        const std::vector<uint8_t> rgb = toSrgb8(img, 3);
        const size_t k = (static_cast<size_t>(y) * img.width + x) * 3;
        if (rgb[k] == 255 && rgb[k + 1] == 255 && rgb[k + 2] == 0) ++solid;
      }
    CHECK(solid > 10);
  }
  SECTION("behind the camera, empty, or off the image: nothing drawn") {
    Image img = grey;
    TextLabel behind = l, empty = l, off = l;
    behind.position = Vec3(0, 0, 20);
    empty.text.clear();
    off.position = Vec3(100, 0, 0);
    drawLabels(img, {behind, empty, off}, camera);
    CHECK(changed(grey, img).count == 0);
  }
  SECTION("a missing font file is a named error") {
    Image img = grey;
    TextLabel bad = l;
    bad.fontFile = "/nonexistent/Font.ttf";
    CHECK_THROWS_WITH(drawLabels(img, {bad}, camera), Catch::Contains("the font file '/nonexistent/Font.ttf' of the labels is missing"));
  }
  SECTION("a scene keeps the labels of the geometry added to it") {
    Scene scene;
    Geometry g;
    g.labels = {l, l};
    scene.add(g);
    scene.add(g);
    CHECK(scene.labels().size() == 4);
  }
}
