#include <catch2/catch.hpp>

#include <cmath>

#include "organisms/tree_plan.h"
#include "tests/organisms/internode.h"

using namespace sprig;
using namespace sprig::organisms;
using lsystem::Skeleton;
using test::seg;

namespace {

// A trunk of two internodes along +Y (0..1, 1..2) and, at y = 1, a lateral branch.
Skeleton fork(double rA, double rLead, double rLat) {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, rA, rA, -1, 0));
  sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, rLead, rLead, 0, 0));
  const DVec3 d = glm::normalize(DVec3(1, 1, 0));
  sk.internodes.push_back(seg({0, 1, 0}, DVec3(0, 1, 0) + d, rLat, rLat, 0, 1));
  sk.internodes.push_back(seg(DVec3(0, 1, 0) + d, DVec3(0, 1, 0) + 2.0 * d, rLat, rLat, 2, 1));
  return sk;
}

}  // namespace

TEST_CASE("planTree::offsets", "[organisms]") {
  SECTION("Eq. 4, 7, 8 closed forms") {
    CHECK(deltaASingle(0.2) == Approx(0.35));
    CHECK(deltaAMultiple(0.2, 0.1) == Approx(0.075));
    CHECK(deltaB(0.2, 0.05) == Approx(0.15));
    CHECK(deltaB(0.1, 0.2) == 0.0);
  }
  SECTION("one-child joint: A shortened by 1.75 r_B, B's base fixed at P") {
    Skeleton sk;
    sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.1, 0.1, -1, 0));
    sk.internodes.push_back(seg({0, 1, 0}, {0, 2, 0}, 0.1, 0.1, 0, 0));
    TreeOptions opt;
    opt.tips = TipStyle::Hemisphere;
    TreePlan plan = planTree(sk, opt);
    REQUIRE(plan.parts.size() == 2);
    REQUIRE(plan.junctions.size() == 1);
    CHECK(plan.junctions[0].deltaA == Approx(0.175));
    CHECK_FALSE(plan.junctions[0].pcm);
    CHECK(plan.parts[0].end.y == Approx(1.0 - 0.175));
    CHECK(plan.parts[0].start.y == Approx(0.0));
    CHECK(plan.parts[1].start.y == Approx(1.0));
    CHECK(plan.parts[1].end.y == Approx(2.0));
    CHECK(plan.parts[0].junctionAtEnd == 0);
    CHECK(plan.parts[1].junctionAtStart == 0);
    CHECK(plan.parts[1].junctionAtEnd == -1);
    CHECK(plan.parts[1].vStart == Approx(1.0));
  }
  SECTION("no basal offset reproduces the coincident joint of Fig. 9 left") {
    Skeleton sk = fork(0.1, 0.1, 0.05);
    TreeOptions opt;
    opt.basalOffset = false;
    TreePlan plan = planTree(sk, opt);
    CHECK(plan.parts[0].end.y == Approx(1.0));
  }
  SECTION("smooth junction with several branches: Eq. 4 with the largest branch, no branch offset") {
    TreeOptions opt;
    TreePlan plan = planTree(fork(0.1, 0.08, 0.05), opt);
    REQUIRE(plan.junctions.size() == 2);
    CHECK(plan.junctions[0].branches.size() == 2);
    CHECK(plan.junctions[0].deltaA == Approx(1.75 * 0.08));
    CHECK(plan.parts[2].start.x == Approx(0.0));
    CHECK(plan.parts[2].start.y == Approx(1.0));
  }
  SECTION("PCM junction: Eq. 8 on A and Eq. 7 on each branch") {
    TreeOptions opt;
    opt.junctions = JunctionModel::Pcm;
    TreePlan plan = planTree(fork(0.1, 0.08, 0.05), opt);
    const Junction& j = plan.junctions[0];
    REQUIRE(j.pcm);
    CHECK(j.deltaA == Approx(2.75 * 0.08 - 0.1));
    CHECK(plan.parts[0].end.y == Approx(1.0 - (2.75 * 0.08 - 0.1)));
    // the leader moves up by r_A - r_lead, the lateral along its axis by r_A - r_lat
    CHECK(plan.parts[1].start.y == Approx(1.0 + 0.02));
    const DVec3 d = glm::normalize(DVec3(1, 1, 0));
    CHECK(glm::length(plan.parts[2].start - (DVec3(0, 1, 0) + 0.05 * d)) == Approx(0.0).margin(1e-12));
    // the lateral's radius at its new base follows its taper (constant here)
    CHECK(plan.parts[2].startRadius == Approx(0.05));
    // the one-child joint inside the lateral is not a PCM junction
    CHECK_FALSE(plan.junctions[1].pcm);
    CHECK(plan.junctions[1].deltaA == Approx(1.75 * 0.05));
  }
  SECTION("PCM without branch offset (Fig. 12 left)") {
    TreeOptions opt;
    opt.junctions = JunctionModel::Pcm;
    opt.branchOffset = false;
    TreePlan plan = planTree(fork(0.1, 0.08, 0.05), opt);
    CHECK(plan.parts[1].start.y == Approx(1.0));
    CHECK(plan.parts[2].start.y == Approx(1.0));
  }
}

