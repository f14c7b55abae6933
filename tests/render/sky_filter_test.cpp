// The edge-avoiding filter of the sky term (render/sky_filter.h): what it keeps exactly
// (constant light, normal creases, depth steps, albedo edges, pixels without a sky term),
// how much noise it removes, and the renders made with it.

#include <catch2/catch.hpp>

#include <cmath>
#include <utility>
#include <vector>

#include "core/rng.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/sky_filter.h"
#include "tests/render/test_scenes.h"

using namespace sprig;
using namespace sprig::render;
using namespace sprig::render::test;

namespace {

constexpr int kW = 40, kH = 30, kSamples = 4;

/// Layers of a plane y = 0 seen from above, one world unit per pixel, albedo 0.5 grey,
/// each pixel's four samples of irradiance luminance e(x, y) + noise(x, y, k).
template <class Irradiance, class Noise>
SkyLayers planeLayers(Irradiance e, Noise noise) {
  SkyLayers l(kW, kH);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const size_t i = l.index(x, y);
      float mean = 0;
      for (int k = 0; k < kSamples; ++k) {
        const float v = e(x, y) + noise(x, y, k);
        mean += v / kSamples;
        l.lumSum[i] += v;
        l.lumSquares[i] += v * v;
      }
      l.count[i] = kSamples;
      l.albedo[i] = Vec3(0.5f);
      l.sky[i] = l.albedo[i] * Vec3(mean);
      l.normal[i] = Vec3(0, kSamples, 0);
      l.position[i] = Vec3(x, 0, y);
    }
  }
  return l;
}

float zeroNoise(int, int, int) { return 0.0f; }

/// Deterministic noise of standard deviation about 0.1 (uniform in [-0.17, 0.17]).
float someNoise(int x, int y, int k) {
  Rng rng(deriveSeed(7, {static_cast<uint64_t>(x), static_cast<uint64_t>(y), static_cast<uint64_t>(k)}));
  return 0.34f * static_cast<float>(rng.uniform()) - 0.17f;
}

/// RMSE of the luminances of e against the constant c over pixels where pick(x) holds.
template <class Pick>
double errorAgainst(const std::vector<Vec3>& e, float c, Pick pick) {
  double sum = 0;
  int n = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x)
      if (pick(x)) {
        const double d = luminance(e[static_cast<size_t>(y) * kW + x]) - c;
        sum += d * d;
        ++n;
      }
  return std::sqrt(sum / n);
}

}  // namespace

TEST_CASE("filteredIrradiance keeps what it must", "[render][sky_filter]") {
  SECTION("a constant irradiance stays constant") {
    const SkyLayers l = planeLayers([](int, int) { return 0.3f; }, zeroNoise);
    for (const Vec3& e : filteredIrradiance(l)) CHECK(e.g == Approx(0.3f).epsilon(1e-5));
  }
  SECTION("a crease: nothing crosses surfaces turned 90 degrees apart") {
    SkyLayers l = planeLayers([](int x, int) { return x < kW / 2 ? 0.2f : 0.8f; }, someNoise);
    for (int y = 0; y < kH; ++y)
      for (int x = kW / 2; x < kW; ++x) l.normal[l.index(x, y)] = Vec3(kSamples, 0, 0);
    const std::vector<Vec3> e = filteredIrradiance(l);
    float leftMax = 0, rightMin = 1;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const float v = luminance(e[l.index(x, y)]);
        if (x < kW / 2) leftMax = std::max(leftMax, v);
        else rightMin = std::min(rightMin, v);
      }
    }
    // Each side stays within its own noise band (0.2 +- 0.17, 0.8 +- 0.17).
    CHECK(leftMax < 0.2f + 0.17f);
    CHECK(rightMin > 0.8f - 0.17f);
  }
  SECTION("a depth step: parallel planes far apart against the pixel footprint do not mix") {
    SkyLayers l = planeLayers([](int x, int) { return x < kW / 2 ? 0.2f : 0.8f; }, zeroNoise);
    for (int y = 0; y < kH; ++y)
      for (int x = kW / 2; x < kW; ++x) l.position[l.index(x, y)].y = 1000.0f;
    const std::vector<Vec3> e = filteredIrradiance(l);
    CHECK(errorAgainst(e, 0.2f, [](int x) { return x < kW / 2; }) < 1e-6);
    CHECK(errorAgainst(e, 0.8f, [](int x) { return x >= kW / 2; }) < 1e-6);
  }
  SECTION("filterSkyTerm: albedo edges and pixels without a sky term are untouched") {
    SkyLayers l = planeLayers([](int, int) { return 0.4f; }, zeroNoise);
    Image image(kW, kH, Vec4(0, 0, 0, 1));
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        const size_t i = l.index(x, y);
        l.albedo[i] = (x / 3 + y / 3) % 2 ? Vec3(0.9f, 0.1f, 0.2f) : Vec3(0.05f, 0.6f, 0.3f);
        l.sky[i] = l.albedo[i] * 0.4f;
        if (x == 5) l.count[i] = 0;  // a column that met no surface
        image.set(x, y, Vec4(l.sky[i] + Vec3(0.25f), 1));
      }
    }
    const Image before = image;
    filterSkyTerm(image, l);
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        INFO("pixel " << x << ", " << y);
        for (int c = 0; c < 3; ++c) CHECK(image.at(x, y)[c] == Approx(before.at(x, y)[c]).margin(1e-6));
      }
    }
    CHECK(image.at(5, 7) == before.at(5, 7));
  }
}

