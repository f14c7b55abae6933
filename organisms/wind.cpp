#include "organisms/wind.h"

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

lsystem::Skeleton swayInWind(const lsystem::Skeleton& sk, const WindOptions& w, double t) {
  if (!(w.speed > 0) || sk.internodes.empty()) return sk;
  lsystem::Skeleton out = sk;
  const size_t n = sk.internodes.size();
  const auto children = sk.children();

  const double az = radians(w.directionDeg);
  const DVec3 toward(std::sin(az), 0.0, std::cos(az));
  const DVec3 upAxis(0, 1, 0);
  const DVec3 leanAxis = glm::normalize(glm::cross(upAxis, toward));  // turns +Y toward `toward`

  double ylo = sk.internodes[0].start.y, yhi = ylo;
  for (const auto& in : sk.internodes) {
    ylo = std::min({ylo, in.start.y, in.end.y});
    yhi = std::max({yhi, in.start.y, in.end.y});
  }
  const double height = std::max(yhi - ylo, 1e-9);
  const double twoPi = 2.0 * kPi;
  const double gust = 1.0 + 0.25 * std::sin(twoPi * w.gustHz * t + phase(w.seed, kSeedGust, 0)) +
                      0.10 * std::sin(twoPi * 2.3 * w.gustHz * t + phase(w.seed, kSeedGust, 1));
  const double lean = w.leanPerSpeed2 * w.speed * w.speed * gust;

  // Parents before children; each branch axis (a chain of one order) shares one phase and
  // spreads its sway over its internodes by length.
  std::vector<size_t> order;
  order.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (sk.internodes[i].parent < 0) order.push_back(i);
  for (size_t k = 0; k < order.size(); ++k)
    for (int32_t c : children[order[k]]) order.push_back(static_cast<size_t>(c));
  std::vector<size_t> axisOf(n);
  std::vector<double> axisLength(n, 0.0);
  for (size_t i : order) {
    const auto& in = sk.internodes[i];
    const bool continues = in.parent >= 0 && sk.internodes[in.parent].order == in.order;
    axisOf[i] = continues ? axisOf[in.parent] : i;
    axisLength[axisOf[i]] += in.length();
  }

  std::vector<DMat3> turn(n, DMat3(1.0));
  for (size_t i : order) {
    const auto& in = sk.internodes[i];
    auto& o = out.internodes[i];
    const DMat3 parentTurn = in.parent >= 0 ? turn[in.parent] : DMat3(1.0);
    DMat3 local(1.0);
    if (in.order == 0) {
      local = rotation(leanAxis, lean * in.length() / height);
    } else {
      const size_t axis = axisOf[i];
      const double share = in.length() / std::max(axisLength[axis], 1e-12);
      const double gain = std::pow(w.orderGain, in.order - 1);
      const double amp = w.swayPerSpeed * w.speed * gain * share;
      const double hz = w.swayHz * gain;
      const DVec3 dir = in.length() > 0 ? glm::normalize(in.end - in.start) : upAxis;
      const DVec3 k1 = perpendicular(dir, toward), k2 = perpendicular(dir, k1);
      const double a1 = amp * (0.5 + std::sin(twoPi * hz * t + phase(w.seed, kSeedSway, axis, 0)));
      const double a2 = 0.35 * amp * std::sin(twoPi * 1.37 * hz * t + phase(w.seed, kSeedSway, axis, 1));
      local = rotation(k2, a2) * rotation(k1, a1);
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
    // Rigidly with the internode it hangs on.
    DMat3 r(1.0);
    DVec3 from(0), to(0);
    if (g.internode >= 0 && static_cast<size_t>(g.internode) < n) {
      r = turn[g.internode];
      from = sk.internodes[g.internode].end;
      to = out.internodes[g.internode].end;
    }
    // Flutter about the attachment point, across the blade.
    const DVec3 pivot = g.kind == lsystem::Organ::Kind::Polygon && !g.points.empty() ? g.points[0] : g.position;
    const DVec3 heading = glm::length(g.heading) > 0 ? glm::normalize(g.heading) : upAxis;
    // cpfg's textured cylinders are wood drawn as meshes: they follow their internode, no flutter.
    const bool tube = g.name == lsystem::kTexturedCylinderName || g.name == lsystem::kTexturedGcName;
    const double f = tube ? 0.0
                          : w.flutterPerSpeed * w.speed * std::sin(twoPi * w.flutterHz * t + phase(w.seed, kSeedLeaf, oi));
    const DMat3 flutter = rotation(perpendicular(heading, toward), f);
    const DMat3 all = r * flutter;
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
