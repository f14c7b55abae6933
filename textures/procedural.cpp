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
  // (Whole ridges of drift per tile when the pattern tiles.)
  const double drift = o.braid == 0 ? 0.0 : std::copysign(tiled(std::abs(o.braid), o.tileV), o.braid) * v;
  double ridge = static_cast<double>(uv.x) * furrows + drift + o.warp * noise_.fbm(p, f, glm::ivec3(0, 0, period(along, o.tileV)));
  const double m = std::clamp(o.maturity, 0.0, 1.0);
  double h = 1 - std::abs(2 * fract(ridge) - 1);  // 1 on a ridge, 0 in a furrow
  if (o.braid != 0) {
    // Braided bark: a second set of furrows drifting the other way, with its own wander;
    // a point is on a ridge only where both sets put it there, so the furrows cross at a
    // shallow angle and interlace around long lens-shaped ridges.
    const double ridge2 = static_cast<double>(uv.x) * furrows - drift + 0.5 +
                          o.warp * noise_.fbm(p + DVec3(7.7, -4.1, 0.0), f, glm::ivec3(0, 0, period(along, o.tileV)));
    h = std::min(h, 1 - std::abs(2 * fract(ridge2) - 1));
  }
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

double BarkTexture::peelLevel(Vec2 uv) const {
  const BarkOptions& o = options_;
  if (!(o.peel > 0)) return -1.0;
  const double m = std::clamp(o.maturity, 0.0, 1.0);
  const double cover = std::clamp(o.peel * (0.4 + 0.6 * m), 0.0, 1.0);
  // A cylinder point with peelPerRidge·furrows features around (periodic in u) and
  // peelFrequency per unit of v; warped by a second fbm so the patches are ragged.
  const double around = std::max(1.0, std::round(std::max(1, o.furrows) * o.peelPerRidge));
  const double a = 2 * kPi * static_cast<double>(uv.x);
  const double r = around / (2 * kPi);
  const double along = tiled(o.peelFrequency, o.tileV);
  const glm::ivec3 per(0, 0, period(along, o.tileV));
  DVec3 p(r * std::cos(a) + 41.7, r * std::sin(a) - 13.1, along * static_cast<double>(uv.y));
  FractalOptions f;
  f.octaves = 3;
  const DVec3 w(noise_.fbm(p + DVec3(5.2, 1.3, 0), f, per), noise_.fbm(p + DVec3(-3.7, 8.1, 0), f, per), 0.0);
  f.octaves = 4;
  const double n = noise_.fbm(p + 0.6 * w, f, per);
  // This warped fbm is about normal with deviation σ = 0.17 (measured over 40,000 points):
  // the level above which a share `cover` lies is σ·Φ⁻¹(1 − cover), Φ⁻¹(p) taken as the
  // logistic approximation ln(p / (1 − p)) / 1.702 (within 3% for p in [0.1, 0.9]).
  const double c = std::clamp(cover, 1e-4, 1 - 1e-4);
  const double t = 0.17 * std::log((1 - c) / c) / 1.702;
  return n - t;
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
  if (o.peel > 0) {
    const double e = peelLevel(uv);
    // Fresh bark: mottled, smooth. Old bark: scaly (fine cracks from a sharper noise).
    // (Left out when the pattern tiles: these two noises do not repeat along v.)
    const double mottle = o.tileV > 0 ? 0.0 : noise_(DVec3(p.x * 0.5 + 3.3, p.y * 0.5, p.z * 0.5 + 9.1));
    const Vec3 fresh = c * static_cast<float>(1 + 0.18 * mottle);
    const double scales = o.tileV > 0 ? 1.0 : std::abs(noise_(DVec3(p.x * 2.5, p.y * 2.5, p.z * 2.5 + 4.4)));
    const Vec3 old = o.peelColor * static_cast<float>(std::max(0.0, grain) * (0.7 + 0.45 * smoothstep(0.0, 0.12, scales)));
    constexpr double kLip = 0.035, kShadow = 0.05;  // in units of the patch field
    if (e >= kLip) {
      c = old;
    } else if (e >= 0) {
      // The curled lip: the patch's paler underside, turning back into the patch.
      const double s = e / kLip;
      c = mix(o.peelColor * 1.45f, old, static_cast<float>(smoothstep(0.3, 1.0, s)));
    } else if (e > -kShadow) {
      // The lip's shadow on the fresh bark, darkest against the edge.
      const double s = -e / kShadow;
      c = fresh * static_cast<float>(0.45 + 0.55 * smoothstep(0.0, 1.0, s));
    } else {
      c = fresh;
    }
  }
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