TEST_CASE("filteredIrradiance: a pixel whose samples all saw no sky is not taken for a noiseless one", "[render][sky_filter]") {
  // A leaf deep in a crown: its four sky rays were all blocked (value 0, spread 0), and its
  // normal, turned 60 degrees from its neighbours', keeps them out of its pooled variance.
  // With variance 0 its luminance weight would admit nothing and it would stay black; the
  // binomial floor (p = 1/6 from 0 of 4) lets the neighbours it faces alike enough in.
  SkyLayers l = planeLayers([](int, int) { return 0.5f; }, someNoise);
  const size_t speck = l.index(kW / 2, kH / 2);
  l.lumSum[speck] = l.lumSquares[speck] = 0.0f;
  l.sky[speck] = Vec3(0);
  l.normal[speck] = float(kSamples) * Vec3(std::sin(radians(60.0)), std::cos(radians(60.0)), 0.0f);
  const float filtered = luminance(filteredIrradiance(l)[speck]);
  INFO("the speck's filtered visibility " << filtered);
  // Measured 0.105: the normal weight (cos^4 60 = 1/16) bounds what the neighbours give.
  CHECK(filtered > 0.05f);
  CHECK(filtered < 0.5f);
  SECTION("more rays per sample: a smaller floor, less taken from the neighbours") {
    l.raySum[speck] = 16.0f * kSamples;
    CHECK(luminance(filteredIrradiance(l)[speck]) < filtered);
  }
  SECTION("without the floor (rays beyond count) the speck stays black") {
    l.raySum[speck] = 1e12f;
    CHECK(luminance(filteredIrradiance(l)[speck]) == 0.0f);
  }
}

TEST_CASE("filteredIrradiance removes noise", "[render][sky_filter]") {
  const SkyLayers l = planeLayers([](int, int) { return 0.5f; }, someNoise);
  std::vector<Vec3> raw(l.sky.size());
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = l.sky[i] / l.albedo[i];
  const auto all = [](int) { return true; };
  const double before = errorAgainst(raw, 0.5f, all), after = errorAgainst(filteredIrradiance(l), 0.5f, all);
  INFO("RMSE " << before << " -> " << after);
  CHECK(after < before / 4);
}

