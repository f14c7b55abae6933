#pragma once
/// Low-discrepancy sample points for the renderer: a Morton-ordered, Owen-scrambled
/// Sobol' sampler after Ahmed and Wonka 2020 ("Screen-Space Blue-Noise Diffusion of Monte
/// Carlo Sampling Error via Hierarchical Ordering of Pixels"), the scheme of pbrt-v4's
/// ZSobolSampler.
///
/// Representation: every 2D request reads the first two dimensions of the Sobol' sequence
/// (a (0,2)-sequence in base 2) at one sample index; successive requests of a camera sample
/// (film, sun, sky rays, ...) are decorrelated by an independent Owen scramble seeded from
/// the dimension number and the render's seed. The sample index of pixel (x, y) and sample
/// k is the pixel's Morton code followed by k's bits, with each base-4 digit permuted by
/// a permutation chosen by a hash of the digits above it (and of the dimension): so the
/// N samples of a pixel are one aligned block of N Sobol' indices (stratified over every
/// elementary interval of area 1/N), and the samples of an aligned 2x2 block of pixels
/// form a block of 4N indices, so neighbouring pixels fill each other's gaps and their
/// errors partly cancel under the reconstruction filter.
/// Everything is a function of (seed, x, y, k, dimension): the same bytes at any thread
/// count or tile order.

#include <cstdint>

#include "core/types.h"

namespace sprig::render {

/// Bits of component dim (0 or 1) of the unscrambled Sobol' point with the given index, as
/// a binary fraction in 32 bits. Dimension 0 is the van der Corput sequence; dimension 1
/// has direction numbers v_1 = 1/2, v_k = v_(k-1) xor v_(k-1)/2 (primitive polynomial
/// x + 1, m_1 = 1: the second dimension of Joe and Kuo's table new-joe-kuo-6.21201).
/// Index bits above 31 are ignored.
uint32_t sobolBits(uint64_t index, int dim);

/// A nested uniform (Owen) scramble of the binary fraction v: every bit is flipped by a
/// hash of the bits above it and seed. The hash is Laine and Karras's (2011) as improved
/// by Burley 2020 ("Practical Hash-based Owen Scrambling", JCGT 9(4)); elementary
/// intervals map onto elementary intervals, so stratification is kept.
uint32_t owenScramble(uint32_t v, uint32_t seed);

/// Owen-scrambled Sobol' component dim (0 or 1) of point index, in [0, 1).
float sobolSample(uint64_t index, int dim, uint32_t seed);

/// Morton-ordered Owen-scrambled Sobol' samples for one image (see the file comment).
/// Cheap to copy; not shared between threads (it holds the current pixel sample).
class ZSobolSampler {
 public:
  /// A sampler for an image of width x height pixels and spp samples per pixel (rounded
  /// up to a power of two internally; a pixel then uses the first spp of its block).
  ZSobolSampler(int width, int height, int spp, uint64_t seed);

  /// Starts sample k of pixel (x, y) at dimension 0.
  void startPixelSample(int x, int y, int k);

  /// The next two dimensions of the current sample, each in [0, 1).
  Vec2 get2D();

  /// The next dimension of the current sample, in [0, 1).
  float get1D();

 private:
  uint64_t sampleIndex();
  /// The permuted base-4 digits from..to-1 (counted from the lowest) of the current index.
  uint64_t permuteDigits(int from, int to) const;
  uint64_t dimensionHash() const;

  static constexpr uint32_t kCachedDimensions = 32;
  uint64_t dimensionHashes_[kCachedDimensions] = {};  ///< deriveSeed(seed, {d}) of the first dimensions
  uint64_t cachedPixel_[kCachedDimensions] = {};      ///< the pixel (Morton code) cachedHigh_ was made for
  uint64_t cachedHigh_[kCachedDimensions] = {};       ///< its permuted pixel digits, per dimension
  int log2Spp_ = 0;
  int base4Digits_ = 0;
  uint64_t seed_ = 0;
  uint64_t mortonIndex_ = 0;
  uint32_t dimension_ = 0;
};

}  // namespace sprig::render
