#include "organisms/tree_plan.h"

#include <algorithm>
#include <cmath>

#include "core/rng.h"

namespace sprig::organisms {

namespace {

// Purposes mixed into deriveSeed so each random choice has its own stream.
constexpr uint64_t kSeedPrune = 0x5052554eull;
constexpr uint64_t kSeedScar = 0x53434152ull;
constexpr uint64_t kSeedBend = 0x42454e44ull;

bool isLateralStart(const lsystem::Skeleton& sk, size_t i) {
  const auto& in = sk.internodes[i];
  return in.parent >= 0 && in.order > sk.internodes[in.parent].order;
}

bool selects(const BranchSelector& sel, const lsystem::Skeleton& sk, size_t i, uint64_t seed, uint64_t purpose) {
  if (std::find(sel.internodes.begin(), sel.internodes.end(), static_cast<int>(i)) != sel.internodes.end())
    return true;
  if (sel.probability <= 0 || !isLateralStart(sk, i)) return false;
  const auto& in = sk.internodes[i];
  if (!sel.orders.empty() && std::find(sel.orders.begin(), sel.orders.end(), in.order) == sel.orders.end())
    return false;
  if (in.start.y >= sel.belowHeight || in.start.y <= sel.aboveHeight) return false;
  Rng rng(deriveSeed(seed, {purpose, static_cast<uint64_t>(i)}));
  return rng.uniform() < sel.probability;
}

DVec3 safeDir(const DVec3& a, const DVec3& b) {
  DVec3 d = b - a;
  double l = glm::length(d);
  return l > 0 ? d / l : DVec3(0, 1, 0);
}

// Any unit vector perpendicular to d.
DVec3 perpendicular(const DVec3& d) {
  DVec3 t = std::abs(d.x) < 0.9 ? DVec3(1, 0, 0) : DVec3(0, 1, 0);
  return glm::normalize(glm::cross(d, t));
}

// Bend angle and direction of one part (§3.6, Fig. 16); d is the internode's unit axis.
void applyBend(ConePart& p, const lsystem::Skeleton& sk, const TreeOptions& opt, const DVec3& d) {
  if (p.kind != ConePart::Kind::Internode || opt.bends.angleDeg == 0) return;
  const auto& in = sk.internodes[p.internode];
  Rng rng(deriveSeed(opt.seed, {kSeedBend, static_cast<uint64_t>(p.internode)}));
  const double jitter = 1.0 + opt.bends.randomness * rng.uniform(-1.0, 1.0);
  if (in.order == 0 || in.parent < 0) {
    if (!opt.bends.trunk) return;
    const DVec3 u = perpendicular(d), w = glm::cross(d, u);
    const double phi = rng.uniform(0.0, 2.0 * kPi);
    p.bendToward = std::cos(phi) * u + std::sin(phi) * w;
    p.bendAngle = radians(opt.bends.angleDeg) * 0.5 * jitter;
    return;
  }
  const auto& parent = sk.internodes[in.parent];
  const DVec3 a = safeDir(parent.start, parent.end);
  // Bow toward n = the part of "away from A's axis" perpendicular to the internode, so the
  // internode first grows more directly away from the axis, then returns to its end point.
  const DVec3 away = d - glm::dot(d, a) * a;
  const double sinPhi = glm::length(away);
  if (sinPhi < std::sin(radians(opt.bends.minBranchAngleDeg))) return;
  DVec3 nrm = away / sinPhi;
  nrm = nrm - glm::dot(nrm, d) * d;
  if (glm::length(nrm) < 1e-9) return;
  p.bendToward = glm::normalize(nrm);
  p.bendAngle = radians(opt.bends.angleDeg) * std::pow(opt.bends.orderScale, in.order - 1) * jitter;
}

}  // namespace

double deltaASingle(double rB, double factor) { return factor * rB; }

double deltaAMultiple(double rA, double rMax, double factor) { return factor * rMax - rA; }

double deltaB(double rA, double ri) { return std::max(0.0, rA - ri); }

namespace {

/// What an internode becomes in the tree.
enum class Fate { Keep, Prune, Stub, Drop };

double partRadius(const TreeOptions& opt, double r) { return std::max(opt.minRadius, r * opt.radiusScale); }

/// Step 1 of planTree: the internodes parents before children, each one's fate (kept,
/// pruned, stub, dropped below a pruned or stub one) and bark v from the root.
struct Fates {
  std::vector<size_t> order;
  std::vector<Fate> fate;
  std::vector<double> vFromRoot;
};

Fates planFates(const lsystem::Skeleton& sk, const TreeOptions& opt, const std::vector<std::vector<int32_t>>& children) {
  const size_t n = sk.internodes.size();
  Fates f{{}, std::vector<Fate>(n, Fate::Keep), std::vector<double>(n, 0.0)};
  f.order.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (sk.internodes[i].parent < 0) f.order.push_back(i);
  for (size_t k = 0; k < f.order.size(); ++k)
    for (int32_t c : children[f.order[k]]) f.order.push_back(static_cast<size_t>(c));
  for (size_t i : f.order) {
    const auto& in = sk.internodes[i];
    if (in.parent >= 0) {
      f.vFromRoot[i] = f.vFromRoot[in.parent] + sk.internodes[in.parent].length();
      if (f.fate[in.parent] != Fate::Keep) {
        f.fate[i] = Fate::Drop;
        continue;
      }
    }
    if ((opt.prune.fromGrammar && in.cut) || selects(opt.prune.select, sk, i, opt.seed, kSeedPrune))
      f.fate[i] = Fate::Prune;
    else if (selects(opt.scars.select, sk, i, opt.seed, kSeedScar))
      f.fate[i] = Fate::Stub;
  }
  return f;
}

/// Step 2 of planTree: one part per surviving internode, in the order of f.
void planParts(const lsystem::Skeleton& sk, const TreeOptions& opt, const Fates& f, TreePlan& plan) {
  plan.partOfInternode.assign(sk.internodes.size(), -1);
  for (size_t i : f.order) {
    if (f.fate[i] == Fate::Drop) continue;
    const auto& in = sk.internodes[i];
    ConePart p;
    p.kind = f.fate[i] == Fate::Prune  ? ConePart::Kind::Pruned
             : f.fate[i] == Fate::Stub ? ConePart::Kind::Stub
                                       : ConePart::Kind::Internode;
    p.internode = static_cast<int32_t>(i);
    p.start = in.start;
    p.end = in.end;
    p.startRadius = partRadius(opt, in.baseRadius);
    p.endRadius = partRadius(opt, in.tipRadius);
    p.vStart = f.vFromRoot[i];
    plan.partOfInternode[i] = static_cast<int32_t>(plan.parts.size());
    plan.parts.push_back(p);
  }
}

/// Step 3 of planTree: junctions and their offsets (Eq. 4, 7, 8): each part's start offset
/// (δB) and end offset (δA).
void planJunctions(const TreeOptions& opt, const std::vector<std::vector<int32_t>>& children, TreePlan& plan,
                   std::vector<double>& startOffset, std::vector<double>& endOffset) {
  startOffset.assign(plan.parts.size(), 0.0);
  endOffset.assign(plan.parts.size(), 0.0);
  for (size_t pi = 0; pi < plan.parts.size(); ++pi) {
    ConePart& a = plan.parts[pi];
    if (a.kind != ConePart::Kind::Internode) continue;
    Junction j;
    j.basal = static_cast<int32_t>(pi);
    j.point = a.end;
    for (int32_t c : children[a.internode])
      if (plan.partOfInternode[c] >= 0) j.branches.push_back(plan.partOfInternode[c]);
    if (j.branches.empty()) continue;
    const double rA = a.endRadius;
    double rMax = 0;
    // A flush scar's stub stands for no branch: A is shortened as for the others alone.
    for (int32_t b : j.branches)
      if (plan.parts[b].kind != ConePart::Kind::Stub || opt.scars.style != ScarStyle::Flush)
        rMax = std::max(rMax, plan.parts[b].startRadius);
    j.pcm = opt.junctions == JunctionModel::Pcm && j.branches.size() > 1;
    if (opt.basalOffset) {
      j.deltaA = j.pcm ? deltaAMultiple(rA, rMax, opt.deltaAMulti) : deltaASingle(rMax, opt.deltaA);
      // A never grows past P by more than its own radius: its cap would poke out.
      j.deltaA = std::max(j.deltaA, -0.5 * rA);
    }
    if (j.pcm && opt.branchOffset)
      for (int32_t b : j.branches)
        if (plan.parts[b].kind != ConePart::Kind::Stub)
          startOffset[b] = deltaB(rA, plan.parts[b].startRadius);
    endOffset[pi] = j.deltaA;
    const auto ji = static_cast<int32_t>(plan.junctions.size());
    a.junctionAtEnd = ji;
    for (int32_t b : j.branches) plan.parts[b].junctionAtStart = ji;
    plan.junctions.push_back(std::move(j));
  }
}

/// A scar's stub (§3.5): a flush one radially from the parent's axis at P out to its bark,
/// so the scar faces straight out of the bark and is round on it (points of the bark at
/// one distance from a radial segment lie on a circle about where it meets the bark);
/// otherwise a short stub along the internode. Both carry the negative primitive that dents
/// the scar.
void shapeStub(ConePart& p, const lsystem::Skeleton& sk, const TreeOptions& opt, const TreePlan& plan, const DVec3& d) {
  const double rb = p.startRadius;
  if (opt.scars.style == ScarStyle::Flush && p.junctionAtStart >= 0) {
    const Junction& j = plan.junctions[p.junctionAtStart];
    const auto& basal = sk.internodes[plan.parts[j.basal].internode];
    const DVec3 axis = safeDir(basal.start, basal.end);
    const double rA = partRadius(opt, basal.tipRadius);
    DVec3 out = d - glm::dot(d, axis) * axis;
    out = glm::length(out) > 1e-9 ? glm::normalize(out) : d;
    p.start = j.point;
    p.end = j.point + rA * out;
    p.startRadius = p.endRadius = std::min(opt.scars.stubRadius * rb, 0.9 * rA);
  } else {
    p.end = p.start + opt.scars.stubLength * rb * d;
    p.startRadius = opt.scars.stubRadius * rb;
    p.endRadius = opt.scars.stubRadius * rb;
  }
  p.negativeCenter = p.end;
  p.negativeRadius = opt.scars.negativeRadius * rb;
  p.negativeWeight = opt.scars.negativeWeight;
}

/// Step 4 of planTree for a kept or pruned part: its offsets s0 (start) and s1 (end), its
/// tip or saw cut, and its bend.
void shapePart(ConePart& p, const lsystem::Skeleton& sk, const TreeOptions& opt, const DVec3& d, double s0, double s1) {
  const double len = glm::length(p.end - p.start);
  const double rb = p.startRadius, rt = p.endRadius;
  auto radiusAt = [&](double t) { return len > 0 ? rb + (rt - rb) * (t / len) : rb; };
  const DVec3 origin = p.start;
  // Offsets may not eat the whole internode: keep at least 10% of it.
  if (s0 + s1 > 0.9 * len) {
    const double k = 0.9 * len / (s0 + s1);
    s0 *= k;
    s1 *= k;
  }
  double t0 = s0, t1 = len - s1;
  if (p.kind == ConePart::Kind::Pruned) {
    const double cut = std::min(std::max(opt.prune.cutFraction * len, opt.prune.minCutDistance * rb + s0), len);
    p.cutPoint = origin + cut * d;
    p.cutNormal = d;
    // The cone runs past the saw by more than its radius so the cap is cut away.
    t1 = std::max(len, cut + 2.0 * radiusAt(cut));
  } else if (p.junctionAtEnd < 0 && opt.tips == TipStyle::Taper) {
    // A natural tip: the radius shrinks and the cap closes exactly at the end point.
    const double tipR = std::min(rt, opt.tipTaper * rb);
    p.start = origin + t0 * d;
    p.startRadius = radiusAt(t0);
    p.endRadius = tipR;
    p.end = origin + std::max(t0 + 0.1 * len, len - tipR) * d;
    p.vStart += t0;
    applyBend(p, sk, opt, d);
    return;
  }
  p.start = origin + t0 * d;
  p.end = origin + t1 * d;
  p.startRadius = radiusAt(t0);
  p.endRadius = std::max(1e-6, radiusAt(t1));
  p.vStart += t0;
  applyBend(p, sk, opt, d);
}

}  // namespace

TreePlan planTree(const lsystem::Skeleton& sk, const TreeOptions& opt) {
  const auto children = sk.children();
  TreePlan plan;
  planParts(sk, opt, planFates(sk, opt, children), plan);
  std::vector<double> startOffset, endOffset;
  planJunctions(opt, children, plan, startOffset, endOffset);
  // Step 4: apply offsets, tips, cuts, stubs and bends to each part.
  for (size_t pi = 0; pi < plan.parts.size(); ++pi) {
    ConePart& p = plan.parts[pi];
    const DVec3 d = safeDir(p.start, p.end);
    if (p.kind == ConePart::Kind::Stub) shapeStub(p, sk, opt, plan, d);
    else shapePart(p, sk, opt, d, startOffset[pi], endOffset[pi]);
  }
  return plan;
}

}  // namespace sprig::organisms
