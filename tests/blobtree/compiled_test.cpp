#include <catch2/catch.hpp>

#include <bit>
#include <cstring>
#include <functional>
#include <map>
#include <utility>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "blobtree/detail/batch_eval.h"
#include "core/rng.h"

#include <cmath>
#include <vector>

using namespace sprig;
using namespace sprig::blobtree;

namespace {

Vec3 randomIn(Rng& rng, Vec3 lo, Vec3 hi) {
  return Vec3(float(rng.uniform(lo.x, hi.x)), float(rng.uniform(lo.y, hi.y)), float(rng.uniform(lo.z, hi.z)));
}

/// A branching structure of cones (a crude tree): `count` cones, each starting at the end of
/// an earlier one, radii shrinking with depth.
NodeId branching(BlobTree& t, Rng& rng, int count, std::vector<NodeId>* cones = nullptr, float scale = 1.0f) {
  struct Tip {
    Vec3 p, dir;
    float r;
  };
  std::vector<Tip> tips{{Vec3(0), Vec3(0, 1, 0), 0.3f * scale}};
  std::vector<NodeId> kids;
  for (int i = 0; i < count; ++i) {
    Tip base = tips[rng.below(uint32_t(tips.size()))];
    Vec3 jitter = randomIn(rng, Vec3(-0.6f), Vec3(0.6f));
    Vec3 dir = glm::normalize(base.dir + jitter);
    float len = scale * float(rng.uniform(0.6, 1.2));
    float r1 = std::max(0.02f * scale, base.r * 0.85f);
    Vec3 end = base.p + len * dir;
    TextureAttr tex;
    tex.textureId = uint16_t(i % 3);
    kids.push_back(t.cone(base.p, end, base.r, r1, tex));
    tips.push_back({end, dir, r1});
  }
  if (cones) *cones = kids;
  return t.blend(kids);
}

/// A scene exercising every operator.
NodeId scene(BlobTree& t, Rng& rng) {
  NodeId trunk = branching(t, rng, 30);
  NodeId ballA = t.point(Vec3(2, 0.5f, 0), 0.5f), ballB = t.point(Vec3(2.6f, 0.5f, 0), 0.45f);
  PcmParams pp;
  NodeId contact = t.pcm(ballA, ballB, pp);
  NodeId ring = t.rotate(t.torus(Vec3(0), Vec3(0, 1, 0), 0.8f, 0.15f), Vec3(1, 0, 0), 0.7f);
  NodeId ringMoved = t.translate(ring, Vec3(-2, 1, 0.5f));
  NodeId pts = t.ricci(std::vector<NodeId>{t.point(Vec3(0, -1.5f, 0), 0.4f), t.point(Vec3(0.5f, -1.5f, 0), 0.4f)}, 4.0f);
  NodeId seg = t.segment(Vec3(-1, -2, 1), Vec3(1, -2, 1), 0.2f);
  NodeId bent = t.bend(seg, Vec3(-1, -2, 1), Vec3(1, -2, 1), 0.4f, Vec3(0, 1, 0));
  Twist tw;
  tw.origin = Vec3(3, -1, 0);
  tw.axis = Vec3(0, 1, 0);
  tw.rateRadPerUnit = 1.2f;
  NodeId twisted = t.twist(t.segment(Vec3(3.3f, -2, 0), Vec3(3.3f, 0, 0), 0.15f), tw);
  Taper tp;
  tp.origin = Vec3(-3, -2, 0);
  tp.axis = Vec3(0, 1, 0);
  tp.length = 2.0f;
  tp.scale0 = 1.0f;
  tp.scale1 = 0.5f;
  NodeId tapered = t.taper(t.segment(Vec3(-3, -2, 0), Vec3(-3, 0, 0), 0.3f), tp);
  NodeId scar = t.negative(t.point(Vec3(0, 0.3f, 0.3f), 0.15f), 0.5f);
  NodeId blend = t.blend(std::vector<NodeId>{trunk, contact, ringMoved, pts, bent, twisted, tapered, scar});
  NodeId cut = t.box(Vec3(-10, -10, 1.2f), Vec3(10, 10, 10), 0.01f);
  return t.difference(blend, cut);
}

/// scene() drawn from Rng(seed) and compiled; rng goes on from where the scene left it.
struct SeededScene {
  Rng rng;
  BlobTree tree;
  NodeId root;
  CompiledBlob blob;
  explicit SeededScene(uint64_t seed) : rng(seed), root(scene(tree, rng)), blob(compile(tree, root)) {}
};

}  // namespace

