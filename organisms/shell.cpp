#include "organisms/shell.h"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "core/rng.h"

namespace sprig::organisms {

using blobtree::BlobTree;
using blobtree::Bend;
using blobtree::NodeId;
using blobtree::TextureAttr;

namespace {

constexpr double kEps = 1e-9;
/// How far the inside canal's newest copy reaches past the canal's tip (unit frame): beyond
/// the tip's rounded end, so the tube is open there.
constexpr float kCanalOpening = 1.0f;

TextureAttr partTexture(ShellPart part) {
  TextureAttr t;
  t.textureId = static_cast<uint16_t>(part);
  return t;
}

Mat4 toFloat(const glm::dmat4& m) { return Mat4(m); }
Vec3 apply(const glm::dmat4& m, const Vec3& p) { return Vec3(m * glm::dvec4(DVec3(p), 1.0)); }

/// The paper's local frame for varices and bumps has +y towards the apex; ours has +y away
/// from it. The reflection maps one to the other (spines are symmetric across z).
const glm::dmat4 kApexSide{1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0};

glm::dmat4 rotateZDeg(double deg) { return glm::rotate(glm::dmat4(1.0), radians(deg), glm::dvec3(0, 0, 1)); }

class ShellBuilder {
 public:
  ShellBuilder(const ShellParams& p, ShellModel& m) : p_(p), m_(m), t_(m.tree), s_(p.spiral), gen_(p.generating) {
    if (p.canal)
      for (const GeneratingPrimitive& g : p.canal->primitives(p.spiral)) gen_.primitives.push_back(g);
  }

  void build();

 private:
  struct Calibration {
    float k = 1.0f;       // radius factor
    float shift = 0.0f;   // outward shift of the generating surface, unit frame
    float canalK = 1.0f;  // radius factor of the canal's primitives (k, or inner_scale of the main canal's)
  };
  // Generating surfaces.
  void placeGenerating(std::vector<NodeId>& out, double theta, const Calibration& cal, ShellPart part, bool withCanal,
                       float canalPastTip = 0.0f);
  Calibration calibrate(float relativeSize) const;
  std::vector<double> sweepAngles(double from, double to) const;
  std::vector<std::vector<double>> bySection(const std::vector<double>& angles) const;
  NodeId insideWhorl(const Calibration& cal);
  // Parts.
  void varix(std::vector<NodeId>& parts, int number, double theta);
  void axialRow(std::vector<NodeId>& out, int number, double theta, const std::vector<float>& sizes);
  NodeId bumps();
  NodeId opening(NodeId shell);
  const std::vector<VarixSpine>& spineRow(double theta) const;
  int whorlOf(double theta) const;
  Bend canalBend(const GeneratingPrimitive& g) const;
  NodeId arcCone(Vec3 a, Vec3 b, float radiusA, float radiusB, std::span<const Bend> bends, double totalDeg,
                 const glm::dmat4& m, ShellPart part);

