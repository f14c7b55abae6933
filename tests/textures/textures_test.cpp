#include <catch2/catch.hpp>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/parallel.h"
#include "core/rng.h"
#include "core/srgb.h"
#include "textures/maps.h"
#include "textures/noise.h"
#include "textures/procedural.h"
#include "textures/registry.h"
#include "tests/paths.h"

using namespace sprig;
using namespace sprig::textures;
namespace fs = std::filesystem;

namespace {

fs::path scratchDir() {
  fs::path d = fs::path(SPRIG_BINARY_DIR) / "test_textures_tmp";
  fs::create_directories(d);
  return d;
}

/// Writes a width x height float image with the given pixels (RGB, rows top to bottom).
void writeFloatImage(const fs::path& path, int w, int h, const std::vector<float>& rgb, OIIO::TypeDesc format) {
  auto out = OIIO::ImageOutput::create(path.string());
  REQUIRE(out);
  OIIO::ImageSpec spec(w, h, 3, format);
  REQUIRE(out->open(path.string(), spec));
  REQUIRE(out->write_image(OIIO::TypeDesc::FLOAT, rgb.data()));
  REQUIRE(out->close());
}

double maxDiff(const Vec3& a, const Vec3& b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
}

}  // namespace

TEST_CASE("PerlinNoise", "[textures]") {
  SECTION("the same seed gives the same values; another seed differs") {
    PerlinNoise a(5), b(5), c(6);
    int differ = 0;
    Rng rng(1);
    for (int i = 0; i < 1000; ++i) {
      DVec3 p(rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(-50, 50));
      CHECK(a(p) == b(p));
      differ += a(p) != c(p);
    }
    CHECK(differ > 900);
  }
  SECTION("zero on the lattice, in [-1, 1], fbm in [-1, 1], turbulence in [0, 1]") {
    PerlinNoise n(3);
    CHECK(n(DVec3(3, -7, 12)) == 0.0);
    Rng rng(2);
    double lo = 1, hi = -1;
    for (int i = 0; i < 200000; ++i) {
      DVec3 p(rng.uniform(-300, 300), rng.uniform(-300, 300), rng.uniform(-300, 300));
      double v = n(p);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      double f = n.fbm(p);
      double t = n.turbulence(p);
      REQUIRE(std::abs(f) <= 1.0);
      REQUIRE(t >= 0.0);
      REQUIRE(t <= 1.0);
    }
    CHECK(lo >= -1.0);
    CHECK(hi <= 1.0);
    CHECK(lo < -0.6);  // the range is used
    CHECK(hi > 0.6);
  }
  SECTION("continuous: a step of 1e-5 changes the value by less than 1e-4") {
    PerlinNoise n(9);
    Rng rng(3);
    for (int i = 0; i < 10000; ++i) {
      DVec3 p(rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-20, 20));
      DVec3 d(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
      d = glm::normalize(d) * 1e-5;
      INFO("seed 3, sample " << i);
      REQUIRE(std::abs(n(p + d) - n(p)) < 1e-4);
      REQUIRE(std::abs(n.fbm(p + d) - n.fbm(p)) < 2e-4);
    }
  }
}

TEST_CASE("PerlinNoise::periodic", "[textures]") {
  PerlinNoise n(11);
  Rng rng(5);
  for (int i = 0; i < 2000; ++i) {
    DVec3 p(rng.uniform(-30, 30), rng.uniform(-30, 30), rng.uniform(-30, 30));
    INFO("seed 5, sample " << i);
    REQUIRE(n.periodic(p, glm::ivec3(0)) == n(p));
    REQUIRE(std::abs(n.periodic(p + DVec3(5, 0, 3), glm::ivec3(5, 0, 3)) - n.periodic(p, glm::ivec3(5, 0, 3))) < 1e-9);
    FractalOptions f;
    REQUIRE(std::abs(n.fbm(p + DVec3(0, 7, 0), f, glm::ivec3(0, 7, 0)) - n.fbm(p, f, glm::ivec3(0, 7, 0))) < 1e-9);
  }
}

