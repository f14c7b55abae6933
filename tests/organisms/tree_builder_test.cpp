#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <vector>

#include "blobtree/compiled.h"
#include "core/rng.h"
#include "organisms/tree_builder.h"
#include "tests/organisms/internode.h"

using namespace sprig;
using namespace sprig::organisms;
using lsystem::Skeleton;
using test::seg;

namespace {

// The tree's field through the reference evaluator (tiny test trees).
struct Field {
  TreeBlob blob;
  float value(Vec3 p) const { return blob.tree.value(blob.root, p); }
};

Field compiled(TreeBlob t) { return Field{std::move(t)}; }

// Distance from `origin` along unit `dir` to the outermost F = 0.5 crossing within maxDist.
double surfaceDistance(const Field& blob, Vec3 origin, Vec3 dir, double maxDist) {
  const int kSteps = 400;
  double prev = maxDist;
  for (int i = kSteps - 1; i >= 0; --i) {
    const double t = maxDist * i / kSteps;
    if (blob.value(origin + float(t) * dir) > 0.5f) {
      double lo = t, hi = prev;  // F(lo) > 0.5 >= F(hi)
      for (int k = 0; k < 40; ++k) {
        const double mid = 0.5 * (lo + hi);
        (blob.value(origin + float(mid) * dir) > 0.5f ? lo : hi) = mid;
      }
      return 0.5 * (lo + hi);
    }
    prev = t;
  }
  return 0.0;
}

// Largest relative deviation of the surface radius from r over heights [y0, y1] on a
// vertical axis through the origin (measured along +X and +Z).
double maxRadiusDeviation(const Field& blob, double r, double y0, double y1) {
  double worst = 0;
  for (int i = 0; i <= 80; ++i) {
    const float y = float(y0 + (y1 - y0) * i / 80.0);
    for (Vec3 dir : {Vec3(1, 0, 0), Vec3(0, 0, 1)}) {
      const double d = surfaceDistance(blob, Vec3(0, y, 0), dir, 4 * r);
      worst = std::max(worst, std::abs(d / r - 1.0));
    }
  }
  return worst;
}


// A basal internode along +Y ending at P = (0,1,0) and two branches in the XY plane at
// ±angle from the vertical, each followed by a second internode.
Skeleton yJunction(double rA, double rB, double angleDeg) {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, rA, rA, -1, 0));
  const double a = radians(angleDeg);
  const DVec3 d0(std::sin(a), std::cos(a), 0), d1(-std::sin(a), std::cos(a), 0), p(0, 1, 0);
  sk.internodes.push_back(seg(p, p + d0, rB, rB, 0, 0));
  sk.internodes.push_back(seg(p, p + d1, rB, rB, 0, 1));
  return sk;
}

}  // namespace

TEST_CASE("buildTreeBlob::one-child joint (Eq. 4)", "[organisms]") {
  Skeleton sk;
  const double r = 0.1;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, r, r, -1, 0));
  sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, r, r, 0, 0));
  TreeOptions opt;
  opt.tips = TipStyle::Hemisphere;
  const double withOffset = maxRadiusDeviation(compiled(buildTreeBlob(sk, opt)), r, 0.5, 1.5);
  opt.basalOffset = false;
  const double without = maxRadiusDeviation(compiled(buildTreeBlob(sk, opt)), r, 0.5, 1.5);
  std::printf("one-child joint: max radius deviation %.2f%% with δA = 1.75 r_B, %.2f%% without\n",
              100 * withOffset, 100 * without);
  CHECK(withOffset < 0.03);
  CHECK(without > 0.10);
}

TEST_CASE("buildTreeBlob::controlled blending", "[organisms]") {
  // Two separate roots crossing at right angles at (0, 0.5, 0): not neighbours.
  Skeleton sk;
  const double r = 0.1;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, r, r, -1, 0));
  sk.internodes.push_back(seg({-0.5, 0.5, 0}, {0.5, 0.5, 0}, r, r, -1, 0));
  TreeOptions opt;
  opt.tips = TipStyle::Hemisphere;
  const auto uni = compiled(buildTreeBlob(sk, opt));
  opt.controlledBlend = false;
  const auto all = compiled(buildTreeBlob(sk, opt));
  // In the corner between the two axes, at equal distance from both: the union stays
  // outside (a crease), the blend fills the corner.
  const float s = float(1.1 * r);
  const Vec3 corner(s, 0.5f + s, 0);
  CHECK(uni.value(corner) < 0.5f);
  CHECK(all.value(corner) > 0.5f);
  // Away from the corner both agree (each internode alone).
  CHECK(uni.value({0, 0.2f, float(0.9 * r)}) == Approx(all.value({0, 0.2f, float(0.9 * r)})).margin(1e-6));
}