  const ShellParams& p_;
  ShellModel& m_;
  BlobTree& t_;
  HelicoSpiral s_;
  GeneratingSurface gen_;  // p.generating plus the canal
  double end_ = 0.0, step_ = 0.0;
  Calibration cal_;  // calibration of the main generating surface
};


int ShellBuilder::whorlOf(double theta) const {
  return std::max(1, static_cast<int>(std::ceil((theta - p_.startDeg) / p_.whorlDeg - 1e-6)));
}

const std::vector<VarixSpine>& ShellBuilder::spineRow(double theta) const {
  static const std::vector<VarixSpine> kNone;
  const auto& rows = p_.varices.spinesByWhorl;
  if (rows.empty()) return kNone;
  const size_t w = static_cast<size_t>(whorlOf(theta));
  return rows[std::min(w, rows.size()) - 1];
}

Bend ShellBuilder::canalBend(const GeneratingPrimitive& g) const {
  return Bend::fromAngle(g.a, g.b, g.bendDirection, static_cast<float>(radians(g.bendDeg)));
}

NodeId ShellBuilder::arcCone(Vec3 a, Vec3 b, float radiusA, float radiusB, std::span<const Bend> bends,
                             double totalDeg, const glm::dmat4& m, ShellPart part) {
  // A cone bent by `bends` (applied in order, each endpoint-preserving) as a polyline of
  // straight cones through points of the bent axis, one per kMaxArcDeg of turning, united
  // (max: no bulge at the joints, and a Lipschitz bound of one cone). The polyline strays
  // from the arc by at most chord·tan(kMaxArcDeg/4)/2 (0.4% of a segment's length) and
  // evaluates as SSE cone batches, where a bend warp costs a scalar atan2 per point.
  // m (a similarity of uniform scale) places the result; radii scale with it.
  constexpr double kMaxArcDeg = 10.0;
  const int segments = std::max(1, static_cast<int>(std::ceil(totalDeg / kMaxArcDeg - 1e-9)));
  const float scale = static_cast<float>(glm::length(DVec3(m[0])));
  auto axis = [&](float t) {
    Vec3 q = a + t * (b - a);
    for (const Bend& bend : bends) q = bend.worldFromLocal(q);
    return apply(m, q);
  };
  std::vector<NodeId> cones;
  Vec3 prev = axis(0.0f);
  for (int i = 1; i <= segments; ++i) {
    const float t0 = static_cast<float>(i - 1) / segments, t1 = static_cast<float>(i) / segments;
    const Vec3 next = axis(t1);
    cones.push_back(t_.cone(prev, next, scale * (radiusA + t0 * (radiusB - radiusA)),
                            scale * (radiusA + t1 * (radiusB - radiusA)), partTexture(part)));
    prev = next;
  }
  return cones.size() == 1 ? cones[0] : t_.unite(cones);
}

ShellBuilder::Calibration ShellBuilder::calibrate(float relativeSize) const {
  // The iso surface of a row of points summed along the curved spiral is smaller than one
  // point's and shifted towards the axis (the concave side gathers more field). Solve for a
  // radius factor k and an outward shift so the cross-section, measured in 12 directions
  // around the generating curve on a primitive and midway between two, has mean radius
  // relativeSize·D(θ) and its centre on the spiral. Self-similarity makes one angle enough.
  const double th0 = p_.startDeg + p_.whorlDeg;
  const blobtree::Kernel kernel = t_.kernel();
  Calibration cal{relativeSize, 0.0f};  // canalK: k, once calibrated
  struct RowPoint {
    DVec3 centre, outward;
    double d;
  };
  std::vector<RowPoint> row;
  for (int j = -12; j <= 12; ++j) {
    const double tj = th0 + j * step_;
    const DVec3 c = s_.point(tj);
    row.push_back({c, glm::normalize(DVec3(c.x, 0.0, c.z)), s_.curveSize(tj)});
  }
  const float isoToSupport = blobtree::supportRadius(kernel, 1.0f);
  auto field = [&](const DVec3& q) {
    double f = 0.0;
    for (const RowPoint& rp : row) {
      const DVec3 c = rp.centre + static_cast<double>(cal.shift) * rp.d * rp.outward;
      const double big = isoToSupport * cal.k * rp.d;
      f += blobtree::kernelValue(kernel, static_cast<float>(glm::dot(q - c, q - c) / (big * big)));
    }
    return f;
  };
  if (field(s_.point(th0) + relativeSize * s_.curveSize(th0) * DVec3(0, 1, 0)) < 0.5) return cal;  // sparse row
  // Mean radius and centre offset (first Fourier coefficient along x) of the cross-section.
  auto measure = [&](double& mean, double& c1) {
    mean = 0.0;
    c1 = 0.0;
    int count = 0;
    for (double half : {0.0, 0.5}) {
      const double tt = th0 + half * step_;
      const DVec3 c = s_.point(tt);
      const DVec3 e = glm::normalize(DVec3(c.x, 0.0, c.z));
      const double d = s_.curveSize(tt);
      for (int a = 0; a < 12; ++a) {
        const double phi = radians(30.0 * a);
        const DVec3 dir = std::cos(phi) * e + std::sin(phi) * DVec3(0, 1, 0);
        double lo = 0.0, hi = 3.0;
        for (int i = 0; i < 32; ++i) {
          const double mid = 0.5 * (lo + hi);
          (field(c + mid * d * dir) > 0.5 ? lo : hi) = mid;
        }
        const double r = 0.5 * (lo + hi);
        mean += r;
        c1 += r * std::cos(phi);
        ++count;
      }
    }
    mean /= count;
    c1 = 2.0 * c1 / count;
  };
  for (int iter = 0; iter < 4; ++iter) {
    double mean = 0.0, c1 = 0.0;
    float lo = 0.05f * relativeSize, hi = relativeSize;
    for (int i = 0; i < 24; ++i) {
      cal.k = 0.5f * (lo + hi);
      measure(mean, c1);
      (mean < relativeSize ? lo : hi) = cal.k;
    }
    cal.k = 0.5f * (lo + hi);
    measure(mean, c1);
    cal.shift = static_cast<float>(cal.shift - c1);
  }
  cal.canalK = cal.k;
  return cal;
}

std::vector<double> ShellBuilder::sweepAngles(double from, double to) const {
  // Surfaces on the global grid startDeg + iΔθ, plus the end angle itself.
  std::vector<double> out;
  const double i0 = std::ceil((from - p_.startDeg) / step_ - kEps);
  for (double i = std::max(0.0, i0);; i += 1.0) {
    const double th = p_.startDeg + i * step_;
    if (th > to + kEps) break;
    out.push_back(th);
  }
  if (out.empty() || out.back() < to - 1e-6) out.push_back(to);
  return out;
}

std::vector<std::vector<double>> ShellBuilder::bySection(const std::vector<double>& angles) const {
  // Surface i (on the grid startDeg + iΔθ) belongs to section ⌊i / surfacesPerSection⌋;
  // empty sections are dropped.
  std::vector<std::vector<double>> out;
  size_t first = 0;
  for (double th : angles) {
    const size_t sec = static_cast<size_t>(std::floor((th - p_.startDeg) / step_ + 1e-6)) / p_.surfacesPerSection;
    if (out.empty()) first = sec;
    if (sec - first >= out.size()) out.resize(sec - first + 1);
    out[sec - first].push_back(th);
  }
  std::erase_if(out, [](const std::vector<double>& v) { return v.empty(); });
  return out;
}

void ShellBuilder::placeGenerating(std::vector<NodeId>& out, double theta, const Calibration& cal, ShellPart part,
                                   bool withCanal, float canalPastTip) {
  // The calibration shifts the row's primitives so the summed tube is centred on the spiral;
  // the canal hangs from that tube and reaches the shell axis in the spiral's own frame, so
  // it is placed there, unshifted. Shifted with the row, every copy's canal stood
  // shift·D(θ) off the axis, and the opening's canal (a shift about twice the main one's
  // for λ 1.6, β 14°) cut through the canal's wall and the axial spines' roots.
  const glm::dmat4 onSpiral = s_.shellFromGenerating(theta);
  const glm::dmat4 shifted = onSpiral * glm::translate(glm::dmat4(1.0), glm::dvec3(cal.shift, 0, 0));
  const double d = s_.curveSize(theta);
  for (const GeneratingPrimitive& g : gen_.primitives) {
    if (g.lastDeg > 0.0 && theta < end_ - g.lastDeg - kEps) continue;
    if (g.canal && !withCanal) continue;
    const glm::dmat4& m = g.canal ? onSpiral : shifted;
    const float radiusScale = g.canal ? cal.canalK : cal.k;
    if (g.kind == GeneratingPrimitive::Kind::Point) {
      out.push_back(t_.point(apply(m, g.a), static_cast<float>(g.radiusA * radiusScale * d), partTexture(part)));
    } else if (g.bendDeg == 0.0f) {
      // canalPastTip lengthens a straight canal cone along its axis, its radius continued.
      const float len = glm::length(g.b - g.a);
      const float ext = g.canal && len > 0.0f ? canalPastTip : 0.0f;
      const Vec3 b = g.b + (ext / std::max(len, 1e-6f)) * (g.b - g.a);
      const float rb = std::max(0.2f * g.radiusB, g.radiusB + (g.radiusB - g.radiusA) * ext / std::max(len, 1e-6f));
      out.push_back(t_.cone(apply(m, g.a), apply(m, b), static_cast<float>(g.radiusA * radiusScale * d),
                            static_cast<float>(rb * radiusScale * d), partTexture(part)));
    } else {
      const Bend bend = canalBend(g);
      out.push_back(arcCone(g.a, g.b, g.radiusA * radiusScale, g.radiusB * radiusScale, std::span(&bend, 1),
                            std::abs(g.bendDeg), m, part));
    }
  }
}

void ShellBuilder::varix(std::vector<NodeId>& parts, int number, double theta) {
  // Eq. 11-13: spines Bk bent towards +y, scaled by (σᵢ, σᵢ, σ_max), moved to the edge x_k,
  // rotated by αᵢ about z; plus two tori; the whole varix placed by P(Bv, θ).
  const VarixOptions& v = p_.varices;
  const std::vector<VarixSpine>& row = spineRow(theta);
  const glm::dmat4 shellFromVarix = s_.shellFromGenerating(theta) * kApexSide;
  const double d = s_.curveSize(theta);
  float sigmaMax = 0.0f;
  for (const VarixSpine& sp : row) sigmaMax = std::max(sigmaMax, sp.size);
  const float len = v.spineLength;
  for (size_t i = 0; i < row.size(); ++i) {
    const VarixSpine& sp = row[i];
    const float tip = sp.size < v.shortSize ? v.shortTipRadius : v.tipRadius;
    const Bend bend = Bend::fromAngle(Vec3(0.0f), Vec3(len, 0.0f, 0.0f), Vec3(0, 1, 0),
                                      static_cast<float>(radians(std::max(v.bendDeg, 0.0f))));
    const NodeId c = arcCone(Vec3(0.0f), Vec3(len, 0.0f, 0.0f), v.baseRadius, tip, std::span(&bend, 1),
                             std::max(v.bendDeg, 0.0f), glm::dmat4(1.0), ShellPart::VarixSpine);
    const double across = v.widenAcross ? sigmaMax : sp.size;
    const glm::dmat4 varixFromSpine = rotateZDeg(sp.angleDeg) *
                                      glm::translate(glm::dmat4(1.0), glm::dvec3(v.edge, 0, 0)) *
                                      glm::scale(glm::dmat4(1.0), glm::dvec3(sp.size, sp.size, across));
    const glm::dmat4 shellFromSpine = shellFromVarix * varixFromSpine;
    parts.push_back(t_.transform(c, toFloat(shellFromSpine)));
    SpineRecord rec;
    rec.part = ShellPart::VarixSpine;
    rec.varix = number;
    rec.index = static_cast<int>(i);
    rec.size = sp.size;
    rec.thetaDeg = theta;
    rec.base = apply(shellFromSpine, Vec3(0.0f));
    rec.tip = apply(shellFromSpine, Vec3(len, 0.0f, 0.0f));
    rec.lengthShell = static_cast<float>(sp.size * len * d);
    rec.tipRadius = static_cast<float>(sp.size * tip * d);
    m_.spines.push_back(rec);
  }
  if (v.tori) {
    for (float major : {1.0f, v.torusOuter}) {
      NodeId tor = t_.torus(Vec3(0.0f), Vec3(0, 0, 1), major, v.torusRadius, partTexture(ShellPart::VarixSpine));
      parts.push_back(t_.transform(tor, toFloat(shellFromVarix)));
    }
  }
  m_.varixDeg.push_back(theta);
}

void ShellBuilder::axialRow(std::vector<NodeId>& out, int number, double theta, const std::vector<float>& sizes) {
  const AxialSpineOptions& a = p_.axialSpines;
  const GeneratingPrimitive* canal = nullptr;
  for (const GeneratingPrimitive& g : gen_.primitives)
    if (g.canal && g.kind == GeneratingPrimitive::Kind::Cone) canal = &g;
  if (!canal || sizes.empty()) return;
  const glm::dmat4 m = s_.shellFromGenerating(theta);
  const double d = s_.curveSize(theta);
  const Bend cb = canalBend(*canal);
  const Vec3 dir = glm::normalize(Vec3(1.0f, a.downTilt, 0.0f));
  for (size_t j = 0; j < sizes.size(); ++j) {
    const float tj = sizes.size() == 1 ? a.firstT
                                        : a.firstT + (a.lastT - a.firstT) * static_cast<float>(j) / (sizes.size() - 1);
    Vec3 base;
    if (p_.canal) {
      base = p_.canal->pointAt(s_, tj);
    } else {
      const Vec3 onAxis = canal->a + tj * (canal->b - canal->a);
      base = canal->bendDeg != 0.0f ? cb.worldFromLocal(onAxis) : onAxis;
    }
    const float size = sizes[j];
    const Vec3 tip = base + dir * (a.length * size);
    std::vector<Bend> bends;
    double turning = 0.0;
    if (a.randomBends) {
      // Fig. 9: each spine bent 3°-9° one to three times, per-spine seeded.
      Rng rng(deriveSeed(p_.seed, {0xA71A1ull, static_cast<uint64_t>(number), j}));
      const int n = a.bendsMin + static_cast<int>(rng.below(static_cast<uint32_t>(a.bendsMax - a.bendsMin + 1)));
      for (int b = 0; b < n; ++b) {
        const double phi = rng.uniform(0.0, 2.0 * kPi);
        const double angDeg = rng.uniform(a.bendMinDeg, a.bendMaxDeg);
        const float ang = static_cast<float>(radians(angDeg));
        const Vec3 u = glm::normalize(glm::cross(dir, Vec3(0, 0, 1)));
        const Vec3 w = glm::cross(dir, u);
        const Vec3 bendDir = static_cast<float>(std::cos(phi)) * u + static_cast<float>(std::sin(phi)) * w;
        bends.push_back(Bend::fromAngle(base, tip, bendDir, ang));
        turning += angDeg;
      }
    }
    out.push_back(arcCone(base, tip, a.baseRadius * size, a.tipRadius * size, bends, turning, m, ShellPart::AxialSpine));
    SpineRecord rec;
    rec.part = ShellPart::AxialSpine;
    rec.varix = number;
    rec.index = static_cast<int>(j);
    rec.size = size;
    rec.thetaDeg = theta;
    rec.base = apply(m, base);
    rec.tip = apply(m, tip);
    rec.lengthShell = static_cast<float>(a.length * size * d);
    rec.tipRadius = static_cast<float>(a.tipRadius * size * d);
    m_.spines.push_back(rec);
  }
}

NodeId ShellBuilder::bumps() {
  // Fig. 8: `setsPerSection` rows between each pair of varices; one bump per second spine of
  // the whorl's row, placed like the spines (Eq. 11) and scaled by (σx, σy, σz + 0.8) with
  // σ ~ n(1, 0.1) relative to the bump size.
  const BumpOptions& b = p_.bumps;
  std::vector<NodeId> all;
  const int sections = static_cast<int>(std::ceil((end_ - p_.startDeg) / p_.sectionDeg - kEps));
  for (int sec = 0; sec < sections; ++sec) {
    for (int set = 1; set <= b.setsPerSection; ++set) {
      const double theta = p_.startDeg + (sec + static_cast<double>(set) / (b.setsPerSection + 1)) * p_.sectionDeg;
      if (theta > end_ - kEps) continue;
      const std::vector<VarixSpine>& row = spineRow(theta);
      const glm::dmat4 shellFromLocal = s_.shellFromGenerating(theta) * kApexSide;
      for (size_t i = 0; i < row.size(); i += 2) {
        Rng rng(deriveSeed(p_.seed, {0xB0B5ull, static_cast<uint64_t>(sec), static_cast<uint64_t>(set), i}));
        double sx = 1, sy = 1, sz = 1;
        if (b.random) {
          sx = rng.normal(1.0, b.sdFraction);
          sy = rng.normal(1.0, b.sdFraction);
          sz = rng.normal(1.0, b.sdFraction);
        }
        sx = std::max(sx, 0.2);
        sy = std::max(sy, 0.2);
        sz = std::max(sz, 0.2) + b.elongation;
        // The paper's point scaled by (σx, σy, σz + 0.8) is an ellipsoid; we use the capsule
        // (a cone of equal radii along z) with the same extents: radius s·(σx + σy)/2 across,
        // s·σz' half-length along the spiral. Same look under the n = 400 blend, and a
        // transform-free SSE primitive (a warp per bump doubled the Murex's tracing time).
        const double r = 0.5 * (sx + sy) * b.size;
        const double half = std::max(0.0, sz * b.size - r);
        const glm::dmat4 shellFromBump =
            shellFromLocal * rotateZDeg(row[i].angleDeg) * glm::translate(glm::dmat4(1.0), glm::dvec3(b.edge, 0, 0));
        const float radius = static_cast<float>(r * s_.curveSize(theta));
        all.push_back(t_.cone(apply(shellFromBump, Vec3(0.0f, 0.0f, static_cast<float>(-half))),
                              apply(shellFromBump, Vec3(0.0f, 0.0f, static_cast<float>(half))), radius, radius,
                              partTexture(ShellPart::Bump)));
      }
    }
  }
  m_.bumpCount = all.size();
  if (all.empty()) return 0;
  return t_.blend(all);
}

NodeId ShellBuilder::insideWhorl(const Calibration& cal) {
  // B_inside of Eq. 14, made "using the same method described for the main body whorl":
  // the inside generating surface summed per section, the sections joined by the main
  // body's blend. Each copy of the inside canal is then the main canal's copy at the same θ
  // with a smaller radius and the same centre line, and each group sums the copies of the
  // main body's group of the same sections, so the hollow stays inside the canal's wall
  // and the axial spines keep their roots. (A plain sum of every section summed more canal
  // copies than any group of the main body and bulged through the wall.) Past the lip the
  // surface opens the aperture without its canal, whose copies there would stand beside the
  // canal; the newest copy's straight cone, lengthened past its tip, opens the tube's end.
  const OpeningOptions& o = p_.opening;
  std::vector<NodeId> sums;
  for (const std::vector<double>& sa : bySection(sweepAngles(std::max(p_.startDeg, end_ - o.depthDeg), end_ + o.extendDeg))) {
    std::vector<NodeId> prims;
    for (double th : sa)
      placeGenerating(prims, th, cal, ShellPart::Inside, th <= end_ + kEps, std::abs(th - end_) < kEps ? kCanalOpening : 0.0f);
    sums.push_back(prims.size() == 1 ? prims[0] : t_.blend(prims));
  }
  if (sums.size() == 1) return sums[0];
  if (!p_.controlledBlending) return t_.blend(sums);
  std::vector<std::vector<uint32_t>> groups;
  for (uint32_t i = 0; i + 1 < sums.size(); ++i) groups.push_back({i, i + 1});
  return t_.controlledBlend(sums, groups);
}

NodeId ShellBuilder::opening(NodeId shell) {
  // Eq. 14-15: B = (B_shell − (B_inside − B_previous)) ∪ B_insidewall.
  const OpeningOptions& o = p_.opening;
  // The inside row's factor makes its tube inner_scale of the main one; its canal is the
  // main canal scaled by inner_scale, so the canal's wall is (1 − inner_scale) of its radius.
  // (Scaled by the inside row's factor, the hollow was 0.85 of the canal with the paper's
  // λ 1.3, β 22.5° and 0.76 at λ 1.6, β 14°: the calibration corrects a row of points, not
  // the canal.)
  Calibration kIn = calibrate(o.innerScale);
  kIn.canalK = o.innerScale * cal_.canalK;
  if (o.show == OpeningOptions::Show::InsideSurface) {
    std::vector<NodeId> one;
    placeGenerating(one, end_, kIn, ShellPart::Inside, true);
    return t_.blend(one);
  }
  NodeId cutter = insideWhorl(kIn);
  if (o.show == OpeningOptions::Show::InsideWhorl) return cutter;
  if (o.subtractPrevious && end_ - 360.0 - o.depthDeg > p_.startDeg - 360.0) {
    std::vector<NodeId> prev;
    const double from = std::max(p_.startDeg, end_ - o.depthDeg - 360.0);
    const double to = end_ + o.extendDeg - 360.0;
    if (to > from)
      for (double th : sweepAngles(from, to)) placeGenerating(prev, th, cal_, ShellPart::Whorl, true);
    if (!prev.empty()) cutter = t_.difference(cutter, t_.blend(prev));
  }
  if (o.show == OpeningOptions::Show::Cutter) return cutter;
  NodeId result = t_.difference(shell, cutter);
  if (o.insideWall) {
    const float major = 0.5f * (1.0f + o.innerScale);
    const float minor = 0.6f * (1.0f - o.innerScale);
    NodeId ring = t_.torus(Vec3(0.0f), Vec3(0, 0, 1), major, minor, partTexture(ShellPart::Inside));
    ring = t_.transform(ring, toFloat(s_.shellFromGenerating(end_)));
    const NodeId both[] = {result, ring};
    result = t_.unite(both);
  }
  return result;
}

void ShellBuilder::build() {
  end_ = p_.endDeg();
  step_ = p_.stepDeg();
  m_.endDeg = end_;
  m_.spiral = s_;
  if (p_.calibrateSize) cal_ = calibrate(1.0f);
  m_.sizeCalibration = cal_.k;
  m_.centreShift = cal_.shift;

  // Sections of the main body (Eq. 9): surface i belongs to section ⌊i / surfacesPerSection⌋;
  // a last section of a single surface joins the one before it.
  std::vector<std::vector<double>> secAngles = bySection(sweepAngles(p_.startDeg, end_));
  if (secAngles.size() > 1 && secAngles.back().size() < 2) {
    secAngles[secAngles.size() - 2].push_back(secAngles.back().front());
    secAngles.pop_back();
  }
  for (const auto& sa : secAngles) {
    std::vector<NodeId> prims;
    for (double th : sa) placeGenerating(prims, th, cal_, ShellPart::Whorl, true);
    m_.sections.push_back(t_.blend(prims));
    m_.sectionStartDeg.push_back(sa.front());
  }
  const size_t nSec = m_.sections.size();

  // Varices (and the axial spines below the last ones), each joined to the sections it
  // touches.
  std::vector<double> varixAngles;
  if (p_.varices.enabled) {
    for (int k = 1;; ++k) {
      const double th = p_.startDeg + k * p_.varices.spacingDeg;
      if (th > end_ - 1e-6) break;
      varixAngles.push_back(th);
    }
    if (p_.varices.lipVarix && (varixAngles.empty() || varixAngles.back() < end_ - 1e-6)) varixAngles.push_back(end_);
  }
  std::vector<NodeId> children = m_.sections;
  std::vector<std::vector<uint32_t>> groups;
  for (size_t i = 0; i + 1 < nSec; ++i) groups.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(i + 1)});
  if (nSec == 1) groups.push_back({0});
  const auto& axialRows = p_.axialSpines.rows;
  const size_t firstAxial = varixAngles.size() > axialRows.size() ? varixAngles.size() - axialRows.size() : 0;
  for (size_t vi = 0; vi < varixAngles.size(); ++vi) {
    const double th = varixAngles[vi];
    std::vector<NodeId> parts;
    varix(parts, static_cast<int>(vi + 1), th);
    if (p_.axialSpines.enabled && vi >= firstAxial) {
      // The newest varix takes the last row (Table 2: varix 3 is at the opening).
      const size_t fromEnd = varixAngles.size() - 1 - vi;
      axialRow(parts, static_cast<int>(vi + 1), th, axialRows[axialRows.size() - 1 - fromEnd]);
    }
    if (parts.empty()) continue;
    const NodeId vnode = parts.size() == 1 ? parts[0] : t_.blend(parts);
    // The section holding θ and the one before it (a varix sits at a section boundary).
    size_t sec = 0;
    while (sec + 1 < nSec && m_.sectionStartDeg[sec + 1] <= th + 1e-6) ++sec;
    const uint32_t idx = static_cast<uint32_t>(children.size());
    children.push_back(vnode);
    if (sec > 0)
      groups[sec - 1].push_back(idx);  // group {sec−1, sec}
    else
      groups.front().push_back(idx);
  }
  if (p_.controlledBlending) {
    m_.mainBody = t_.controlledBlend(children, groups);
  } else {
    m_.mainBody = t_.blend(children);
  }

