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
};

/// The skeleton swayed by wind at time `seconds`. Lengths and radii are kept (every
/// internode and organ moves rigidly); speed <= 0 returns the skeleton as it is. O(n).
lsystem::Skeleton swayInWind(const lsystem::Skeleton& skeleton, const WindOptions& wind, double seconds);

}  // namespace sprig::organisms