TEST_CASE("filteredIrradiance averages across surfaces turned every way, as a crown's leaves", "[render][sky_filter]") {
  // Each pixel's normal leans up to 50 degrees from the vertical in its own direction; the
  // demodulated value (the sky's visibility) is the same everywhere. The normal weight
  // (cos^4) lets such neighbours share their noise; with SVGF's cos^128 they could not.
  SkyLayers l = planeLayers([](int, int) { return 0.5f; }, someNoise);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      Rng rng(deriveSeed(11, {static_cast<uint64_t>(x), static_cast<uint64_t>(y)}));
      const float tilt = radians(50.0f) * static_cast<float>(rng.uniform()), turn = 6.2831853f * static_cast<float>(rng.uniform());
      l.normal[l.index(x, y)] = float(kSamples) * Vec3(std::sin(tilt) * std::cos(turn), std::cos(tilt), std::sin(tilt) * std::sin(turn));
    }
  }
  std::vector<Vec3> raw(l.sky.size());
  for (size_t i = 0; i < raw.size(); ++i) raw[i] = l.sky[i] / l.albedo[i];
  const auto all = [](int) { return true; };
  const double before = errorAgainst(raw, 0.5f, all);
  SkyFilterSettings sharp;
  sharp.normalPowerLog2 = 7;
  const double after = errorAgainst(filteredIrradiance(l), 0.5f, all), afterSharp = errorAgainst(filteredIrradiance(l, sharp), 0.5f, all);
  INFO("RMSE " << before << " -> " << after << " (cos^128: " << afterSharp << ")");
  CHECK(after < before / 3);
  CHECK(afterSharp > before / 2);
}

TEST_CASE("openSkyIrradiance: the sky's light with nothing in the way", "[render][sky_filter]") {
  RenderSettings s;
  s.ground = false;
  s.skyZenith = Vec3(0.2f, 0.4f, 0.8f);
  s.skyHorizon = Vec3(0.9f, 0.7f, 0.5f);
  const auto near = [](const Vec3& a, const Vec3& b, float tol) {
    INFO(a.r << " " << a.g << " " << a.b << " against " << b.r << " " << b.g << " " << b.b);
    CHECK(glm::length(a - b) < tol);
  };
  SECTION("facing up: the sky's blend sqrt(cos) weighted by cos over the hemisphere") {
    // With mu = cos(theta) of density 2 mu, E[sqrt(mu)] = 4/5: H + 4/5 (Z - H). The table's
    // quadrature is off by 1.9e-3 here (0.2 % of |Z - H|).
    near(openSkyIrradiance(s, Vec3(0, 1, 0)), s.skyHorizon + 0.8f * (s.skyZenith - s.skyHorizon), 3e-3f);
  }
  SECTION("facing down without a ground: the horizon's radiance everywhere below it") {
    near(openSkyIrradiance(s, Vec3(0, -1, 0)), s.skyHorizon, 1e-5f);
  }
  SECTION("a sky of one colour: the same light for every normal") {
    s.skyZenith = s.skyHorizon;
    for (const Vec3& n : {Vec3(0, 1, 0), glm::normalize(Vec3(1, 1, 0)), Vec3(0, 0, 1), glm::normalize(Vec3(0.3f, -1, 0.5f))})
      near(openSkyIrradiance(s, n), s.skyHorizon, 1e-5f);
  }
  SECTION("facing down over the ground: the ground's bounce") {
    s.ground = true;
    s.sun = false;
    near(openSkyIrradiance(s, Vec3(0, -1, 0)), s.groundColor * 0.5f * (s.skyZenith + s.skyHorizon) * 0.5f, 1e-5f);
  }
}

TEST_CASE("renderImage with the sky filter", "[render][sky_filter]") {
  Scene scene;
  addSpheres(scene);
  const Camera cam = frameBounds(Box3{Vec3(-1.2f, 0, -1.2f), Vec3(2.2f, 2, 1.2f)}, ViewSpec{}, 1.4);
  RenderSettings rs = quietSettings(70, 50);
  rs.sun = false;  // the sky alone: its noise is the render's noise, apart from the edges'
  rs.skyFilter = false;
  rs.spp = 256;
  const Image reference = renderImage(scene, cam, rs);
  rs.spp = 4;
  const Image noisy = renderImage(scene, cam, rs);
  rs.skyFilter = true;
  rs.threads = 2;
  const Image filtered = renderImage(scene, cam, rs);
  SECTION("same bytes at 1 and 2 threads") {
    rs.threads = 1;
    CHECK(renderImage(scene, cam, rs).pixels == filtered.pixels);
  }
  SECTION("much less error than the unfiltered render") {
    // Measured 0.0141 -> 0.0055 (0.0079 when the filter smoothed the irradiance, not the
    // visibility): what is left is the spheres' and the horizon's edges,
    // which only more camera samples smooth.
    const double before = rmse(noisy, reference), after = rmse(filtered, reference);
    INFO("RMSE " << before << " -> " << after);
    CHECK(after < 0.65 * before);
  }
  SECTION("alpha and the background are the unfiltered render's") {
    for (int y = 0; y < rs.height; ++y)
      for (int x = 0; x < rs.width; ++x) CHECK(filtered.at(x, y).a == noisy.at(x, y).a);
    CHECK(filtered.at(0, 0) == noisy.at(0, 0));  // sky at the top-left corner
  }
}

