#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/tracer.h"
#include "core/rng.h"

using namespace sprig;
using namespace sprig::blobtree;

TEST_CASE("clipToBox", "[blobtree]") {
  const Box3 box{Vec3(-1.0f), Vec3(1.0f)};
  SECTION("a ray through the box is clipped to its faces") {
    float t0 = 0.0f, t1 = 100.0f;
    REQUIRE(clipToBox(box, Vec3(-3, 0, 0), Vec3(1, 0, 0), t0, t1));
    CHECK(t0 == 2.0f);
    CHECK(t1 == 4.0f);
  }
  SECTION("a zero direction component keeps the span only inside the slab") {
    float t0 = 0.0f, t1 = 100.0f;
    CHECK(clipToBox(box, Vec3(0.5f, -3, 0), Vec3(0, 2, 0), t0, t1));
    CHECK(t0 == 1.0f);
    t0 = 0.0f, t1 = 100.0f;
    CHECK_FALSE(clipToBox(box, Vec3(1.5f, -3, 0), Vec3(0, 2, 0), t0, t1));
  }
  SECTION("a span that ends before the box is empty") {
    float t0 = 0.0f, t1 = 1.0f;
    CHECK_FALSE(clipToBox(box, Vec3(-3, 0, 0), Vec3(1, 0, 0), t0, t1));
  }
}

TEST_CASE("traceSegment", "[blobtree]") {
  const uint64_t seed = GENERATE(31u, 32u);
  INFO("seed " << seed);
  Rng rng(seed);
  BlobTree t;
  std::vector<NodeId> kids;
  for (int i = 0; i < 6; ++i)
    kids.push_back(t.cone(Vec3(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1))),
                          Vec3(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1))),
                          float(rng.uniform(0.05, 0.3)), float(rng.uniform(0.05, 0.3))));
  CompiledBlob blob = compile(t, t.blend(kids));
  const float size = glm::length(blob.bounds().size());
  int hits = 0;
  for (int i = 0; i < 200; ++i) {
    Vec3 o = blob.bounds().center() + 2.0f * size * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
    Vec3 target(float(rng.uniform(-0.8, 0.8)), float(rng.uniform(-0.8, 0.8)), float(rng.uniform(-0.8, 0.8)));
    Ray ray{o, 0.5f * (target - o)};  // not unit length: t is in the ray's units
    float L = blob.lipschitz() * glm::length(ray.direction);
    const float tol = 1e-6f * size / glm::length(ray.direction);
    std::optional<float> th = traceSegment(blob, ray, 0.0f, 4.0f, L, tol);
    std::optional<float> any = traceSegment(blob, ray, 0.0f, 4.0f, L, tol, Crossing::Any);
    REQUIRE(th.has_value() == any.has_value());
    if (!th) continue;
    ++hits;
    CHECK(*any <= *th);
    Hit h = hitAt(blob, ray, *th);
    Sample s = blob.sample(h.point);
    CHECK(std::abs(s.value - kIso) / glm::length(s.gradient) < 1e-4f * size);
    CHECK(glm::dot(h.normal, ray.direction) < 0.0f);  // entering from outside
    for (int k = 1; k < 100; ++k) CHECK(blob.value(o + (*th * float(k) / 100.0f) * ray.direction) < kIso);
  }
  CHECK(hits > 20);
}