TEST_CASE("CompiledBlob::value", "[blobtree]") {
  uint64_t seed = GENERATE(1u, 2u, 3u);
  INFO("seed " << seed);
  auto&& [rng, t, root, b] = SeededScene(seed);
  Box3 box = b.bounds().expanded(0.5f);
  SECTION("culled tape equals the reference evaluator and the unculled tape") {
    for (int i = 0; i < 3000; ++i) {
      Vec3 p = randomIn(rng, box.lo, box.hi);
      float ref = t.value(root, p);
      CHECK(b.value(p) == Approx(ref).margin(1e-5));
      CHECK(b.valueNoCulling(p) == Approx(ref).margin(1e-5));
      CHECK(b.sample(p).value == Approx(ref).margin(1e-5));
    }
  }
  SECTION("batched values equal point values, coherent and scattered batches") {
    std::vector<Vec3> pts;
    Vec3 c = randomIn(rng, box.lo, box.hi);
    for (int i = 0; i < 500; ++i) pts.push_back(c + randomIn(rng, Vec3(-0.3f), Vec3(0.3f)));
    for (int i = 0; i < 500; ++i) pts.push_back(randomIn(rng, box.lo, box.hi));
    std::vector<float> out(pts.size());
    b.values(pts, out);
    for (size_t i = 0; i < pts.size(); ++i) CHECK(out[i] == Approx(b.value(pts[i])).margin(1e-5));
  }
  SECTION("tiny batches (one point-grid cell: the O(1) child list) equal point values; tiny boxes' bounds are sound") {
    for (int k = 0; k < 300; ++k) {
      Vec3 c = randomIn(rng, box.lo, box.hi);
      std::vector<Vec3> pts;
      for (int i = 0; i < 8; ++i) pts.push_back(c + randomIn(rng, Vec3(0.0f), Vec3(0.02f)));
      std::vector<float> out(pts.size());
      b.values(pts, out);
      Interval iv = b.valueBounds(Box3{c, c + Vec3(0.02f)});
      for (size_t i = 0; i < pts.size(); ++i) {
        CHECK(out[i] == Approx(b.value(pts[i])).margin(1e-5));
        CHECK(out[i] >= iv.lo - 1e-5f);
        CHECK(out[i] <= iv.hi + 1e-5f);
      }
    }
  }
  SECTION("support bounds: every node's field is 0 outside its box") {
    for (NodeId id = 0; id < t.size(); ++id) {
      Box3 nb = t.node(id).bounds;
      if (nb.empty() || nb.size().x > 1e30f) continue;
      Box3 around = nb.expanded(1.0f);
      for (int i = 0; i < 200; ++i) {
        Vec3 p = randomIn(rng, around.lo, around.hi);
        if (nb.contains(p)) continue;
        CHECK(t.value(id, p) == 0.0f);
      }
    }
  }
  SECTION("interval bounds and local Lipschitz bounds are sound on random boxes") {
    for (int i = 0; i < 200; ++i) {
      Vec3 c = randomIn(rng, box.lo, box.hi);
      float e = float(rng.uniform(0.01, 1.0));
      Box3 q{c - e, c + e};
      Interval iv = b.valueBounds(q);
      float L = b.lipschitz(q);
      CHECK(L <= b.lipschitz() * 1.0001f);
      for (int k = 0; k < 40; ++k) {
        Vec3 p = randomIn(rng, q.lo, q.hi), r = randomIn(rng, q.lo, q.hi);
        float fp = b.value(p), fr = b.value(r);
        CHECK(fp >= iv.lo - 1e-5f);
        CHECK(fp <= iv.hi + 1e-5f);
        CHECK(std::abs(fp - fr) <= L * glm::length(p - r) * 1.001f + 1e-5f);
      }
    }
  }
}

TEST_CASE("CompiledBlob::lipschitz: a saw's or a box's ramp counts only where it slopes", "[blobtree]") {
  // A pruned branch: a cone cut by a halfspace of ramp 1e-3 (bound 1000), as the tree
  // builder saws it; and the same cone kept inside a box of the same ramp.
  BlobTree t;
  const NodeId cone = t.cone(Vec3(0), Vec3(0, 2, 0), 0.3f, 0.2f);
  const NodeId saw = t.halfspace(Vec3(0, 1, 0), Vec3(0, 1, 0));
  const NodeId sawn[2] = {cone, saw};
  const NodeId cut = t.intersect(sawn);
  const NodeId slab = t.box(Vec3(-1, 0.2f, -1), Vec3(1, 0.6f, 1));
  const NodeId boxed[2] = {cone, slab};
  const NodeId inBox = t.intersect(boxed);
  for (NodeId root : {cut, inBox}) {
    CompiledBlob b = compile(t, root);
    const CompiledBlob coneAlone = compile(t, cone);
    REQUIRE(b.lipschitz() >= 999.0f);  // the ramp's own bound, 1 / 1e-3
    // Away from the plane or the faces: the cone's bound alone.
    const Box3 away{Vec3(-0.05f, 0.35f, -0.05f), Vec3(0.05f, 0.45f, 0.05f)};
    CHECK(b.lipschitz(away) == Approx(coneAlone.lipschitz(away)));
    CHECK(b.lipschitz(away) < 10.0f);
    // Through the plane (y = 1) or a face (y = 0.6): the ramp's.
    const Box3 across{Vec3(-0.3f, root == cut ? 0.95f : 0.55f, -0.3f), Vec3(0.3f, root == cut ? 1.05f : 0.65f, 0.3f)};
    CHECK(b.lipschitz(across) >= 999.0f);
    // Sound on random boxes near the cut: |f(p) - f(q)| <= L |p - q|.
    Rng rng(7);
    for (int i = 0; i < 300; ++i) {
      Vec3 c = randomIn(rng, Vec3(-0.4f, 0.0f, -0.4f), Vec3(0.4f, 1.2f, 0.4f));
      float e = float(rng.uniform(1e-4, 0.1));
      Box3 q{c - e, c + e};
      float L = b.lipschitz(q);
      for (int k = 0; k < 20; ++k) {
        Vec3 p = randomIn(rng, q.lo, q.hi), r = randomIn(rng, q.lo, q.hi);
        CHECK(std::abs(b.value(p) - b.value(r)) <= L * glm::length(p - r) * 1.001f + 1e-5f);
      }
    }
  }
}