TEST_CASE("buildTreeBlob::PCM junction (Eq. 5-8)", "[organisms]") {
  const double rA = 0.1, rB = 0.08;
  Skeleton sk = yJunction(rA, rB, 35);
  TreeOptions opt;
  opt.tips = TipStyle::Hemisphere;
  const auto smooth = compiled(buildTreeBlob(sk, opt));
  opt.junctions = JunctionModel::Pcm;
  const auto pcm = compiled(buildTreeBlob(sk, opt));
  TreeOptions noOffset = opt;
  noOffset.branchOffset = false;
  const auto pcmNoOffset = compiled(buildTreeBlob(sk, noOffset));
  TreeOptions noBulge = opt;
  noBulge.pcmBulge = 0;
  const auto contact = compiled(buildTreeBlob(sk, noBulge));

  SECTION("no bulge below the junction with the branch offset (Fig. 12)") {
    // Largest radius of the basal internode from well below P up to P, across and in
    // the branching plane.
    auto widest = [&](const Field& b) {
      double w = 0;
      for (int i = 0; i <= 50; ++i) {
        const float y = float(0.5 + 0.5 * i / 50.0);
        w = std::max(w, surfaceDistance(b, {0, y, 0}, {0, 0, 1}, 0.5));
      }
      return w / rA - 1.0;
    };
    const double dev = widest(pcm), devNo = widest(pcmNoOffset), devSmooth = widest(smooth);
    std::printf("Y junction below P: bulge %.2f%% PCM with δB (Eq. 7), %.2f%% PCM without, %.2f%% smooth\n",
                100 * dev, 100 * devNo, 100 * devSmooth);
    CHECK(dev < 0.01);
    CHECK(devNo > 0.03);
    CHECK(devSmooth > 0.05);
  }
  SECTION("a ridge along the seam between the branches") {
    // Cross-sections of the crotch at heights above P, seen along Z (normal to the branch
    // plane): Z(x) is the surface's distance from the branch plane at offset x from the
    // seam x = 0. The bare contact (no bulge) meets in a valley at the seam; the PCM bulge
    // raises a crest there (the branch bark ridge), well outside the bare contact.
    auto z = [&](const Field& b, double x, double y) {
      return surfaceDistance(b, {float(x), float(y), 0}, {0, 0, 1}, 0.5);
    };
    for (double y = 1.04; y <= 1.081; y += 0.02) {
      const double seamPcm = z(pcm, 0, y), seamContact = z(contact, 0, y), seamSmooth = z(smooth, 0, y);
      std::printf("seam at y = P + %.2f: PCM %.4f, contact without bulge %.4f, smooth %.4f; PCM at x = 0.04: %.4f\n",
                  y - 1, seamPcm, seamContact, seamSmooth, z(pcm, 0.04, y));
      // the ridge stands out of the bare contact by at least 10% of the branch radius
      CHECK(seamPcm - seamContact > 0.1 * rB);
      // a crest: the seam is higher than the surface beside it, where the contact has a valley
      CHECK(seamPcm > z(pcm, 0.04, y));
      CHECK(seamContact < z(contact, 0.02, y));
      // and still inside the smooth blend's fillet (PCM <= summation, see docs/TREES.md)
      for (double x = 0; x <= 0.061; x += 0.01) CHECK(z(pcm, x, y) <= z(smooth, x, y) + 1e-4);
    }
  }
}

