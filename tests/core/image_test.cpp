#include <catch2/catch.hpp>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <unistd.h>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/paths.h"
#include "core/srgb.h"
#include "core/timer.h"
#include "tests/scratch_dir.h"

using namespace sprig;
namespace fs = std::filesystem;
using sprig::test::scratchDir;

namespace {

/// What run writes on stderr (file descriptor 2, where libpng prints).
template <class F>
std::string capturedStderr(F run) {
  std::fflush(stderr);
  std::FILE* sink = std::tmpfile();
  const int saved = dup(2);
  dup2(fileno(sink), 2);
  run();
  std::fflush(stderr);
  dup2(saved, 2);
  close(saved);
  std::rewind(sink);
  std::string text;
  for (int c; (c = std::fgetc(sink)) != EOF;) text += char(c);
  std::fclose(sink);
  return text;
}

// The linear value whose sRGB float times 255 is 0.49999997f, just below the first rounding
// tie: the only float input whose byte differs between OpenImageIO's two roundings (core/image.h
// textureMapByte; found by scanning every float).
constexpr float kHalfBelowTie = 0x1.3e4566p-13f;

}  // namespace

TEST_CASE("writeImage", "[core]") {
  Image img(8, 4, Vec4(0.5f, 0.25f, 1.0f, 1.0f));
  fs::path dir = scratchDir("image-write");
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

TEST_CASE("Image8 holds the bytes writeImage stores", "[core]") {
  // A float image written as a texture map (OpenImageIO converts its sRGB floats to bytes)
  // and its Image8 (Sprig's textureMapByte) must make PNGs of the same pixels: every value
  // near each rounding tie of 255·s, in the first 20 values of a 7-pixel row (OpenImageIO's
  // four-at-a-time body) and in the last (converted one by one), out-of-range values too.
  std::vector<float> linear;
  for (int k = 0; k < 255; ++k) {
    float v = float(srgbToLinear(double(k + 0.5) / 255.0));
    for (int d = 0; d < 40; ++d) v = std::nextafter(v, 0.0f);
    for (int d = 0; d < 81; ++d, v = std::nextafter(v, 2.0f))
      if (v != kHalfBelowTie) linear.push_back(v);
  }
  linear.push_back(-0.25f);
  linear.push_back(1.5f);
  const int width = 7, height = int(linear.size());
  Image img(width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) img.set(x, y, Vec4(linear[size_t(y)], linear[size_t(y)], linear[size_t(y)], 1.0f));
  // The one linear float whose bytes differ between OpenImageIO's two roundings.
  CHECK(float(linearToSrgb(double(kHalfBelowTie))) * 255.0f == 0.49999997f);
  CHECK(textureMapByte(kHalfBelowTie) == 0);
  CHECK(textureMapByte(std::nextafter(kHalfBelowTie, 1.0f)) == 1);
  const fs::path dir = scratchDir("image8");
  for (const ImageEncoding encoding : {ImageEncoding::TextureMap, ImageEncoding::Data, ImageEncoding::Picture}) {
    INFO("encoding " << int(encoding));
    const Image8 bytes = toImage8(img, encoding);
    REQUIRE(bytes.values.size() == size_t(width) * size_t(height) * (encoding == ImageEncoding::Picture ? 4 : 3));
    writeImage(img, dir / "float.png", encoding);
    writeImage(bytes, dir / "bytes.png");
    // The same pixels and the same colour space: readImage decodes both alike.
    CHECK(readImageInfo(dir / "bytes.png").srgb == readImageInfo(dir / "float.png").srgb);
    CHECK(readImage(dir / "bytes.png").pixels == readImage(dir / "float.png").pixels);
    // At every zlib level.
    ImageWriteOptions fast;
    fast.pngLevel = 1;
    writeImage(bytes, dir / "fast.png", fast);
    CHECK(readImage(dir / "fast.png").pixels == readImage(dir / "float.png").pixels);
    // Image8::at decodes colours as readImage decodes the file (which takes an untagged
    // 8-bit file, a Data one, for sRGB too: there at() gives byte / 255).
    const Image back = readImage(dir / "bytes.png");
    for (int y = 0; y < height; y += 97)
      for (int x = 0; x < width; ++x) {
        const Vec4 v = bytes.at(x, y);
        if (encoding == ImageEncoding::Data)
          CHECK(Vec3(back.at(x, y)) == Vec3(srgbToLinear(v.r), srgbToLinear(v.g), srgbToLinear(v.b)));
        else
          CHECK(v == back.at(x, y));
      }
  }
  CHECK_THROWS_AS(writeImage(toImage8(img, ImageEncoding::Data), dir / "x.jpg"), std::invalid_argument);
  fs::remove_all(dir);
}

namespace {

// textureMapByte's definition (core/image.h), a pow() per value.
int textureMapByteByFormula(float linear) {
  const float y = float(linearToSrgb(double(linear))) * 255.0f;
  return std::isnan(y) ? 0 : int(std::clamp(std::round(y), 0.0f, 255.0f));
}

}  // namespace

TEST_CASE("textureMapByte: its table gives the formula's byte", "[core]") {
  // Every float within 64 steps of each value where the byte steps up, and a spread of
  // others; the hidden case below checks every float.
  size_t checked = 0;
  for (int k = 0; k < 256; ++k) {
    float v = float(srgbToLinear(double(k + 0.5) / 255.0));
    for (int d = 0; d < 64; ++d) v = std::nextafter(v, -1.0f);
    for (int d = 0; d < 129; ++d, v = std::nextafter(v, 2.0f), ++checked)
      REQUIRE(int(textureMapByte(v)) == textureMapByteByFormula(v));
  }
  for (float v = -0.5f; v < 1.5f; v += 1.0f / 4099.0f, ++checked) REQUIRE(int(textureMapByte(v)) == textureMapByteByFormula(v));
  CHECK(checked > 40000);
  CHECK(textureMapByte(-0.0f) == 0);
  CHECK(textureMapByte(std::nanf("")) == 0);
  CHECK(textureMapByte(INFINITY) == 255);
  CHECK(textureMapByte(1.0f) == 255);
}

TEST_CASE("textureMapByte gives the formula's byte at every float in [0, 1]", "[.][exhaustive]") {
  // 1,065,353,217 values, a pow() each: about 30 s.
  size_t differ = 0;
  for (float v = 0.0f; v <= 1.0f; v = std::nextafter(v, 2.0f)) differ += int(textureMapByte(v)) != textureMapByteByFormula(v);
  CHECK(differ == 0);
}

TEST_CASE("writeImage's pngLevel", "[core]") {
  // zlib's header names its level's class (RFC 1950 FLEVEL, bits 6-7 of the second byte):
  // 0 for levels 0-1, 2 for the default level 6.
  Image img(64, 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) img.set(x, y, Vec4(float(x) / 63.0f, float(y) / 63.0f, 0.5f, 1.0f));
  const fs::path dir = scratchDir("image-png-level");
  auto flevel = [](const fs::path& png) {
    const std::string bytes = readFile(png);
    const size_t idat = bytes.find("IDAT");
    REQUIRE(idat != std::string::npos);
    return (uint8_t(bytes[idat + 5]) >> 6) & 3;
  };
  writeImage(img, dir / "default.png", ImageEncoding::TextureMap);
  ImageWriteOptions fast;
  fast.pngLevel = 1;
  writeImage(img, dir / "fast.png", ImageEncoding::TextureMap, fast);
  CHECK(flevel(dir / "default.png") == 2);
  CHECK(flevel(dir / "fast.png") == 0);
  CHECK(readImage(dir / "fast.png").pixels == readImage(dir / "default.png").pixels);
  fs::remove_all(dir);
}

TEST_CASE("readImage", "[core]") {
  fs::path dir = scratchDir("image-read");
  Image img(3, 2, Vec4(0.5f, 0.25f, 1.0f, 1.0f));
  SECTION("a PNG reads back as the linear value of its sRGB bytes") {
    writeImage(img, dir / "x.png");
    ImageInfo info = readImageInfo(dir / "x.png");
    CHECK(info.width == 3);
    CHECK(info.height == 2);
    CHECK(info.channels == 4);
    CHECK(info.srgb);
    Image back = readImage(dir / "x.png");
    REQUIRE(back.pixels.size() == img.pixels.size());
    CHECK(back.at(2, 1).r == srgbToLinear(188 / 255.0f));
    CHECK(back.at(2, 1).b == 1.0f);
    CHECK(back.at(2, 1).a == 1.0f);
  }
  SECTION("an EXR reads back linear, a texture-map PNG without alpha reads back opaque") {
    writeImage(img, dir / "x.exr");
    CHECK_FALSE(readImageInfo(dir / "x.exr").srgb);
    CHECK(readImage(dir / "x.exr").pixels == img.pixels);
    writeImage(img, dir / "map.png", ImageEncoding::TextureMap);
    CHECK(readImageInfo(dir / "map.png").channels == 3);
    CHECK(readImage(dir / "map.png").at(0, 0).a == 1.0f);
  }
  SECTION("a file that is not an image throws ImageReadError with OIIO's reason") {
    { std::ofstream(dir / "bad.png") << "not a PNG"; }
    CHECK_THROWS_AS(readImage(dir / "bad.png"), ImageReadError);
    try {
      readImageInfo(dir / "bad.png");
      FAIL("no throw");
    } catch (const ImageReadError& e) {
      CHECK(std::string(e.what()).rfind("cannot read image '", 0) == 0);
      CHECK_FALSE(e.reason().empty());
    }
  }
  SECTION("a damaged PNG: libpng's message is the reason, and nothing reaches stderr") {
    writeImage(Image(16, 16, Vec4(0.5f)), dir / "good.png");
    std::ifstream in(dir / "good.png", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t idat = bytes.find("IDAT");
    REQUIRE(idat != std::string::npos);
    std::string renamed = bytes;  // the image data's chunk type damaged: 'IDA\0'
    renamed[idat + 3] = '\0';
    std::ofstream(dir / "renamed.png", std::ios::binary) << renamed;
    std::ofstream(dir / "cut.png", std::ios::binary) << bytes.substr(0, idat + 12);  // the image data cut short
    const auto reasonOf = [](const fs::path& path, bool pixels, std::string& printed) {
      std::string reason;
      printed = capturedStderr([&] {
        try {
          if (pixels) readImage(path);
          else readImageInfo(path);
        } catch (const ImageReadError& e) {
          reason = e.reason();
        }
      });
      return reason;
    };
    std::string printed;
    CHECK(reasonOf(dir / "renamed.png", false, printed) == "PNG read error: IDA[00]: invalid chunk type");
    CHECK(printed.empty());
    CHECK(reasonOf(dir / "cut.png", true, printed).rfind("PNG read error: ", 0) == 0);
    CHECK(printed.empty());
    CHECK(reasonOf(dir / "good.png", true, printed).empty());
  }
  fs::remove_all(dir);
}

TEST_CASE("writeAnimatedGif", "[core]") {
  fs::path dir = scratchDir("image-gif");
  std::vector<Image> frames{Image(4, 4, Vec4(1, 0, 0, 1)), Image(4, 4, Vec4(0, 0, 1, 1))};
  writeAnimatedGif(frames, 10, dir / "a.gif");
  auto in = OIIO::ImageInput::open((dir / "a.gif").string());
  REQUIRE(in);
  CHECK(in->spec().get_int_attribute("oiio:LoopCount", -1) == 0);
  CHECK(in->seek_subimage(1, 0));
  CHECK_FALSE(in->seek_subimage(2, 0));
  in->close();
  CHECK_THROWS_AS(writeAnimatedGif({}, 10, dir / "b.gif"), std::runtime_error);
  CHECK_FALSE(fs::exists(dir / "b.gif"));
  fs::remove_all(dir);
}

TEST_CASE("writeAnimatedGif dithers the palette of a smooth sky", "[core]") {
  // A slow sky ramp of 256 x 64 pixels with 8923 distinct 8-bit colours, more than a GIF
  // frame's 256: each palette colour covers a patch of the ramp. Dithered, the pixels of a
  // patch mix neighbouring palette colours so that their mean follows the ramp; undithered
  // (each pixel its nearest palette colour) the patch is one flat band.
  constexpr int kWidth = 256, kHeight = 64, kBox = 4;
  std::vector<int> source(3 * kWidth * kHeight);  // the 8-bit sRGB values the frame holds
  Image frame(kWidth, kHeight);
  for (int y = 0; y < kHeight; ++y)
    for (int x = 0; x < kWidth; ++x) {
      const double t = x / double(kWidth - 1), s = y / double(kHeight - 1);
      const int rgb[3] = {int(std::lround(40 + 100 * t + 30 * s)), int(std::lround(70 + 120 * t + 60 * s)),
                          int(std::lround(130 + 110 * t))};
      for (int c = 0; c < 3; ++c) {
        source[3 * (y * kWidth + x) + c] = rgb[c];
        frame.pixels[4 * (y * kWidth + x) + c] = srgbToLinear(rgb[c] / 255.0f);
      }
    }
  fs::path dir = scratchDir("image-gif-dither");
  writeAnimatedGif({frame}, 10, dir / "sky.gif");
  auto in = OIIO::ImageInput::open((dir / "sky.gif").string());
  REQUIRE(in);
  std::vector<uint8_t> rgba(4 * kWidth * kHeight);
  REQUIRE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, rgba.data()));
  in->close();

  // The colours the GIF used, and each source pixel's nearest of them: the undithered frame.
  std::vector<int> gif(source.size()), nearest(source.size()), palette;
  for (size_t i = 0; i < size_t(kWidth) * kHeight; ++i) {
    for (int c = 0; c < 3; ++c) gif[3 * i + c] = rgba[4 * i + c];
    const int packed = (gif[3 * i] << 16) | (gif[3 * i + 1] << 8) | gif[3 * i + 2];
    if (std::find(palette.begin(), palette.end(), packed) == palette.end()) palette.push_back(packed);
  }
  REQUIRE(palette.size() <= 256);
  for (size_t i = 0; i < size_t(kWidth) * kHeight; ++i) {
    int best = 0, bestDistance = 1 << 30;
    for (int p : palette) {
      const int d[3] = {(p >> 16) - source[3 * i], ((p >> 8) & 255) - source[3 * i + 1], (p & 255) - source[3 * i + 2]};
      const int distance = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      if (distance < bestDistance) {
        best = p;
        bestDistance = distance;
      }
    }
    for (int c = 0; c < 3; ++c) nearest[3 * i + c] = (best >> (16 - 8 * c)) & 255;
  }
  // Mean absolute error of the 4 x 4 box means against the source's, in 8-bit steps.
  auto boxError = [&](const std::vector<int>& image) {
    double sum = 0;
    for (int by = 0; by < kHeight; by += kBox)
      for (int bx = 0; bx < kWidth; bx += kBox)
        for (int c = 0; c < 3; ++c) {
          int difference = 0;
          for (int y = by; y < by + kBox; ++y)
            for (int x = bx; x < bx + kBox; ++x)
              difference += image[3 * (y * kWidth + x) + c] - source[3 * (y * kWidth + x) + c];
          sum += std::abs(difference) / double(kBox * kBox);
        }
    return sum / (3.0 * (kWidth / kBox) * (kHeight / kBox));
  };
  // Measured with Sprig's encoder (median cut over distinct colours, Floyd-Steinberg): 0.316
  // dithered, 0.585 for the nearest colours (OpenImageIO 2.4.7's gif.h: 0.295 and 0.617).
  const double dithered = boxError(gif), undithered = boxError(nearest);
  INFO("box error dithered " << dithered << ", undithered " << undithered);
  CHECK(dithered < 0.45);
  CHECK(dithered < 0.7 * undithered);

  // Same frames, same bytes.
  writeAnimatedGif({frame}, 10, dir / "again.gif");
  auto bytesOf = [](const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(file), {});
  };
  CHECK(bytesOf(dir / "sky.gif") == bytesOf(dir / "again.gif"));
  fs::remove_all(dir);
}

