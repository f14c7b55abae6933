#include "textures/noise.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace sprig::textures {

namespace {

inline double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }
inline double lerp(double t, double a, double b) { return a + t * (b - a); }

/// Dot of (x, y, z) with one of the 12 cube-edge gradients (16 cases, 4 repeated), as in
/// Perlin 2002.
inline double grad(int hash, double x, double y, double z) {
  int h = hash & 15;
  double u = h < 8 ? x : y;
  double v = h < 4 ? y : (h == 12 || h == 14 ? x : z);
  return ((h & 1) ? -u : u) + ((h & 2) ? -v : v);
}

}  // namespace

PerlinNoise::PerlinNoise(uint64_t seed) {
  std::array<uint8_t, 256> p;
  for (int i = 0; i < 256; ++i) p[i] = static_cast<uint8_t>(i);
  Rng rng(deriveSeed(seed, {0x9e11u}));
  for (uint32_t i = 255; i > 0; --i) std::swap(p[i], p[rng.below(i + 1)]);
  for (int i = 0; i < 512; ++i) perm_[i] = p[i & 255];
}

double PerlinNoise::operator()(const DVec3& pt) const { return eval(pt, glm::ivec3(0)); }

double PerlinNoise::periodic(const DVec3& pt, const glm::ivec3& period) const { return eval(pt, period); }

double PerlinNoise::eval(const DVec3& pt, const glm::ivec3& period) const {
  // Lattice corners c0 = floor(x) and c1 = c0 + 1, wrapped modulo the period (or 256).
  auto corners = [](double f, int n, int& c0, int& c1) {
    auto i = static_cast<int64_t>(f);
    if (n > 0 && n <= 256) {
      c0 = static_cast<int>(((i % n) + n) % n);
      c1 = (c0 + 1) % n;
    } else {
      c0 = static_cast<int>(i & 255);
      c1 = (c0 + 1) & 255;
    }
  };
  double fx = std::floor(pt.x), fy = std::floor(pt.y), fz = std::floor(pt.z);
  int X0, X1, Y0, Y1, Z0, Z1;
  corners(fx, period.x, X0, X1);
  corners(fy, period.y, Y0, Y1);
  corners(fz, period.z, Z0, Z1);
  double x = pt.x - fx, y = pt.y - fy, z = pt.z - fz;
  double u = fade(x), v = fade(y), w = fade(z);
  const uint8_t* p = perm_.data();
  // Perlin's hash of a corner: p[p[p[X] + Y] + Z] (indices stay below 512).
  const int A0 = p[p[X0] + Y0], A1 = p[p[X0] + Y1], B0 = p[p[X1] + Y0], B1 = p[p[X1] + Y1];
  return lerp(w,
              lerp(v, lerp(u, grad(p[A0 + Z0], x, y, z), grad(p[B0 + Z0], x - 1, y, z)),
                   lerp(u, grad(p[A1 + Z0], x, y - 1, z), grad(p[B1 + Z0], x - 1, y - 1, z))),
              lerp(v, lerp(u, grad(p[A0 + Z1], x, y, z - 1), grad(p[B0 + Z1], x - 1, y, z - 1)),
                   lerp(u, grad(p[A1 + Z1], x, y - 1, z - 1), grad(p[B1 + Z1], x - 1, y - 1, z - 1))));
}

double PerlinNoise::fbm(const DVec3& p, const FractalOptions& o) const {
  double sum = 0, norm = 0, amp = 1, freq = 1;
  for (int k = 0; k < std::max(1, o.octaves); ++k) {
    sum += amp * (*this)(p * freq);
    norm += amp;
    amp *= o.gain;
    freq *= o.lacunarity;
  }
  return sum / norm;
}

double PerlinNoise::fbm(const DVec3& p, const FractalOptions& o, const glm::ivec3& period) const {
  double sum = 0, norm = 0, amp = 1, freq = 1;
  for (int k = 0; k < std::max(1, o.octaves); ++k) {
    glm::ivec3 pk(static_cast<int>(std::lround(period.x * freq)), static_cast<int>(std::lround(period.y * freq)),
                  static_cast<int>(std::lround(period.z * freq)));
    sum += amp * eval(p * freq, pk);
    norm += amp;
    amp *= o.gain;
    freq *= o.lacunarity;
  }
  return sum / norm;
}

double PerlinNoise::turbulence(const DVec3& p, const FractalOptions& o) const {
  double sum = 0, norm = 0, amp = 1, freq = 1;
  for (int k = 0; k < std::max(1, o.octaves); ++k) {
    sum += amp * std::abs((*this)(p * freq));
    norm += amp;
    amp *= o.gain;
    freq *= o.lacunarity;
  }
  return sum / norm;
}

}  // namespace sprig::textures