TEST_CASE("buildTreeBlob::bend keeps both endpoints (§3.6)", "[organisms]") {
  const double r = 0.05;
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.1, 0.1, -1, 0));
  const DVec3 p(0, 1, 0), d = glm::normalize(DVec3(1, 1, 0));
  sk.internodes.push_back(seg(p, p + d, r, r, 0, 1));
  TreeOptions opt;
  opt.tips = TipStyle::Hemisphere;
  opt.bends.angleDeg = 30;
  TreeBlob blob = buildTreeBlob(sk, opt);
  const ConePart& part = blob.plan.parts[1];
  REQUIRE(part.bendAngle == Approx(radians(30)));
  const blobtree::NodeId bent = blob.partNodes[1];
  auto f = [&](DVec3 q) { return blob.tree.value(bent, Vec3(q)); };
  // Both endpoints stay inside, and the surface still reaches one radius past each end
  // along the arc's end tangents (the cap of the bent cone).
  CHECK(f(part.start) > 0.5f);
  CHECK(f(part.end) > 0.5f);
  const DVec3 n = part.bendToward;
  const double th = part.bendAngle;
  const DVec3 tStart = std::cos(th) * d + std::sin(th) * n, tEnd = std::cos(th) * d - std::sin(th) * n;
  CHECK(f(part.start - 0.9 * r * tStart) > 0.5f);
  CHECK(f(part.end + 0.9 * r * tEnd) > 0.5f);
  CHECK(f(part.end + 1.1 * r * tEnd) < 0.5f);
  // The middle has moved off the chord by the sagitta L/2·tan(θ/2).
  const double L = part.length(), sag = 0.5 * L * std::tan(th / 2);
  const DVec3 mid = 0.5 * (part.start + part.end);
  CHECK(f(mid) < 0.5f);
  CHECK(f(mid + sag * n) > 0.5f);
  CHECK(f(mid + (sag + 1.1 * r) * n) < 0.5f);
  CHECK(f(mid + (sag + 0.9 * r) * n) > 0.5f);
}

TEST_CASE("buildTreeBlob::pruning leaves a planar face (§3.5, Fig. 14)", "[organisms]") {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 2, 0}, 0.1, 0.1, -1, 0));
  const DVec3 p(0, 1, 0), d = glm::normalize(DVec3(1, 0.5, 0));
  sk.internodes.push_back(seg(p, p + d, 0.06, 0.05, 0, 1, true));
  sk.internodes.push_back(seg(p + d, p + 2.0 * d, 0.05, 0.04, 1, 1));
  sk.internodes[0].end = {0, 1, 0};
  sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, 0.1, 0.1, 0, 0));
  TreeBlob blob = buildTreeBlob(sk, TreeOptions{});
  const Field field{std::move(blob)};
  const ConePart& cutPart = field.blob.plan.parts[field.blob.plan.partOfInternode[1]];
  REQUIRE(cutPart.kind == ConePart::Kind::Pruned);
  CHECK(field.blob.plan.partOfInternode[2] == -1);
  // Points on a disc in the cut plane: just before the plane inside, just after outside,
  // so the face is the plane itself.
  const DVec3 u = glm::normalize(glm::cross(d, DVec3(0, 0, 1))), w = glm::cross(d, u);
  int checked = 0;
  for (int i = 0; i < 12; ++i) {
    const double ang = 2 * kPi * i / 12;
    for (double rho : {0.0, 0.02, 0.035}) {
      const DVec3 q = cutPart.cutPoint + rho * (std::cos(ang) * u + std::sin(ang) * w);
      CHECK(field.value(Vec3(q - 1e-3 * d)) > 0.5f);
      CHECK(field.value(Vec3(q + 1e-3 * d)) < 0.5f);
      ++checked;
    }
  }
  CHECK(checked == 36);
  // Nothing of the removed branch is left beyond the cut.
  CHECK(field.value(Vec3(p + 1.5 * d)) == 0.0f);
}

