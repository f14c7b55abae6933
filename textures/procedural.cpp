#include "textures/procedural.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace sprig::textures {

namespace {

inline double fract(double x) { return x - std::floor(x); }
inline double smoothstep(double e0, double e1, double x) {
  double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}
inline Vec3 mix(const Vec3& a, const Vec3& b, double t) { return a + (b - a) * static_cast<float>(t); }

}  // namespace

Vec3 NoiseTexture::color(const DVec3& p) const {
  const NoiseColorOptions& o = options_;
  double t = o.turbulence ? noise_.turbulence(p * o.scale, o.fractal) : 0.5 + 0.5 * noise_.fbm(p * o.scale, o.fractal);
  return mix(o.colorA, o.colorB, std::clamp(t, 0.0, 1.0));
}

namespace {

/// A frequency along v rounded to whole cycles per tile (unchanged when tile <= 0).
double tiled(double freq, int tile) { return tile > 0 ? std::max(1.0, std::round(freq * tile)) / tile : freq; }
/// The lattice period along an axis sampled at freq * v, for a tile (0 = none).
int period(double freq, int tile) { return tile > 0 ? static_cast<int>(std::lround(freq * tile)) : 0; }

}  // namespace

double BarkTexture::height(Vec2 uv) const {
  const BarkOptions& o = options_;
  const int furrows = std::max(1, o.furrows);
  const double v = uv.y;
  // A point on a cylinder of circumference `furrows`: periodic in u, one unit per ridge.
  double a = 2 * kPi * static_cast<double>(uv.x);
  double r = furrows / (2 * kPi);
  double along = tiled(o.alongFrequency, o.tileV);
  DVec3 p(r * std::cos(a), r * std::sin(a), along * v);
  FractalOptions f;
  f.octaves = 4;
  double ridge = static_cast<double>(uv.x) * furrows + o.warp * noise_.fbm(p, f, glm::ivec3(0, 0, period(along, o.tileV)));
  const double m = std::clamp(o.maturity, 0.0, 1.0);
  double h = 1 - std::abs(2 * fract(ridge) - 1);  // 1 on a ridge, 0 in a furrow
  // sharpness > 1 narrows the furrows; young bark's are narrower still, and shallower.
  h = 1 - std::pow(1 - h, std::max(1e-3, o.sharpness * (1 + 4 * (1 - m))));
  h = 1 - (0.2 + 0.8 * m) * (1 - h);
  const double cracks = o.cracks * m;
  if (cracks > 0) {
    // Cross cracks split each ridge into plates. The plate coordinate q depends on the
    // ridge's index (random phase, wavy spacing); the index changes only in a furrow, where
    // h = 0, so h stays continuous. Taken modulo furrows, the index keeps u periodic.
    double index = std::fmod(std::floor(ridge), static_cast<double>(furrows));
    if (index < 0) index += furrows;
    double phase = Rng(deriveSeed(o.seed, {0xba4cu, static_cast<uint64_t>(index)})).uniform();
    double plates = tiled(1.5 * o.alongFrequency, o.tileV);
    double wave = tiled(0.9 * o.alongFrequency, o.tileV);
    double q = v * plates + phase +
               0.35 * noise_.periodic(DVec3(index * 7.31 + 0.5, v * wave, 3.7), glm::ivec3(0, period(wave, o.tileV), 0));
    double d = std::abs(q - std::round(q));  // distance to the nearest crack, in plate lengths
    h *= 1 - cracks * (1 - smoothstep(0.01, 0.035, d));
  }
  return h;
}

double BarkTexture::lenticelCover(Vec2 uv) const {
  const BarkOptions& o = options_;
  if (!(o.lenticels > 0)) return 0;
  const int furrows = std::max(1, o.furrows);
  const double x = static_cast<double>(uv.x) * furrows;
  const double freq = tiled(o.lenticelFrequency, o.tileV);
  const int rows = period(freq, o.tileV);  // > 0: rows repeat every tile
  const double y = static_cast<double>(uv.y) * freq;
  const double ci = std::floor(x), cj = std::floor(y);
  const double fx = x - ci, fy = y - cj;
  double cover = 0;
  for (int dj = -1; dj <= 1; ++dj) {
    for (int di = -1; di <= 1; ++di) {
      // The cell index around is taken modulo furrows: the lenticels close at u = 1.
      auto cellX = static_cast<int64_t>(std::fmod(ci + di, static_cast<double>(furrows)));
      if (cellX < 0) cellX += furrows;
      auto cellY = static_cast<int64_t>(cj) + dj;
      if (rows > 0) cellY = ((cellY % rows) + rows) % rows;
      Rng rng(deriveSeed(o.seed, {0x1e27u, static_cast<uint64_t>(cellX), static_cast<uint64_t>(cellY)}));
      const bool present = rng.uniform() < o.lenticels;
      const double cx = di + 0.5 + (rng.uniform() - 0.5) * 0.6;
      const double cy = dj + 0.5 + (rng.uniform() - 0.5) * 0.6;
      const double size = 0.7 + 0.6 * rng.uniform();
      if (!present) continue;
      // Each lenticel its own lens, wider (across the branch) than long: half-width a in
      // [0.22, 0.38] cells, half-length b in [0.10, 0.20], and an outline between a diamond
      // and an ellipse, (|dx|/a)^e + (|dy|/b)^e <= size^e with e in [1.2, 2.2], roughened
      // by a little noise (so no two are stamped alike). It reaches at most 0.3 + 0.38·1.3 <
      // 0.8 cells from its cell's centre: the 3x3 cells searched hold every lenticel that
      // can cover the point.
      const double a = 0.22 + 0.16 * rng.uniform(), b = 0.10 + 0.10 * rng.uniform();
      const double e = 1.2 + 1.0 * rng.uniform();
      const double dx = std::abs(fx - cx) / a, dy = std::abs(fy - cy) / b;
      if (dx > 1.5 * size || dy > 1.5 * size) continue;
      // (The noise is taken about the lenticel's own centre, keyed by its wrapped cell, so
      // the pattern still closes at u = 1.)
      const double rough =
          1 + 0.08 * noise_(DVec3(6 * (fx - cx) + 3.1 * double(cellX), 6 * (fy - cy) + 1.7 * double(cellY), 1.7));
      const double d = std::pow(std::pow(dx, e) + std::pow(dy, e), 1 / e) / size * rough;
      cover = std::max(cover, smoothstep(1.0, 0.75, d));
    }
  }
  return cover;
}

