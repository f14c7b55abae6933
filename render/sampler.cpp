#include "render/sampler.h"

#include <algorithm>
#include <array>

#include "core/rng.h"

namespace sprig::render {

namespace {

/// Bit i of x moved to bit 2i (x below 2^32).
uint64_t spreadBits(uint64_t x) {
  x &= 0xffffffffull;
  x = (x | (x << 16)) & 0x0000ffff0000ffffull;
  x = (x | (x << 8)) & 0x00ff00ff00ff00ffull;
  x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0full;
  x = (x | (x << 2)) & 0x3333333333333333ull;
  x = (x | (x << 1)) & 0x5555555555555555ull;
  return x;
}

uint32_t reverseBits(uint32_t v) {
  v = ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 8) & 0x00ff00ffu) | ((v & 0x00ff00ffu) << 8);
  return (v >> 16) | (v << 16);
}

/// ceil(log2(n)) for n >= 1.
int log2Ceil(uint64_t n) {
  int k = 0;
  while ((uint64_t{1} << k) < n) ++k;
  return k;
}

/// Dimension 1's bits are the xor of the direction numbers of the index's set bits, so
/// they are linear over GF(2) in the index: entry [j][b] is the xor for byte j of the index
/// equal to b, and sobolBits xors four lookups instead of walking up to 32 bits (a loop of
/// data-dependent branches that was 6-7 % of a tree's exact render).
std::array<std::array<uint32_t, 256>, 4> makeDimension1Bytes() {
  std::array<uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (int k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  std::array<std::array<uint32_t, 256>, 4> t{};
  for (int j = 0; j < 4; ++j)
    for (int b = 0; b < 256; ++b)
      for (int k = 0; k < 8; ++k)
        if (b & (1 << k)) t[size_t(j)][size_t(b)] ^= v[size_t(8 * j + k)];
  return t;
}

const std::array<std::array<uint32_t, 256>, 4> kDimension1Bytes = makeDimension1Bytes();

/// The 24 permutations of the four base-4 digits.
constexpr uint8_t kPermutations[24][4] = {
    {0, 1, 2, 3}, {0, 1, 3, 2}, {0, 2, 1, 3}, {0, 2, 3, 1}, {0, 3, 2, 1}, {0, 3, 1, 2},
    {1, 0, 2, 3}, {1, 0, 3, 2}, {1, 2, 0, 3}, {1, 2, 3, 0}, {1, 3, 2, 0}, {1, 3, 0, 2},
    {2, 1, 0, 3}, {2, 1, 3, 0}, {2, 0, 1, 3}, {2, 0, 3, 1}, {2, 3, 0, 1}, {2, 3, 1, 0},
    {3, 1, 2, 0}, {3, 1, 0, 2}, {3, 2, 1, 0}, {3, 2, 0, 1}, {3, 0, 2, 1}, {3, 0, 1, 2}};

}  // namespace

uint32_t sobolBits(uint64_t index, int dim) {
  if (dim == 0) return reverseBits(static_cast<uint32_t>(index));
  const auto i = static_cast<uint32_t>(index);
  return kDimension1Bytes[0][i & 0xffu] ^ kDimension1Bytes[1][(i >> 8) & 0xffu] ^
         kDimension1Bytes[2][(i >> 16) & 0xffu] ^ kDimension1Bytes[3][i >> 24];
}

uint32_t owenScramble(uint32_t v, uint32_t seed) {
  // In bit-reversed order every step below changes a bit only as a function of the bits
  // below it (multiplication and addition carry upward), i.e. of the higher bits of v.
  v = reverseBits(v);
  v ^= v * 0x3d20adeau;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return reverseBits(v);
}

float sobolSample(uint64_t index, int dim, uint32_t seed) {
  constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;
  return std::min(static_cast<float>(owenScramble(sobolBits(index, dim), seed)) * 0x1p-32f, kOneMinusEpsilon);
}

