#pragma once
/// The skeleton side of the BlobTree tree builder: where each cone primitive goes.
///
/// planTree() turns a Skeleton into a TreePlan, a neutral list of cone parts grouped by
/// junction, with every offset of "BlobTree Trees" (Galbraith, MacMurchy, Wyvill) applied:
/// the basal internode shortened by δA (Eq. 4, Eq. 8), PCM branches moved off the branching
/// point by δB_i (Eq. 7), tapered tips, pruned and scarred branches, and per-internode bend
/// angles. buildTreeBlob() (tree_builder.h) only translates the plan into BlobTree nodes, so
/// all the paper's geometry is testable here without evaluating a field.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/types.h"
#include "lsystem/skeleton.h"
#include "organisms/tree_options.h"

namespace sprig::organisms {

/// One cone primitive of the tree: the (offset) segment of one internode.
struct ConePart {
  enum class Kind {
    Internode,  ///< an ordinary internode
    Pruned,     ///< first internode of a sawn-off branch: intersected with the keep side of `cutPlane`
    Stub,       ///< the short stub of a lost branch, blended with a negative field (a scar)
  };
  Kind kind = Kind::Internode;
  int32_t internode = -1;        ///< skeleton internode it represents
  DVec3 start{0}, end{0};        ///< primitive segment after offsets (world)
  double startRadius = 0;        ///< 0.5-iso radius at start
  double endRadius = 0;          ///< 0.5-iso radius at end
  double vStart = 0;             ///< distance along the axes from the root to `start` (bark v)
  int32_t junctionAtStart = -1;  ///< junction where this part is a branch (-1 at the root)
  int32_t junctionAtEnd = -1;    ///< junction where this part is the basal internode (-1 at a tip)
  /// Pruned: the saw's plane as (point, normal); the kept side is where dot(x - point, normal) < 0.
  DVec3 cutPoint{0}, cutNormal{0};
  /// Stub: the negative field's center and radius (a point primitive at the stub's end).
  DVec3 negativeCenter{0};
  double negativeRadius = 0;
  double negativeWeight = 0;
  /// Bend (§3.6): tangent angle at the start, in radians; 0 = straight. The bow lies in the
  /// plane of `start, end` and `bendToward` (a unit vector perpendicular to the axis).
  double bendAngle = 0;
  DVec3 bendToward{0};

  /// Axis length of the primitive.
  double length() const { return glm::length(end - start); }
};

/// The internodes that meet at one branching point P (the basal internode's tip).
struct Junction {
  int32_t basal = -1;            ///< part index of the basal internode A
  std::vector<int32_t> branches; ///< part indices of the branches B_i, in skeleton order
  DVec3 point{0};                ///< the branching point P
  bool pcm = false;              ///< branches combined by PCM (several branches and the PCM model)
  double deltaA = 0;             ///< length removed from A's tip (Eq. 4 or Eq. 8)
};

/// All cone parts and junctions of one tree.
struct TreePlan {
  std::vector<ConePart> parts;
  std::vector<Junction> junctions;
  std::vector<int32_t> partOfInternode;  ///< skeleton index -> part index, -1 when dropped
};

/// Eq. 4: length removed from the basal internode when it carries one branch of radius rB.
double deltaASingle(double rB, double factor = 1.75);
/// Eq. 8: length removed from the basal internode of radius rA carrying several branches
/// whose largest radius is rMax (negative values lengthen A).
double deltaAMultiple(double rA, double rMax, double factor = 2.75);
/// Eq. 7: displacement of a PCM branch of radius ri away from the branching point.
double deltaB(double rA, double ri);

/// Lays out the cone parts of `skeleton` under `options`. Deterministic: random choices
/// use deriveSeed(options.seed, {purpose, internode}). O(internodes).
TreePlan planTree(const lsystem::Skeleton& skeleton, const TreeOptions& options);

}  // namespace sprig::organisms