TEST_CASE("writeAnimatedGif keeps a small plant's colours in the first frame", "[core]") {
  // A growth animation's first frame: a sprout of 3 x 6 pixels (a brown stem under green
  // leaves) in a 160 x 120 sky gradient, then the grown plant filling a quarter of the frame.
  // A palette built by median cut over pixels (OpenImageIO's gif.h) spends its entries by
  // pixel count: the sprout's 18 pixels got none of their own and came back in sky colours
  // while the later frame's plant kept its colours. With each distinct colour counting
  // once, the sprout keeps its own.
  constexpr int kWidth = 160, kHeight = 120;
  const Vec3 leaf = {0.05f, 0.35f, 0.04f}, stem = {0.3f, 0.2f, 0.08f};  // linear
  auto frameWith = [&](int plantWidth, int plantHeight) {
    Image frame(kWidth, kHeight);
    for (int y = 0; y < kHeight; ++y)
      for (int x = 0; x < kWidth; ++x) {
        const float s = y / float(kHeight - 1), t = x / float(kWidth - 1);
        const bool plant = std::abs(x - kWidth / 2) * 2 < plantWidth && y >= kHeight - 4 - plantHeight && y < kHeight - 4;
        const Vec3 c = !plant ? Vec3(0.35f + 0.4f * s + 0.05f * t, 0.5f + 0.35f * s, 0.8f + 0.12f * s)
                              : y >= kHeight - 6 ? stem : leaf;
        for (int k = 0; k < 3; ++k) frame.pixels[4 * (size_t(y) * kWidth + x) + k] = c[k];
      }
    return frame;
  };
  fs::path dir = scratchDir("image-gif-sprout");
  writeAnimatedGif({frameWith(3, 6), frameWith(60, 60)}, 10, dir / "grow.gif");
  auto in = OIIO::ImageInput::open((dir / "grow.gif").string());
  REQUIRE(in);
  std::vector<uint8_t> rgba(4 * kWidth * kHeight);
  REQUIRE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, rgba.data()));
  in->close();
  auto srgb8 = [](float v) { return int(std::lround(255 * linearToSrgb(v))); };
  int sprout = 0;
  for (int y = kHeight - 10; y < kHeight - 4; ++y)
    for (int x = kWidth / 2 - 1; x <= kWidth / 2 + 1; ++x, ++sprout) {
      const Vec3 c = y >= kHeight - 6 ? stem : leaf;
      const uint8_t* p = &rgba[4 * (size_t(y) * kWidth + x)];
      INFO("sprout pixel " << x << "," << y << ": " << int(p[0]) << " " << int(p[1]) << " " << int(p[2]));
      CHECK(std::abs(p[0] - srgb8(c.x)) + std::abs(p[1] - srgb8(c.y)) + std::abs(p[2] - srgb8(c.z)) <= 12);
    }
  CHECK(sprout == 18);
  fs::remove_all(dir);
}