TEST_CASE("BarkTexture", "[textures]") {
  BarkOptions o;
  o.seed = 4;
  BarkTexture bark(o);
  SECTION("periodic in u with period 1") {
    Rng rng(4);
    for (int i = 0; i < 2000; ++i) {
      Vec2 uv(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform(-3, 3)));
      INFO("u " << uv.x << " v " << uv.y);
      REQUIRE(std::abs(bark.height(uv) - bark.height(uv + Vec2(1, 0))) < 1e-4);
      REQUIRE(maxDiff(bark.color(uv), bark.color(uv + Vec2(-1, 0))) < 1e-4);
    }
  }
  SECTION("with tileV = 1 it also repeats in v") {
    o.tileV = 1;
    BarkTexture tile(o);
    Rng rng(6);
    for (int i = 0; i < 2000; ++i) {
      Vec2 uv(static_cast<float>(rng.uniform()), static_cast<float>(rng.uniform()));
      INFO("u " << uv.x << " v " << uv.y);
      REQUIRE(std::abs(tile.height(uv) - tile.height(uv + Vec2(0, 1))) < 1e-4);
      REQUIRE(maxDiff(tile.color(uv), tile.color(uv + Vec2(0, -1))) < 1e-4);
    }
  }
  SECTION("without warp there are exactly `furrows` ridges and furrows around") {
    o.warp = 0;
    o.furrows = 7;
    BarkTexture straight(o);
    int ridges = 0;
    double minH = 1, maxH = 0;
    const int n = 7000;
    for (int i = 0; i < n; ++i) {
      double h0 = straight.height(Vec2(float(i) / n, 0.3f));
      double h1 = straight.height(Vec2(float(i + 1) / n, 0.3f));
      double h2 = straight.height(Vec2(float(i + 2) / n, 0.3f));
      ridges += h1 > h0 && h1 >= h2;
      minH = std::min(minH, h1);
      maxH = std::max(maxH, h1);
    }
    CHECK(ridges == 7);
    CHECK(minH < 0.01);
    CHECK(maxH > 0.99);
  }
  SECTION("colors lie between the furrow and ridge colors (up to grain)") {
    for (int i = 0; i < 500; ++i) {
      Vec3 c = bark.color(Vec2(i / 500.0f, i * 0.01f));
      CHECK(c.x >= 0);
      CHECK(c.x <= o.ridgeColor.x * (1 + o.grain) + 1e-5);
    }
  }
}