TEST_CASE("buildTreeBlob::knob scars dent the stub (§3.5, Fig. 15)", "[organisms]") {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.1, 0.1, -1, 0));
  sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, 0.1, 0.1, 0, 0));
  sk.internodes.push_back(seg({0, 1, 0}, {1, 1, 0}, 0.06, 0.05, 0, 1));
  TreeOptions opt;
  opt.scars.select.internodes = {2};
  opt.scars.style = ScarStyle::Knob;
  opt.scars.stubLength = 1.5;
  opt.scars.stubRadius = 1.0;
  opt.scars.negativeRadius = 0.8;
  const Field scar{buildTreeBlob(sk, opt)};
  opt.scars.negativeWeight = 0;
  const Field stub{buildTreeBlob(sk, opt)};
  // Along the stub's axis: the plain stub reaches its end plus cap; the negative field
  // hollows it back toward the trunk.
  const double reachStub = surfaceDistance(stub, {0, 1, 0}, {1, 0, 0}, 0.5);
  const double reachScar = surfaceDistance(scar, {0, 1, 0}, {1, 0, 0}, 0.5);
  std::printf("scar: stub reaches %.4f from the trunk axis, with the negative field %.4f\n", reachStub, reachScar);
  CHECK(reachStub > 1.5 * 0.06 + 0.06);
  CHECK(reachScar < reachStub - 0.02);
  // a bigger negative field makes a bigger scar
  opt.scars.negativeWeight = 1;
  opt.scars.negativeRadius = 1.2;
  const Field bigger{buildTreeBlob(sk, opt)};
  CHECK(surfaceDistance(bigger, {0, 1, 0}, {1, 0, 0}, 0.5) < reachScar);
  // the rest of the branch is gone
  CHECK(stub.value({0.8f, 1, 0}) == 0.0f);
}

namespace {

/// The bark around a scar against the same trunk without the branch: surface distance from
/// the trunk's axis on a grid of azimuths (±60° about the branch's side) and heights
/// (±2.5 branch radii about the branching point).
struct ScarShape {
  double raise = 0, dip = 0;     ///< largest outward / inward deviation from the plain trunk
  double height = 0, width = 0;  ///< extent of the dip (deeper than a quarter of the deepest) along the axis / around it
};

ScarShape scarShape(ScarStyle style) {
  const double rT = 0.1, rB = 0.06;
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, rT, rT, -1, 0));
  sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, rT, rT, 0, 0));
  const Field plain{buildTreeBlob(sk, TreeOptions{})};
  const DVec3 d(std::sin(radians(60)), std::cos(radians(60)), 0);
  sk.internodes.push_back(seg({0, 1, 0}, DVec3(0, 1, 0) + d, rB, 0.05, 0, 1));
  TreeOptions opt;
  opt.scars.select.internodes = {2};
  opt.scars.style = style;
  if (style == ScarStyle::Knob) {  // the Fig. 15 settings before flush scars
    opt.scars.stubLength = 1.6;
    opt.scars.stubRadius = 1.2;
    opt.scars.negativeRadius = 0.9;
    opt.scars.negativeWeight = 1.15;
  }
  const Field scar{buildTreeBlob(sk, opt)};
  constexpr int kN = 41;
  std::vector<double> dev(kN * kN);
  ScarShape s;
  for (int i = 0; i < kN; ++i)
    for (int k = 0; k < kN; ++k) {
      const double phi = radians(-60.0 + 120.0 * i / (kN - 1));
      const float y = static_cast<float>(1.0 + rB * (-2.5 + 5.0 * k / (kN - 1)));
      const Vec3 dir(static_cast<float>(std::cos(phi)), 0, static_cast<float>(std::sin(phi)));
      const double e = surfaceDistance(scar, {0, y, 0}, dir, 0.5) - surfaceDistance(plain, {0, y, 0}, dir, 0.5);
      dev[i * kN + k] = e;
      s.raise = std::max(s.raise, e);
      s.dip = std::min(s.dip, e);
    }
  int i0 = kN, i1 = -1, k0 = kN, k1 = -1;
  for (int i = 0; i < kN; ++i)
    for (int k = 0; k < kN; ++k)
      if (dev[i * kN + k] < 0.25 * s.dip) {
        i0 = std::min(i0, i), i1 = std::max(i1, i);
        k0 = std::min(k0, k), k1 = std::max(k1, k);
      }
  if (i1 >= i0) {
    s.width = rT * radians(120.0 * (i1 - i0 + 1) / (kN - 1));
    s.height = rB * 5.0 * (k1 - k0 + 1) / (kN - 1);
  }
  std::printf("scar (%s): raise %.4f dip %.4f, dip %.4f high x %.4f around\n",
              style == ScarStyle::Flush ? "flush" : "knob", s.raise, s.dip, s.height, s.width);
  return s;
}

}  // namespace

