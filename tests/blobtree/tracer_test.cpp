#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <stdexcept>
#include <vector>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/tracer.h"
#include "core/parallel.h"
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
    // Any stops at the first batch with a sign change, which may lie past the crossing
    // First finds by searching ahead of it.
    CHECK(*any >= 0.0f);
    CHECK(*any <= 4.0f);
    Hit h = hitAt(blob, ray, *th);
    Sample s = blob.sample(h.point);
    CHECK(std::abs(s.value - kIso) / glm::length(s.gradient) < 1e-4f * size);
    CHECK(glm::dot(h.normal, ray.direction) < 0.0f);  // entering from outside
    for (int k = 1; k < 100; ++k) CHECK(blob.value(o + (*th * float(k) / 100.0f) * ray.direction) < kIso);
  }
  CHECK(hits > 20);
}

namespace {

Vec3 randomIn(Rng& rng, const Box3& b) {
  return Vec3(float(rng.uniform(b.lo.x, b.hi.x)), float(rng.uniform(b.lo.y, b.hi.y)), float(rng.uniform(b.lo.z, b.hi.z)));
}

/// A body of cones under a Ricci blend with many small, steep bumps (the Murex's make-up):
/// a cell's bound is set by the steepest bump that reaches it, a sub-cell's by its own.
CompiledBlob bumpyBody(Rng& rng) {
  BlobTree t;
  std::vector<NodeId> body, bumps;
  for (int i = 0; i < 4; ++i)
    body.push_back(t.cone(randomIn(rng, Box3{Vec3(-1.0f), Vec3(1.0f)}), randomIn(rng, Box3{Vec3(-1.0f), Vec3(1.0f)}),
                          float(rng.uniform(0.2, 0.4)), float(rng.uniform(0.1, 0.3))));
  const CompiledBlob bodyBlob = compile(t, t.blend(body));
  for (int i = 0; i < 40; ++i)
    bumps.push_back(t.point(randomIn(rng, bodyBlob.bounds()), float(rng.uniform(0.03, 0.08))));
  return compile(t, t.ricci(std::vector<NodeId>{t.blend(body), t.blend(bumps)}, 8.0f));
}

/// Thin bent cones under PCM and sum groups, united (the poplar's make-up: bend maps and
/// PCM steps in every cell's tape).
CompiledBlob bentTree(Rng& rng) {
  BlobTree t;
  std::vector<NodeId> groups;
  for (int g = 0; g < 4; ++g) {
    std::vector<NodeId> bent;
    const Vec3 base = randomIn(rng, Box3{Vec3(-1.0f), Vec3(1.0f)});
    for (int k = 0; k < 3; ++k) {
      const Vec3 dir = glm::normalize(randomIn(rng, Box3{Vec3(-1.0f), Vec3(1.0f)}));
      const Vec3 end = base + float(rng.uniform(0.6, 1.0)) * dir;
      const Vec3 side = glm::cross(dir, glm::normalize(randomIn(rng, Box3{Vec3(-1.0f), Vec3(1.0f)})));
      bent.push_back(t.bend(t.cone(base, end, 0.08f, 0.05f), base, end, float(rng.uniform(0.02, 0.06)), side));
    }
    groups.push_back(g % 2 == 0 ? t.pcm(bent) : t.blend(bent));
  }
  return compile(t, t.unite(groups));
}

}  // namespace

