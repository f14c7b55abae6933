#pragma once
/// A skeleton drawn directly: internodes as tapered round curves, organs as flat polygons,
/// diamond leaves and spheres (the fast preview of a plant; BlobTree trees build their
/// surfaces in organisms/tree_builder instead).
///
/// The result is neutral geometry (core/shapes.h, core/mesh.h) that any renderer can take.

#include <vector>

#include "core/mesh.h"
#include "core/shapes.h"
#include "lsystem/skeleton.h"

namespace sprig::organisms {

/// How a skeleton's parts are sized and coloured.
struct SkeletonGeometryOptions {
  double radiusScale = 1.0;          ///< multiplies every internode and sphere radius
  double minRadiusFraction = 0.002;  ///< radius floor as a fraction of the skeleton's bounds diagonal
  bool organs = true;                ///< build organs (polygons, spheres, named surfaces)
  /// Colours by turtle colour index (`'`); an organ whose index (> 0) has an entry uses it.
  std::vector<Vec3> palette;
  Vec3 leafColor{0.16f, 0.38f, 0.08f};   ///< polygons and named surfaces without a palette entry
  Vec3 fruitColor{0.55f, 0.08f, 0.06f};  ///< spheres without a palette entry
};

/// A skeleton as curves, a leaf mesh and spheres.
struct SkeletonGeometry {
  CurveSet internodes;  ///< an internode that continues its parent's end shares the joint
  Mesh leaves;          ///< polygons fan-triangulated (Newell normals), named surfaces as diamonds, cpfg surface meshes as placed
  std::vector<Vec3> leafColors;  ///< one per leaf triangle
  SphereSet fruit;               ///< sphere organs
};

/// Builds the preview geometry of skeleton. Cost: O(internodes + organ points). A cpfg
/// surface with a texture (Organ::texture) is left out: its images are the view file's.
SkeletonGeometry buildSkeletonGeometry(const lsystem::Skeleton& skeleton, const SkeletonGeometryOptions& options = {});

}  // namespace sprig::organisms
