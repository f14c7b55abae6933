#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
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

TEST_CASE("SubCellBounds", "[blobtree]") {
  const uint64_t seed = GENERATE(41u, 42u);
  INFO("seed " << seed);
  Rng rng(seed);
  auto randomIn = [&](const Box3& b) {
    return Vec3(float(rng.uniform(b.lo.x, b.hi.x)), float(rng.uniform(b.lo.y, b.hi.y)), float(rng.uniform(b.lo.z, b.hi.z)));
  };
  // A body of cones under a Ricci blend with many small, steep bumps (the Murex's make-up):
  // a cell's bound is set by the steepest bump that reaches it, a sub-cell's by its own.
  BlobTree t;
  std::vector<NodeId> body, bumps;
  for (int i = 0; i < 4; ++i)
    body.push_back(t.cone(randomIn(Box3{Vec3(-1.0f), Vec3(1.0f)}), randomIn(Box3{Vec3(-1.0f), Vec3(1.0f)}),
                          float(rng.uniform(0.2, 0.4)), float(rng.uniform(0.1, 0.3))));
  const CompiledBlob bodyBlob = compile(t, t.blend(body));
  for (int i = 0; i < 40; ++i) bumps.push_back(t.point(randomIn(bodyBlob.bounds()), float(rng.uniform(0.03, 0.08))));
  const NodeId root = t.ricci(std::vector<NodeId>{t.blend(body), t.blend(bumps)}, 8.0f);
  const CompiledBlob blob = compile(t, root);
  SurfaceCellOptions opt;
  opt.prunedTapes = true;
  const CellSet cells = blob.surfaceCells(0.25f, opt);
  REQUIRE(cells.cells.size() > 50);
  const SubCellBounds sub(cells, blob, 4);
  CHECK(sub.divisions() == 4);
  const float tol = 1e-6f * glm::length(blob.bounds().size());

  SECTION("a segment's bound holds on the gradient along it, and no crossing where 0.5 is excluded") {
    int tighter = 0, excluded = 0;
    for (int n = 0; n < 600; ++n) {
      const uint32_t ci = uint32_t(rng.uniform(0.0, double(cells.cells.size()) - 1e-9));
      const Cell& cell = cells.cells[ci];
      // Short segments (the tracer's sub-intervals) and whole chords of the cell.
      const Vec3 p = randomIn(cell.box);
      const Vec3 q = n % 2 ? randomIn(cell.box) : p + 0.3f * (randomIn(cell.box) - p);
      const Ray ray{p, q - p};
      const SubCellBounds::Bound b = sub.segment(ci, ray, 0.0f, 1.0f);
      INFO("cell " << ci << " from " << p.x << " " << p.y << " " << p.z << " to " << q.x << " " << q.y << " " << q.z);
      // No check that b.lipschitz <= cell.lipschitz: the sub-cells' bounds come from their
      // own bound walk, which is not monotone in the box to the last per cent (clang's build
      // gave 8.157 against the cell's 8.001); the tracer takes the smaller of the two.
      bool below = false, above = false;
      float prev = 0.0f;
      for (int k = 0; k <= 64; ++k) {
        const Vec3 x = p + (float(k) / 64.0f) * (q - p);
        const float g = glm::length(blob.gradient(x)), f = blob.value(x);
        CHECK(g <= b.lipschitz * 1.0001f + 1e-5f);
        if (k > 0) CHECK(std::abs(f - prev) <= b.lipschitz * glm::length(q - p) / 64.0f * 1.0001f + 1e-6f);
        prev = f;
        (f > kIso ? above : below) = true;
      }
      if (!b.maySurface) CHECK_FALSE((below && above));
      tighter += b.lipschitz < 0.5f * cell.lipschitz;
      excluded += !b.maySurface;
    }
    CHECK(tighter > 100);
    CHECK(excluded > 100);
  }
  SECTION("a segment outside its cell gets the cell's own bound") {
    const Cell& cell = cells.cells[0];
    const Vec3 far = cell.box.hi + Vec3(1.0f);
    const SubCellBounds::Bound b = sub.segment(0, Ray{far, Vec3(1, 0, 0)}, 0.0f, 1.0f);
    CHECK(b.lipschitz == cell.lipschitz);
    CHECK(b.maySurface);
  }
  SECTION("traceCell finds the same crossings, to the bit, with and without sub-cell bounds") {
    int hits = 0;
    for (int n = 0; n < 1500; ++n) {
      const uint32_t ci = uint32_t(rng.uniform(0.0, double(cells.cells.size()) - 1e-9));
      const Cell& cell = cells.cells[ci];
      const Vec3 target = randomIn(cell.box);
      const Vec3 o = target - 3.0f * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
      const Ray ray{o, target - o};
      const CompiledBlob& tape = cells.tapeOf(cell, blob);
      for (Crossing mode : {Crossing::FirstStraddle, Crossing::Any, Crossing::First}) {
        const std::optional<float> plain = traceCell(tape, cell, ray, 0.0f, 10.0f, tol, mode);
        const std::optional<float> narrowed = traceCell(tape, cell, ray, 0.0f, 10.0f, tol, mode, sub, ci);
        REQUIRE(plain.has_value() == narrowed.has_value());
        if (plain) CHECK(*plain == *narrowed);
        hits += plain.has_value();
      }
    }
    CHECK(hits > 300);
  }
  SECTION("k outside 1..8 is refused") {
    CHECK_THROWS_AS(SubCellBounds(cells, blob, 0), std::invalid_argument);
    CHECK_THROWS_AS(SubCellBounds(cells, blob, 9), std::invalid_argument);
  }
}