TEST_CASE("SubCellBounds", "[blobtree]") {
  const uint64_t seed = GENERATE(41u, 42u);
  INFO("seed " << seed);
  Rng rng(seed);
  auto randomIn = [&](const Box3& b) { return ::randomIn(rng, b); };
  const CompiledBlob blob = bumpyBody(rng);
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

TEST_CASE("traceSegment: Crossing::Any answers at the first batch with a sign change", "[blobtree]") {
  // Samples at t = 0, 1, ..., 7 along x: a small ball between the first two samples (a
  // double crossing hidden from them) and a large one whose surface lies between t = 4
  // and 5. Any returns the start of the straddling interval of the first batch, without
  // the search of the intervals ahead of it that First and FirstStraddle make.
  BlobTree t;
  const NodeId small = t.point(Vec3(0.5f, 0.0f, 0.0f), 0.3f);
  const NodeId large = t.point(Vec3(6.0f, 0.0f, 0.0f), 1.5f);
  const CompiledBlob blob = compile(t, t.blend(std::vector<NodeId>{small, large}));
  for (int i = 0; i <= 4; ++i) {
    INFO("x = " << i);
    REQUIRE(blob.value(Vec3(float(i), 0.0f, 0.0f)) < kIso);
  }
  REQUIRE(blob.value(Vec3(5.0f, 0.0f, 0.0f)) > kIso);
  REQUIRE(blob.value(Vec3(0.5f, 0.0f, 0.0f)) > kIso);
  const Ray ray{Vec3(0.0f), Vec3(1.0f, 0.0f, 0.0f)};
  const float L = blob.lipschitz();
  const std::optional<float> first = traceSegment(blob, ray, 0.0f, 7.0f, L, 1e-5f, Crossing::FirstStraddle);
  const std::optional<float> any = traceSegment(blob, ray, 0.0f, 7.0f, L, 1e-5f, Crossing::Any);
  REQUIRE(first.has_value());
  CHECK(*first < 0.5f);  // the small ball's near side
  REQUIRE(any.has_value());
  CHECK(*any == 4.0f);
}

namespace {

/// The free-sub-cell tests' scenes (0: a bumpy body, 1: a bent tree) and their surface
/// cells with pruned tapes.
struct FreeScene {
  CompiledBlob blob;
  CellSet cells;
};
FreeScene freeScene(Rng& rng, int scene) {
  FreeScene s{scene == 0 ? bumpyBody(rng) : bentTree(rng), {}};
  SurfaceCellOptions opt;
  opt.prunedTapes = true;
  s.cells = s.blob.surfaceCells(scene == 0 ? 0.25f : 0.12f, opt);
  REQUIRE(s.cells.cells.size() > 50);
  return s;
}

}  // namespace

TEST_CASE("FreeSubCells", "[blobtree]") {
  const uint64_t seed = GENERATE(41u, 42u);
  const int scene = GENERATE(0, 1);
  INFO("seed " << seed << ", scene " << scene);
  Rng rng(seed);
  const FreeScene fs = freeScene(rng, scene);
  const CompiledBlob& blob = fs.blob;
  const CellSet& cells = fs.cells;
  const FreeSubCells free(cells, blob);
  REQUIRE(free.size() == cells.cells.size());
  constexpr int k = FreeSubCells::kDivisions;
  const float tol = 1e-6f * glm::length(blob.bounds().size());

  SECTION("F stays off 0.5 in every free sub-cell, widened by the crossing test's margin") {
    // Random points of each free sub-cell's widened box, from the cell's tape (as the tracer
    // evaluates): all on the side of the sub-cell's centre, by more than half the value margin.
    int freeSubs = 0, close = 0;
    for (size_t ci = 0; ci < cells.cells.size(); ci += 3) {
      const Cell& cell = cells.cells[ci];
      const CompiledBlob& tape = cells.tapeOf(cell, blob);
      const Vec3 edge = (cell.box.hi - cell.box.lo) / float(k);
      const float margin = FreeSubCells::kMarginCells * (cell.box.hi.x - cell.box.lo.x);
      for (int s = 0; s < k * k * k; ++s) {
        if (!(free.mask(uint32_t(ci)) >> s & 1)) continue;
        ++freeSubs;
        const Vec3 lo = cell.box.lo + Vec3(float(s % k), float(s / k % k), float(s / (k * k))) * edge;
        const Box3 sub = Box3{lo, lo + edge}.expanded(margin);
        std::vector<Vec3> pts(40);
        for (Vec3& p : pts) p = randomIn(rng, sub);
        // The corners too, where the bound is tightest.
        for (int c = 0; c < 8; ++c) pts[size_t(c)] = Vec3(c & 1 ? sub.hi.x : sub.lo.x, c & 2 ? sub.hi.y : sub.lo.y, c & 4 ? sub.hi.z : sub.lo.z);
        pts.push_back(sub.center());
        std::vector<float> f(pts.size());
        tape.values(pts, f);
        const bool inside = f.back() > kIso;
        float nearest = 1e30f;
        for (size_t i = 0; i < pts.size(); ++i) {
          INFO("cell " << ci << ", sub-cell " << s << ", point " << i);
          CHECK((f[i] > kIso) == inside);
          CHECK(std::abs(f[i] - kIso) > 0.5f * FreeSubCells::kValueMargin);
          nearest = std::min(nearest, std::abs(f[i] - kIso));
        }
        close += nearest < 0.5f * std::abs(f.back() - kIso);
      }
    }
    CHECK(freeSubs > 500);
    // In some free sub-cells F comes more than halfway from the centre's value to 0.5: the
    // proof is not loose everywhere, so a wrong one would show.
    CHECK(close > 20);
  }
  SECTION("traceCell with the free sub-cells finds the same crossings, to the bit") {
    int hits = 0, freeSpans = 0;
    for (int n = 0; n < 1500; ++n) {
      const uint32_t ci = uint32_t(rng.uniform(0.0, double(cells.cells.size()) - 1e-9));
      const Cell& cell = cells.cells[ci];
      const Vec3 target = randomIn(rng, cell.box);
      const Vec3 o = target - 3.0f * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
      const Ray ray{o, target - o};
      const CompiledBlob& tape = cells.tapeOf(cell, blob);
      float t0 = 0.0f, t1 = 10.0f;
      if (clipToBox(cell.box, ray.origin, ray.direction, t0, t1)) freeSpans += free.spanFree(cell, ci, ray, t0, t1);
      for (Crossing mode : {Crossing::FirstStraddle, Crossing::Any, Crossing::First}) {
        const std::optional<float> plain = traceCell(tape, cell, ray, 0.0f, 10.0f, tol, mode);
        const std::optional<float> proved = traceCell(tape, cell, ray, 0.0f, 10.0f, tol, mode, free, nullptr, ci);
        REQUIRE(plain.has_value() == proved.has_value());
        if (plain) CHECK(*plain == *proved);
        hits += plain.has_value();
      }
    }
    CHECK(hits > 200);  // enough crossings to compare (264-330 by seed and compiler)
    CHECK(freeSpans > 150);
  }
  SECTION("dropWhole leaves out the wholly free cells, keeping the order of the others") {
    CellSet kept = cells;
    FreeSubCells masks = free;
    const size_t dropped = masks.dropWhole(kept);
    CHECK(dropped > 0);
    REQUIRE(kept.cells.size() + dropped == cells.cells.size());
    REQUIRE(masks.size() == kept.cells.size());
    size_t j = 0;
    for (size_t i = 0; i < cells.cells.size(); ++i) {
      if (free.mask(uint32_t(i)) == FreeSubCells::kWhole) continue;
      REQUIRE(j < kept.cells.size());
      CHECK(kept.cells[j].index == cells.cells[i].index);
      CHECK(masks.mask(uint32_t(j)) == free.mask(uint32_t(i)));
      ++j;
    }
    CHECK(j == kept.cells.size());
  }
}

TEST_CASE("FreeSubCells lazily", "[blobtree]") {
  // Proved when rays come (FreeSubCells(cells, blob, proveAt)): the same masks as proved
  // when made, the same crossings to the bit as with those masks and as without any, at one
  // and at two threads; and a cell is proved only once its proveAt-th trace has entered it.
  const uint64_t seed = GENERATE(43u, 44u);
  const int scene = GENERATE(0, 1);
  INFO("seed " << seed << ", scene " << scene);
  Rng rng(seed);
  const FreeScene fs = freeScene(rng, scene);
  const CompiledBlob& blob = fs.blob;
  const CellSet& cells = fs.cells;
  const FreeSubCells eager(cells, blob);
  const float tol = 1e-6f * glm::length(blob.bounds().size());

  SECTION("the masks proved lazily are those proved when made") {
    const FreeSubCells lazy(cells, blob, 0);
    CHECK(lazy.provenCount() == 0);
    int whole = 0;
    for (uint32_t c = 0; c < cells.cells.size(); ++c) {
      INFO("cell " << c);
      CHECK(lazy.mask(c) == eager.mask(c));
      whole += eager.mask(c) == FreeSubCells::kWhole;
    }
    CHECK(lazy.provenCount() == cells.cells.size());
    CHECK(whole > 0);
  }
  SECTION("rays into half the cells: the same crossings, the others never proved") {
    // Random rays aimed at the even cells' boxes, each traced in the cell it aims at, with
    // the masks proved when made, proved at the first and at the second trace, and without.
    struct Shot {
      uint32_t cell;
      Ray ray;
    };
    std::vector<Shot> shots;
    for (int n = 0; n < 3000; ++n) {
      const uint32_t ci = 2 * uint32_t(rng.uniform(0.0, double(cells.cells.size() / 2) - 1e-9));
      const Vec3 target = randomIn(rng, cells.cells[ci].box);
      const Vec3 o = target - 3.0f * glm::normalize(Vec3(rng.normal(), rng.normal(), rng.normal()));
      shots.push_back({ci, Ray{o, target - o}});
    }
    const Crossing modes[] = {Crossing::FirstStraddle, Crossing::Any, Crossing::First};
    auto traceAll = [&](const FreeSubCells& free, int threads) {
      const ThreadLimit limit(threads);
      std::vector<std::optional<float>> t(shots.size() * 3);
      parallelFor(0, t.size(), [&](size_t i) {
        const Shot& s = shots[i / 3];
        const Cell& cell = cells.cells[s.cell];
        t[i] = traceCell(cells.tapeOf(cell, blob), cell, s.ray, 0.0f, 10.0f, tol, modes[i % 3], free, nullptr, s.cell);
      });
      return t;
    };
    const std::vector<std::optional<float>> none = traceAll(FreeSubCells{}, 1);
    const std::vector<std::optional<float>> whenMade = traceAll(eager, 2);
    int hits = 0;
    for (uint32_t proveAt : {1u, 4u}) {
      for (int threads : {1, 2}) {
        INFO("proved at trace " << proveAt << ", " << threads << " threads");
        const FreeSubCells lazy(cells, blob, proveAt);
        const std::vector<std::optional<float>> got = traceAll(lazy, threads);
        hits = 0;
        for (size_t i = 0; i < got.size(); ++i) {
          REQUIRE(got[i].has_value() == none[i].has_value());
          REQUIRE(whenMade[i].has_value() == none[i].has_value());
          if (!none[i]) continue;
          ++hits;
          CHECK(*got[i] == *none[i]);
          CHECK(*whenMade[i] == *none[i]);
        }
        // Each trace of a shot enters its cell (three modes a shot); a cell is proved once
        // it has had proveAt traces, and no odd cell ever is.
        std::vector<int> traces(cells.cells.size(), 0);
        for (const Shot& s : shots) traces[s.cell] += 3;
        size_t expected = 0;
        for (uint32_t c = 0; c < cells.cells.size(); ++c) {
          INFO("cell " << c << ", " << traces[c] << " traces");
          CHECK(lazy.proven(c) == (traces[c] >= int(proveAt)));
          expected += traces[c] >= int(proveAt);
          if (c % 2 == 1) CHECK(!lazy.proven(c));
        }
        CHECK(lazy.provenCount() == expected);
        CHECK(expected < cells.cells.size() / 2 + 1);
      }
    }
    CHECK(hits > 300);
  }
}