TEST_CASE("renderImage's second pass: samples where the filter leaves noise", "[render][sky_filter]") {
  Scene scene;
  addSpheres(scene);
  const Camera cam = frameBounds(Box3{Vec3(-1.2f, 0, -1.2f), Vec3(2.2f, 2, 1.2f)}, ViewSpec{}, 1.4);
  RenderSettings rs = quietSettings(70, 50);
  rs.sun = false;  // the sky alone: its noise is what the filter leaves and the pass spends on
  rs.refineThreshold = 0.005f;  // this small scene's filter leaves little: half the default
  rs.skyFilter = false;
  rs.spp = 256;
  const Image reference = renderImage(scene, cam, rs);
  rs.spp = 4;
  rs.skyFilter = true;
  rs.edgeSamples = 0;  // a first pass of spp samples per pixel
  rs.refineSamples = 0;
  RenderStats plain, refined;
  const Image a = renderImage(scene, cam, rs, &plain);
  rs.refineSamples = 8;
  rs.threads = 2;
  const Image b = renderImage(scene, cam, rs, &refined);
  SECTION("same bytes at 1 and 2 threads and another tile size") {
    rs.threads = 1;
    rs.tileSize = 7;
    RenderStats serial;
    CHECK(renderImage(scene, cam, rs, &serial).pixels == b.pixels);
    CHECK(serial.cameraRays == refined.cameraRays);
  }
  SECTION("a marked pixel traces its first pass again and refineSamples more") {
    const uint64_t extra = refined.cameraRays - plain.cameraRays;
    CHECK(extra % (4 + 8) == 0);
    // The shadowed and sky-lit parts the filter cannot smooth, not every pixel.
    CHECK(extra > 0);
    CHECK(extra < plain.cameraRays / 4 / 2 * 12);
  }
  SECTION("a threshold no pixel crosses: the same image as one pass") {
    rs.refineThreshold = 1e9f;
    RenderStats none;
    CHECK(renderImage(scene, cam, rs, &none).pixels == a.pixels);
    CHECK(none.cameraRays == plain.cameraRays);
  }
  SECTION("less error for the samples spent") {
    const double before = rmse(a, reference), after = rmse(b, reference);
    INFO("RMSE " << before << " -> " << after << ", camera samples x"
                 << double(refined.cameraRays) / double(plain.cameraRays));
    CHECK(after < 0.9 * before);
  }
}

TEST_CASE("renderImage's second pass on tiny images, the box filter and the stratified sampler", "[render][sky_filter]") {
  Scene scene;
  addSpheres(scene);
  const Camera cam = frameBounds(Box3{Vec3(-1.2f, 0, -1.2f), Vec3(2.2f, 2, 1.2f)}, ViewSpec{}, 1.4);
  for (const auto& [w, h] : {std::pair{1, 1}, std::pair{3, 2}, std::pair{40, 1}}) {
    for (Filter filter : {Filter::Tent, Filter::Box}) {
      for (Sampling sampling : {Sampling::ZSobol, Sampling::Stratified}) {
        RenderSettings rs = quietSettings(w, h);
        rs.sun = false;
        rs.filter = filter;
        rs.filterRadius = 2.5f;
        rs.sampler = sampling;
        rs.spp = 1;
        rs.refineThreshold = 0.0f;  // every pixel with a sky term is marked
        rs.threads = 2;
        RenderStats stats;
        const Image a = renderImage(scene, cam, rs, &stats);
        rs.threads = 1;
        CHECK(renderImage(scene, cam, rs).pixels == a.pixels);
        for (float v : a.pixels) CHECK(std::isfinite(v));
        // At most the first pass, its repeat and 8 more per pixel; the ground and the
        // spheres have a sky term, so the wider images have marked pixels.
        CHECK(stats.cameraRays <= static_cast<uint64_t>(w) * h * (1 + 1 + 8));
        if (w * h >= 6) CHECK(stats.cameraRays > static_cast<uint64_t>(w) * h);
      }
    }
  }
}
