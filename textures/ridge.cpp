#include "textures/ridge.h"

#include <algorithm>
#include <cmath>

namespace sprig::textures {

namespace {

/// Depth of the folds in H (units of the band's width): slopes of about ±0.3·relief.
constexpr double kFoldDepth = 0.05;

}  // namespace

double RidgeShade::wander(const Vec3& p) const {
  if (options_.lines <= 0) return 0.0;
  return 0.35 * noise_(DVec3(p) * options_.wanderScale + DVec3(0.37, 0.11, 0.73));
}

/// A fold's profile at contact c: 1 in the middle of a fold, 0 between folds; the phase
/// lines·c^1.5 runs faster toward c = 1, so the folds bunch up at the crest.
double RidgeShade::fold(double c, double wander) const {
  if (options_.lines <= 0 || !(c > 0)) return 0.0;
  const double phase = options_.lines * std::pow(c, 1.5) + wander;
  return std::pow(0.5 + 0.5 * std::cos(2 * kPi * phase), 6.0);
}

double RidgeShade::darkness(double contact, const Vec3& p) const {
  const double arc = arcs_ ? arcs_->sample(p).darkness : 0.0;
  const double c = std::clamp(contact, 0.0, 1.0);
  if (!(c > 0) || !(options_.darkening > 0)) return arc;
  const double crest = c * c * c;
  const double folds = c * fold(c, wander(p));
  const double seam = std::clamp(options_.darkening * (crest + 0.8 * folds * (1 - crest)), 0.0, 1.0);
  return 1 - (1 - seam) * (1 - arc);
}

double RidgeShade::slope(double contact, const Vec3& p) const {
  const double c = std::clamp(contact, 0.0, 1.0);
  if (!(options_.relief > 0) || !(c > 0) || !(c < 1)) return 0.0;
  // H(c) = smoothstep(c) − kFoldDepth·c·fold(c)/rate, the folds scaled by the phase's rate
  // dφ/dc so their slope stays about the same as they crowd together.
  const double w = wander(p);
  auto H = [&](double x) {
    const double rate = std::max(1.0, 1.5 * options_.lines * std::sqrt(std::max(x, 0.0)));
    return x * x * (3 - 2 * x) - kFoldDepth * x * fold(x, w) * (options_.lines > 0 ? 2 * kPi / rate : 0.0);
  };
  const double h = 1e-3;
  const double lo = std::max(0.0, c - h), hi = std::min(1.0, c + h);
  return options_.relief * (H(hi) - H(lo)) / (hi - lo);
}

Vec3 RidgeShade::shadingNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const {
  Vec3 out = seamNormal(n, contact, contactGradient, p);
  if (!arcs_ || !(arcs_->options().relief > 0)) return out;
  const Vec3 g = arcs_->sample(p).heightGradient;
  const Vec3 gt = g - glm::dot(g, out) * out;  // uphill along the surface
  const float len = glm::length(gt);
  if (!(len > 0)) return out;
  const float s = std::min(len, 4.0f);  // the slope, capped so the normal never turns past the surface
  const Vec3 tilted = out - s * (gt / len);
  const float tl = glm::length(tilted);
  return tl > 0 ? tilted / tl : out;
}

Vec3 RidgeShade::seamNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const {
  if (!(options_.relief > 0) || !(contact > 0)) return n;
  const Vec3 gt = contactGradient - glm::dot(contactGradient, n) * n;  // along the surface, toward the seam
  const float len = glm::length(gt);
  if (!(len > 1e-5f * glm::length(contactGradient))) return n;  // (rounding left of a normal gradient)
  // The slope, capped so the normal never turns past the surface.
  const double s = std::clamp(slope(contact, p), -4.0, 4.0);
  const Vec3 tilted = n - static_cast<float>(s) * (gt / len);
  const float tl = glm::length(tilted);
  return tl > 0 ? tilted / tl : n;
}

namespace {

/// Roundness of the arc's apex (branch radii): the crest is √(x² + k²) − k below the apex.
constexpr double kApexRound = 0.8;
/// Branches closer than this to their parent's axis are charted as if at this angle.
constexpr double kMinSinAlpha = 0.26;  // 15°

double smooth01(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

}  // namespace

std::optional<RidgeArcs::Arc> RidgeArcs::chart(const RidgeArc& in, const RidgeArcOptions& o) {
  const float la = glm::length(in.parentAxis), lb = glm::length(in.branchAxis);
  if (!(la > 0) || !(lb > 0) || !(in.parentRadius > 0) || !(in.branchRadius > 0)) return std::nullopt;
  Arc a;
  a.in = in;
  a.in.parentAxis = in.parentAxis / la;
  a.in.branchAxis = in.branchAxis / lb;
  const Vec3 radial = a.in.branchAxis - glm::dot(a.in.branchAxis, a.in.parentAxis) * a.in.parentAxis;
  const float lr = glm::length(radial);
  if (!(lr > 1e-3f)) return std::nullopt;  // a branch along its parent has no side to arch over
  a.out = radial / lr;
  a.side = glm::cross(a.in.parentAxis, a.out);
  a.sinAlpha = std::max(static_cast<double>(lr), kMinSinAlpha);
  const double cosAlpha = glm::dot(a.in.branchAxis, a.in.parentAxis);
  a.zPierce = a.in.parentRadius * cosAlpha / a.sinAlpha;
  a.zApex = 1 / a.sinAlpha + o.rise;
  // Influence: a sphere around the pierce point holding the chart's whole arc and the
  // band beside it, plus a branch radius outward (the crotch's fillet).
  const double rB = a.in.branchRadius;
  const double reach = rB * (std::hypot(o.spread, std::abs(a.zApex) + o.droop * o.spread) + o.width + 1.5);
  const Vec3 c = a.in.point + static_cast<float>(a.zPierce) * a.in.parentAxis + a.in.parentRadius * a.out;
  a.lo = c - Vec3(static_cast<float>(reach));
  a.hi = c + Vec3(static_cast<float>(reach));
  return a;
}

RidgeArcs::RidgeArcs(const std::vector<RidgeArc>& arcs, const RidgeArcOptions& options) : options_(options) {
  for (const RidgeArc& in : arcs)
    if (auto a = chart(in, options_)) arcs_.push_back(*a);
  if (arcs_.empty()) return;
  // The grid: cells about twice the median reach, at most 64 per axis.
  Vec3 lo(arcs_[0].lo), hi(arcs_[0].hi);
  std::vector<float> reach;
  for (const Arc& a : arcs_) {
    lo = glm::min(lo, a.lo);
    hi = glm::max(hi, a.hi);
    reach.push_back(a.hi.x - a.lo.x);
  }
  std::nth_element(reach.begin(), reach.begin() + reach.size() / 2, reach.end());
  const Vec3 ext = hi - lo;
  cell_ = std::max({reach[reach.size() / 2], ext.x / 64, ext.y / 64, ext.z / 64, 1e-6f});
  gridLo_ = lo;
  dims_ = glm::max(glm::ivec3(1), glm::ivec3(glm::ceil(ext / cell_)));
  const size_t cells = static_cast<size_t>(dims_.x) * dims_.y * dims_.z;
  auto cellRange = [&](const Arc& a, glm::ivec3& c0, glm::ivec3& c1) {
    c0 = glm::clamp(glm::ivec3(glm::floor((a.lo - gridLo_) / cell_)), glm::ivec3(0), dims_ - 1);
    c1 = glm::clamp(glm::ivec3(glm::floor((a.hi - gridLo_) / cell_)), glm::ivec3(0), dims_ - 1);
  };
  std::vector<uint32_t> count(cells + 1, 0);
  for (const Arc& a : arcs_) {
    glm::ivec3 c0, c1;
    cellRange(a, c0, c1);
    for (int z = c0.z; z <= c1.z; ++z)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) ++count[(static_cast<size_t>(z) * dims_.y + y) * dims_.x + x + 1];
  }
  for (size_t i = 0; i < cells; ++i) count[i + 1] += count[i];
  cellStart_ = count;
  cellArcs_.resize(count[cells]);
  for (uint32_t i = 0; i < arcs_.size(); ++i) {
    glm::ivec3 c0, c1;
    cellRange(arcs_[i], c0, c1);
    for (int z = c0.z; z <= c1.z; ++z)
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) cellArcs_[count[(static_cast<size_t>(z) * dims_.y + y) * dims_.x + x]++] = i;
  }
}

