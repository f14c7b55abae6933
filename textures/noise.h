#pragma once
/// Gradient noise and fractal sums.
///
/// Perlin's improved noise (Perlin, "Improving Noise", SIGGRAPH 2002): a lattice of
/// pseudo-random gradients (the 12 cube-edge directions, picked by hashing the cell corner
/// through a permutation table), blended with the quintic fade 6t^5 - 15t^4 + 10t^3 so the
/// field is C2. The permutation is shuffled from a seed with sprig::Rng, so a seed fixes
/// every value bit for bit on every platform. Values lie in [-1, 1] (about ±0.9 in practice)
/// and are 0 at every lattice point; the pattern repeats every 256 units on each axis.

#include <array>
#include <cstdint>

#include "core/types.h"

namespace sprig::textures {

/// Octave settings of a fractal sum (fBm or turbulence).
struct FractalOptions {
  int octaves = 5;          ///< number of noise layers, >= 1
  double lacunarity = 2.0;  ///< frequency ratio between octaves
  double gain = 0.5;        ///< amplitude ratio between octaves
};

/// Seeded 3D gradient noise. Immutable after construction; thread-safe to evaluate.
class PerlinNoise {
 public:
  /// Permutation shuffled (Fisher-Yates on sprig::Rng) from seed.
  explicit PerlinNoise(uint64_t seed = 0);

  /// Noise at p, in [-1, 1]; 0 on integer lattice points. Cost: 8 gradient dots.
  double operator()(const DVec3& p) const;
  /// 2D slice at z = 0.
  double operator()(double x, double y) const { return (*this)(DVec3(x, y, 0)); }

  /// Noise that repeats with an integer period on each axis (a period in [1, 256]; 0 keeps
  /// the lattice's own 256): lattice corners are wrapped modulo the period (tileable noise).
  /// Equals operator() when every period is 0.
  double periodic(const DVec3& p, const glm::ivec3& period) const;

  /// Fractal Brownian motion: sum_k gain^k noise(lacunarity^k p), divided by sum_k gain^k
  /// so the result stays in [-1, 1].
  double fbm(const DVec3& p, const FractalOptions& options = {}) const;
  /// fBm whose octave k uses periodic() with period * lacunarity^k (rounded): the sum
  /// repeats with `period` when lacunarity is an integer.
  double fbm(const DVec3& p, const FractalOptions& options, const glm::ivec3& period) const;
  /// Turbulence: the same sum of |noise|, normalized to [0, 1].
  double turbulence(const DVec3& p, const FractalOptions& options = {}) const;

 private:
  double eval(const DVec3& p, const glm::ivec3& period) const;

  std::array<uint8_t, 512> perm_;  ///< the permutation, twice, so hashes need no wrap
};

}  // namespace sprig::textures