TEST_CASE("BarkTexture maturity and lenticels", "[textures]") {
  BarkOptions o;
  o.seed = 11;
  o.warp = 0;
  o.furrows = 8;
  SECTION("young bark keeps 80% of its height; mature bark reaches the furrow floor") {
    // h = 1 − (0.2 + 0.8 m)(1 − h0) with h0 in [0, 1] and no cracks at m = 0.
    o.maturity = 0;
    BarkTexture young(o);
    o.maturity = 1;
    BarkTexture old(o);
    double youngMin = 1, oldMin = 1;
    for (int i = 0; i < 4000; ++i) {
      const Vec2 uv(float(i) / 4000, 0.37f);
      youngMin = std::min(youngMin, young.height(uv));
      oldMin = std::min(oldMin, old.height(uv));
    }
    CHECK(youngMin >= 0.8 - 1e-9);
    CHECK(youngMin < 0.81);
    CHECK(oldMin < 0.01);
  }
  SECTION("furrows widen with age: the fraction of the circumference below half height grows") {
    // Without warp and cracks the profile is 1 − (0.2 + 0.8 m)(1 − h0)^s with
    // s = 1.8·(1 + 4(1 − m)); below 0.5 where (1 − h0) > (0.5 / (0.2 + 0.8 m))^(1/s):
    // a fraction 1 − that of the circumference (h0 is linear in u inside each ridge).
    o.cracks = 0;
    double last = -1;
    for (double m : {0.5, 0.75, 1.0}) {
      o.maturity = m;
      BarkTexture bark(o);
      int below = 0;
      const int n = 8000;
      for (int i = 0; i < n; ++i) below += bark.height(Vec2((i + 0.5f) / n, 0.2f)) < 0.5;
      const double s = 1.8 * (1 + 4 * (1 - m));
      const double expected = 1 - std::pow(0.5 / (0.2 + 0.8 * m), 1 / s);
      INFO("maturity " << m);
      CHECK(double(below) / n == Approx(std::max(0.0, expected)).margin(0.002));
      CHECK(double(below) / n > last);
      last = double(below) / n;
    }
  }
  SECTION("lenticels: none by default; lenses covering the expected share; closed at u = 1") {
    BarkTexture none(o);
    CHECK(none.lenticelCover(Vec2(0.3f, 0.4f)) == 0);
    o.lenticels = 1;
    o.lenticelFrequency = 10;
    BarkTexture bark(o);
    // Every cell holds a lens (|dx|/a)^e + (|dy|/b)^e <= (size·t)^e, a uniform in [0.22, 0.38],
    // b in [0.10, 0.20], e in [1.2, 2.2], size in [0.7, 1.3] (outline noise of ±8% averages
    // out); cover > 0.5 for t < 0.875 (the smoothstep's midpoint). A superellipse's area is
    // 4ab·Γ(1 + 1/e)²/Γ(1 + 2/e), so per cell 4·E[a]·E[b]·E[G(e)]·0.875²·E[size²] with
    // E[size²] = 1 + 0.3²/3 and E[G] by quadrature over e.
    double meanG = 0;
    for (int k = 0; k < 1000; ++k) {
      const double e = 1.2 + (k + 0.5) / 1000;
      meanG += std::pow(std::tgamma(1 + 1 / e), 2) / std::tgamma(1 + 2 / e) / 1000;
    }
    const double expected = 4 * 0.30 * 0.15 * meanG * 0.875 * 0.875 * (1 + 0.09 / 3);
    int covered = 0;
    const int nu = 400, nv = 400;
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) covered += bark.lenticelCover(Vec2((i + 0.5f) / nu, (j + 0.5f) / nv * 4)) > 0.5;
    CHECK(double(covered) / (nu * nv) == Approx(expected).epsilon(0.15));
    Rng rng(3);
    for (int i = 0; i < 500; ++i) {
      const Vec2 uv(float(rng.uniform()), float(rng.uniform(-2, 2)));
      REQUIRE(std::abs(bark.lenticelCover(uv) - bark.lenticelCover(uv + Vec2(1, 0))) < 1e-3);
    }
  }
  SECTION("lenticels darken young bark only") {
    o.lenticels = 1;
    o.lenticelFrequency = 10;
    o.maturity = 1;
    BarkTexture old(o);
    o.lenticels = 0;
    BarkTexture plain(o);
    for (int i = 0; i < 300; ++i) {
      const Vec2 uv(i / 300.0f, i * 0.013f);
      REQUIRE(maxDiff(old.color(uv), plain.color(uv)) < 1e-6);
    }
  }
}

