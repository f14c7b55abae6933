#include "model/wind_export.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>

#include "core/parallel.h"
#include "model/model.h"

namespace sprig {

namespace {

/// A piece of the skeleton as a cone: axis a -> b, radius ra at a, rb at b.
struct Bone {
  DVec3 a{0}, b{0};
  double ra = 0, rb = 0;
};

/// The bones of the internodes, or of the organs: an organ from its attachment to its
/// farthest point (a sphere: its centre with its radius; a predefined surface: along its
/// heading by its size).
std::vector<Bone> bonesOf(const lsystem::Skeleton& sk, const organisms::WindRig& rig, bool organs) {
  std::vector<Bone> bones;
  if (!organs) {
    for (const auto& in : sk.internodes) bones.push_back({in.start, in.end, in.baseRadius, in.tipRadius});
    return bones;
  }
  for (size_t o = 0; o < sk.organs.size(); ++o) {
    const lsystem::Organ& g = sk.organs[o];
    Bone bone{rig.organs[o].pivot, rig.organs[o].pivot, 0, 0};
    if (g.kind == lsystem::Organ::Kind::Sphere) {
      bone = {g.position, g.position, g.radius, g.radius};
    } else if (!g.points.empty()) {
      for (const DVec3& p : g.points)
        if (glm::length(p - bone.a) > glm::length(bone.b - bone.a)) bone.b = p;
    } else {
      bone.b = g.position + g.heading * g.radius;
    }
    bones.push_back(bone);
  }
  return bones;
}

/// The nearest bone by axis distance minus radius, through a uniform grid of their boxes
/// (each box grown by the bone's larger radius). Rings of cells around the query's cell
/// are searched until the next ring cannot hold anything nearer: a bone first met in ring
/// r is at least (r - 1)·h away.
class BoneGrid {
 public:
  explicit BoneGrid(const std::vector<Bone>& bones) : bones_(bones) {
    DBox3 all;
    for (const Bone& b : bones) all.extend(box(b));
    lo_ = all.lo;
    const DVec3 extent = glm::max(all.hi - all.lo, DVec3(1e-9));
    const double h = std::cbrt(extent.x * extent.y * extent.z / double(std::max<size_t>(bones.size(), 1)));
    for (int k = 0; k < 3; ++k) dims_[k] = int(std::clamp(std::ceil(extent[k] / std::max(h, 1e-12)), 1.0, 128.0));
    h_ = std::max({extent.x / dims_.x, extent.y / dims_.y, extent.z / dims_.z});
    std::vector<uint32_t> count(size_t(dims_.x) * dims_.y * dims_.z + 1, 0);
    auto each = [&](const Bone& b, auto&& f) {
      const DBox3 bb = box(b);
      const glm::ivec3 c0 = cell(bb.lo), c1 = cell(bb.hi);
      for (int z = c0.z; z <= c1.z; ++z)
        for (int y = c0.y; y <= c1.y; ++y)
          for (int x = c0.x; x <= c1.x; ++x) f(index({x, y, z}));
    };
    for (const Bone& b : bones) each(b, [&](size_t c) { ++count[c + 1]; });
    for (size_t c = 1; c < count.size(); ++c) count[c] += count[c - 1];
    start_ = count;
    ids_.resize(count.back());
    for (size_t i = 0; i < bones.size(); ++i) each(bones[i], [&](size_t c) { ids_[count[c]++] = uint32_t(i); });
  }

  /// The nearest bone to q and the parameter along it; (-1, 0) without bones.
  std::pair<int32_t, double> nearest(const DVec3& q) const {
    int32_t best = -1;
    double bestValue = std::numeric_limits<double>::infinity(), bestS = 0;
    const glm::ivec3 c = cell(q);
    const int maxRing = std::max({dims_.x, dims_.y, dims_.z});
    for (int r = 0; r <= maxRing; ++r) {
      for (int z = c.z - r; z <= c.z + r; ++z)
        for (int y = c.y - r; y <= c.y + r; ++y)
          for (int x = c.x - r; x <= c.x + r; ++x) {
            if (std::max({std::abs(x - c.x), std::abs(y - c.y), std::abs(z - c.z)}) != r) continue;
            if (x < 0 || y < 0 || z < 0 || x >= dims_.x || y >= dims_.y || z >= dims_.z) continue;
            const size_t k = index({x, y, z});
            for (uint32_t j = start_[k]; j < start_[k + 1]; ++j) {
              double s = 0;
              const double v = coneDistance(bones_[ids_[j]], q, s);
              if (v < bestValue || (v == bestValue && int32_t(ids_[j]) < best)) best = int32_t(ids_[j]), bestValue = v, bestS = s;
            }
          }
      if (best >= 0 && bestValue <= r * h_) break;
    }
    return {best, bestS};
  }

