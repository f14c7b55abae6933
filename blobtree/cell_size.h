#pragma once
/// The automatic cell size rule shared by the polygonizer and the renderer's surface cells.
///
/// One rule, parameterized: the edge follows the model's smallest feature (so the thinnest
/// twig gets several cells across), bounded above and below by fractions of the model's
/// bounds diagonal. Each caller keeps its own numbers (see CellSizeRule).

#include "blobtree/compiled.h"

namespace sprig::blobtree {

/// Parameters of autoCellSize(). With diag the bounds diagonal, r the smallest feature
/// radius (CompiledBlob::smallestFeature()) and L the thinnest limb
/// (CompiledBlob::thinnestLimb()), the floor is
///   floor = diag / finestDivisions, lowered to limbFraction · L when limbFraction > 0 and
///           diag / limbFinestDivisions <= limbFraction · L < diag / finestDivisions
/// and the edge is
///   r > 0:  clamp(featureFraction · r, floor, diag / coarsestDivisions)
///   r = 0:  max(diag / noFeatureDivisions, floor)
/// A non-positive finestDivisions drops the lower bound.
///
/// Why the limb term: a limb of radius L holds, around every point of its axis, a ball of
/// radius L; a ball of radius above √3/2 of the cell edge always holds a grid point, and
/// the nearest grid points of successive axis points are neighbours along a grid axis, so
/// at an edge of at most L (limbFraction 1, a margin of 15%) the grid points inside the
/// limb form one chain joined by cell edges and the mesher keeps the limb in one piece
/// (the bound is an edge of 2/√3 · L = 1.155 · L; limbFraction 1.1 keeps a 5% margin).
/// A coarser floor can cut a uniformly thin twig into specks (ABOP Fig. 2.8a: 15,368 pieces
/// at diag / 2500, its twigs' radius 0.59 of that edge). A tapered tip (smallestFeature())
/// may still end early: only the thick end of each primitive is promised. A limb thinner
/// than diag / limbFinestDivisions / limbFraction leaves the floor alone (the cost bound
/// could not buy its guarantee).
struct CellSizeRule {
  float featureFraction = 0.5f;      ///< cell edge per unit of the smallest feature radius
  float coarsestDivisions = 64.0f;   ///< the edge is at most diag / this
  float finestDivisions = 2500.0f;   ///< the edge is at least diag / this (<= 0: no floor)
  float noFeatureDivisions = 64.0f;  ///< edge diag / this when the model has no sized primitive
  float limbFraction = 0.0f;         ///< the floor is at most this · thinnestLimb() (<= 0: no limb term)
  float limbFinestDivisions = 4000.0f;  ///< ... when that is at least diag / this (the limb term's cost bound)
};

/// The automatic cell edge (world units) of blob under rule; 0 for an empty blob. The
/// rule's fields must be positive (finestDivisions may be <= 0). An unbounded blob (a bare
/// cutter) gives a meaningless edge: callers reject it (CompiledBlob::surfaceCells throws,
/// resolveCellSize throws first).
float autoCellSize(const CompiledBlob& blob, const CellSizeRule& rule);

}  // namespace sprig::blobtree