TEST_CASE("CompiledBlob::gradient", "[blobtree]") {
  uint64_t seed = GENERATE(11u, 12u, 13u);
  INFO("seed " << seed);
  auto&& [rng, t, root, b] = SeededScene(seed);
  Box3 box = b.bounds();
  const float h = 3e-4f;
  int compared = 0;
  for (int i = 0; i < 20000 && compared < 1500; ++i) {
    Vec3 p = randomIn(rng, box.lo, box.hi);
    float f = b.value(p);
    if (f < 0.02f || f > 1.5f) continue;
    Vec3 g = b.gradient(p);
    Vec3 fd(0.0f), fwd(0.0f), bwd(0.0f);
    bool kink = false;
    for (int a = 0; a < 3; ++a) {
      Vec3 e(0.0f);
      e[a] = h;
      double fp = b.value(p + e), fm = b.value(p - e);
      fd[a] = float((fp - fm) / (2.0 * h));
      fwd[a] = float((fp - f) / h);
      bwd[a] = float((f - fm) / h);
      // Skip points next to a kink (max/min switch, clamp): one-sided slopes disagree.
      if (std::abs(fwd[a] - bwd[a]) > 0.05f * (1.0f + std::abs(fd[a]))) kink = true;
    }
    if (kink) continue;
    ++compared;
    INFO("p = (" << p.x << ", " << p.y << ", " << p.z << ") f = " << f);
    CHECK(glm::length(g - fd) <= 0.01f * (1.0f + glm::length(fd)));
  }
  CHECK(compared > 500);
}

TEST_CASE("CompiledBlob::sample attributes", "[blobtree]") {
  BlobTree t;
  TextureAttr ta, tb;
  ta.textureId = 3;
  tb.textureId = 5;
  tb.vOffset = 10.0f;
  NodeId a = t.cone(Vec3(0), Vec3(0, 2, 0), 0.5f, 0.5f, ta);
  NodeId c = t.cone(Vec3(0, 2, 0), Vec3(0, 4, 0), 0.5f, 0.5f, tb);
  CompiledBlob b = compile(t, t.blend(std::vector<NodeId>{a, c}));
  Sample low = b.sample(Vec3(0.5f, 1.0f, 0));
  REQUIRE(low.attributes.textureCount == 1);
  CHECK(low.attributes.textureIds[0] == 3);
  CHECK(low.attributes.uv.y == Approx(1.0f));  // v = distance along the axis
  Sample joint = b.sample(Vec3(0.5f, 2.0f, 0));
  REQUIRE(joint.attributes.textureCount == 2);
  CHECK(joint.attributes.textureWeights[0] == Approx(0.5f));
  CHECK(joint.attributes.uv.y == Approx(0.5f * (2.0f + 10.0f)));  // Σ f·v / Σ f
  CHECK(glm::dot(-joint.gradient, Vec3(1, 0, 0)) > 0.0f);  // outward normal points away
}

TEST_CASE("CompiledBlob::intersect", "[blobtree]") {
  uint64_t seed = GENERATE(21u, 22u);
  INFO("seed " << seed);
  auto&& [rng, t, root, b] = SeededScene(seed);
  Box3 box = b.bounds();
  float size = glm::length(box.size());
  SECTION("every hit lies on the surface within 1e-4 of the model size and is the first crossing") {
    int hits = 0;
    for (int i = 0; i < 400; ++i) {
      Vec3 o = box.center() + glm::normalize(randomIn(rng, Vec3(-1), Vec3(1))) * size;
      Vec3 target = randomIn(rng, box.lo * 0.5f, box.hi * 0.5f);
      Ray ray{o, target - o};
      auto hit = b.intersect(ray, 0.0f, 10.0f);
      if (!hit) continue;
      ++hits;
      Sample s = b.sample(hit->point);
      CHECK(std::abs(s.value - kIso) / glm::length(s.gradient) < 1e-4f * size);
      CHECK(glm::length(hit->point - (o + hit->t * ray.direction)) < 1e-4f * size);
      CHECK(glm::dot(hit->normal, ray.direction) < 0.0f);  // entering from outside
      // No crossing before the hit: sample the ray densely.
      for (int k = 1; k < 200; ++k) CHECK(b.value(o + (hit->t * float(k) / 200.0f) * ray.direction) < kIso);
    }
    CHECK(hits > 100);
  }
  SECTION("per-cell intersection over surface cells finds the same first hit") {
    CellSet cells = b.surfaceCells(0.1f);
    REQUIRE(!cells.cells.empty());
    for (const Cell& c : cells.cells) CHECK(c.bounds.contains(kIso));
    for (int i = 0; i < 60; ++i) {
      Vec3 o = box.center() + glm::normalize(randomIn(rng, Vec3(-1), Vec3(1))) * size;
      Ray ray{o, randomIn(rng, box.lo * 0.5f, box.hi * 0.5f) - o};
      auto hit = b.intersect(ray, 0.0f, 10.0f);
      std::optional<Hit> best;
      for (const Cell& c : cells.cells) {
        auto h = b.intersectCell(c, ray, 0.0f, 10.0f);
        if (h && (!best || h->t < best->t)) best = h;
      }
      REQUIRE(bool(hit) == bool(best));
      if (hit) CHECK(glm::length(hit->point - best->point) < 1e-4f * size);
    }
  }
}