  NodeId shell = m_.mainBody;
  if (p_.bumps.enabled) {
    const NodeId b = bumps();
    if (b != 0) {
      const NodeId both[] = {shell, b};
      shell = p_.bumps.blendN > 1.0f ? t_.ricci(both, p_.bumps.blendN) : t_.blend(both);
    }
  }
  if (p_.opening.enabled) shell = opening(shell);
  m_.shellRoot = shell;
  m_.worldFromShell = p_.pose * (p_.apexUp ? glm::rotate(glm::dmat4(1.0), kPi, glm::dvec3(1, 0, 0)) : glm::dmat4(1.0));
  m_.root = m_.worldFromShell != glm::dmat4(1.0) ? t_.transform(shell, toFloat(m_.worldFromShell)) : shell;
}

}  // namespace

double ShellParams::endDeg() const { return ageDeg ? *ageDeg : whorls * whorlDeg; }
double ShellParams::stepDeg() const { return sectionDeg / surfacesPerSection; }

GeneratingSurface GeneratingSurface::point() {
  GeneratingSurface g;
  g.primitives.push_back(GeneratingPrimitive{});
  return g;
}

double CanalOptions::tipX(const HelicoSpiral& spiral) const { return -1.0 / spiral.sizeRatio() + axisOffset; }