TEST_CASE("linearToSrgb", "[core]") {
  SECTION("float and double overloads are one formula") {
    for (float v : {0.0f, 0.001f, 0.0031308f, 0.2f, 0.5f, 0.9f})
      CHECK(linearToSrgb(v) == Approx(linearToSrgb(static_cast<double>(v))).margin(1e-6));
    CHECK(linearToSrgb(2.0f) == linearToSrgb(1.0f));
    CHECK(linearToSrgb(-1.0) == 0.0);
  }
  SECTION("srgbToLinear inverts it") {
    for (double v : {0.0, 0.01, 0.04045, 0.3, 0.7, 1.0}) CHECK(srgbToLinear(linearToSrgb(v)) == Approx(v).margin(1e-12));
  }
  SECTION("toSrgb8 rounds, clamps, and maps NaN to 0") {
    Image img(2, 1, Vec4(2.0f, -1.0f, std::nanf(""), 0.5f));
    auto bytes = toSrgb8(img, 4);
    CHECK(bytes == std::vector<uint8_t>{255, 0, 0, 128, 255, 0, 0, 128});
  }
}

TEST_CASE("lowerExtension", "[core]") {
  CHECK(lowerExtension("a/B.PNG") == ".png");
  CHECK(lowerExtension("x.tar.GZ") == ".gz");
  CHECK(lowerExtension("noext") == "");
  CHECK(asciiLower("sRGB-\xC3\x89") == "srgb-\xC3\x89");
}

TEST_CASE("secondsSince", "[core]") {
  auto t0 = std::chrono::steady_clock::now();
  double s = secondsSince(t0);
  CHECK(s >= 0.0);
  CHECK(s < 60.0);
}