ZSobolSampler::ZSobolSampler(int width, int height, int spp, uint64_t seed)
    : log2Spp_(log2Ceil(static_cast<uint64_t>(std::max(spp, 1)))), seed_(seed) {
  const int log2Resolution = log2Ceil(static_cast<uint64_t>(std::max({width, height, 1})));
  base4Digits_ = log2Resolution + (log2Spp_ + 1) / 2;
  for (uint32_t d = 0; d < kCachedDimensions; ++d) {
    dimensionHashes_[d] = deriveSeed(seed_, {d});
    cachedPixel_[d] = ~uint64_t{0};
  }
}

void ZSobolSampler::startPixelSample(int x, int y, int k) {
  const uint64_t morton = spreadBits(static_cast<uint64_t>(x)) | (spreadBits(static_cast<uint64_t>(y)) << 1);
  mortonIndex_ = (morton << log2Spp_) | static_cast<uint64_t>(k);
  dimension_ = 0;
}

uint64_t ZSobolSampler::permuteDigits(int from, int to) const {
  // Permute each base-4 digit of the Morton index by a permutation picked by the digits
  // above it: a bijection on every aligned block of 4^j indices.
  const int oddShift = (log2Spp_ & 1) != 0 ? 1 : 0;
  const uint64_t key = 0x55555555ull * dimension_ ^ seed_;
  uint64_t index = 0;
  for (int i = from - 1; i >= to; --i) {
    const int shift = 2 * i - oddShift;
    const uint64_t digit = (mortonIndex_ >> shift) & 3;
    const uint64_t p = (mix64((mortonIndex_ >> (shift + 2)) ^ key) >> 24) % 24;
    index |= static_cast<uint64_t>(kPermutations[p][digit]) << shift;
  }
  return index;
}

uint64_t ZSobolSampler::sampleIndex() {
  // Digits i >= pixelDigit hold the pixel's Morton code alone: the same for all samples of
  // the pixel, so they are permuted once per pixel and dimension. With an odd log2(spp)
  // the last digit is a single bit, flipped by a hash.
  const bool oddBits = (log2Spp_ & 1) != 0;
  const int pixelDigit = (log2Spp_ + 1) / 2;
  const uint64_t pixel = mortonIndex_ >> log2Spp_;
  uint64_t index;
  if (dimension_ < kCachedDimensions && cachedPixel_[dimension_] == pixel) {
    index = cachedHigh_[dimension_];
  } else {
    index = permuteDigits(base4Digits_, pixelDigit);
    if (dimension_ < kCachedDimensions) {
      cachedPixel_[dimension_] = pixel;
      cachedHigh_[dimension_] = index;
    }
  }
  index |= permuteDigits(pixelDigit, oddBits ? 1 : 0);
  if (oddBits) index |= (mortonIndex_ & 1) ^ (mix64((mortonIndex_ >> 1) ^ (0x55555555ull * dimension_ ^ seed_)) & 1);
  return index;
}

uint64_t ZSobolSampler::dimensionHash() const {
  return dimension_ < kCachedDimensions ? dimensionHashes_[dimension_] : deriveSeed(seed_, {dimension_});
}

Vec2 ZSobolSampler::get2D() {
  const uint64_t index = sampleIndex();
  // Index bits above 31 (images beyond 2^32 samples) select a different scramble.
  const uint64_t h = index >> 32 ? deriveSeed(dimensionHash(), {index >> 32}) : dimensionHash();
  dimension_ += 2;
  return {sobolSample(index, 0, static_cast<uint32_t>(h)), sobolSample(index, 1, static_cast<uint32_t>(h >> 32))};
}

float ZSobolSampler::get1D() {
  const uint64_t index = sampleIndex();
  const uint64_t h = index >> 32 ? deriveSeed(dimensionHash(), {index >> 32}) : dimensionHash();
  dimension_ += 1;
  return sobolSample(index, 0, static_cast<uint32_t>(h));
}

}  // namespace sprig::render
