#include <catch2/catch.hpp>

#include <algorithm>

#include "blobtree/blobtree.h"
#include "blobtree/cell_size.h"
#include "blobtree/compiled.h"
#include "blobtree/polygonize.h"

using namespace sprig;
using namespace sprig::blobtree;

TEST_CASE("autoCellSize", "[blobtree]") {
  BlobTree tree;
  std::vector<NodeId> kids = {tree.point(Vec3(0), 1.0f), tree.point(Vec3(1.5f, 0, 0), 0.01f)};
  CompiledBlob blob = compile(tree, tree.blend(kids));
  const float diag = glm::length(blob.bounds().size());
  SECTION("the renderer's rule: 1.5 radii within [diag/1000, diag/40]") {
    CellSizeRule rule{.featureFraction = 1.5f, .coarsestDivisions = 40.0f, .finestDivisions = 1000.0f, .noFeatureDivisions = 64.0f};
    CHECK(autoCellSize(blob, rule) == std::clamp(1.5f * 0.01f, diag / 1000.0f, diag / 40.0f));
    rule.finestDivisions = 0.0f;  // no floor
    CHECK(autoCellSize(blob, rule) == 1.5f * 0.01f);
  }
  SECTION("the polygonizer's rule is resolveCellSize") {
    PolygonizeOptions opt;
    CellSizeRule rule{.featureFraction = opt.featureFraction, .coarsestDivisions = opt.sizeDivisions,
                      .finestDivisions = opt.maxDivisions, .noFeatureDivisions = opt.sizeDivisions};
    CHECK(autoCellSize(blob, rule) == resolveCellSize(blob, opt));
  }
  SECTION("a model without sized primitives takes diag / noFeatureDivisions") {
    BlobTree cutter;
    CompiledBlob box = compile(cutter, cutter.box(Vec3(0), Vec3(1)));
    const float boxDiag = glm::length(box.bounds().size());
    CHECK(autoCellSize(box, CellSizeRule{.noFeatureDivisions = 64.0f}) == boxDiag / 64.0f);
  }
  SECTION("an empty blob gives 0") { CHECK(autoCellSize(CompiledBlob(), CellSizeRule{}) == 0.0f); }
}