void RidgeArcs::profile(const Arc& a, double x, double z, double& dark, double& height) const {
  const RidgeArcOptions& o = options_;
  dark = height = 0.0;
  const double ax = std::abs(x);
  if (!(ax < o.spread)) return;
  // Step 1: the crest z_c(x) and the distance from it, measured across the crest.
  const double root = std::sqrt(x * x + kApexRound * kApexRound);
  const double zc = a.zApex - o.droop * (root - kApexRound);
  const double dzc = -o.droop * x / root;
  const double d = (z - zc) / std::sqrt(1 + dzc * dzc);
  // Step 2: the band narrows to half toward the ends and fades out over the last 45%.
  const double r = ax / o.spread;
  const double hw = o.width * (1 - 0.5 * r * r);
  const double t = d / hw;
  if (!(std::abs(t) < 1)) return;
  const double bump = (1 - t * t) * (1 - t * t);
  const double fade = 1 - smooth01(0.55, 1.0, r);
  dark = o.darkening * bump * fade;
  height = hw * bump * fade;
}

RidgeArcs::Sample RidgeArcs::sample(const Vec3& p) const {
  Sample out;
  if (arcs_.empty()) return out;
  const glm::ivec3 c = glm::ivec3(glm::floor((p - gridLo_) / cell_));
  if (glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, dims_))) return out;
  const size_t cell = (static_cast<size_t>(c.z) * dims_.y + c.y) * dims_.x + c.x;
  for (uint32_t k = cellStart_[cell]; k < cellStart_[cell + 1]; ++k) {
    const Arc& a = arcs_[cellArcs_[k]];
    if (glm::any(glm::lessThan(p, a.lo)) || glm::any(glm::greaterThan(p, a.hi))) continue;
    // The chart: z along the parent from the pierce point, x around it (arc length at the
    // parent's radius), both in branch radii; and the weights off the chart's plane.
    const DVec3 d = DVec3(p) - DVec3(a.in.point);
    const DVec3 axis(a.in.parentAxis);
    const double za = glm::dot(d, axis);
    const DVec3 q = d - za * axis;
    const double rho = glm::length(q);
    if (!(rho > 0)) continue;
    const double cx = glm::dot(q, DVec3(a.out)), cy = glm::dot(q, DVec3(a.side));
    const double theta = std::atan2(cy, cx);
    const double rA = a.in.parentRadius, rB = a.in.branchRadius;
    const double x = rA * theta / rB, z = (za - a.zPierce) / rB;
    // Only on the parent's front (the branch's side) and near its bark, not on the branch:
    // the weight falls from 0.6 to 1.5 branch radii outside the parent's radius, and
    // within 1.2 branch radii of the branch's axis (its surface and the fillet at its base).
    const double front = smooth01(0.0, 0.35, cx / rho);
    const double near = 1 - smooth01(0.6, 1.5, (rho - rA) / rB);
    const DVec3 b(a.in.branchAxis);
    const double offAxis = glm::length(d - std::max(0.0, glm::dot(d, b)) * b) / rB;
    const double w = front * near * smooth01(1.0, 1.2, offAxis);
    if (!(w > 0)) continue;
    double dark, h;
    profile(a, x, z, dark, h);
    out.darkness = std::max(out.darkness, dark * w);
    if (options_.relief > 0 && h > 0) {
      // Height gradient by central differences in the chart, then to world: d/dx along the
      // parent's circumference (scaled from radius rA to ρ), d/dz along its axis.
      const double e = 1e-3;
      double d0, hxp, hxm, hzp, hzm;
      profile(a, x + e, z, d0, hxp);
      profile(a, x - e, z, d0, hxm);
      profile(a, x, z + e, d0, hzp);
      profile(a, x, z - e, d0, hzm);
      const double gx = (hxp - hxm) / (2 * e) * rA / rho, gz = (hzp - hzm) / (2 * e);
      const DVec3 around = glm::cross(axis, q / rho);
      out.heightGradient += Vec3(options_.relief * w * (gx * around + gz * axis));
    }
  }
  return out;
}

