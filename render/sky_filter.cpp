#include "render/sky_filter.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/parallel.h"

namespace sprig::render {

SkyLayers::SkyLayers(int w, int h) : width(w), height(h) {
  const size_t n = static_cast<size_t>(w) * h;
  sky.assign(n, Vec3(0));
  albedo.assign(n, Vec3(0));
  normal.assign(n, Vec3(0));
  position.assign(n, Vec3(0));
  lumSum.assign(n, 0.0f);
  lumSquares.assign(n, 0.0f);
  count.assign(n, 0.0f);
  raySum.assign(n, 0.0f);
  weight.assign(n, 0.0f);
}

namespace {

/// The least albedo channel the filter divides by; below it the channel keeps its sky term.
constexpr float kMinAlbedo = 1e-4f;

/// e^x for x <= 0, within about 2e-4 relative: 2^(x log2 e) split into an integer power
/// built in the exponent bits and a degree-4 polynomial of the fraction. Weights need no
/// more, and it is several times cheaper than std::exp on the filter's millions of taps.
float fastExpNegative(float x) {
  if (!(x > -80.0f)) return 0.0f;
  const float y = x * 1.44269504f;
  const float fl = std::floor(y);
  const float f = y - fl;
  const float p = 1.0f + f * (0.69314718f + f * (0.24022651f + f * (0.05550411f + f * 0.00961813f)));
  const int32_t e = static_cast<int32_t>(fl) + 127;
  if (e <= 0) return 0.0f;
  const uint32_t bits = static_cast<uint32_t>(e) << 23;
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

/// What the filter reads of each pixel, made once from the layers.
struct Guides {
  int width = 0, height = 0;
  std::vector<Vec3> irradiance;  ///< E = sky / albedo per channel
  std::vector<float> lum;        ///< luminance of E
  std::vector<Vec3> normal;      ///< unit normal; zero marks a pixel outside the filter
  std::vector<Vec3> position;
  std::vector<float> footprint;  ///< least distance to a 4-neighbour's point (0: none)
  std::vector<float> invFootprint;  ///< 1 / (sigmaPlane * footprint); infinity where footprint is 0
  int normalPowerLog2 = 2;       ///< SkyFilterSettings::normalPowerLog2
  size_t index(int x, int y) const { return static_cast<size_t>(y) * width + x; }
  bool active(size_t i) const { return normal[i] != Vec3(0); }
};

Vec3 demodulate(const Vec3& sky, const Vec3& albedo) {
  Vec3 e(0);
  for (int c = 0; c < 3; ++c) e[c] = albedo[c] > kMinAlbedo ? sky[c] / albedo[c] : 0.0f;
  return e;
}

/// Whether pixel i has a sky term the filter may replace.
bool filterable(const SkyLayers& l, size_t i) {
  const float maxAlbedo = std::max({l.albedo[i].r, l.albedo[i].g, l.albedo[i].b});
  return l.count[i] > 0.0f && maxAlbedo > kMinAlbedo && glm::length(l.normal[i]) > 1e-6f;
}

Guides makeGuides(const SkyLayers& l) {
  Guides g;
  g.width = l.width;
  g.height = l.height;
  const size_t n = static_cast<size_t>(l.width) * l.height;
  g.irradiance.assign(n, Vec3(0));
  g.lum.assign(n, 0.0f);
  g.normal.assign(n, Vec3(0));
  g.position = l.position;
  g.footprint.assign(n, 0.0f);
  for (size_t i = 0; i < n; ++i) {
    if (!filterable(l, i)) continue;
    g.normal[i] = glm::normalize(l.normal[i]);
    g.irradiance[i] = demodulate(l.sky[i], l.albedo[i]);
    g.lum[i] = luminance(g.irradiance[i]);
  }
  parallelFor(0, static_cast<size_t>(l.height), [&](size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < l.width; ++x) {
      const size_t i = g.index(x, y);
      if (!g.active(i)) continue;
      float best = std::numeric_limits<float>::infinity();
      const int dx[4] = {-1, 1, 0, 0}, dy[4] = {0, 0, -1, 1};
      for (int k = 0; k < 4; ++k) {
        const int qx = x + dx[k], qy = y + dy[k];
        if (qx < 0 || qy < 0 || qx >= l.width || qy >= l.height || !g.active(g.index(qx, qy))) continue;
        best = std::min(best, glm::length(g.position[g.index(qx, qy)] - g.position[i]));
      }
      g.footprint[i] = std::isfinite(best) ? best : 0.0f;
    }
  });
  g.invFootprint.resize(n);
  return g;
}

/// The argument -a of the plane weight exp(-a) of tap q for pixel p at pixel distance
/// 1 / invDist, times -1; negative where the normal weight is 0, with that weight in wn.
float planeExponent(const Guides& g, size_t p, size_t q, float invDist, float& wn) {
  if (!g.active(q)) return -1.0f;
  float c = glm::dot(g.normal[p], g.normal[q]);
  if (c <= 0.0f) return -1.0f;
  for (int k = 0; k < g.normalPowerLog2; ++k) c *= c;
  wn = c;
  const float d = std::abs(glm::dot(g.normal[p], g.position[q] - g.position[p]));
  return d == 0.0f ? 0.0f : d * g.invFootprint[p] * invDist;
}

/// The normal and plane weight of tap q for pixel p at pixel distance dist (> 0).
float geometryWeight(const Guides& g, size_t p, size_t q, float dist) {
  float wn = 0;
  const float a = planeExponent(g, p, q, 1.0f / dist, wn);
  return a < 0.0f ? 0.0f : wn * fastExpNegative(-a);
}

/// The least per-sample variance of pixel p: that of a visibility seen through
/// the pixel's mean sky rays per sample with the rule of succession's estimate from its own
/// samples, p = (k + 1) / (n + 2) for mean k / n (clamped to [0, 1]). Without it, a pixel
/// whose few samples happen to agree (all its sky rays blocked, deep in a crown) has
/// variance 0, its luminance weight admits no neighbour, and it keeps its raw value: a
/// black speck.
double varianceFloor(const SkyLayers& l, size_t p) {
  const double n = l.count[p];
  const double k = std::clamp(static_cast<double>(l.lumSum[p]) / n, 0.0, 1.0) * n;
  const double q = (k + 1.0) / (n + 2.0);
  return q * (1.0 - q) / std::max(1.0, static_cast<double>(l.raySum[p]) / n);
}

/// The variance of each active pixel's mean demodulated luminance: the per-sample variance
/// pooled over the pixel and its 3x3 neighbours that pass the geometry test (at least
/// varianceFloor), over its own sample count.
std::vector<float> initialVariance(const SkyLayers& l, const Guides& g) {
  std::vector<float> var(l.lumSum.size(), 0.0f);
  parallelFor(0, static_cast<size_t>(l.height), [&](size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < l.width; ++x) {
      const size_t p = g.index(x, y);
      if (!g.active(p)) continue;
      double n = 0, sum = 0, squares = 0;
      for (int qy = std::max(0, y - 1); qy <= std::min(l.height - 1, y + 1); ++qy) {
        for (int qx = std::max(0, x - 1); qx <= std::min(l.width - 1, x + 1); ++qx) {
          const size_t q = g.index(qx, qy);
          if (q != p && geometryWeight(g, p, q, 1.0f) < 0.5f) continue;
          n += l.count[q];
          sum += l.lumSum[q];
          squares += l.lumSquares[q];
        }
      }
      if (l.count[p] <= 0.0f) continue;
      double perSample = varianceFloor(l, p);
      if (n >= 2.0) {
        const double mean = sum / n;
        perSample = std::max(perSample, (squares - n * mean * mean) / (n - 1.0));
      }
      var[p] = static_cast<float>(perSample / l.count[p]);
    }
  });
  return var;
}

/// One à-trous pass at the given step: new irradiance and variance of every active pixel.
void atrousPass(const Guides& g, int step, const SkyFilterSettings& s, const std::vector<Vec3>& in,
                const std::vector<float>& inVar, std::vector<Vec3>& out, std::vector<float>& outVar) {
  // The B3-spline kernel (radius 2) or its 3-tap sibling (radius 1), as in Dammertz et al.
  static constexpr float kB3[5] = {1.0f / 16, 1.0f / 4, 3.0f / 8, 1.0f / 4, 1.0f / 16};
  static constexpr float kB1[5] = {0, 1.0f / 4, 1.0f / 2, 1.0f / 4, 0};
  const float* h = s.kernelRadius == 1 ? kB1 : kB3;
  const int lo = 2 - s.kernelRadius, hi = 2 + s.kernelRadius;
  float invDist[5][5];
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 5; ++i)
      invDist[j][i] = 1.0f / (static_cast<float>(step) * std::sqrt(static_cast<float>((i - 2) * (i - 2) + (j - 2) * (j - 2))));
  std::vector<float> lum(in.size());
  for (size_t i = 0; i < in.size(); ++i) lum[i] = luminance(in[i]);
  parallelFor(0, static_cast<size_t>(g.height), [&](size_t row) {
    const int y = static_cast<int>(row);
    for (int x = 0; x < g.width; ++x) {
      const size_t p = g.index(x, y);
      out[p] = in[p];
      outVar[p] = inVar[p];
      if (!g.active(p)) continue;
      const float invSigmaL = 1.0f / (s.sigmaLuminance * std::sqrt(std::max(inVar[p], 0.0f)) + 1e-6f);
      Vec3 sum = h[2] * h[2] * in[p];
      float wsum = h[2] * h[2], varSum = wsum * wsum * inVar[p];
      for (int j = lo; j <= hi; ++j) {
        const int qy = y + (j - 2) * step;
        if (qy < 0 || qy >= g.height) continue;
        for (int i = lo; i <= hi; ++i) {
          const int qx = x + (i - 2) * step;
          if (qx < 0 || qx >= g.width || (i == 2 && j == 2)) continue;
          const size_t q = g.index(qx, qy);
          float wn = 0;
          const float a = planeExponent(g, p, q, invDist[j][i], wn);
          if (a < 0.0f) continue;
          const float w = h[i] * h[j] * wn * fastExpNegative(-a - std::abs(lum[p] - lum[q]) * invSigmaL);
          sum += w * in[q];
          wsum += w;
          varSum += w * w * inVar[q];
        }
      }
      out[p] = sum / wsum;
      outVar[p] = varSum / (wsum * wsum);
    }
  });
}

}  // namespace