double CanalOptions::arcHeight(const HelicoSpiral& spiral) const {
  const double turn = radians(turnDeg);
  return (start.x - tipX(spiral)) * std::sin(turn) / (1.0 - std::cos(turn));
}

double CanalOptions::centreLength(const HelicoSpiral& spiral) const {
  const double turn = radians(turnDeg);
  const double rho = (start.x - tipX(spiral)) / (1.0 - std::cos(turn));
  return rho * turn + std::max(0.0, length - arcHeight(spiral));
}

Vec3 CanalOptions::pointAt(const HelicoSpiral& spiral, double t) const {
  // Arc of radius ρ about the centre (start.x − ρ·cos(turn), start.y − ... ): parametrized by
  // the angle ψ from the axis direction, turning from `turn` down to 0.
  const double turn = radians(turnDeg);
  const double rho = (start.x - tipX(spiral)) / (1.0 - std::cos(turn));
  const double arc = rho * turn, total = centreLength(spiral);
  const double s = std::clamp(t, 0.0, 1.0) * total;
  if (s <= arc) {
    const double psi = turn - s / rho;
    // Direction at ψ: (−sin ψ, cos ψ); x falls by ρ(cos ψ − cos turn), y rises by ρ(sin turn − sin ψ).
    return Vec3(static_cast<float>(start.x - rho * (std::cos(psi) - std::cos(turn))),
                static_cast<float>(start.y + rho * (std::sin(turn) - std::sin(psi))), 0.0f);
  }
  return Vec3(static_cast<float>(tipX(spiral)), static_cast<float>(start.y + arcHeight(spiral) + (s - arc)), 0.0f);
}

