#pragma once
/// Neutral geometry besides triangle meshes: tapered round curves and spheres.
///
/// Producers (organisms/ builds them from skeletons) and the renderer (render/ hands them to
/// Embree as round linear curves and sphere points) share these plain arrays, so neither
/// names the other's types.

#include <cstdint>
#include <vector>

#include "core/types.h"

namespace sprig {

/// Chains of tapered round segments (cones with round joints). Segment i runs from
/// vertices[segments[i]] to vertices[segments[i] + 1]; each vertex holds a position and a
/// radius (w). A segment whose flag has kJoinedBefore/kJoinedAfter shares that end with the
/// previous/next segment of its chain, so the joint is one round vertex, not two caps.
struct CurveSet {
  static constexpr uint8_t kJoinedBefore = 1;  ///< continues the previous segment
  static constexpr uint8_t kJoinedAfter = 2;   ///< is continued by the next segment

  std::vector<Vec4> vertices;     ///< xyz position, w radius (world units)
  std::vector<uint32_t> segments;  ///< index of each segment's first vertex
  std::vector<uint8_t> flags;      ///< one per segment: kJoinedBefore | kJoinedAfter

  bool empty() const { return segments.empty(); }
};

/// Spheres with a colour each.
struct SphereSet {
  std::vector<Vec4> spheres;  ///< xyz centre, w radius (world units)
  std::vector<Vec3> colors;   ///< linear RGB, one per sphere

  bool empty() const { return spheres.empty(); }
};

}  // namespace sprig