TEST_CASE("CompiledBlob::intersect thin cone", "[blobtree]") {
  // A cone of radius 0.01 inside a model of size 10 is never stepped over.
  BlobTree t;
  NodeId big1 = t.point(Vec3(-4, -4, -4), 1.0f), big2 = t.point(Vec3(4, 4, 4), 1.0f);
  NodeId thin = t.cone(Vec3(-3, 0, 0), Vec3(3, 0, 0), 0.01f, 0.01f);
  CompiledBlob b = compile(t, t.blend(std::vector<NodeId>{big1, big2, thin}));
  Rng rng(5);
  for (int i = 0; i < 200; ++i) {
    float x = float(rng.uniform(-2.9, 2.9));
    Vec3 target(x, float(rng.uniform(-0.008, 0.008)), 0.0f);
    Vec3 o = target + glm::normalize(randomIn(rng, Vec3(-1), Vec3(1)) + Vec3(0, 0, 3)) * 9.0f;
    auto hit = b.intersect(Ray{o, target - o}, 0.0f, 2.0f);
    REQUIRE(hit);
    CHECK(std::abs(hit->point.y) < 0.011f);
    CHECK(std::abs(hit->point.z) < 0.011f);
  }
}

TEST_CASE("CompiledBlob::surfaceCells", "[blobtree]") {
  BlobTree t;
  CompiledBlob b = compile(t, t.point(Vec3(0.1f, 0.2f, 0.3f), 1.0f));
  CellSet coarse = b.surfaceCells(0.1f), fine = b.surfaceCells(0.05f);
  CHECK(coarse.cellSize <= 0.1f);
  CHECK(fine.cellSize == Approx(coarse.cellSize * 0.5f));
  // Work follows the area: halving the cell size multiplies the count by about 4.
  double ratio = double(fine.cells.size()) / double(coarse.cells.size());
  CHECK(ratio > 3.2);
  CHECK(ratio < 4.8);
  // Every surface point lies in some cell; each cell lists the primitive.
  for (const Cell& c : coarse.cells) {
    CHECK(c.primitiveCount == 1);
    CHECK(c.box.size().x == Approx(coarse.cellSize));
  }
  Rng rng(3);
  for (int i = 0; i < 300; ++i) {
    Vec3 p = Vec3(0.1f, 0.2f, 0.3f) + glm::normalize(randomIn(rng, Vec3(-1), Vec3(1)));
    bool found = false;
    for (const Cell& c : coarse.cells) found = found || c.box.contains(p);
    CHECK(found);
  }
  SECTION("exact cell size; no Lipschitz bounds or primitive lists when not asked for") {
    SurfaceCellOptions o;
    o.exactCellSize = true;
    o.lipschitz = false;
    o.primitiveLists = false;
    CellSet exact = b.surfaceCells(0.0731f, o);
    CHECK(exact.cellSize == 0.0731f);
    CHECK(exact.primitives.empty());
    REQUIRE(!exact.cells.empty());
    for (const Cell& c : exact.cells) {
      CHECK(c.lipschitz == 0.0f);
      CHECK(c.primitiveCount == 0);
      CHECK(c.box.size().x == Approx(0.0731f));
    }
    double exactRatio = double(exact.cells.size()) / double(coarse.cells.size());
    double expected = std::pow(double(coarse.cellSize) / 0.0731, 2.0);
    CHECK(exactRatio == Approx(expected).epsilon(0.2));
  }
  SECTION("adjacent cells share their faces bit for bit (no cracks between them)") {
    // A sphere off the grid's center and one centred on it (its faces pass through 0, where a
    // crack of one ulp once let a ray with a direction component of 1e-16 miss every cell).
    BlobTree t2;
    CompiledBlob centred = compile(t2, t2.point(Vec3(0.0f), 0.37f));
    for (const CellSet& set : {b.surfaceCells(0.0371f), centred.surfaceCells(0.0173f)}) {
      std::map<std::array<int32_t, 3>, const Cell*> byIndex;
      for (const Cell& c : set.cells) byIndex[c.index] = &c;
      int shared = 0, cracked = 0;
      for (const Cell& c : set.cells)
        for (int axis = 0; axis < 3; ++axis) {
          std::array<int32_t, 3> next = c.index;
          ++next[size_t(axis)];
          auto it = byIndex.find(next);
          if (it == byIndex.end()) continue;
          ++shared;
          if (c.box.hi[axis] != it->second->box.lo[axis]) ++cracked;
        }
      INFO(set.cells.size() << " cells, " << shared << " shared faces");
      CHECK(shared > 100);
      CHECK(cracked == 0);
    }
  }
  // Deterministic.
  CellSet again = b.surfaceCells(0.1f);
  REQUIRE(again.cells.size() == coarse.cells.size());
  for (size_t i = 0; i < again.cells.size(); ++i) CHECK(again.cells[i].index == coarse.cells[i].index);
}