std::vector<GeneratingPrimitive> CanalOptions::primitives(const HelicoSpiral& spiral) const {
  const double turn = radians(turnDeg);
  const double rho = (start.x - tipX(spiral)) / (1.0 - std::cos(turn));
  const double arc = rho * turn, total = centreLength(spiral);
  const float rMid = static_cast<float>(radiusStart + (radiusEnd - radiusStart) * arc / total);
  std::vector<GeneratingPrimitive> out;
  GeneratingPrimitive bent;
  bent.kind = GeneratingPrimitive::Kind::Cone;
  bent.a = Vec3(start.x, start.y, 0.0f);
  bent.b = pointAt(spiral, arc / total);
  bent.radiusA = radiusStart;
  bent.radiusB = rMid;
  bent.bendDeg = turnDeg;
  // The arc bulges towards the apex and the axis side of its chord: it first heads inwards.
  bent.bendDirection = Vec3(-1.0f, -1.0f, 0.0f);
  bent.lastDeg = sweepDeg;
  bent.canal = true;
  out.push_back(bent);
  if (total - arc > 1e-6) {
    GeneratingPrimitive straight = bent;
    straight.a = bent.b;
    straight.b = pointAt(spiral, 1.0);
    straight.radiusA = rMid;
    straight.radiusB = radiusEnd;
    straight.bendDeg = 0.0f;
    out.push_back(straight);
  }
  return out;
}