FilteredSky filterSky(const SkyLayers& layers, const SkyFilterSettings& settings) {
  Guides g = makeGuides(layers);
  g.normalPowerLog2 = std::clamp(settings.normalPowerLog2, 0, 8);
  std::vector<Vec3> e = g.irradiance, next(e.size());
  for (size_t i = 0; i < g.footprint.size(); ++i)
    g.invFootprint[i] = g.footprint[i] > 0.0f ? 1.0f / (settings.sigmaPlane * g.footprint[i]) : std::numeric_limits<float>::infinity();
  std::vector<float> var = initialVariance(layers, g), nextVar(var.size());
  for (int pass = 0; pass < settings.passes; ++pass) {
    atrousPass(g, 1 << pass, settings, e, var, next, nextVar);
    e.swap(next);
    var.swap(nextVar);
  }
  return {std::move(e), std::move(var)};
}

std::vector<Vec3> filteredIrradiance(const SkyLayers& layers, const SkyFilterSettings& settings) {
  return filterSky(layers, settings).irradiance;
}

Vec3 filteredSkyTerm(const SkyLayers& layers, size_t i, const Vec3& e) {
  Vec3 filtered = layers.sky[i];
  for (int c = 0; c < 3; ++c)
    if (layers.albedo[i][c] > kMinAlbedo) filtered[c] = layers.albedo[i][c] * e[c];
  return filtered;
}

bool hasSkyTerm(const SkyLayers& layers, size_t i) { return filterable(layers, i); }

void applySkyTerm(Image& image, const SkyLayers& layers, const std::vector<Vec3>& e) {
  for (int y = 0; y < layers.height; ++y) {
    for (int x = 0; x < layers.width; ++x) {
      const size_t i = layers.index(x, y);
      if (!filterable(layers, i)) continue;
      const Vec4 v = image.at(x, y);
      image.set(x, y, Vec4(glm::max(Vec3(v) + filteredSkyTerm(layers, i, e[i]) - layers.sky[i], Vec3(0)), v.a));
    }
  }
}

void filterSkyTerm(Image& image, const SkyLayers& layers, const SkyFilterSettings& settings) {
  applySkyTerm(image, layers, filterSky(layers, settings).irradiance);
}

}  // namespace sprig::render
