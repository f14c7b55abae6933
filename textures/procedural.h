#pragma once
/// Procedural color textures: noise, bark, shell stripes and spots, leaf.
///
/// Each texture is an options struct (documented defaults, a seed) and a small immutable
/// class holding the seeded noise. color() returns linear RGB and is a pure function of
/// its arguments, so it is thread-safe and gives the same bytes everywhere. Surface textures take
/// natural coordinates (u, v):
///  - on a branch u in [0, 1) is the angle around the axis (u = angle / 2 pi) and v the
///    distance along it in world units (BlobTree cone primitives' natural coordinates);
///  - on a shell u runs around the generating curve and v along the growth direction.
/// Patterns that must close around a branch (bark) are exactly periodic in u with period 1.

#include <cstdint>

#include "core/types.h"
#include "textures/noise.h"

namespace sprig::textures {

/// What each noise-driven texture holds: its options and the Perlin noise seeded with
/// options.seed. A plain base (no virtual functions): the registry holds the concrete
/// texture types in a std::variant.
template <class Options>
class SeededTexture {
 public:
  /// The texture for `options`, its noise seeded with options.seed.
  explicit SeededTexture(const Options& options = {}) : options_(options), noise_(options.seed) {}
  /// The options the texture was made with.
  const Options& options() const { return options_; }

