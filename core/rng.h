#pragma once
/// Seeded random numbers whose sequences Sprig specifies itself.
///
/// std:: distributions differ between standard libraries, so every draw here is
/// defined bit for bit: the generator is PCG32 (O'Neill 2014, XSH-RR output, 64-bit LCG
/// state), seeded through SplitMix64; uniform doubles take the top 53 bits of two draws;
/// normals use the Box-Muller transform. Per-item seeds come from mixing a base seed with
/// the item's identity (seed, step, module index, ...), so results never depend on the
/// order in which threads visit items.

#include <cstdint>
#include <initializer_list>

namespace sprig {

/// SplitMix64 finalizer: a bijective 64-bit mix (Steele, Lea, Flood 2014).
constexpr uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// A seed for one item, derived from a base seed and the item's identity.
constexpr uint64_t deriveSeed(uint64_t seed, std::initializer_list<uint64_t> ids) {
  uint64_t h = mix64(seed);
  for (uint64_t id : ids) h = mix64(h ^ mix64(id + 0x632be59bd9b4e019ull));
  return h;
}

/// PCG32 generator with Sprig-specified derived distributions.
class Rng {
 public:
  /// A generator seeded with seed (equal seeds give equal sequences everywhere).
  explicit Rng(uint64_t seed = 0) { reseed(seed); }

  /// Restarts the sequence from seed, as if newly constructed with it.
  void reseed(uint64_t seed) {
    state_ = 0;
    inc_ = (mix64(seed ^ 0xda3e39cb94b95bdbull) << 1u) | 1u;
    next32();
    state_ += mix64(seed);
    next32();
  }

  /// Next 32 uniformly distributed bits.
  uint32_t next32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  /// Next 64 uniformly distributed bits (two 32-bit draws, high first).
  uint64_t next64() {
    uint64_t hi = next32();
    return (hi << 32) | next32();
  }

  /// Uniform double in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(next64() >> 11) * 0x1.0p-53; }

  /// Uniform double in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }

  /// Uniform integer in [0, n) for n > 0 (Lemire's multiply-shift; exact for n < 2^32 up to a 2^-32 bias).
  uint32_t below(uint32_t n) { return static_cast<uint32_t>((static_cast<uint64_t>(next32()) * n) >> 32); }

  /// Normal deviate (Box-Muller, one value per call; the second is discarded so the
  /// sequence depends only on the number of calls).
  double normal(double mean = 0.0, double sd = 1.0);

 private:
  uint64_t state_ = 0;
  uint64_t inc_ = 1;
};

/// The POSIX rand48 generator behind drand48/erand48: the 48-bit state steps as
/// X' = (0x5DEECE66D X + 0xB) mod 2^48 and each draw is X' / 2^48 (exactly; 48 bits).
/// Sprig implements it rather than calling libc (global state) so that cpfg files draw
/// cpfg's own sequences (lsystem/, docs/GRAMMAR.md) on any platform and any thread.
class Rand48 {
 public:
  /// A generator whose state is x (its low 48 bits).
  explicit constexpr Rand48(uint64_t x = 0) : x_(x & kMask) {}
  /// The state of erand48's array {w0, w1, w2} (w0 least significant), which seed48 sets.
  static constexpr Rand48 fromWords(uint16_t w0, uint16_t w1, uint16_t w2) {
    return Rand48(static_cast<uint64_t>(w0) | (static_cast<uint64_t>(w1) << 16) | (static_cast<uint64_t>(w2) << 32));
  }
  /// Next draw in [0, 1).
  double next() {
    x_ = (0x5DEECE66Dull * x_ + 0xBu) & kMask;
    return static_cast<double>(x_) * 0x1.0p-48;
  }
  uint64_t state() const { return x_; }

 private:
  static constexpr uint64_t kMask = (1ull << 48) - 1;
  uint64_t x_;
};

}  // namespace sprig