std::vector<RidgeCrestPoint> RidgeArcs::crest(const RidgeArc& arc, const RidgeArcOptions& o, int count) {
  std::vector<RidgeCrestPoint> out;
  const std::optional<Arc> a = chart(arc, o);
  if (!a || count < 2) return out;
  const double rA = a->in.parentRadius, rB = a->in.branchRadius;
  const DVec3 axis(a->in.parentAxis), outward(a->out), side(a->side), b(a->in.branchAxis), P(a->in.point);
  out.reserve(static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    // The crest z_c(x) and the band's half-width and fade, as in profile().
    const double x = o.spread * (2.0 * i / (count - 1) - 1);
    const double zc = a->zApex - o.droop * (std::sqrt(x * x + kApexRound * kApexRound) - kApexRound);
    const double r = std::abs(x) / o.spread;
    const double hw = o.width * (1 - 0.5 * r * r);
    const double fade = 1 - smooth01(0.55, 1.0, r);
    // The chart point on the parent's cylinder, and the weights of sample() there (near = 1).
    const double theta = x * rB / rA;
    const DVec3 n = std::cos(theta) * outward + std::sin(theta) * side;
    const DVec3 p = P + (a->zPierce + zc * rB) * axis + rA * n;
    const DVec3 d = p - P;
    const double offAxis = glm::length(d - std::max(0.0, glm::dot(d, b)) * b) / rB;
    RidgeCrestPoint c;
    c.position = Vec3(p);
    c.normal = Vec3(n);
    c.halfWidth = static_cast<float>(hw * rB);
    c.weight = static_cast<float>(fade * smooth01(0.0, 0.35, std::cos(theta)) * smooth01(1.0, 1.2, offAxis));
    out.push_back(c);
  }
  return out;
}

}  // namespace sprig::textures