  /// Axis distance of q to bone minus its radius at the nearest axis point (parameter s).
  static double coneDistance(const Bone& b, const DVec3& q, double& s) {
    const DVec3 d = b.b - b.a;
    const double len2 = glm::dot(d, d);
    s = len2 > 0 ? std::clamp(glm::dot(q - b.a, d) / len2, 0.0, 1.0) : 0.0;
    return glm::length(q - (b.a + s * d)) - (b.ra + s * (b.rb - b.ra));
  }

 private:
  static DBox3 box(const Bone& b) {
    const double r = std::max(b.ra, b.rb);
    return DBox3{glm::min(b.a, b.b) - DVec3(r), glm::max(b.a, b.b) + DVec3(r)};
  }
  glm::ivec3 cell(const DVec3& p) const {
    const DVec3 f = glm::floor((p - lo_) / h_);
    return glm::clamp(glm::ivec3(glm::clamp(f, DVec3(-1), DVec3(1e6))), glm::ivec3(0), dims_ - 1);
  }
  size_t index(const glm::ivec3& c) const { return (size_t(c.z) * dims_.y + c.y) * dims_.x + c.x; }

  const std::vector<Bone>& bones_;
  DVec3 lo_{0};
  double h_ = 1;
  glm::ivec3 dims_{1};
  std::vector<uint32_t> start_, ids_;
};

/// One term of the linearized sway: weight(t)·coefficient·(axis × (q − pivot)).
struct Term {
  size_t target;
  double coefficient;
  DVec3 axis, pivot;
};

/// The targets (names and weights over the loop's keyframes) and each internode's and
/// organ's own terms.
struct Targets {
  std::vector<std::string> names;
  std::vector<std::vector<float>> weights;
  std::map<long, size_t> byCycles;  ///< cycles per loop -> its sin target (cos: + 1)
  std::vector<float> times;

  explicit Targets(const organisms::WindRig& rig) {
    const double loop = rig.options.loopSeconds;
    const int frames = int(std::lround(loop * kWindFps));
    for (int f = 0; f <= frames; ++f) times.push_back(float(loop * f / frames));
    names = {"static", "gust"};
    weights.assign(2, std::vector<float>(times.size(), 1.0f));
    for (int f = 0; f <= frames; ++f) weights[1][size_t(f)] = float(rig.gust(loop * (f % frames) / frames));
  }

  /// The sin target of frequency hz (its cos target follows), made on first use.
  size_t sway(double hz, double loop) {
    const long m = std::lround(hz * loop);
    auto [it, fresh] = byCycles.try_emplace(m, names.size());
    if (!fresh) return it->second;
    const int frames = int(times.size()) - 1;
    names.push_back("sway_" + std::to_string(m) + "_sin");
    names.push_back("sway_" + std::to_string(m) + "_cos");
    std::vector<float> s(times.size()), c(times.size());
    for (int f = 0; f <= frames; ++f) {
      const double angle = 2.0 * kPi * double(m) * double(f % frames) / frames;
      s[size_t(f)] = float(std::sin(angle)), c[size_t(f)] = float(std::cos(angle));
    }
    weights.push_back(std::move(s));
    weights.push_back(std::move(c));
    return it->second;
  }