TEST_CASE("CompiledBlob::surfaceCells under a root with a point grid", "[blobtree]") {
  // Roots of many children (a point grid over them): the search lists the root's children
  // once for a cube inside one grid cell and filters that list for the cubes below it. The
  // cells, their order and their bounds must be those of a plain search that asks
  // valueBounds at every cube.
  Rng rng(11);
  BlobTree t;
  std::vector<NodeId> cones;
  const NodeId blend = branching(t, rng, 150, &cones);
  const NodeId united = t.unite(cones);
  PcmParams pp;
  const NodeId pressed = t.pcm(cones, pp);
  SurfaceCellOptions o;
  o.exactCellSize = true;
  o.lipschitz = false;
  o.primitiveLists = false;
  const float cell = 0.05f;
  for (NodeId root : {blend, united, pressed}) {
    CompiledBlob b = compile(t, root);
    CellSet cells = b.surfaceCells(cell, o);
    const Box3 rb = b.bounds();
    float E = std::max(rb.size().x, std::max(rb.size().y, rb.size().z)) * 1.0001f + 1e-20f;
    const int depth = int(std::ceil(std::log2(E / cell)));
    E = cell * float(1 << depth);
    REQUIRE(cells.origin == rb.center() - Vec3(0.5f * E));
    std::vector<std::pair<std::array<int32_t, 3>, Interval>> ref;
    std::function<void(std::array<int32_t, 3>, int)> visit = [&](std::array<int32_t, 3> idx, int level) {
      const float e = E / float(1 << level);
      const Box3 box{cells.origin + Vec3(float(idx[0]), float(idx[1]), float(idx[2])) * e,
                     cells.origin + Vec3(float(idx[0] + 1), float(idx[1] + 1), float(idx[2] + 1)) * e};
      const Interval iv = b.valueBounds(box);
      if (!iv.contains(kIso)) return;
      if (level == depth) {
        ref.push_back({idx, iv});
        return;
      }
      for (int c = 0; c < 8; ++c)
        visit({idx[0] * 2 + (c & 1), idx[1] * 2 + ((c >> 1) & 1), idx[2] * 2 + ((c >> 2) & 1)}, level + 1);
    };
    visit({0, 0, 0}, 0);
    INFO(ref.size() << " cells");
    REQUIRE(ref.size() > 5000);
    REQUIRE(cells.cells.size() == ref.size());
    size_t differ = 0;
    for (size_t i = 0; i < ref.size(); ++i)
      differ += cells.cells[i].index != ref[i].first ||
                std::memcmp(&cells.cells[i].bounds, &ref[i].second, sizeof(Interval)) != 0;
    CHECK(differ == 0);
    // indicesOnly: the same cells' indices in the same order, and nothing else.
    SurfaceCellOptions only = o;
    only.indicesOnly = true;
    CellSet indices = b.surfaceCells(cell, only);
    CHECK(indices.cells.empty());
    REQUIRE(indices.indices.size() == ref.size());
    differ = 0;
    for (size_t i = 0; i < ref.size(); ++i)
      differ += indices.indices[i] != glm::ivec3(ref[i].first[0], ref[i].first[1], ref[i].first[2]);
    CHECK(differ == 0);
  }
  SurfaceCellOptions bad;
  bad.indicesOnly = true;  // with the default lipschitz and primitive lists
  CHECK_THROWS_AS(compile(t, blend).surfaceCells(cell, bad), std::invalid_argument);
}

TEST_CASE("CellSet::tapes (pruned tapes per surface cell)", "[blobtree]") {
  SurfaceCellOptions pruned;
  pruned.prunedTapes = true;
  SECTION("a pruned tape evaluates to the full tape's value at points of its cell") {
    for (uint64_t seed : {5u, 17u, 29u}) {
      SeededScene s(seed);
      CellSet cells = s.blob.surfaceCells(0.06f, pruned);
      REQUIRE(cells.cells.size() > 1000);
      REQUIRE(!cells.tapes.empty());
      CHECK(cells.tapes.size() < cells.cells.size() / 4);  // neighbours share tapes
      Rng rng(seed + 1);
      size_t exact = 0, compared = 0, prunedNodes = 0;
      float worst = 0.0f;
      for (size_t ci = 0; ci < cells.cells.size(); ci += 7) {
        const Cell& c = cells.cells[ci];
        REQUIRE(c.tape < cells.tapes.size());
        const CompiledBlob& p = cells.tapeOf(c, s.blob);
        prunedNodes += p.nodeCount();
        Vec3 pts[8];
        float full[8], mine[8];
        for (Vec3& q : pts) q = randomIn(rng, c.box.lo, c.box.hi);
        s.blob.values(pts, std::span<float>(full, 8));
        p.values(pts, std::span<float>(mine, 8));
        for (int i = 0; i < 8; ++i) {
          INFO("seed " << seed << " cell " << ci << " point " << i);
          // The same terms; only a grid node's child order may differ between the batch and
          // the cell, which changes a sum by its rounding.
          CHECK(mine[i] == Approx(full[i]).margin(1e-6));
          worst = std::max(worst, std::abs(mine[i] - full[i]));
          exact += mine[i] == full[i];
          ++compared;
          CHECK(p.value(pts[i]) == Approx(s.blob.value(pts[i])).margin(1e-6));
        }
        Vec3 q = randomIn(rng, c.box.lo, c.box.hi);
        Sample a = s.blob.sample(q), b = p.sample(q);
        CHECK(b.value == Approx(a.value).margin(1e-6));
        CHECK(glm::length(b.gradient - a.gradient) <= 1e-4f * std::max(1.0f, glm::length(a.gradient)));
        CHECK(b.attributes.textureCount == a.attributes.textureCount);
        CHECK(p.valueBounds(c.box).lo <= a.value);
        CHECK(p.valueBounds(c.box).hi >= a.value);
      }
      INFO("seed " << seed << ": " << exact << " of " << compared << " bit-identical, worst " << worst);
      CHECK(exact * 10 >= compared * 9);
      // The walk is shorter: on average a cell's tape is a small part of the whole.
      size_t sampled = (cells.cells.size() + 6) / 7;
      CHECK(double(prunedNodes) / double(sampled) < 0.25 * double(s.blob.nodeCount()));
    }
  }
  SECTION("pruning removes the nodes that cannot reach a cell (counts)") {
    // Three separate balls in a sum blend, minus a box cutter around the third:
    // 6 nodes. Near the first ball only the ball is left (blend of one = the ball; the
    // cutter cannot reach and the ball's field lies in [0, 1], so the difference goes too).
    BlobTree t;
    NodeId a = t.point(Vec3(0, 0, 0), 1.0f), b = t.point(Vec3(10, 0, 0), 1.0f), c = t.point(Vec3(20, 0, 0), 1.0f);
    NodeId sum = t.blend(std::vector<NodeId>{a, b, c});
    NodeId cut = t.box(Vec3(19.5f, -5, -5), Vec3(25, 5, 5), 0.01f);
    CompiledBlob blob = compile(t, t.difference(sum, cut));
    REQUIRE(blob.nodeCount() == 6);
    CellSet cells = blob.surfaceCells(0.1f, pruned);
    REQUIRE(!cells.cells.empty());
    size_t nearA = 0, nearC = 0;
    Rng rng(8);
    for (const Cell& cell : cells.cells) {
      const CompiledBlob& p = cells.tapeOf(cell, blob);
      Vec3 m = cell.box.center();
      if (m.x < 5.0f) {
        ++nearA;
        CHECK(p.nodeCount() == 1);
      } else if (m.x > 15.0f && cell.box.hi.x < 19.49f) {
        CHECK(p.nodeCount() == 1);  // the cutter (support from x = 19.495) cannot reach: ball c alone
      } else if (m.x > 15.0f && cell.box.hi.x > 19.5f) {
        ++nearC;
        CHECK(p.nodeCount() == 3);  // difference(ball c, cutter)
      }
      Vec3 pts[8];
      float full[8], mine[8];
      for (Vec3& q : pts) q = randomIn(rng, cell.box.lo, cell.box.hi);
      blob.values(pts, std::span<float>(full, 8));
      p.values(pts, std::span<float>(mine, 8));
      for (int i = 0; i < 8; ++i) CHECK(mine[i] == full[i]);  // no grid node: bit for bit
    }
    CHECK(nearA > 100);
    CHECK(nearC > 20);
    // Tapes are shared: all cells of ball a have the same one.
    CHECK(cells.tapes.size() <= 8);
  }
  SECTION("off by default") {
    SeededScene s(5);
    CellSet cells = s.blob.surfaceCells(0.1f);
    CHECK(cells.tapes.empty());
    for (const Cell& c : cells.cells) CHECK(c.tape == Cell::kNoTape);
  }
}

