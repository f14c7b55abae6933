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
  if (rule.finestDivisions > 0.0f) h = std::max(h, diag / rule.finestDivisions);
  return h;
}

}  // namespace sprig::blobtree
