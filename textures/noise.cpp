#include "textures/noise.h"

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

double PerlinNoise::operator()(const DVec3& pt) const {
  double fx = std::floor(pt.x), fy = std::floor(pt.y), fz = std::floor(pt.z);
  int X = static_cast<int>(static_cast<int64_t>(fx) & 255);
  int Y = static_cast<int>(static_cast<int64_t>(fy) & 255);
  int Z = static_cast<int>(static_cast<int64_t>(fz) & 255);
  double x = pt.x - fx, y = pt.y - fy, z = pt.z - fz;
  double u = fade(x), v = fade(y), w = fade(z);
  const uint8_t* p = perm_.data();
  int A = p[X] + Y, AA = p[A] + Z, AB = p[A + 1] + Z;
  int B = p[X + 1] + Y, BA = p[B] + Z, BB = p[B + 1] + Z;
  return lerp(w,
              lerp(v, lerp(u, grad(p[AA], x, y, z), grad(p[BA], x - 1, y, z)),
                   lerp(u, grad(p[AB], x, y - 1, z), grad(p[BB], x - 1, y - 1, z))),
              lerp(v, lerp(u, grad(p[AA + 1], x, y, z - 1), grad(p[BA + 1], x - 1, y, z - 1)),
                   lerp(u, grad(p[AB + 1], x, y - 1, z - 1), grad(p[BB + 1], x - 1, y - 1, z - 1))));
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