 protected:
  Options options_;
  PerlinNoise noise_;
};

/// Two-color noise: mix(colorA, colorB, t) with t = fbm (mapped to [0, 1]) or turbulence
/// of the 3D point scale * p.
struct NoiseColorOptions {
  Vec3 colorA{0.05f, 0.05f, 0.05f};
  Vec3 colorB{0.8f, 0.8f, 0.8f};
  double scale = 4.0;         ///< features per unit
  FractalOptions fractal;
  bool turbulence = false;    ///< use turbulence (sharp creases) instead of fBm
  bool solid = false;         ///< registry lookups use the 3D position instead of (u, v, 0)
  uint64_t seed = 0;
};
/// Two-color noise texture.
class NoiseTexture : public SeededTexture<NoiseColorOptions> {
 public:
  /// Made from its options (SeededTexture: the noise is seeded with options.seed).
  using SeededTexture::SeededTexture;
  /// Color at a 3D point (solid texture).
  Vec3 color(const DVec3& p) const;
  /// Color at (u, v): the point (u, v, 0).
  Vec3 color(Vec2 uv) const { return color(DVec3(uv.x, uv.y, 0)); }
};

/// Bark: ridged furrows running along the branch.
///
/// Around the branch lie `furrows` ridges (an integer, so the pattern closes at u = 1).
/// A ridge coordinate r = u * furrows + warp * fbm(cylinder point) is folded into a ridge
/// profile h = 1 - |2 fract(r) - 1| (1 on a ridge, 0 in a furrow), sharpened to
/// 1 - (1 - h)^sharpness, then darkened along cross cracks (zero lines of a noise per
/// ridge) that split the ridges into plates. The fbm is evaluated on the cylinder point
/// (R cos 2 pi u, R sin 2 pi u, alongFrequency * v) with R = furrows / (2 pi), so it is periodic in u,
/// has about one feature per ridge width across and alongFrequency features per unit of v.
/// Color: mix(furrowColor, ridgeColor, h), times 1 + grain * fbm (fine lengthwise grain).
///
/// Age (`maturity` m in [0, 1], 1 = the pattern above): young bark is smooth. The furrows'
/// depth is 0.2 + 0.8 m and their profile exponent sharpness·(1 + 4 (1 − m)) (hairline
/// cracks on young bark that widen and deepen as it ages); the cross cracks scale with m;
/// the ridge color goes from youngColor (m = 0) to ridgeColor (m = 1). Lenticels (young
/// bark's breathing pores, lens- to diamond-shaped on a poplar, each of its own size, width
/// and outline) sit one per cell of a jittered grid
/// (one cell per ridge width around, lenticelFrequency rows per unit of v; the cell index
/// around is taken modulo furrows, so they too close at u = 1), present in a fraction
/// `lenticels` of the cells, darkening the bark by (1 − m).
///
/// Braided bark (`braid` ≠ 0): a second set of furrows, drifting the other way (below).
///
/// Peeling bark (`peel` > 0; an arbutus, a madrone, a plane): the outer bark comes away in
/// irregular patches. A level set of a domain-warped fbm on the cylinder point (about
/// `peelFrequency` patches per unit of v, `peelPerRidge` per ridge width around, so patches
/// keep their size in world units on every branch when the tree sets it from its ridge
/// width) splits the bark into old bark still on (`peelColor`, scaly with fine cracks) over
/// a cover of peel·(0.4 + 0.6 m), and the smooth fresh bark beneath (the furrow pattern
/// above, coloured as set, mottled). A patch's edge curls away: a pale lip (the patch's
/// underside) on its rim and a thin dark shadow on the fresh bark just outside it.
struct BarkOptions {
  int furrows = 9;                     ///< ridges around the branch, >= 1
  double warp = 0.6;                   ///< how far the furrows wander sideways (in ridge widths)
  double alongFrequency = 1.5;         ///< noise features per unit of v (plates about 1/alongFrequency long)
  double sharpness = 1.8;              ///< ridge profile exponent (> 1: narrow dark furrows)
  double grain = 0.25;                 ///< strength of the fine grain
  double cracks = 0.8;                 ///< depth of the cross cracks that split ridges into plates (0 = none)
  /// > 0: the pattern also repeats every tileV units of v (for tileable image maps); each
  /// frequency along v is then rounded to a whole number of cycles per tile. 0: no tiling.
  int tileV = 0;
  Vec3 ridgeColor{0.20f, 0.14f, 0.09f};
  Vec3 furrowColor{0.035f, 0.025f, 0.018f};
  double maturity = 1.0;               ///< bark age in [0, 1]: 0 young and smooth, 1 fully furrowed
  double lenticels = 0.0;              ///< fraction of lenticel cells holding one, in [0, 1] (0 = none)
  double lenticelFrequency = 4.0;      ///< lenticel rows per unit of v (whole rows per tile when tileV > 0)
  Vec3 youngColor{0.20f, 0.14f, 0.09f};    ///< ridge color of young bark (maturity 0)
  Vec3 lenticelColor{0.05f, 0.04f, 0.035f};
  /// Braided furrows (a lime, an ash): two sets of furrows drifting sideways by ±braid
  /// ridge widths per unit of v cross at a shallow angle, and the bark is ridge only where
  /// both say so: long lens-shaped ridges between interlacing furrows. 0: one set.
  double braid = 0.0;
  double peel = 0.0;                   ///< share of old bark still on in peeling patches at m = 1, in [0, 1] (0 = none)
  double peelFrequency = 4.0;          ///< peeling patches per unit of v
  double peelPerRidge = 0.5;           ///< peeling patches per ridge width around
  Vec3 peelColor{0.36f, 0.31f, 0.26f}; ///< old, grey-brown bark of the patches
  uint64_t seed = 0;
};
/// Bark texture.
class BarkTexture : public SeededTexture<BarkOptions> {
 public:
  /// Made from its options (SeededTexture: the noise is seeded with options.seed).
  using SeededTexture::SeededTexture;
  /// Ridge height in [0, 1] at (u, v) (1 = top of a ridge): the bark's bump map.
  double height(Vec2 uv) const;
  /// Bark color at (u, v).
  Vec3 color(Vec2 uv) const;
  /// Lenticel cover in [0, 1] at (u, v) before the maturity fade (0 when lenticels = 0).
  double lenticelCover(Vec2 uv) const;
  /// Peeling patches at (u, v): the signed distance-like level e of the patch field (> 0 on
  /// old bark still on, < 0 on fresh bark; 0 at a patch's edge), in units of the field.
  /// Returns -1 (all fresh bark) when peel is 0.
  double peelLevel(Vec2 uv) const;
};

/// Shell stripes: bands at constant v (growth lines) or at constant u (spiral bands).
///
/// Band coordinate b = (spiral ? u : v) * frequency + wobble * fbm(u, v); inside a band
/// when fract(b) < duty; the edge is smoothed over `softness` (in band periods).
struct StripesOptions {
  double frequency = 8.0;    ///< bands per unit
  double duty = 0.4;         ///< fraction of each period in stripeColor
  double wobble = 0.15;      ///< band waviness (in periods)
  double softness = 0.04;    ///< edge width (in periods)
  bool spiral = false;       ///< bands at constant u (following the growth direction) instead of constant v
  Vec3 baseColor{0.85f, 0.75f, 0.60f};
  Vec3 stripeColor{0.35f, 0.16f, 0.07f};
  uint64_t seed = 0;
};
/// Stripes texture.
class StripesTexture : public SeededTexture<StripesOptions> {
 public:
  /// Made from its options (SeededTexture: the noise is seeded with options.seed).
  using SeededTexture::SeededTexture;
  /// Stripe color at (u, v).
  Vec3 color(Vec2 uv) const;
};

/// Spots: one round spot per cell of a jittered grid (cells of size 1 / frequency); the
/// spot center and radius are drawn per cell from deriveSeed(seed, {cell x, cell y}).
struct SpotsOptions {
  double frequency = 6.0;     ///< cells per unit
  double radius = 0.3;        ///< mean spot radius (in cells)
  double radiusJitter = 0.4;  ///< relative radius variation
  double jitter = 0.7;        ///< center displacement (in cells, up to ±jitter/2)
  double softness = 0.05;     ///< edge width (in cells)
  double density = 0.8;       ///< fraction of cells that have a spot
  Vec3 baseColor{0.90f, 0.85f, 0.75f};
  Vec3 spotColor{0.25f, 0.08f, 0.04f};
  uint64_t seed = 0;
};
/// Spots texture.
class SpotsTexture {
 public:
  /// Made from its options (spots draw per-cell values from options.seed; no noise).
  explicit SpotsTexture(const SpotsOptions& options = {}) : options_(options) {}
  /// Spot color at (u, v). Cost: the 9 neighbouring cells.
  Vec3 color(Vec2 uv) const;
  /// The options the texture was made with.
  const SpotsOptions& options() const { return options_; }

 private:
  SpotsOptions options_;
};

/// Leaf blade: u across (0 and 1 the edges, 0.5 the midrib), v from base (0) to tip (1).
/// Green with fbm mottling, a pale midrib, pale lateral veins leaving it at `veinAngleDeg`,
/// and a lighter margin.
struct LeafOptions {
  int veins = 7;               ///< lateral vein pairs
  double veinAngleDeg = 55;    ///< angle of lateral veins to the midrib
  double veinWidth = 0.012;    ///< vein half width (in u units)
  Vec3 bladeColor{0.10f, 0.30f, 0.05f};
  Vec3 veinColor{0.35f, 0.50f, 0.15f};
  double mottle = 0.25;        ///< strength of the fbm mottling
  uint64_t seed = 0;
};
/// Leaf texture.
class LeafTexture : public SeededTexture<LeafOptions> {
 public:
  /// Made from its options (SeededTexture: the noise is seeded with options.seed).
  using SeededTexture::SeededTexture;
  /// Leaf color at (u, v).
  Vec3 color(Vec2 uv) const;
};

}  // namespace sprig::textures