TEST_CASE("BarkTexture braided furrows and peeling patches", "[textures]") {
  SECTION("braid: a vertical line crosses 2·braid furrows per unit of v (none without braid)") {
    // Without wander (warp 0) the two furrow sets drift by ±braid ridge widths per unit of v,
    // so a line at fixed u enters a furrow of each set braid times per unit of v. (On the
    // lines u = k/20 the two sets' furrows cross it half a period apart; elsewhere they may
    // pass close enough to merge into one, which is where the braid's furrows join.)
    for (double braid : {0.0, 4.0}) {
      BarkOptions o;
      o.furrows = 10;
      o.warp = 0;
      o.cracks = 0;
      o.braid = braid;
      BarkTexture bark(o);
      for (float u : {0.05f, 0.35f, 0.8f}) {
        int entries = 0;
        bool inFurrow = bark.height(Vec2(u, 0.0f)) < 0.2;
        for (int i = 1; i <= 50000; ++i) {
          const bool now = bark.height(Vec2(u, static_cast<float>(5.0 * i / 50000))) < 0.2;
          if (now && !inFurrow) ++entries;
          inFurrow = now;
        }
        INFO("braid " << braid << ", u " << u);
        CHECK(std::abs(entries - static_cast<int>(2 * braid * 5)) <= 1);
      }
      // Still closed around the branch.
      for (float v : {0.1f, 0.77f, 2.3f}) CHECK(bark.height(Vec2(0.0f, v)) == Approx(bark.height(Vec2(1.0f, v))).margin(1e-9));
    }
  }
  SECTION("peel: the share of old bark is peel·(0.4 + 0.6·maturity), patches close at u = 1") {
    for (double maturity : {0.0, 1.0}) {
      BarkOptions o;
      o.furrows = 12;
      o.peel = 0.5;
      o.peelFrequency = 3;
      o.maturity = maturity;
      o.seed = 7;
      BarkTexture bark(o);
      int old = 0, n = 0;
      for (int j = 0; j < 400; ++j)
        for (int i = 0; i < 100; ++i, ++n)
          if (bark.peelLevel(Vec2(static_cast<float>(i / 100.0), static_cast<float>(j * 0.05))) > 0) ++old;
      const double share = double(old) / n, expected = 0.5 * (0.4 + 0.6 * maturity);
      INFO("maturity " << maturity << ": old bark on " << share << " of the surface, expected " << expected);
      CHECK(share == Approx(expected).margin(0.08));
      for (float v : {0.3f, 4.1f}) CHECK(bark.peelLevel(Vec2(0.0f, v)) == Approx(bark.peelLevel(Vec2(1.0f, v))).margin(1e-9));
      // Inside a patch the colour is the old bark's, a greyer colour than the fresh bark.
      for (int j = 0; j < 400; ++j) {
        const Vec2 uv(0.25f, static_cast<float>(j * 0.05));
        if (bark.peelLevel(uv) > 0.05) {
          const Vec3 c = bark.color(uv);
          CHECK(c.x / std::max(1e-6f, c.z) == Approx(o.peelColor.x / o.peelColor.z).margin(1e-4));
        }
      }
    }
    BarkOptions none;
    BarkTexture plain(none);
    CHECK(plain.peelLevel(Vec2(0.3f, 0.4f)) == -1.0);
  }
}

TEST_CASE("StripesTexture and SpotsTexture", "[textures]") {
  SECTION("stripes without wobble: band centers and gaps, exactly periodic") {
    StripesOptions o;
    o.wobble = 0;
    o.frequency = 4;
    o.duty = 0.5;
    StripesTexture s(o);
    CHECK(maxDiff(s.color(Vec2(0.3f, 0.25f / 4)), o.stripeColor) < 1e-6);  // center of band 0
    CHECK(maxDiff(s.color(Vec2(0.3f, 0.75f / 4)), o.baseColor) < 1e-6);    // center of gap 0
    CHECK(maxDiff(s.color(Vec2(0.9f, 0.25f / 4 + 2 * 0.25f)), o.stripeColor) < 1e-6);
    o.spiral = true;
    StripesTexture sp(o);
    CHECK(maxDiff(sp.color(Vec2(0.25f / 4, 0.7f)), o.stripeColor) < 1e-6);
  }
  SECTION("spots are deterministic; density 0 leaves the base color; coverage is sensible") {
    SpotsOptions o;
    o.seed = 8;
    SpotsTexture a(o), b(o);
    int covered = 0;
    const int n = 100;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        Vec2 uv(i / float(n), j / float(n));
        Vec3 c = a.color(uv);
        REQUIRE(c == b.color(uv));
        covered += maxDiff(c, o.spotColor) < 0.05;
      }
    // Expected: density * pi r^2 per cell = 0.8 * 0.28 ~ 0.23 of the area.
    CHECK(covered > n * n * 0.12);
    CHECK(covered < n * n * 0.35);
    o.density = 0;
    SpotsTexture none(o);
    CHECK(none.color(Vec2(0.31f, 0.77f)) == o.baseColor);
  }
}

