#include "organisms/wind.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/rng.h"
#include "lsystem/turtle.h"

namespace sprig::organisms {

namespace {

constexpr uint64_t kSeedGust = 0x47555354ull;   // "GUST"
constexpr uint64_t kSeedSway = 0x53574159ull;   // "SWAY"
constexpr uint64_t kSeedLeaf = 0x4c454146ull;   // "LEAF"

/// Rotation by angle (radians) about unit axis k (Rodrigues).
DMat3 rotation(const DVec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
  // Column-major: m[col][row].
  return DMat3(t * k.x * k.x + c, t * k.x * k.y + s * k.z, t * k.x * k.z - s * k.y,  //
               t * k.x * k.y - s * k.z, t * k.y * k.y + c, t * k.y * k.z + s * k.x,  //
               t * k.x * k.z + s * k.y, t * k.y * k.z - s * k.x, t * k.z * k.z + c);
}

/// A unit vector perpendicular to both a and b, or to a alone when they are parallel.
DVec3 perpendicular(const DVec3& a, const DVec3& b) {
  DVec3 k = glm::cross(a, b);
  if (glm::length(k) > 1e-9) return glm::normalize(k);
  k = glm::cross(a, std::abs(a.x) < 0.9 ? DVec3(1, 0, 0) : DVec3(0, 0, 1));
  return glm::normalize(k);
}

/// A phase in [0, 2π) from the seed.
double phase(uint64_t seed, uint64_t purpose, uint64_t id, uint64_t k = 0) {
  Rng rng(deriveSeed(seed, {purpose, id, k}));
  return 2.0 * kPi * rng.uniform();
}

}  // namespace

double loopHz(double hz, double loopSeconds) {
  if (!(loopSeconds > 0)) return hz;
  return std::max(1.0, std::round(hz * loopSeconds)) / loopSeconds;
}

double WindRig::gust(double t) const {
  const double twoPi = 2.0 * kPi;
  return 1.0 + kGustGain1 * std::sin(twoPi * gustHz[0] * t + gustPhase[0]) +
         kGustGain2 * std::sin(twoPi * gustHz[1] * t + gustPhase[1]);
}

namespace {

/// The rig's internodes: axes, shares, amplitudes, frequencies and phases. rig.order set.
void rigInternodes(const lsystem::Skeleton& sk, WindRig& rig) {
  const WindOptions& w = rig.options;
  const size_t n = sk.internodes.size();
  const DVec3 upAxis(0, 1, 0);
  const double az = radians(w.directionDeg);
  const DVec3 toward(std::sin(az), 0.0, std::cos(az));
  std::vector<double> axisLength(n, 0.0), before(n, 0.0);
  rig.internodes.assign(n, InternodeWind{});
  for (size_t i : rig.order) {
    const auto& in = sk.internodes[i];
    InternodeWind& iw = rig.internodes[i];
    const bool continues = in.parent >= 0 && sk.internodes[in.parent].order == in.order;
    iw.axis = continues ? rig.internodes[in.parent].axis : i;
    iw.length = in.length();
    before[i] = axisLength[iw.axis];
    axisLength[iw.axis] += iw.length;
  }
  for (size_t i : rig.order) {
    const auto& in = sk.internodes[i];
    InternodeWind& iw = rig.internodes[i];
    if (in.order == 0) {
      const bool continues = in.parent >= 0 && sk.internodes[in.parent].order == 0;
      iw.axisFrom = continues ? rig.internodes[in.parent].axisTo : 0.0;
      iw.axisTo = iw.axisFrom + iw.length / rig.height;
      continue;
    }
    const double total = std::max(axisLength[iw.axis], 1e-12);
    iw.axisFrom = before[i] / total;
    iw.axisTo = (before[i] + iw.length) / total;
    const double share = iw.length / total;
    const double gain = std::pow(w.orderGain, in.order - 1);
    iw.amplitude = w.swayPerSpeed * w.speed * gain * share;
    iw.hz = loopHz(w.swayHz * gain, w.loopSeconds);
    iw.hz2 = loopHz(kCrossSwayHzRatio * w.swayHz * gain, w.loopSeconds);
    const DVec3 dir = iw.length > 0 ? glm::normalize(in.end - in.start) : upAxis;
    iw.k1 = perpendicular(dir, toward);
    iw.k2 = perpendicular(dir, iw.k1);
    iw.phase1 = phase(w.seed, kSeedSway, iw.axis, 0);
    iw.phase2 = phase(w.seed, kSeedSway, iw.axis, 1);
  }
}

/// The rig's organs: pivots, flutter axes, amplitudes and phases.
void rigOrgans(const lsystem::Skeleton& sk, WindRig& rig) {
  const WindOptions& w = rig.options;
  const double az = radians(w.directionDeg);
  const DVec3 toward(std::sin(az), 0.0, std::cos(az));
  rig.organs.assign(sk.organs.size(), OrganWind{});
  for (size_t oi = 0; oi < sk.organs.size(); ++oi) {
    const lsystem::Organ& g = sk.organs[oi];
    OrganWind& ow = rig.organs[oi];
    ow.pivot = g.kind == lsystem::Organ::Kind::Polygon && !g.points.empty() ? g.points[0] : g.position;
    const DVec3 heading = glm::length(g.heading) > 0 ? glm::normalize(g.heading) : DVec3(0, 1, 0);
    ow.axis = perpendicular(heading, toward);
    // cpfg's textured cylinders are wood drawn as meshes: they follow their internode, no flutter.
    const bool tube = g.name == lsystem::kTexturedCylinderName || g.name == lsystem::kTexturedGcName;
    ow.amplitude = tube ? 0.0 : w.flutterPerSpeed * w.speed;
    ow.hz = loopHz(w.flutterHz, w.loopSeconds);
    ow.phase = phase(w.seed, kSeedLeaf, oi);
  }
}

}  // namespace

WindRig windRig(const lsystem::Skeleton& sk, const WindOptions& w) {
  WindRig rig;
  rig.options = w;
  const size_t n = sk.internodes.size();
  const double az = radians(w.directionDeg);
  const DVec3 toward(std::sin(az), 0.0, std::cos(az));
  rig.leanAxis = glm::normalize(glm::cross(DVec3(0, 1, 0), toward));  // turns +Y toward `toward`
  if (n > 0) {
    double ylo = sk.internodes[0].start.y, yhi = ylo;
    for (const auto& in : sk.internodes) {
      ylo = std::min({ylo, in.start.y, in.end.y});
      yhi = std::max({yhi, in.start.y, in.end.y});
    }
    rig.height = std::max(yhi - ylo, 1e-9);
  }
  rig.leanTop = w.leanPerSpeed2 * w.speed * w.speed;
  rig.gustHz[0] = loopHz(w.gustHz, w.loopSeconds);
  rig.gustHz[1] = loopHz(kGustHzRatio2 * w.gustHz, w.loopSeconds);
  rig.gustPhase[0] = phase(w.seed, kSeedGust, 0);
  rig.gustPhase[1] = phase(w.seed, kSeedGust, 1);
  // Parents before children.
  const auto children = sk.children();
  rig.order.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (sk.internodes[i].parent < 0) rig.order.push_back(i);
  for (size_t k = 0; k < rig.order.size(); ++k)
    for (int32_t c : children[rig.order[k]]) rig.order.push_back(static_cast<size_t>(c));
  rigInternodes(sk, rig);
  rigOrgans(sk, rig);
  return rig;
}

lsystem::Skeleton swayInWind(const lsystem::Skeleton& sk, const WindOptions& w, double t) {
  if (!(w.speed > 0) || sk.internodes.empty()) return sk;
  const WindRig rig = windRig(sk, w);
  lsystem::Skeleton out = sk;
  const size_t n = sk.internodes.size();
  const double twoPi = 2.0 * kPi;
  const double lean = rig.leanTop * rig.gust(t);

  std::vector<DMat3> turn(n, DMat3(1.0));
  for (size_t i : rig.order) {
    const auto& in = sk.internodes[i];
    const InternodeWind& iw = rig.internodes[i];
    auto& o = out.internodes[i];
    const DMat3 parentTurn = in.parent >= 0 ? turn[in.parent] : DMat3(1.0);
    DMat3 local(1.0);
    if (in.order == 0) {
      local = rotation(rig.leanAxis, lean * iw.length / rig.height);
    } else {
      const double a1 = iw.amplitude * (kSwayBias + std::sin(twoPi * iw.hz * t + iw.phase1));
      const double a2 = kCrossSwayGain * iw.amplitude * std::sin(twoPi * iw.hz2 * t + iw.phase2);
      local = rotation(iw.k2, a2) * rotation(iw.k1, a1);
    }
    turn[i] = local * parentTurn;
    if (in.parent >= 0) {
      const auto& p = sk.internodes[in.parent];
      o.start = out.internodes[in.parent].end + parentTurn * (in.start - p.end);
    }
    o.end = o.start + turn[i] * (in.end - in.start);
    o.up = turn[i] * in.up;
  }

  for (size_t oi = 0; oi < out.organs.size(); ++oi) {
    lsystem::Organ& g = out.organs[oi];
    const OrganWind& ow = rig.organs[oi];
    // Rigidly with the internode it hangs on.
    DMat3 r(1.0);
    DVec3 from(0), to(0);
    if (g.internode >= 0 && static_cast<size_t>(g.internode) < n) {
      r = turn[g.internode];
      from = sk.internodes[g.internode].end;
      to = out.internodes[g.internode].end;
    }
    // Flutter about the attachment point, across the blade.
    const double f = ow.amplitude > 0 ? ow.amplitude * std::sin(twoPi * ow.hz * t + ow.phase) : 0.0;
    const DMat3 flutter = rotation(ow.axis, f);
    const DMat3 all = r * flutter;
    const DVec3 pivot = ow.pivot;
    auto move = [&](const DVec3& x) { return to + r * (pivot - from) + all * (x - pivot); };
    for (DVec3& p : g.points) p = move(p);
    for (DVec3& nrm : g.normals) nrm = all * nrm;  // surface files' and textured organs' normals turn with them
    g.position = move(g.position);
    g.heading = all * g.heading;
    g.left = all * g.left;
    g.up = all * g.up;
  }
  return out;
}

}  // namespace sprig::organisms
