#pragma once
/// The detail procedures of Velho, Perlin, Ying and Biermann, "Procedural shape synthesis on
/// subdivision surfaces" (2002), §4: functions F(p, l) that add a level's detail, and a
/// procedure that replays captured detail (analysis, §2.2). Each has an options struct with
/// its defaults; all lengths are world units, all levels are synthesis levels (1 = the
/// first subdivision). Every procedure is seeded and deterministic.
///
/// | procedure | coordinates | law over levels (§4.1) |
/// |---|---|---|
/// | rock | 3D (the reference surface) | fractal: amplitude x gain^k, frequency x lacunarity^k |
/// | berry | surface seeds + 3D distance | fractal: domes of radius R ratio^k on clusters of seeds |
/// | tentacle | surface seed | morphogenic: reference length x level over a range (the pseudo-code) |
/// | spur | surface seed | arbitrary: one length per level over a range (Fig. 8a mine, Fig. 10) |
/// | mushroom | 3D around a surface seed | morphogenic: a designed profile split 2^-k over a range |

#include <array>
#include <memory>
#include <vector>

#include "organisms/multires.h"
#include "organisms/placement.h"

namespace sprig::organisms {

/// A range of synthesis levels, both ends included.
struct LevelRange {
  int first = 1;
  int last = 1000;
  bool contains(int l) const { return l >= first && l <= last; }
};

/// §4.2.1 Rock: at level l = first + k, the normal detail amplitude gain^k noise(frequency
/// lacunarity^k p + shift_k), p the reference surface position (Perlin noise; each octave
/// shifted by a seeded offset so octaves are independent). All levels in one pass of the
/// synthesis: O(N). With scalar, the value goes to the scalar channel (the planet, §6.3)
/// instead of the surface.
struct RockOptions {
  float amplitude = 0.1f;
  float frequency = 2.0f;  ///< noise cycles per unit at the first level
  float gain = 0.5f;       ///< amplitude ratio between levels (0.5 = 1/f)
  float lacunarity = 2.0f;
  LevelRange levels;
  bool scalar = false;
  uint64_t seed = 1;
};
std::shared_ptr<const DetailProcedure> makeRock(const RockOptions& options);

/// §4.2.2 Berry: Poisson-disk seeds on the surface at the first level; at every level each
/// vertex rises along its (evolving) normal by height R_l sqrt(1 - r^2 / R_l^2), r its
/// distance to its closest seed, R_l = radius ratio^k. Seeds of level l+1 are a Poisson-disk
/// cluster (spacing ratio^(k+1)) of the vertices under a dome of level l (within
/// `cluster` R_l of its seed).
struct BerryOptions {
  float radius = 0.2f;
  float ratio = 0.5f;
  float height = 1.0f;    ///< multiplies the dome height (1 = a spherical cap of radius R)
  float cluster = 0.8f;   ///< child seeds within cluster R_l of their parent
  LevelRange levels{1, 3};
  Placement placement;    ///< seeds of the first level (default: spacing = 1.8 radius)
};
std::shared_ptr<const DetailProcedure> makeBerry(const BerryOptions& options);

/// §4.2.3 Tentacle, the paper's pseudo-code: at local level k = l - first + 1,
///   magnitude = length k;  ph = (pi/3) k;  d = (sin(theta + ph), cos(theta + ph), 1);
///   if k is even: flip d;  detail = d magnitude,
/// in the seed's local frame. theta = angle + spin time; length grows as
/// min(1, time / grow) of its value (animation, Fig. 7). What "flip" negates is a choice
/// (the printed pseudo-code's sign is lost in the scanned text): Tangent (the default)
/// negates the tangential part, so successive links swing to alternate sides ("grow in
/// alternating directions") while the tentacle grows out; All negates the whole vector,
/// whose normal parts sum to -2 length over four levels (a pit, not a tentacle); None
/// keeps every link turning the same way.
enum class Alternate { Tangent, All, None };
struct TentacleOptions {
  float length = 0.05f;
  float angleDeg = 0;
  float spinDeg = 0;     ///< theta increase over time 0..1
  float grow = 0;        ///< 0: full length at every time; else full length from time = grow
  Alternate alternate = Alternate::Tangent;
  LevelRange levels{1, 4};
  Placement placement;
};
std::shared_ptr<const DetailProcedure> makeTentacle(const TentacleOptions& options);

/// Spur (Fig. 10) and the mine's spikes (Fig. 8a): the seed moves along its normal by
/// `length` at each level of the range (a spike whose base narrows with the level).
struct SpurOptions {
  float length = 0.1f;
  LevelRange levels{1, 1};
  Placement placement;
};
std::shared_ptr<const DetailProcedure> makeSpur(const SpurOptions& options);

/// §4.2.4 Mushroom cloud: around each seed, reference points at distance rho < footprint in
/// the seed's tangent plane move onto a mushroom profile C(rho) = (radial, height) in the
/// seed's frame (fixed at the first level: 3D coordinates around the seed). At level first +
/// k the vertices in the footprint move onto the reference moved by the share
/// W_k = sum_{j<=k} 2^-j / sum_j 2^-j of the profile's displacement (the coarser levels take
/// the larger shares: proportional to scale); the detail is that target minus the subdivided
/// surface, so the mushroom owns its footprint (other detail there is replaced). The profile is a simple curve whose z bands separate its four pieces (cap top
/// z >= H, underside H - t .. H, stalk 0 .. H - t, foot z = 0) for every growth fraction,
/// so on a plane the target surface is embedded at every level (docs/ORGANISMS.md).
struct MushroomOptions {
  float height = 0.3f;       ///< H: the cap's rim above the surface
  float capRadius = 0.25f;   ///< the cap's rim radius
  float capTop = 0.1f;       ///< the cap's dome above the rim
  float capUnder = 0.06f;    ///< the underside's depth below the rim
  float stalkRadius = 0.06f;
  float footprint = 0.4f;    ///< reference radius the feature takes (> capRadius)
  float grow = 0;            ///< 0: full at every time; else full from time = grow
  LevelRange levels{1, 4};
  Placement placement;
};
std::shared_ptr<const DetailProcedure> makeMushroom(const MushroomOptions& options);

/// The mushroom profile of options at reference radius rho (0..footprint): (radial distance,
/// height) in the seed's frame, MushroomCurve(options)(rho) (which tabulates the curve:
/// build a MushroomCurve to sample many points). Exposed for the embedding test.
Vec2 mushroomProfile(const MushroomOptions& options, float rho);

/// Where the profile's pieces meet, as fractions u = rho / footprint: the cap's top is
/// [0, a], its underside [a, b], the stalk [b, c], the foot [c, 1]. Each piece takes a share
/// of the footprint in proportion to its length, so the reference points spread evenly
/// along the profile. (Fixed shares, 0.35, 0.55, 0.75, gave a stalk of 0.2 in height 0.032
/// of reference radius on the mushroom planet: its triangles were 6 times longer than the
/// reference grid, slivers whose shading streaked.)
std::array<float, 3> mushroomBreaks(const MushroomOptions& options);

/// Half-width, in u = rho / footprint, of the window over which the profile's corners (the
/// cap's rim, where the stalk meets the underside and where it meets the foot) are rounded.
/// Sharp, they fell between the vertices of the reference grid, a different way at every
/// angle round the seed: the rims were notched and the stalks and feet streaked. 0.07 is
/// 0.04 of the planet's 0.59-long profile, about one and a half vertex steps of its level
/// 6 along the curve (0.04 left the rims notched).
inline constexpr float kMushroomRounding = 0.07f;

/// The mushroom profile as the operator uses it, tabulated once per feature: the pieces
/// (mushroomPieces' shares, mushroomBreaks) with their corners rounded by the mean over
/// u ± kMushroomRounding, eased back to the pieces within 2 kMushroomRounding of either
/// end (the apex stays on the axis; the foot ends on the ground with slope 1). A call
/// interpolates a table of kTableSteps + 1 points: O(1).
class MushroomCurve {
 public:
  explicit MushroomCurve(const MushroomOptions& options);
  /// (radial distance, height) at reference radius rho (clamped to 0..footprint).
  Vec2 operator()(float rho) const;
  const std::array<float, 3>& breaks() const { return breaks_; }

 private:
  static constexpr int kTableSteps = 1024;
  float footprint_;
  std::array<float, 3> breaks_;
  std::vector<Vec2> table_;
};

/// Captured detail (§2.2 analysis): offsets[l][v] in local frames, replayed at level l.
std::shared_ptr<const DetailProcedure> makeStoredDetail(std::vector<std::vector<Vec3>> offsets);

}  // namespace sprig::organisms