TEST_CASE("ImageTexture", "[textures]") {
  fs::path dir = scratchDir();
  SECTION("texel centers of a linear EXR return the texel colors") {
    const int w = 4, h = 2;
    std::vector<float> rgb(w * h * 3);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        float* p = &rgb[(y * w + x) * 3];
        p[0] = 0.1f * x;
        p[1] = 0.5f * y;
        p[2] = 0.25f + 0.125f * x * y;
      }
    fs::path file = dir / "texels_4x2.exr";
    writeFloatImage(file, w, h, rgb, OIIO::TypeDesc::FLOAT);
    ImageTexture t = ImageTexture::open(file.string(), {"s.yaml", 1, 1});
    CHECK(t.width() == 4);
    CHECK(t.height() == 2);
    CHECK(!t.srgb());
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        Vec3 c = t.color(Vec2((x + 0.5f) / w, (y + 0.5f) / h));
        const float* p = &rgb[(y * w + x) * 3];
        INFO("texel " << x << "," << y);
        CHECK(maxDiff(c, Vec3(p[0], p[1], p[2])) < 1e-5);
      }
    // Halfway between texels (0,0) and (1,0): bilinear average.
    Vec3 mid = t.color(Vec2(1.0f / w, 0.5f / h));
    CHECK(mid.x == Approx(0.05f).margin(1e-5));
  }
  SECTION("a wide footprint reads a coarse mip level: a checkerboard filters to its mean") {
    const int w = 64;
    std::vector<float> rgb(w * w * 3);
    for (int y = 0; y < w; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 3; ++k) rgb[(y * w + x) * 3 + k] = ((x + y) & 1) ? 1.0f : 0.0f;
    fs::path file = dir / "checker_64.exr";
    writeFloatImage(file, w, w, rgb, OIIO::TypeDesc::FLOAT);
    ImageTexture t = ImageTexture::open(file.string(), {"s.yaml", 1, 1});
    Vec3 sharp = t.color(Vec2(0.5f / w, 0.5f / w));
    CHECK(sharp.x == Approx(0.0f).margin(1e-5));  // texel (0,0) exactly at the finest level
    Vec3 wide = t.color(Vec2(0.37f, 0.61f), Vec2(0.25f, 0), Vec2(0, 0.25f));
    CHECK(wide.x == Approx(0.5f).margin(0.02));
  }
  SECTION("8-bit PNG values are sRGB, returned linear") {
    std::vector<float> rgb(2 * 2 * 3, 0.5f);
    rgb[0] = 1.0f;
    fs::path file = dir / "srgb_2x2.png";
    writeFloatImage(file, 2, 2, rgb, OIIO::TypeDesc::UINT8);
    ImageTexture t = ImageTexture::open(file.string(), {"s.yaml", 1, 1});
    CHECK(t.srgb());
    Vec3 c = t.color(Vec2(0.25f, 0.25f));
    CHECK(c.x == Approx(1.0f).margin(1e-5));
    CHECK(c.y == Approx(srgbToLinear(128 / 255.0)).margin(1e-4));
  }
  SECTION("a missing file is an InputError at the referencing location") {
    SourceLoc where{"species/oak.yaml", 7, 14};
    try {
      ImageTexture::open((dir / "no_such_bark.png").string(), where);
      FAIL("no throw");
    } catch (const InputError& e) {
      std::string msg = e.what();
      CHECK(msg.rfind("species/oak.yaml:7:14: error: cannot find file '", 0) == 0);
      CHECK(msg.find("no_such_bark.png'") != std::string::npos);
    }
  }
  SECTION("an unreadable file is an InputError too") {
    fs::path file = dir / "garbage.png";
    writeFileAtomic(file, "this is not a PNG");
    CHECK_THROWS_AS(ImageTexture::open(file.string(), {"a.yaml", 2, 3}), InputError);
    TextureRegistry reg;
    CHECK_THROWS_AS(reg.addImage(file.string(), {"a.yaml", 2, 3}), InputError);
    CHECK(reg.size() == 0);
  }
}

