#include <catch2/catch.hpp>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"

using namespace sprig;
using namespace sprig::blobtree;

TEST_CASE("BlobTree::point", "[blobtree]") {
  BlobTree t;
  NodeId p = t.point(Vec3(0), 1.0f);
  CompiledBlob b = compile(t, p);
  CHECK(b.value(Vec3(1, 0, 0)) == Approx(0.5f).margin(1e-5));
}
