#pragma once
/// Wind: a tree's skeleton swayed at a moment in time (`sprig animate --wind`).
///
/// The wind turns every internode about its own base, and everything above it follows
/// (children are carried rigidly by their parent's turn), so the skeleton stays connected
/// and the BlobTree built from the swayed skeleton blends its junctions exactly as the
/// still tree's: nothing tears. Three motions add up (docs/TREES.md "Wind"):
/// - the trunk leans downwind, each order-0 internode by a share of the lean proportional to
///   its length, the lean growing with the square of the speed (the drag) and breathing
///   with slow gusts;
/// - each branch sways about its base, the amplitude growing with the speed and the branch
///   order, the frequency with the order (thin branches are faster), phases from the seed;
/// - leaves (organs) flutter about their attachment, fastest of all.
/// Turning is about axes perpendicular to the up axis or to the internode, so heights change
/// little and displacement grows with height above the ground. Deterministic: phases come
/// from deriveSeed(seed, {internode}); speed 0 returns the skeleton unchanged.

#include <cstdint>
#include <vector>

#include "core/types.h"
#include "lsystem/skeleton.h"

namespace sprig::organisms {

/// What the wind does.
struct WindOptions {
  double speed = 0;            ///< wind speed, m/s (0 = no wind)
  double directionDeg = 0;     ///< azimuth the wind blows toward, around +Y from +Z toward +X (0 = toward +Z)
  uint64_t seed = 1;           ///< seed of the phases
  double leanPerSpeed2 = 0.0012;  ///< trunk lean at the top, radians per (m/s)²
  double swayPerSpeed = 0.012;    ///< order-1 branch sway amplitude, radians per m/s
  double orderGain = 1.5;         ///< sway amplitude factor per order above 1
  double flutterPerSpeed = 0.02;  ///< leaf flutter amplitude, radians per m/s
  double gustHz = 0.25;           ///< trunk gust frequency
  double swayHz = 0.6;            ///< order-1 sway frequency (x orderGain per order)
  double flutterHz = 1.5;         ///< leaf flutter frequency (at most fps / 8 keeps frames smooth)
  /// > 0: every frequency above is rounded to a whole number of cycles (at least one) per
  /// loopSeconds (loopHz), so the sway repeats with that period (glTF exports: kWindLoopSeconds).
  double loopSeconds = 0;
};

/// hz rounded to a whole number of cycles (at least one) per loopSeconds; hz itself when
/// loopSeconds <= 0.
double loopHz(double hz, double loopSeconds);

/// The second, crosswise sway of a branch: this times the branch's frequency and amplitude.
inline constexpr double kCrossSwayHzRatio = 1.37;
inline constexpr double kCrossSwayGain = 0.35;
/// The downwind sway's bias: a branch turns amplitude·(kSwayBias + sin) about its first axis.
inline constexpr double kSwayBias = 0.5;
/// Gusts: lean(t) = top lean · (1 + kGustGain1 sin(2π gustHz t + φ1) + kGustGain2 sin(2π kGustHzRatio2 gustHz t + φ2)).
inline constexpr double kGustGain1 = 0.25;
inline constexpr double kGustGain2 = 0.10;
inline constexpr double kGustHzRatio2 = 2.3;

/// One internode's part of the wind: how its own turn about its base varies in time.
/// Order 0 turns lean(t)·length/height about WindRig::leanAxis; order o >= 1 turns
/// rotation(k2, a2)·rotation(k1, a1) with a1 = amplitude·(kSwayBias + sin(2π hz t + phase1)),
/// a2 = kCrossSwayGain·amplitude·sin(2π hz2 t + phase2).
struct InternodeWind {
  size_t axis = 0;         ///< first internode of its branch axis (a chain of one order)
  double axisFrom = 0;     ///< share of its axis's turn accumulated at its start: axis length before it / axis length (order 0: of the lean, by height)
  double axisTo = 0;       ///< the same at its end
  double length = 0;       ///< its length
  DVec3 k1{0}, k2{0};      ///< order >= 1: the two turning axes (unit, from its rest direction)
  double amplitude = 0;    ///< order >= 1: radians of the downwind sway
  double hz = 0, hz2 = 0;  ///< order >= 1: frequencies of the downwind and crosswise sways
  double phase1 = 0, phase2 = 0;  ///< order >= 1: their phases (radians, one pair per axis)
};

/// One organ's flutter: it turns amplitude·sin(2π hz t + phase) about axis through pivot,
/// after its internode's motion (tubes: amplitude 0).
struct OrganWind {
  DVec3 pivot{0}, axis{1, 0, 0};
  double amplitude = 0, hz = 0, phase = 0;
};

/// The wind's model laid out per internode and organ (what swayInWind evaluates at each
/// moment): exports take their attributes and morph targets from it, so they follow the
/// renders' wind by construction. Built in O(n).
struct WindRig {
  WindOptions options;
  DVec3 leanAxis{1, 0, 0};     ///< the trunk turns about it toward the wind
  double height = 1;           ///< the skeleton's height (the lean is spread by length / height)
  double leanTop = 0;          ///< lean at gust 1, radians (leanPerSpeed2·speed²)
  double gustHz[2] = {0, 0};   ///< the gusts' frequencies
  double gustPhase[2] = {0, 0};
  std::vector<size_t> order;   ///< internodes, parents before children
  std::vector<InternodeWind> internodes;
  std::vector<OrganWind> organs;
  /// The gust factor at time t: 1 + kGustGain1 sin(..) + kGustGain2 sin(..).
  double gust(double t) const;
};

/// The rig of skeleton in wind (speed may be 0: the amplitudes are then 0). O(n).
WindRig windRig(const lsystem::Skeleton& skeleton, const WindOptions& wind);

/// The skeleton swayed by wind at time `seconds`. Lengths and radii are kept (every
/// internode and organ moves rigidly); speed <= 0 returns the skeleton as it is. O(n).
lsystem::Skeleton swayInWind(const lsystem::Skeleton& skeleton, const WindOptions& wind, double seconds);

}  // namespace sprig::organisms