TEST_CASE("TextureRegistry", "[textures]") {
  TextureRegistry reg;
  TextureId c = reg.add(ConstantTexture{Vec3(0.2f, 0.3f, 0.4f)});
  BarkOptions bo;
  TextureId b = reg.add(BarkTexture(bo));
  NoiseColorOptions no;
  no.solid = true;
  TextureId n = reg.add(NoiseTexture(no));
  CHECK(c == 0);
  CHECK(b == 1);
  CHECK(n == 2);
  CHECK(reg.color(c, Vec2(0.5f)) == Vec3(0.2f, 0.3f, 0.4f));
  CHECK(reg.color(b, Vec2(0.1f, 0.2f)) == BarkTexture(bo).color(Vec2(0.1f, 0.2f)));
  // A solid texture follows the position, not uv.
  CHECK(reg.color(n, Vec2(0.1f), Vec3(1.3f, 2.1f, 0.7f)) == reg.color(n, Vec2(0.9f), Vec3(1.3f, 2.1f, 0.7f)));
  CHECK_THROWS_AS(reg.color(7, Vec2(0)), std::out_of_range);
}

TEST_CASE("texture maps", "[textures]") {
  SECTION("bake is the same at any thread count") {
    TextureRegistry reg;
    TextureId id = reg.add(LeafTexture());
    Image one, two;
    {
      ThreadLimit limit(1);
      one = bake(reg, id, 64, 48);
    }
    two = bake(reg, id, 64, 48);
    CHECK(one.pixels == two.pixels);
  }
  SECTION("the shipped maps are Sprig's own output, small, and up to date") {
    for (const MapSpec& m : shippedMaps()) {
      fs::path file = fs::path(SPRIG_SOURCE_DIR) / "textures" / "maps" / m.file;
      INFO(file);
      REQUIRE(fs::exists(file));
      CHECK(fs::file_size(file) < 300 * 1024);
      ImageTexture t = ImageTexture::open(file.string(), {"test", 1, 1});
      CHECK(t.width() == m.size);
      // Re-bake a few rows and compare with the file's pixels (8-bit sRGB: within 1/255).
      auto in = OIIO::ImageInput::open(file.string());
      REQUIRE(in);
      std::vector<float> pixels(static_cast<size_t>(m.size) * m.size * 3);
      REQUIRE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::FLOAT, pixels.data()));
      TextureRegistry reg;
      TextureId id = reg.add(m.texture);
      Image baked = bake(reg, id, m.size, m.size);
      double worst = 0;
      for (size_t i = 0; i < pixels.size(); i += 97) worst = std::max(worst, std::abs(pixels[i] - linearToSrgb(static_cast<double>(baked.pixels[i / 3 * 4 + i % 3]))));
      CHECK(worst <= 1.0 / 255 + 1e-6);
    }
  }
}

/// Regenerates textures/maps/ (hidden: run `test_textures "[.maps]"`).
TEST_CASE("texture maps: regenerate", "[.maps]") {
  for (const MapSpec& m : shippedMaps()) {
    TextureRegistry reg;
    TextureId id = reg.add(m.texture);
    writeImage(bake(reg, id, m.size, m.size), fs::path(SPRIG_SOURCE_DIR) / "textures" / "maps" / m.file,
               ImageEncoding::TextureMap);
  }
}