std::vector<std::vector<VarixSpine>> murexTable1() {
  // Table 1 as read from the paper (its columns were lost in extraction; see docs/SHELLS.md):
  // whorl 1 carries no spines, each later whorl adds spines below the shoulder, whorl 7 has
  // the full row from −90° to 80°.
  return {
      {},
      {{50, 0.8f}},
      {{50, 0.9f}},
      {{40, 0.8f}, {50, 1.5f}, {60, 0.7f}},
      {{20, 0.9f}, {30, 0.7f}, {40, 1.5f}, {50, 0.64f}, {60, 1.06f}},
      {{-10, 0.55f}, {0, 0.8f}, {10, 1.55f}, {20, 0.64f}, {30, 0.7f}, {40, 0.55f}, {50, 0.96f}, {60, 0.6f}},
      {{-90, 0.55f}, {-80, 0.64f}, {-70, 0.55f}, {-60, 1.14f}, {-50, 0.55f}, {-40, 1.92f}, {-30, 0.55f},
       {-20, 0.82f}, {-10, 0.55f}, {0, 1.44f}, {10, 0.64f}, {20, 0.64f}, {30, 0.55f}, {40, 1.62f}, {50, 0.72f},
       {60, 0.64f}, {70, 0.55f}, {80, 0.5f}},
  };
}