TEST_CASE("planTree::tips", "[organisms]") {
  Skeleton sk;
  sk.internodes.push_back(seg({0, 0, 0}, {0, 1, 0}, 0.1, 0.08, -1, 0));
  TreeOptions opt;
  SECTION("taper: small tip radius, cap closing at the end point") {
    TreePlan plan = planTree(sk, opt);
    const ConePart& p = plan.parts[0];
    CHECK(p.endRadius == Approx(0.035));
    CHECK(p.end.y + p.endRadius == Approx(1.0));
  }
  SECTION("hemisphere: the paper's cap of the tip radius") {
    opt.tips = TipStyle::Hemisphere;
    TreePlan plan = planTree(sk, opt);
    CHECK(plan.parts[0].endRadius == Approx(0.08));
    CHECK(plan.parts[0].end.y == Approx(1.0));
  }
}

TEST_CASE("planTree::pruning and scars", "[organisms]") {
  SECTION("grammar cut: first lateral internode sawn, its descendants dropped") {
    Skeleton sk = fork(0.1, 0.08, 0.05);
    sk.internodes[2].cut = true;
    TreePlan plan = planTree(sk, TreeOptions{});
    REQUIRE(plan.parts.size() == 3);
    CHECK(plan.partOfInternode[3] == -1);
    const ConePart& p = plan.parts[plan.partOfInternode[2]];
    CHECK(p.kind == ConePart::Kind::Pruned);
    const DVec3 d = glm::normalize(DVec3(1, 1, 0));
    CHECK(glm::length(p.cutNormal - d) == Approx(0.0).margin(1e-12));
    CHECK(glm::length(p.cutPoint - (DVec3(0, 1, 0) + 0.5 * d)) == Approx(0.0).margin(1e-12));
    // the cone goes past the cut so no cap survives
    CHECK(glm::dot(p.end - p.cutPoint, d) > 2 * 0.05 - 1e-12);
    // the pruned branch is still part of its junction
    CHECK(plan.junctions[0].branches.size() == 2);
  }
  SECTION("species selector by order, seeded probability 1 and 0") {
    Skeleton sk = fork(0.1, 0.08, 0.05);
    TreeOptions opt;
    opt.prune.select.probability = 1.0;
    opt.prune.select.orders = {1};
    CHECK(planTree(sk, opt).parts[2].kind == ConePart::Kind::Pruned);
    opt.prune.select.orders = {2};
    CHECK(planTree(sk, opt).parts[2].kind == ConePart::Kind::Internode);
    opt.prune.select.orders = {};
    opt.prune.select.belowHeight = 0.5;
    CHECK(planTree(sk, opt).parts[2].kind == ConePart::Kind::Internode);
  }
  SECTION("knob scar: stub of stubLength base radii plus a negative field at its end") {
    Skeleton sk = fork(0.1, 0.08, 0.05);
    TreeOptions opt;
    opt.scars.select.internodes = {2};
    opt.scars.style = ScarStyle::Knob;
    opt.scars.stubRadius = 1.0;
    opt.scars.negativeRadius = 0.8;
    TreePlan plan = planTree(sk, opt);
    REQUIRE(plan.parts.size() == 3);
    const ConePart& p = plan.parts[2];
    CHECK(p.kind == ConePart::Kind::Stub);
    CHECK(p.length() == Approx(1.5 * 0.05));
    CHECK(p.startRadius == Approx(0.05));
    CHECK(p.negativeRadius == Approx(0.8 * 0.05));
    CHECK(glm::length(p.negativeCenter - p.end) == Approx(0.0).margin(1e-12));
  }
  SECTION("flush scar: a radial stub from P to the parent's bark, the negative field where it meets it") {
    Skeleton sk = fork(0.1, 0.08, 0.05);
    TreeOptions opt;
    opt.scars.select.internodes = {2};
    TreePlan plan = planTree(sk, opt);
    REQUIRE(plan.parts.size() == 3);
    const ConePart& p = plan.parts[2];
    const Junction& j = plan.junctions[p.junctionAtStart];
    CHECK(p.kind == ConePart::Kind::Stub);
    CHECK(glm::length(p.start - j.point) == Approx(0.0).margin(1e-12));
    CHECK(p.length() == Approx(0.1));  // the basal internode's tip radius
    const DVec3 axis = glm::normalize(sk.internodes[0].end - sk.internodes[0].start);
    CHECK(glm::dot(p.end - p.start, axis) == Approx(0.0).margin(1e-12));  // radial
    CHECK(p.startRadius == Approx(0.8 * 0.05));
    CHECK(p.negativeRadius == Approx(0.9 * 0.05));
    CHECK(glm::length(p.negativeCenter - p.end) == Approx(0.0).margin(1e-12));
  }
}

