#include "blobtree/cell_size.h"

#include <algorithm>

namespace sprig::blobtree {

float autoCellSize(const CompiledBlob& blob, const CellSizeRule& rule) {
  Box3 b = blob.bounds();
  if (b.empty()) return 0.0f;
  const float diag = glm::length(b.size());
  const float feature = blob.smallestFeature();
  float h = feature > 0.0f ? std::min(diag / rule.coarsestDivisions, rule.featureFraction * feature)
                           : diag / rule.noFeatureDivisions;
  if (rule.finestDivisions > 0.0f) {
    float floor = diag / rule.finestDivisions;
    const float limb = blob.thinnestLimb();
    // The limb term applies only where it can be met: a limb thinner than the cost bound
    // allows would pay up to its full price and still fall apart.
    const float limbFloor = rule.limbFinestDivisions > 0.0f ? diag / rule.limbFinestDivisions : 0.0f;
    if (rule.limbFraction > 0.0f && limb > 0.0f && rule.limbFraction * limb >= limbFloor)
      floor = std::min(floor, rule.limbFraction * limb);
    h = std::max(h, floor);
  }
  return h;
}

}  // namespace sprig::blobtree