  /// Terms of a sinusoid amplitude·sin(2π hz t + phase) turning about axis through pivot.
  void sinusoid(std::vector<Term>& out, double amplitude, double hz, double phase, const DVec3& axis, const DVec3& pivot,
                double loop) {
    const size_t k = sway(hz, loop);
    out.push_back({k, amplitude * std::cos(phase), axis, pivot});
    out.push_back({k + 1, amplitude * std::sin(phase), axis, pivot});
  }
};

/// The terms of internode i's own turn about its base.
std::vector<Term> internodeTerms(const organisms::WindRig& rig, const lsystem::Internode& in, const organisms::InternodeWind& iw,
                                 Targets& targets) {
  std::vector<Term> terms;
  const double loop = rig.options.loopSeconds;
  if (in.order == 0) {
    terms.push_back({1, rig.leanTop * iw.length / rig.height, rig.leanAxis, in.start});
    return terms;
  }
  if (in.order > kWindMorphMaxOrder) return terms;  // rides on its branch (its own sway: _WIND)
  terms.push_back({0, iw.amplitude * organisms::kSwayBias, iw.k1, in.start});
  targets.sinusoid(terms, iw.amplitude, iw.hz, iw.phase1, iw.k1, in.start, loop);
  targets.sinusoid(terms, organisms::kCrossSwayGain * iw.amplitude, iw.hz2, iw.phase2, iw.k2, in.start, loop);
  return terms;
}

/// Per internode and target: (A, B) with the displacement of a point q it carries
/// A × q − B (its own and its ancestors' turns summed, the linearization).
std::vector<std::vector<std::pair<DVec3, DVec3>>> accumulate(const organisms::WindRig& rig, const lsystem::Skeleton& sk,
                                                             Targets& targets) {
  std::vector<std::vector<Term>> own(sk.internodes.size());
  for (size_t i : rig.order) own[i] = internodeTerms(rig, sk.internodes[i], rig.internodes[i], targets);
  for (size_t o = 0; o < rig.organs.size(); ++o)  // every flutter target exists before the tables are sized
    if (rig.organs[o].amplitude > 0) targets.sway(rig.organs[o].hz, rig.options.loopSeconds);
  std::vector<std::vector<std::pair<DVec3, DVec3>>> acc(sk.internodes.size());
  for (size_t i : rig.order) {
    const int32_t p = sk.internodes[i].parent;
    acc[i] = p >= 0 ? acc[size_t(p)] : std::vector<std::pair<DVec3, DVec3>>(targets.names.size(), {DVec3(0), DVec3(0)});
    for (const Term& t : own[i]) {
      acc[i][t.target].first += t.coefficient * t.axis;
      acc[i][t.target].second += t.coefficient * glm::cross(t.axis, t.pivot);
    }
  }
  return acc;
}

}  // namespace

std::vector<WindBinding> bindToSkeleton(const std::vector<DVec3>& points, const lsystem::Skeleton& sk, bool organs) {
  organisms::WindOptions none;
  const organisms::WindRig rig = organisms::windRig(sk, none);
  const bool toOrgans = organs && !sk.organs.empty();
  const std::vector<Bone> bones = bonesOf(sk, rig, toOrgans);
  std::vector<WindBinding> out(points.size());
  if (bones.empty()) return out;
  const BoneGrid grid(bones);
  parallelFor(0, points.size(), [&](size_t v) {
    const auto [j, s] = grid.nearest(points[v]);
    WindBinding& b = out[v];
    b.along = s;
    if (toOrgans) b.organ = j, b.internode = sk.organs[size_t(j)].internode;
    else b.internode = j;
    if (b.internode >= int32_t(sk.internodes.size())) b.internode = -1;
  }, 1024);
  return out;
}

glm::vec4 windAttribute(const organisms::WindRig& rig, const lsystem::Skeleton& sk, const WindBinding& b) {
  const int order = b.internode >= 0 ? sk.internodes[size_t(b.internode)].order : 0;
  if (b.organ >= 0) {
    const organisms::OrganWind& ow = rig.organs[size_t(b.organ)];
    return {float(order + 1), float(ow.phase), float(b.along), float(ow.hz)};
  }
  if (b.internode < 0) return {0.0f, float(rig.gustPhase[0]), 0.0f, float(rig.gustHz[0])};
  const organisms::InternodeWind& iw = rig.internodes[size_t(b.internode)];
  const float weight = float(std::min(1.0, iw.axisFrom + b.along * (iw.axisTo - iw.axisFrom)));
  if (order == 0) return {0.0f, float(rig.gustPhase[0]), weight, float(rig.gustHz[0])};
  return {float(order), float(iw.phase1), weight, float(iw.hz)};
}

PartMorph windMorph(const organisms::WindRig& rig, const lsystem::Skeleton& sk, const std::vector<DVec3>& points,
                    const std::vector<WindBinding>& bindings) {
  Targets targets(rig);
  const auto acc = accumulate(rig, sk, targets);
  const size_t nt = targets.names.size();
  std::vector<std::vector<Vec3>> disp(nt, std::vector<Vec3>(points.size(), Vec3(0.0f)));
  parallelFor(0, points.size(), [&](size_t v) {
    const WindBinding& b = bindings[v];
    const DVec3& q = points[v];
    if (b.internode >= 0)
      for (size_t k = 0; k < nt; ++k) {
        const auto& [a, c] = acc[size_t(b.internode)][k];
        disp[k][v] = Vec3(glm::cross(a, q) - c);
      }
    if (b.organ >= 0 && rig.organs[size_t(b.organ)].amplitude > 0) {
      const organisms::OrganWind& ow = rig.organs[size_t(b.organ)];
      const size_t k = targets.byCycles.at(std::lround(ow.hz * rig.options.loopSeconds));
      const DVec3 turn = glm::cross(ow.axis, q - ow.pivot);
      disp[k][v] += Vec3(ow.amplitude * std::cos(ow.phase) * turn);
      disp[k + 1][v] += Vec3(ow.amplitude * std::sin(ow.phase) * turn);
    }
  }, 1024);
  PartMorph m;
  m.animation = "wind";
  m.times = targets.times;
  for (size_t k = 0; k < nt; ++k) {
    if (std::all_of(disp[k].begin(), disp[k].end(), [](const Vec3& d) { return d == Vec3(0.0f); })) continue;
    m.names.push_back(targets.names[k]);
    m.targets.push_back(std::move(disp[k]));
    m.weights.push_back(targets.weights[k]);
  }
  return m;
}

void addWind(std::vector<LodLevel>& levels, const lsystem::Skeleton& skeleton, organisms::WindOptions wind, const Vec3& offset) {
  wind.loopSeconds = kWindLoopSeconds;
  const organisms::WindRig rig = organisms::windRig(skeleton, wind);
  for (size_t level = 0; level < levels.size(); ++level)
    for (ExportPart& part : levels[level].parts) {
      if (part.mesh.triangles.empty()) continue;
      const bool wood = part.name == "wood" || part.name.rfind("textured_wood_", 0) == 0;
      std::vector<DVec3> points(part.mesh.positions.size());
      for (size_t v = 0; v < points.size(); ++v) points[v] = DVec3(part.mesh.positions[v]) - DVec3(offset);
      const std::vector<WindBinding> bindings = bindToSkeleton(points, skeleton, !wood);
      VertexAttribute attribute{"_WIND", std::vector<glm::vec4>(points.size())};
      for (size_t v = 0; v < points.size(); ++v) attribute.values[v] = windAttribute(rig, skeleton, bindings[v]);
      part.attributes.push_back(std::move(attribute));
      if (level == 0 && wind.speed > 0) {
        PartMorph m = windMorph(rig, skeleton, points, bindings);
        if (!m.targets.empty()) part.morph = std::make_shared<const PartMorph>(std::move(m));
      }
    }
}

std::optional<organisms::WindOptions> addModelWind(SpeciesModel& model, const Stage& stage, std::vector<LodLevel>& levels,
                                                   const Vec3& offset, const std::optional<std::pair<double, double>>& wind) {
  auto source = model.windSource(stage);
  if (!source) return std::nullopt;
  organisms::WindOptions& w = source->second;
  if (wind) w.speed = wind->first, w.directionDeg = wind->second;
  addWind(levels, source->first, w, offset);
  return w;
}

}  // namespace sprig