TEST_CASE("buildTreeBlob::flush scars are round and stay on the bark's cylinder (§3.5, Fig. 15)", "[organisms]") {
  const double rB = 0.06;
  const ScarShape flush = scarShape(ScarStyle::Flush);
  // Within a quarter of the lost branch's radius of the bark everywhere around the scar...
  CHECK(flush.raise < 0.25 * rB);
  CHECK(flush.dip > -0.25 * rB);
  // ...yet a scar: a shallow round dish, as high as it is wide (within 30%).
  CHECK(flush.dip < -0.05 * rB);
  REQUIRE(flush.width > 0);
  CHECK(flush.height / flush.width == Approx(1.0).margin(0.3));
  // The knob scars (a stub out along the branch, dented at its end) stand far off the bark.
  const ScarShape knob = scarShape(ScarStyle::Knob);
  CHECK(knob.raise > 0.3 * rB);
  CHECK(knob.raise > 10 * flush.raise);
}

TEST_CASE("buildTreeBlob::deterministic", "[organisms]") {
  Skeleton sk = yJunction(0.1, 0.07, 30);
  TreeOptions opt;
  opt.junctions = JunctionModel::Pcm;
  opt.bends.angleDeg = 20;
  opt.bends.randomness = 0.5;
  TreeBlob a = buildTreeBlob(sk, opt), b = buildTreeBlob(sk, opt);
  REQUIRE(a.tree.size() == b.tree.size());
  CHECK(a.root == b.root);
  for (int i = 0; i < 200; ++i) {
    const Vec3 q(float(std::sin(i) * 0.3), float(0.8 + 0.003 * i), float(std::cos(i * 1.7) * 0.2));
    CHECK(a.tree.value(a.root, q) == b.tree.value(b.root, q));
  }
}

TEST_CASE("buildLeafMesh", "[organisms]") {
  Skeleton sk;
  lsystem::Organ blade;
  blade.kind = lsystem::Organ::Kind::Surface;
  blade.position = {1, 2, 3};
  blade.heading = {0, 1, 0};
  blade.left = {-1, 0, 0};
  blade.up = {0, 0, 1};
  blade.radius = 0.5;
  sk.organs.push_back(blade);
  lsystem::Organ quad;
  quad.kind = lsystem::Organ::Kind::Polygon;
  quad.points = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  sk.organs.push_back(quad);
  TreeOptions opt;
  Mesh m = buildLeafMesh(sk, opt);
  SECTION("counts, normals and extent") {
    // blade: base + 7 rows of 3 + tip = 23 vertices, 28 triangles; quad: 4 and 2
    CHECK(m.vertexCount() == 23 + 4);
    CHECK(m.triangleCount() == 28 + 2);
    CHECK(m.uvs.size() == m.vertexCount());
    CHECK(m.colors.size() == m.vertexCount());
    CHECK(m.materials.size() == m.triangleCount());
    CHECK(m.materials[0] == opt.leaves.material);
    for (size_t i = 0; i < 23; ++i) CHECK(m.normals[i].z == Approx(1.0f));
    CHECK(m.positions[22].y == Approx(2.5f));  // tip at position + scale·heading
    // triangles face their normal (counter-clockwise seen from up)
    for (size_t t = 0; t < m.triangleCount(); ++t) {
      const auto& tri = m.triangles[t];
      const Vec3 n = glm::cross(m.positions[tri.y] - m.positions[tri.x], m.positions[tri.z] - m.positions[tri.x]);
      CHECK(glm::dot(n, m.normals[tri.x]) > 0);
    }
  }
  SECTION("disabled leaves") {
    opt.leaves.enabled = false;
    CHECK(buildLeafMesh(sk, opt).triangleCount() == 0);
  }
  SECTION("same seed same bytes") {
    Mesh m2 = buildLeafMesh(sk, opt);
    CHECK(m2.positions == m.positions);
    CHECK(m2.colors == m.colors);
  }
}