TEST_CASE("planTree::bends", "[organisms]") {
  Skeleton sk = fork(0.1, 0.08, 0.05);
  TreeOptions opt;
  opt.bends.angleDeg = 20;
  opt.bends.orderScale = 0.5;
  TreePlan plan = planTree(sk, opt);
  SECTION("the trunk and its collinear leader stay straight") {
    CHECK(plan.parts[0].bendAngle == 0.0);
    CHECK(plan.parts[1].bendAngle == 0.0);
  }
  SECTION("a lateral bows away from its basal internode's axis") {
    const ConePart& p = plan.parts[2];
    CHECK(p.bendAngle == Approx(radians(20)));
    const DVec3 d = glm::normalize(DVec3(1, 1, 0));
    CHECK(glm::dot(p.bendToward, d) == Approx(0.0).margin(1e-12));
    // n = (1,-1,0)/sqrt2: more horizontal than the branch itself, i.e. away from the Y axis
    CHECK(p.bendToward.x > 0);
    CHECK(p.bendToward.y < 0);
    // the second lateral internode continues straight from the first: not bent
    CHECK(plan.parts[3].bendAngle == 0.0);
  }
  SECTION("randomness is seeded: same seed same angle, other seed other angle") {
    opt.bends.randomness = 0.5;
    TreePlan a = planTree(sk, opt), b = planTree(sk, opt);
    CHECK(a.parts[2].bendAngle == b.parts[2].bendAngle);
    opt.seed = 99;
    TreePlan c = planTree(sk, opt);
    CHECK(c.parts[2].bendAngle != a.parts[2].bendAngle);
    CHECK(std::abs(c.parts[2].bendAngle - radians(20)) <= 0.5 * radians(20));
  }
}
