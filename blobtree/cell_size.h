#pragma once
/// The automatic cell size rule shared by the polygonizer and the renderer's surface cells.
///
/// One rule, parameterized: the edge follows the model's smallest feature (so the thinnest
/// twig gets several cells across), bounded above and below by fractions of the model's
/// bounds diagonal. Each caller keeps its own numbers (see CellSizeRule).

#include "blobtree/compiled.h"

namespace sprig::blobtree {

/// Parameters of autoCellSize(). With diag the bounds diagonal and r the smallest feature
/// radius (CompiledBlob::smallestFeature()):
///   r > 0:  clamp(featureFraction · r, diag / finestDivisions, diag / coarsestDivisions)
///   r = 0:  max(diag / noFeatureDivisions, diag / finestDivisions)
/// A non-positive finestDivisions drops the lower bound.
struct CellSizeRule {
  float featureFraction = 0.5f;      ///< cell edge per unit of the smallest feature radius
  float coarsestDivisions = 64.0f;   ///< the edge is at most diag / this
  float finestDivisions = 2500.0f;   ///< the edge is at least diag / this (<= 0: no floor)
  float noFeatureDivisions = 64.0f;  ///< edge diag / this when the model has no sized primitive
};

/// The automatic cell edge (world units) of blob under rule; 0 for an empty blob. The
/// rule's fields must be positive (finestDivisions may be <= 0). An unbounded blob (a bare
/// cutter) gives a meaningless edge: callers reject it (CompiledBlob::surfaceCells throws,
/// resolveCellSize throws first).
float autoCellSize(const CompiledBlob& blob, const CellSizeRule& rule);

}  // namespace sprig::blobtree