TEST_CASE("buildTreeBlob::pruned tapes of a PCM tree with bends", "[organisms]") {
  // A binary tree of 63 internodes (PCM junctions, 8° bends, as the poplar): each surface
  // cell's pruned tape gives the whole tape's value at the cell's points and is much shorter.
  Skeleton sk;
  struct Tip {
    int index;
    DVec3 dir;
    double len, r;
  };
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.08, 0.06, -1, 0));
  std::vector<Tip> tips{{0, {0, 1, 0}, 1.0, 0.06}};
  for (int depth = 0; depth < 5; ++depth) {
    std::vector<Tip> next;
    for (const Tip& t : tips) {
      const DVec3 p = sk.internodes[size_t(t.index)].end;
      for (int side : {-1, 1}) {
        const double a = radians(35.0) * side;
        const DVec3 axis = depth % 2 == 0 ? DVec3(0, 0, 1) : DVec3(1, 0, 0);
        DVec3 d = t.dir * std::cos(a) + glm::cross(axis, t.dir) * std::sin(a) + axis * glm::dot(axis, t.dir) * (1 - std::cos(a));
        d = glm::normalize(d);
        const double len = t.len * 0.75, r = t.r * 0.75;
        sk.internodes.push_back(seg(p, p + len * d, t.r, r, t.index, depth + 1));
        next.push_back({int(sk.internodes.size() - 1), d, len, r});
      }
    }
    tips = std::move(next);
  }
  REQUIRE(sk.internodes.size() == 63);
  TreeOptions opt;
  opt.junctions = JunctionModel::Pcm;
  opt.bends.angleDeg = 8;
  opt.bends.randomness = 0.5;
  TreeBlob tb = buildTreeBlob(sk, opt);
  const blobtree::CompiledBlob blob = blobtree::compile(tb.tree, tb.root);
  blobtree::SurfaceCellOptions so;
  so.prunedTapes = true;
  const blobtree::CellSet cells = blob.surfaceCells(0.02f, so);
  REQUIRE(cells.cells.size() > 2000);
  Rng rng(4);
  size_t nodes = 0, sampled = 0;
  for (size_t ci = 0; ci < cells.cells.size(); ci += 5, ++sampled) {
    const blobtree::Cell& c = cells.cells[ci];
    const blobtree::CompiledBlob& p = cells.tapeOf(c, blob);
    REQUIRE(&p != &blob);
    nodes += p.nodeCount();
    Vec3 pts[8];
    float full[8], mine[8];
    for (Vec3& q : pts) q = c.box.lo + Vec3(float(rng.uniform()), float(rng.uniform()), float(rng.uniform())) * c.box.size();
    blob.values(pts, std::span<float>(full, 8));
    p.values(pts, std::span<float>(mine, 8));
    for (int i = 0; i < 8; ++i) {
      INFO("cell " << ci << " point " << i);
      CHECK(mine[i] == Approx(full[i]).margin(1e-6));
    }
    const blobtree::Sample a = blob.sample(pts[0]), b = p.sample(pts[0]);
    CHECK(b.value == Approx(a.value).margin(1e-6));
    CHECK(glm::length(b.gradient - a.gradient) <= 1e-4f * std::max(1.0f, glm::length(a.gradient)));
    CHECK(b.attributes.contact == Approx(a.attributes.contact).margin(1e-5));
  }
  INFO(blob.nodeCount() << " nodes in the tape, " << double(nodes) / double(sampled) << " per cell on average");
  CHECK(double(nodes) / double(sampled) < 0.1 * double(blob.nodeCount()));
  CHECK(cells.tapes.size() < cells.cells.size() / 4);
}

namespace {

// A trunk of radius 0.25 (basal to P = (0,1,0), leader above) and one lateral of radius
// 0.08 leaving P 75° from vertical toward +X: the geometry of fig_tree_18b.
Skeleton lateralOnTrunk() {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.25, 0.25, -1, 0));
  const double a = radians(75.0);
  const DVec3 p(0, 1, 0);
  sk.internodes.push_back(seg(p, {0, 2.6, 0}, 0.24, 0.24, 0, 0));
  sk.internodes.push_back(seg(p, p + 1.2 * DVec3(std::sin(a), std::cos(a), 0), 0.08, 0.08, 0, 1));
  return sk;
}

TreeOptions raisedRidgeOptions(double height) {
  TreeOptions opt;
  opt.junctions = JunctionModel::Pcm;
  textures::RidgeArcOptions& arc = opt.bark.ridgeArc;
  arc.rise = 1.1;
  arc.droop = 1.2;
  arc.spread = 4.5;
  arc.width = 0.5;
  arc.height = height;
  return opt;
}

}  // namespace