TEST_CASE("CompiledBlob::sample contact gradient", "[blobtree]") {
  // Two PCM cones meeting at a fork: in the propagation band, Attributes::contact is
  // 1 − (c − f_j)/w of the weaker cone, and contactGradient is its gradient ∇f_j / w.
  const uint64_t seed = 11;
  INFO("seed " << seed);
  BlobTree t;
  PcmParams pp;
  pp.width = 0.25f;
  NodeId a = t.cone(Vec3(0, 0, 0), Vec3(0, 1, 0), 0.12f, 0.10f);
  NodeId b = t.cone(Vec3(0, 0.05f, 0), Vec3(0.6f, 0.8f, 0.1f), 0.09f, 0.07f);
  CompiledBlob blob = compile(t, t.pcm(a, b, pp));
  Rng rng(seed);
  int inBand = 0;
  for (int i = 0; i < 4000 && inBand < 200; ++i) {
    const Vec3 p = randomIn(rng, Vec3(-0.2f, 0.0f, -0.2f), Vec3(0.4f, 0.6f, 0.2f));
    const Sample s = blob.sample(p);
    const float c = s.attributes.contact;
    if (!(c > 0.05f && c < 0.95f)) {
      if (c == 0.0f) CHECK(s.attributes.contactGradient == Vec3(0.0f));
      continue;
    }
    // Stay away from where the weaker cone changes (both contacts near): finite differences
    // must not straddle the switch.
    const float h = 1e-3f;
    Vec3 fd;
    bool smooth = true;
    for (int k = 0; k < 3; ++k) {
      Vec3 e(0.0f);
      e[k] = h;
      const float cp = blob.sample(p + e).attributes.contact, cm = blob.sample(p - e).attributes.contact;
      fd[k] = (cp - cm) / (2 * h);
      const float c2 = (cp + cm) / 2;
      smooth = smooth && std::abs(c2 - c) < 1e-3f;
    }
    if (!smooth) continue;
    ++inBand;
    INFO("p " << p.x << "," << p.y << "," << p.z << " contact " << c);
    CHECK(glm::length(s.attributes.contactGradient - fd) < 0.02f * std::max(1.0f, glm::length(fd)));
    CHECK(glm::length(s.attributes.contactGradient) > 0.0f);
  }
  CHECK(inBand >= 50);
}