Vec3 BarkTexture::color(Vec2 uv) const {
  const BarkOptions& o = options_;
  double h = height(uv);
  const int furrows = std::max(1, o.furrows);
  double a = 2 * kPi * static_cast<double>(uv.x);
  double r = 4 * furrows / (2 * kPi);
  // Fine lengthwise grain: four times finer across than the ridges, stretched along v.
  double along = tiled(0.5 * o.alongFrequency, o.tileV);
  DVec3 p(r * std::cos(a) + 17.3, r * std::sin(a), along * static_cast<double>(uv.y));
  FractalOptions f;
  f.octaves = 3;
  double grain = 1 + o.grain * noise_.fbm(p, f, glm::ivec3(0, 0, period(along, o.tileV)));
  const double m = std::clamp(o.maturity, 0.0, 1.0);
  Vec3 c = mix(o.furrowColor, mix(o.youngColor, o.ridgeColor, m), h) * static_cast<float>(std::max(0.0, grain));
  if (m < 1 && o.lenticels > 0) c = mix(c, o.lenticelColor, (1 - m) * lenticelCover(uv));
  return c;
}

Vec3 StripesTexture::color(Vec2 uv) const {
  const StripesOptions& o = options_;
  double u = uv.x, v = uv.y;
  double b = (o.spiral ? u : v) * o.frequency;
  if (o.wobble != 0) b += o.wobble * noise_.fbm(DVec3(u * o.frequency * 0.5, v * o.frequency * 0.5, 0.37));
  double duty = std::clamp(o.duty, 0.0, 1.0);
  double dc = std::abs(fract(b) - duty / 2);  // distance to the band's center, periodic
  dc = std::min(dc, 1 - dc);
  double inside = duty / 2 - dc;  // > 0 inside the band
  double s = std::max(1e-6, o.softness) / 2;
  return mix(o.baseColor, o.stripeColor, smoothstep(-s, s, inside));
}

Vec3 SpotsTexture::color(Vec2 uv) const {
  const SpotsOptions& o = options_;
  double x = uv.x * o.frequency, y = uv.y * o.frequency;
  double ci = std::floor(x), cj = std::floor(y);
  double fx = x - ci, fy = y - cj;
  double cover = 0;
  for (int dj = -1; dj <= 1; ++dj) {
    for (int di = -1; di <= 1; ++di) {
      auto cellX = static_cast<int64_t>(ci) + di, cellY = static_cast<int64_t>(cj) + dj;
      Rng rng(deriveSeed(o.seed, {static_cast<uint64_t>(cellX), static_cast<uint64_t>(cellY)}));
      bool present = rng.uniform() < o.density;
      double cx = di + 0.5 + (rng.uniform() - 0.5) * o.jitter;
      double cy = dj + 0.5 + (rng.uniform() - 0.5) * o.jitter;
      double rad = o.radius * (1 + o.radiusJitter * (2 * rng.uniform() - 1));
      if (!present) continue;
      double d = std::hypot(fx - cx, fy - cy);
      double s = std::max(1e-6, o.softness) / 2;
      cover = std::max(cover, smoothstep(rad + s, rad - s, d));
    }
  }
  return mix(o.baseColor, o.spotColor, cover);
}

Vec3 LeafTexture::color(Vec2 uv) const {
  const LeafOptions& o = options_;
  double u = uv.x, v = std::clamp(static_cast<double>(uv.y), 0.0, 1.0);
  double dx = std::abs(u - 0.5);
  // Blade with mottling, lighter toward the margin.
  double mottle = 1 + o.mottle * noise_.fbm(DVec3(u * 9, v * 9, 0.5));
  Vec3 c = o.bladeColor * static_cast<float>(mottle);
  c = mix(c, o.veinColor, 0.35 * smoothstep(0.40, 0.5, dx));
  // Lateral veins: lines leaving the midrib toward the tip at veinAngle, slightly curved.
  double cot = 1 / std::tan(radians(std::clamp(o.veinAngleDeg, 5.0, 89.0)));
  double along = v - std::pow(dx * 2, 1.3) * 0.5 * cot;
  double q = along * o.veins + 0.5;
  double dist = std::abs(q - std::round(q)) / o.veins * std::sin(radians(o.veinAngleDeg));
  double taper = 1 - 0.6 * dx * 2;  // veins thin toward the margin
  double vein = smoothstep(o.veinWidth * taper, o.veinWidth * taper * 0.4, dist);
  if (along < 0.02 || along > 0.97) vein = 0;
  // Midrib: wide at the base, thin at the tip.
  double ribWidth = o.veinWidth * (2.2 - 1.6 * v);
  double rib = smoothstep(ribWidth, ribWidth * 0.5, dx);
  return mix(c, o.veinColor, std::max(vein * 0.8, rib));
}

}  // namespace sprig::textures