TEST_CASE("raisedRidgeArc: the bark rises along the arc's crest by the height", "[organisms]") {
  const Skeleton sk = lateralOnTrunk();
  const double rB = 0.08, height = 0.3;
  const Field plain = compiled(buildTreeBlob(sk, raisedRidgeOptions(0)));
  const Field raised = compiled(buildTreeBlob(sk, raisedRidgeOptions(height)));
  REQUIRE(raised.blob.tree.size() > plain.blob.tree.size());
  const std::vector<textures::RidgeArc> arcs = ridgeArcs(raised.blob);
  REQUIRE(arcs.size() == 1);
  const double rA = arcs[0].parentRadius;
  // The bark's height along the parent's normal through a point, from the parent's axis.
  auto bark = [&](const Field& f, Vec3 onBark, Vec3 normal) {
    return surfaceDistance(f, onBark - float(rA) * normal, normal, 2 * rA);
  };

  SECTION("along the crest: raised by height·r_B·weight") {
    const std::vector<textures::RidgeCrestPoint> crest =
        textures::RidgeArcs::crest(arcs[0], raisedRidgeOptions(height).bark.ridgeArc, 41);
    REQUIRE(crest.size() == 41);
    CHECK(crest[20].weight == Approx(1.0));  // the apex
    CHECK(crest.front().weight == 0.0f);
    CHECK(crest.back().weight == 0.0f);
    double worst = 0;
    int measured = 0;
    for (const textures::RidgeCrestPoint& c : crest) {
      if (c.weight < 0.3f) continue;
      const double raise = bark(raised, c.position, c.normal) - bark(plain, c.position, c.normal);
      const double want = height * rB * c.weight;
      worst = std::max(worst, std::abs(raise - want) / (height * rB));
      ++measured;
      INFO("crest point at " << c.position.x << ", " << c.position.y << ", " << c.position.z << ", weight " << c.weight);
      CHECK(raise == Approx(want).margin(0.1 * height * rB));
    }
    std::printf("raised ridge: %d crest points, largest error %.1f%% of the height %.4f\n", measured, 100 * worst,
                height * rB);
    CHECK(measured >= 15);
    const textures::RidgeCrestPoint& apex = crest[20];
    CHECK(bark(raised, apex.position, apex.normal) - bark(plain, apex.position, apex.normal) ==
          Approx(height * rB).margin(0.05 * height * rB));
  }
  SECTION("far from the arc: the same surface") {
    // The parent's back, below the lateral, high above the apex: exactly unchanged.
    for (double y : {0.4, 0.8, 1.0, 1.3, 1.6, 2.2}) {
      const Vec3 back(-float(rA), float(y), 0), n(-1, 0, 0);
      CHECK(bark(raised, back, n) == bark(plain, back, n));
    }
    for (double y : {0.3, 0.6, 1.9, 2.2}) {
      const Vec3 front(float(rA), float(y), 0), n(1, 0, 0);
      CHECK(bark(raised, front, n) == bark(plain, front, n));
    }
    // The lateral's own surface beyond the junction.
    const double a = radians(75.0);
    const Vec3 along = Vec3(float(std::sin(a)), float(std::cos(a)), 0), up = Vec3(-float(std::cos(a)), float(std::sin(a)), 0);
    const Vec3 axisPoint = Vec3(0, 1, 0) + 0.7f * along;
    CHECK(surfaceDistance(raised, axisPoint, up, 0.3) == surfaceDistance(plain, axisPoint, up, 0.3));
  }
}