TEST_CASE("CompiledBlob::valuesAndGradients", "[blobtree]") {
  // The batched value-and-gradient evaluator against sample() (the scalar evaluator) on the
  // scene of every operator, and on unions, intersections and a PCM of three children.
  uint64_t seed = GENERATE(21u, 22u, 23u);
  INFO("seed " << seed);
  auto&& [rng, t, root, sceneBlob] = SeededScene(seed);
  NodeId a = t.point(Vec3(0, 0, 0), 0.6f), c = t.segment(Vec3(0.5f, 0, 0), Vec3(0.5f, 1, 0), 0.3f);
  NodeId d = t.cone(Vec3(-0.4f, -0.3f, 0), Vec3(0.2f, 0.9f, 0.3f), 0.35f, 0.2f);
  NodeId extra = t.blend(std::vector<NodeId>{t.unite(std::vector<NodeId>{a, c}), t.translate(t.intersect(std::vector<NodeId>{a, d}), Vec3(2, 0, 0)),
                                             t.translate(t.pcm(std::vector<NodeId>{a, c, d}), Vec3(0, 2, 0))});
  for (const CompiledBlob& b : {sceneBlob, compile(t, extra)}) {
    Box3 box = b.bounds();
    std::vector<Vec3> pts;
    for (int k = 0; k < 20; ++k) {  // coherent clusters (one grid cell) and scattered points
      Vec3 ctr = randomIn(rng, box.lo, box.hi);
      for (int i = 0; i < 50; ++i) pts.push_back(ctr + randomIn(rng, Vec3(-0.05f), Vec3(0.05f)));
    }
    for (int i = 0; i < 1000; ++i) pts.push_back(randomIn(rng, box.lo, box.hi));
    std::vector<float> v(pts.size());
    std::vector<Vec3> g(pts.size());
    b.valuesAndGradients(pts, v, g);
    int nonzero = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
      Sample s = b.sample(pts[i]);
      INFO("p = (" << pts[i].x << ", " << pts[i].y << ", " << pts[i].z << ")");
      CHECK(v[i] == Approx(s.value).margin(1e-5));
      CHECK(glm::length(g[i] - s.gradient) <= 1e-4f * (1.0f + glm::length(s.gradient)));
      nonzero += v[i] > 0.0f;
    }
    CHECK(nonzero > 100);  // the points reach the field, not just empty space
  }
}

/// Four groups of three bent cones, alternately under a PCM and a sum, united: fewer than
/// kBvhMinChildren children per node, so the child order never depends on a batch's box.
struct BentGroups {
  Rng rng;
  BlobTree t;
  std::vector<NodeId> bends;
  std::vector<std::pair<Vec3, Vec3>> axes;
  CompiledBlob blob;

  explicit BentGroups(uint64_t seed) : rng(seed) {
    std::vector<NodeId> groups;
    for (int g = 0; g < 4; ++g) {
      std::vector<NodeId> bent;
      Vec3 base = randomIn(rng, Vec3(-1.0f), Vec3(1.0f));
      for (int k = 0; k < 3; ++k) {
        Vec3 dir = glm::normalize(randomIn(rng, Vec3(-1.0f), Vec3(1.0f)));
        Vec3 end = base + float(rng.uniform(0.6, 1.0)) * dir;
        NodeId cone = t.cone(base, end, 0.12f, 0.08f);
        axes.emplace_back(base, end);
        Vec3 side = glm::cross(dir, glm::normalize(randomIn(rng, Vec3(-1.0f), Vec3(1.0f))));
        bent.push_back(t.bend(cone, base, end, float(rng.uniform(0.02, 0.06)), side));
        bends.push_back(bent.back());
      }
      groups.push_back(g % 2 == 0 ? t.pcm(bent) : t.blend(bent));
    }
    blob = compile(t, t.unite(groups));
  }

  /// 8 samples of a ray segment, as the tracer takes them, from near a random cone's axis
  /// and long enough to leave a bend box.
  std::vector<Vec3> segment() {
    const auto& [a0, a1] = axes[rng.below(uint32_t(axes.size()))];
    Vec3 o = glm::mix(a0, a1, float(rng.uniform())) + randomIn(rng, Vec3(-0.2f), Vec3(0.2f));
    Vec3 d = glm::normalize(randomIn(rng, Vec3(-1.0f), Vec3(1.0f))) * float(rng.uniform(0.05, 0.6));
    std::vector<Vec3> pts;
    for (int i = 0; i < 8; ++i) pts.push_back(o + (float(i) / 7.0f) * d);
    return pts;
  }
};

TEST_CASE("CompiledBlob::values under bends (batches straddling a bend's support)", "[blobtree]") {
  // The batched evaluator maps through a bend only the points inside the bend's support box
  // and gives the others 0. Bent cones under a PCM, a union and a sum: a point evaluated in
  // an 8-point batch that straddles bend boxes gets the same bits as the point evaluated
  // alone, and the scalar evaluator's value within 1e-6.
  uint64_t seed = GENERATE(31u, 32u, 33u);
  INFO("seed " << seed);
  BentGroups scene(seed);
  const BlobTree& t = scene.t;
  const std::vector<NodeId>& bends = scene.bends;
  const CompiledBlob& b = scene.blob;
  int straddling = 0, nonzero = 0;
  for (int k = 0; k < 400; ++k) {
    const std::vector<Vec3> pts = scene.segment();
    std::vector<float> out(8);
    b.values(pts, out);
    Box3 batch;
    for (const Vec3& p : pts) batch.extend(p);
    bool straddles = false, positive = false;
    for (NodeId id : bends) {
      const Box3& nb = t.node(id).bounds;
      if (!nb.overlaps(batch)) continue;
      for (const Vec3& p : pts) straddles = straddles || !nb.contains(p);
    }
    for (int i = 0; i < 8; ++i) {
      float alone = 0.0f;
      b.values(std::span<const Vec3>(&pts[size_t(i)], 1), std::span<float>(&alone, 1));
      INFO("p = (" << pts[size_t(i)].x << ", " << pts[size_t(i)].y << ", " << pts[size_t(i)].z << ")");
      CHECK(out[size_t(i)] == alone);
      CHECK(out[size_t(i)] == Approx(b.value(pts[size_t(i)])).margin(1e-6));
      positive = positive || out[size_t(i)] > 0.0f;
    }
    straddling += straddles && positive;
    nonzero += positive;
  }
  CHECK(straddling > 40);  // batches reaching the field with points inside and outside a bend's box
  CHECK(nonzero > 100);
}