std::vector<std::vector<float>> murexTable2() {
  return {
      {0.96f, 0.92f, 0.84f, 0.68f, 0.45f, 0.25f},
      {0.95f, 0.99f, 0.76f, 0.51f, 0.35f, 0.28f},
      {1.00f, 0.90f, 0.92f, 0.70f, 0.60f},
  };
}

ShellParams murexCabritii() {
  ShellParams p;
  p.spiral = HelicoSpiral{1.3, 22.5, 0.2};
  p.whorls = 7;
  p.whorlDeg = 348.0;
  p.sectionDeg = 116.0;
  p.surfacesPerSection = 6;
  p.generating = GeneratingSurface::point();
  p.canal = CanalOptions{};
  p.axialSpines.length = 1.8f;  // long slender canal spines (Fig. 13-14); Table 2 sizes are relative to it
  p.varices.enabled = true;
  p.varices.spinesByWhorl = murexTable1();
  p.bumps.enabled = true;
  p.axialSpines.enabled = true;
  p.axialSpines.rows = murexTable2();
  p.opening.enabled = true;
  p.seed = 1;
  return p;
}

float shellCellSize(const blobtree::CompiledBlob& blob) { return glm::length(blob.bounds().size()) / 120.0f; }

ShellModel buildShell(const ShellParams& p, const SourceLoc& loc) {
  auto fail = [&](const std::string& msg) { throw InputError(loc, "shell: " + msg); };
  if (!(p.spiral.lambda > 1.0)) fail("lambda must be > 1");
  if (!(p.spiral.betaDeg > 0.0 && p.spiral.betaDeg <= 90.0)) fail("beta must lie in (0, 90] degrees");
  if (!(p.spiral.r0 > 0.0)) fail("r0 must be > 0");
  if (p.whorls < 1 || !(p.whorlDeg > 0.0) || !(p.sectionDeg > 0.0) || p.surfacesPerSection < 1)
    fail("whorls, whorl angle, section angle and surfaces per section must be positive");
  if (p.generating.primitives.empty()) fail("the generating surface has no primitive");
  if (p.canal) {
    const CanalOptions& c = *p.canal;
    if (!(c.length > 0.0f) || !(c.radiusStart > 0.0f) || !(c.radiusEnd > 0.0f) || !(c.sweepDeg > 0.0))
      fail("canal length, radii and sweep must be > 0");
    if (!(c.start.x > c.tipX(p.spiral)))
      fail("the canal must start farther from the shell axis than its tip (start x " + std::to_string(c.start.x) +
           ", tip x " + std::to_string(c.tipX(p.spiral)) + ")");
    if (!(c.turnDeg > 0.0f && c.turnDeg <= 90.0f)) fail("canal turn must lie in (0, 90] degrees");
    if (!(c.arcHeight(p.spiral) <= c.length))
      fail("the canal is too short for its turn: the bend alone reaches " + std::to_string(c.arcHeight(p.spiral)) +
           " along the axis, more than its length " + std::to_string(c.length));
  }
  if (!(p.endDeg() >= p.startDeg)) fail("age (theta_end) must not be below the start angle");
  if (p.varices.enabled && !(p.varices.spacingDeg > 0.0)) fail("varix spacing must be > 0");
  if (p.axialSpines.enabled && (p.axialSpines.bendsMin < 0 || p.axialSpines.bendsMax < p.axialSpines.bendsMin))
    fail("axial spine bend counts must satisfy 0 <= min <= max");
  if (p.opening.enabled && !(p.opening.innerScale > 0.0f && p.opening.innerScale < 1.0f))
    fail("opening inner_scale must lie in (0, 1)");
  ShellModel m;
  m.tree.setSourceLoc(loc);
  ShellBuilder(p, m).build();
  return m;
}

}  // namespace sprig::organisms