TEST_CASE("raisedRidgeArc: every evaluator sees the ridge", "[organisms]") {
  const TreeBlob plainBlob = buildTreeBlob(lateralOnTrunk(), raisedRidgeOptions(0));
  const TreeBlob raisedBlob = buildTreeBlob(lateralOnTrunk(), raisedRidgeOptions(0.3));
  const blobtree::CompiledBlob plain = blobtree::compile(plainBlob.tree, plainBlob.root);
  const blobtree::CompiledBlob raised = blobtree::compile(raisedBlob.tree, raisedBlob.root);
  const std::vector<textures::RidgeArc> arcs = ridgeArcs(raisedBlob);
  REQUIRE(arcs.size() == 1);
  const std::vector<textures::RidgeCrestPoint> crest =
      textures::RidgeArcs::crest(arcs[0], raisedRidgeOptions(0.3).bark.ridgeArc, 41);
  // The relief cones are not limbs: the cell size rules see the tree without them.
  CHECK(raised.thinnestLimb() == plain.thinnestLimb());
  CHECK(raised.smallestFeature() == plain.smallestFeature());

  const uint64_t seed = 20;
  INFO("seed " << seed);
  Rng rng(seed);
  // Points about the crest, from inside the bark to past the ridge's top.
  std::vector<Vec3> points;
  for (int i = 0; i < 512; ++i) {
    const textures::RidgeCrestPoint& c = crest[size_t(rng.uniform(8, 33))];
    const Vec3 jitter(float(rng.uniform(-0.02, 0.02)), float(rng.uniform(-0.02, 0.02)), float(rng.uniform(-0.02, 0.02)));
    points.push_back(c.position + float(rng.uniform(-0.02, 0.04)) * c.normal + jitter);
  }
  std::vector<float> batch(points.size()), batchPlain(points.size());
  raised.values(points, batch);
  plain.values(points, batchPlain);
  int higher = 0, onSeam = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Vec3 p = points[i];
    const float v = raised.value(p);
    // point and batch agree (to the rounding of the sums)
    CHECK(batch[i] == Approx(v).margin(1e-5));
    // the reference evaluator agrees
    CHECK(raisedBlob.tree.value(raisedBlob.root, p) == Approx(v).margin(1e-5));
    // the ridge only adds
    CHECK(v >= plain.value(p) - 1e-6f);
    if (v > batchPlain[i] + 1e-3f) ++higher;
    // the gradient against central differences, where the field is smooth within h: the
    // relief cones are united by max, so a point on a seam between two of them has one-sided
    // differences that disagree, and there no gradient exists to compare with.
    const Vec3 g = raised.gradient(p);
    const float h = 1e-4f;
    Vec3 forward, backward;
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 e(0.0f);
      e[axis] = h;
      forward[axis] = (raised.value(p + e) - v) / h;
      backward[axis] = (v - raised.value(p - e)) / h;
    }
    const Vec3 fd = 0.5f * (forward + backward);
    if (glm::length(forward - backward) > 0.02f * glm::length(fd) + 0.05f) {
      ++onSeam;
      continue;
    }
    CHECK(glm::length(g - fd) <= 0.02f * glm::length(fd) + 0.05f);
  }
  CHECK(onSeam < 512 / 20);  // seams are thin: nearly every point is compared
  CHECK(higher > 512 / 3);  // a good part of the points lie within the ridge's support
  // Half the ridge's height above the plain bark at the apex: outside the plain tree,
  // inside the raised one.
  const textures::RidgeCrestPoint& apex = crest[20];
  double lo = -0.05, hi = 0.05;  // along the normal from the crest point: inside, outside
  REQUIRE(plain.value(apex.position + float(lo) * apex.normal) > 0.5f);
  REQUIRE(plain.value(apex.position + float(hi) * apex.normal) < 0.5f);
  for (int k = 0; k < 40; ++k) {
    const double mid = 0.5 * (lo + hi);
    (plain.value(apex.position + float(mid) * apex.normal) > 0.5f ? lo : hi) = mid;
  }
  const Vec3 above = apex.position + float(lo + 0.5 * 0.3 * 0.08) * apex.normal;
  CHECK(plain.value(above) < 0.5f);
  CHECK(raised.value(above) > 0.5f);

  // Interval and Lipschitz bounds over random boxes about the crest hold at random points.
  for (int i = 0; i < 400; ++i) {
    const Vec3 c = points[size_t(i)];
    const float half = float(rng.uniform(0.001, 0.04));
    const Box3 box{c - Vec3(half), c + Vec3(half)};
    const blobtree::Interval iv = raised.valueBounds(box);
    const float L = raised.lipschitz(box);
    Vec3 prev = c;
    float prevValue = raised.value(c);
    for (int k = 0; k < 8; ++k) {
      const Vec3 q = c + half * Vec3(float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)), float(rng.uniform(-1, 1)));
      const float v = raised.value(q);
      CHECK(iv.lo <= v + 1e-6f);
      CHECK(v <= iv.hi + 1e-6f);
      CHECK(std::abs(v - prevValue) <= L * glm::length(q - prev) * 1.0001f + 1e-6f);
      prev = q;
      prevValue = v;
    }
  }
}