TEST_CASE("CompiledBlob::values: a batch of 8 has the bits of the same points in a longer batch", "[blobtree]") {
  // Batches of at most 8 points (the tracer's) walk the tape at a fixed width of 8 lanes,
  // longer ones at the block width, and a bend whose batch holds at most four real points
  // maps only four lanes. The same points padded with copies of the last one (the same box,
  // so the same culling and child order) must get the same bits either way: 1 to 8 points of
  // ray segments through the bent groups and through the scene of every operator.
  uint64_t seed = GENERATE(41u, 42u);
  INFO("seed " << seed);
  BentGroups scene(seed);
  auto&& [rng, t, root, every] = SeededScene(seed);
  int compared = 0, positive = 0;
  for (const CompiledBlob* b : {&scene.blob, &every}) {
    const Box3 box = b->bounds();
    for (int k = 0; k < 600; ++k) {
      std::vector<Vec3> pts = scene.segment();
      if (b == &every) {  // a segment of the whole scene's box
        const Vec3 o = randomIn(rng, box.lo, box.hi), d = randomIn(rng, Vec3(-0.3f), Vec3(0.3f));
        for (int i = 0; i < 8; ++i) pts[size_t(i)] = o + (float(i) / 7.0f) * d;
      }
      pts.resize(size_t(1 + k % 8));  // 1 to 8 real points
      std::vector<Vec3> longer = pts;
      longer.resize(24, pts.back());  // a block-width walk (more than 8 points), same box
      std::vector<float> fixed(pts.size()), block(longer.size());
      b->values(pts, fixed);
      b->values(longer, block);
      for (size_t i = 0; i < pts.size(); ++i) {
        INFO("p = (" << pts[i].x << ", " << pts[i].y << ", " << pts[i].z << "), " << pts.size() << " points");
        CHECK(std::bit_cast<uint32_t>(fixed[i]) == std::bit_cast<uint32_t>(block[i]));
        ++compared;
        positive += fixed[i] > 0.0f;
      }
    }
  }
  CHECK(compared == 2 * 2700);
  CHECK(positive > 500);  // the points reach the field, not just empty space
}

TEST_CASE("evalBatch: the AVX2 walk has the bits of the baseline walk", "[blobtree]") {
  // The batch walk is compiled for the x86-64-v2 baseline (SSE) and for AVX2 and picked at
  // run time (blobtree/detail/batch_eval.cpp); the two must agree to the bit, or an image
  // would depend on the CPU. Random batches of 1 to 8 points (the tracer's fixed width) and
  // of 9 to 300 (the block width: the polygonizer, the free sub-cells' 64 centres), as ray
  // samples and as scattered points, through bent cones under PCM and sum groups and
  // through the scene of every operator, each evaluated with both walks.
  using detail::BatchIsa;
  if (!detail::batchIsaSupported(BatchIsa::Avx2)) {
    WARN("this CPU has no AVX2: the AVX2 walk is not compared");
    return;
  }
  struct Restore {
    BatchIsa isa = detail::batchIsa();
    ~Restore() { detail::setBatchIsa(isa); }
  } restore;
  uint64_t seed = GENERATE(51u, 52u);
  INFO("seed " << seed);
  BentGroups scene(seed);
  auto&& [rng, t, root, every] = SeededScene(seed);
  int compared = 0, positive = 0;
  for (const CompiledBlob* b : {&scene.blob, &every}) {
    const Box3 box = b->bounds();
    for (int k = 0; k < 400; ++k) {
      std::vector<Vec3> pts;
      const size_t count = k % 2 == 0 ? size_t(1 + k % 8) : size_t(9 + rng.below(292));
      if (k % 4 < 2 && b == &scene.blob) {  // ray samples near a bent cone, as the tracer takes them
        while (pts.size() < count) {
          const std::vector<Vec3> seg = scene.segment();
          pts.insert(pts.end(), seg.begin(), seg.end());
        }
        pts.resize(count);
      } else {  // scattered points of a random box inside the scene's
        const Vec3 c = randomIn(rng, box.lo, box.hi), h = randomIn(rng, Vec3(0.01f), Vec3(0.5f));
        for (size_t i = 0; i < count; ++i) pts.push_back(c + randomIn(rng, -h, h));
      }
      std::vector<float> base(count), avx(count);
      detail::setBatchIsa(BatchIsa::Baseline);
      b->values(pts, base);
      REQUIRE(detail::setBatchIsa(BatchIsa::Avx2) == BatchIsa::Baseline);
      b->values(pts, avx);
      REQUIRE(detail::batchIsa() == BatchIsa::Avx2);
      for (size_t i = 0; i < count; ++i) {
        INFO("p = (" << pts[i].x << ", " << pts[i].y << ", " << pts[i].z << "), " << count << " points");
        CHECK(std::bit_cast<uint32_t>(base[i]) == std::bit_cast<uint32_t>(avx[i]));
        ++compared;
        positive += base[i] > 0.0f;
      }
    }
  }
  CHECK(compared > 20000);
  CHECK(positive > 2000);  // the points reach the field, not just empty space
}
