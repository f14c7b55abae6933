#include "organisms/detail.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "core/parallel.h"
#include "core/rng.h"
#include "textures/noise.h"

namespace sprig::organisms {

namespace {

constexpr size_t kGrain = 2048;

/// The last level of a range that the subdivision reaches.
int lastLevel(const LevelRange& r, const Subdivision& sub) { return std::min(r.last, sub.levels()); }

/// Growth factor of an animated feature at time t: min(1, t / grow), or 1 when grow is 0.
float growth(float grow, double time) { return grow > 0 ? float(std::clamp(time / double(grow), 0.0, 1.0)) : 1.0f; }

std::vector<Vec3> seedPoints(const std::vector<Seed>& seeds) {
  std::vector<Vec3> p;
  p.reserve(seeds.size());
  for (const Seed& s : seeds) p.push_back(s.point);
  return p;
}

/// Adds local offset d at a seed: at its vertex, or spread over its corners (placement.h).
void addAtSeed(const Seed& s, const Vec3& d, LevelDetail& out) {
  for (int i = 0; i < s.cornerCount; ++i) out.offset[s.corners[i]] += s.weights[i] * d;
}

// ---- rock ----------------------------------------------------------------------------

class Rock final : public DetailProcedure {
 public:
  explicit Rock(const RockOptions& o) : o_(o), noise_(o.seed) {
    Rng rng(deriveSeed(o.seed, {0x726f636bu}));
    for (auto& s : shifts_) s = DVec3(rng.uniform(0, 256), rng.uniform(0, 256), rng.uniform(0, 256));
  }
  std::string name() const override { return "rock"; }
  bool writesScalar() const override { return o_.scalar; }

  std::unique_ptr<DetailRun> start(const Subdivision&) const override {
    struct Run final : DetailRun {
      const Rock& rock;
      explicit Run(const Rock& r) : rock(r) {}
      void add(const LevelView& view, LevelDetail& out) override { rock.add(view, out); }
    };
    return std::make_unique<Run>(*this);
  }

 private:
  void add(const LevelView& view, LevelDetail& out) const {
    if (!o_.levels.contains(view.level)) return;
    const int k = view.level - o_.levels.first;
    const double a = double(o_.amplitude) * std::pow(double(o_.gain), k);
    const double f = double(o_.frequency) * std::pow(double(o_.lacunarity), k);
    const DVec3 shift = shifts_[size_t(k) % shifts_.size()];
    parallelFor(0, view.reference.size(), [&](size_t v) {
      const float value = float(a * noise_(f * DVec3(view.reference[v]) + shift));
      if (o_.scalar) out.scalar[v] += value;
      else out.offset[v].z += value;
    }, kGrain);
  }

  RockOptions o_;
  textures::PerlinNoise noise_;
  std::array<DVec3, 16> shifts_;
};

// ---- berry ---------------------------------------------------------------------------

class Berry final : public DetailProcedure {
 public:
  explicit Berry(const BerryOptions& o) : o_(o) {}
  std::string name() const override { return "berry"; }

  std::unique_ptr<DetailRun> start(const Subdivision&) const override {
    struct Run final : DetailRun {
      const BerryOptions& o;
      std::vector<Seed> seeds;
      float radius = 0, spacing = 0;
      explicit Run(const BerryOptions& opts) : o(opts) {}

      void add(const LevelView& view, LevelDetail& out) override {
        if (!o.levels.contains(view.level)) return;
        if (view.level == o.levels.first) {
          seeds = placeSeeds(o.placement, view);
          radius = o.radius;
          spacing = o.placement.spacing;
        } else {
          childSeeds(view);
        }
        if (seeds.empty()) return;
        // Domes: each vertex rises by R sqrt(1 - r^2/R^2) toward its closest seed (§4.2.2).
        const std::vector<Vec3> points = seedPoints(seeds);
        const PointGrid grid(points, radius);
        const float h = o.height, R = radius;
        parallelFor(0, view.smooth.size(), [&](size_t v) {
          const int64_t s = grid.nearest(view.smooth[v], R);
          if (s < 0) return;
          const Vec3 d = view.smooth[v] - points[size_t(s)];
          const float q = 1.0f - glm::dot(d, d) / (R * R);
          if (q > 0) out.offset[v].z += h * R * std::sqrt(q);
        }, kGrain);
      }

      /// Seeds of this level: a Poisson-disk cluster under each dome of the previous one.
      void childSeeds(const LevelView& view) {
        followSeeds(seeds, view);
        const std::vector<Vec3> parents = seedPoints(seeds);
        const PointGrid grid(parents, radius);
        const float reach = o.cluster * radius;
        std::vector<uint32_t> candidates;
        for (uint32_t v = 0; v < view.smooth.size(); ++v)
          if (grid.nearest(view.smooth[v], reach) >= 0) candidates.push_back(v);
        radius *= o.ratio;
        spacing *= o.ratio;
        seeds.clear();
        for (uint32_t v : poissonDisk(view.smooth, candidates, spacing, deriveSeed(o.placement.seed, {uint64_t(view.level)}))) {
          Seed s;
          s.vertex = s.corners[0] = v;
          s.point = view.smooth[v];
          seeds.push_back(s);
        }
      }
    };
    return std::make_unique<Run>(o_);
  }

 private:
  BerryOptions o_;
};

// ---- tentacle and spur ---------------------------------------------------------------

/// A procedure whose features sit at seeds placed at the first level of its range and
/// whose detail at level l is f(k = l - first + 1, time) in each seed's local frame.
class SeedFeature : public DetailProcedure {
 public:
  SeedFeature(LevelRange levels, Placement placement) : levels_(levels), placement_(std::move(placement)) {}

  std::unique_ptr<DetailRun> start(const Subdivision&) const override {
    struct Run final : DetailRun {
      const SeedFeature& feature;
      std::vector<Seed> seeds;
      explicit Run(const SeedFeature& f) : feature(f) {}
      void add(const LevelView& view, LevelDetail& out) override {
        if (!feature.levels_.contains(view.level)) return;
        if (view.level == feature.levels_.first) seeds = placeSeeds(feature.placement_, view);
        else followSeeds(seeds, view);
        const Vec3 d = feature.detail(view.level - feature.levels_.first + 1, view.time);
        for (const Seed& s : seeds) addAtSeed(s, d, out);
      }
    };
    return std::make_unique<Run>(*this);
  }

 protected:
  /// The local-frame detail at local level k (1-based) and time.
  virtual Vec3 detail(int k, double time) const = 0;

 private:
  LevelRange levels_;
  Placement placement_;
};

class Tentacle final : public SeedFeature {
 public:
  explicit Tentacle(const TentacleOptions& o) : SeedFeature(o.levels, o.placement), o_(o) {}
  std::string name() const override { return "tentacle"; }

 protected:
  Vec3 detail(int level, double time) const override {
    // The paper's pseudo-code (§4.2.3), with level the tentacle's own level.
    const double theta = radians(double(o_.angleDeg) + double(o_.spinDeg) * time);
    const double magnitude = double(o_.length) * growth(o_.grow, time) * level;
    const double ph = (kPi / 3.0) * level;
    DVec3 displace(std::sin(theta + ph), std::cos(theta + ph), 1.0);
    if (level % 2 == 0 && o_.alternate == Alternate::All) displace *= -1.0;
    if (level % 2 == 0 && o_.alternate == Alternate::Tangent) displace.x = -displace.x, displace.y = -displace.y;
    return Vec3(displace * magnitude);
  }

 private:
  TentacleOptions o_;
};

class Spur final : public SeedFeature {
 public:
  explicit Spur(const SpurOptions& o) : SeedFeature(o.levels, o.placement), o_(o) {}
  std::string name() const override { return "spur"; }

 protected:
  Vec3 detail(int, double) const override { return Vec3(0, 0, o_.length); }

 private:
  SpurOptions o_;
};

// ---- mushroom ------------------------------------------------------------------------

class Mushroom final : public DetailProcedure {
 public:
  explicit Mushroom(const MushroomOptions& o) : o_(o) {}
  std::string name() const override { return "mushroom"; }

  std::unique_ptr<DetailRun> start(const Subdivision& sub) const override {
    struct Run final : DetailRun {
      const MushroomOptions& o;
      int levelsUsed;
      MushroomCurve curve;
      std::vector<Vec3> origins;
      std::vector<Frame> frames;
      Run(const MushroomOptions& opts, int used) : o(opts), levelsUsed(used), curve(opts) {}

      void add(const LevelView& view, LevelDetail& out) override {
        if (!o.levels.contains(view.level)) return;
        if (view.level == o.levels.first) {
          for (const Seed& s : placeSeeds(o.placement, view)) {
            origins.push_back(s.surface ? s.point : view.reference[s.vertex]);
            frames.push_back(view.frames[s.vertex]);
          }
        }
        // The feature's shape at level first + k: the reference surface moved by the share
        // W_k = sum_{j<=k} 2^-j / sum_j 2^-j of the profile's displacement. The detail is the
        // difference between that shape and the subdivided surface (§4.1: F is the difference
        // between the feature at two successive levels), so the vertices of every level lie
        // on the feature exactly and the finest level on the whole profile.
        const int k = view.level - o.levels.first;
        double total = 0, done = 0;
        for (int j = 0; j < levelsUsed; ++j) total += std::ldexp(1.0, -j);
        for (int j = 0; j <= k; ++j) done += std::ldexp(1.0, -j);
        const float w = float(done / total) * growth(o.grow, view.time);
        const PointGrid grid(view.reference, o.footprint);
        for (size_t s = 0; s < origins.size(); ++s) {
          const Frame& fs = frames[s];
          grid.near(origins[s], o.footprint, [&](uint32_t v, float) {
            const Vec3 q = view.reference[v] - origins[s];
            const Vec2 xy(glm::dot(q, fs.t), glm::dot(q, fs.b));
            const float rho = glm::length(xy);
            if (rho >= o.footprint) return;
            const Vec2 c = curve(rho);
            const Vec3 radial = rho > 1e-12f ? (xy.x * fs.t + xy.y * fs.b) / rho : Vec3(0.0f);
            // On a curved base the profile's heights are over the base, not over the seed's
            // tangent plane: a point moved from rho to c.x keeps the base's height there,
            // h (c.x / rho)^2 for the height h of the base at rho over the tangent plane (a
            // second-order fit; 0 on a plane), so the foot stays on the base.
            const float h = glm::dot(q, fs.n);
            const float lift = rho > 1e-12f ? h * (c.x * c.x / (rho * rho) - 1.0f) : 0.0f;
            const Vec3 target = view.reference[v] + w * ((c.x - rho) * radial + (c.y + lift) * fs.n);
            out.offset[v] += view.frames[v].toLocal(target - view.smooth[v]);
          });
        }
      }
    };
    const int used = std::max(1, lastLevel(o_.levels, sub) - o_.levels.first + 1);
    return std::make_unique<Run>(o_, used);
  }

 private:
  MushroomOptions o_;
};

// ---- captured detail -----------------------------------------------------------------

class StoredDetail final : public DetailProcedure {
 public:
  explicit StoredDetail(std::vector<std::vector<Vec3>> offsets) : offsets_(std::move(offsets)) {}
  std::string name() const override { return "captured"; }
  std::unique_ptr<DetailRun> start(const Subdivision&) const override {
    struct Run final : DetailRun {
      const std::vector<std::vector<Vec3>>& offsets;
      explicit Run(const std::vector<std::vector<Vec3>>& o) : offsets(o) {}
      void add(const LevelView& view, LevelDetail& out) override {
        const size_t l = size_t(view.level);
        if (l >= offsets.size() || offsets[l].size() != out.offset.size()) return;
        for (size_t v = 0; v < out.offset.size(); ++v) out.offset[v] += offsets[l][v];
      }
    };
    return std::make_unique<Run>(offsets_);
  }

 private:
  std::vector<std::vector<Vec3>> offsets_;
};

}  // namespace

namespace {

Vec2 capTop(const MushroomOptions& o, float s) { return {o.capRadius * s, o.height + o.capTop * (1.0f - s * s)}; }
Vec2 capUnder(const MushroomOptions& o, float s) {
  return {o.capRadius + (o.stalkRadius - o.capRadius) * s, o.height - o.capUnder * std::sin(0.5f * float(kPi) * s)};
}

}  // namespace

std::array<float, 3> mushroomBreaks(const MushroomOptions& o) {
  // The curved pieces' lengths by 64 chords each (within 0.01 %).
  auto length = [&](Vec2 (*piece)(const MushroomOptions&, float)) {
    float sum = 0.0f;
    for (int i = 0; i < 64; ++i) sum += glm::length(piece(o, float(i + 1) / 64.0f) - piece(o, float(i) / 64.0f));
    return sum;
  };
  const float top = length(capTop), under = length(capUnder);
  const float stalk = std::max(o.height - o.capUnder, 0.0f), foot = std::max(o.footprint - o.stalkRadius, 0.0f);
  const float total = top + under + stalk + foot;
  if (!(total > 0.0f)) return {0.35f, 0.55f, 0.75f};
  return {top / total, (top + under) / total, (top + under + stalk) / total};
}

namespace {

// The pieces of the profile at u = rho / footprint in [0, 1], corners sharp.
Vec2 mushroomPieces(const MushroomOptions& o, const std::array<float, 3>& breaks, float u) {
  // Four pieces over u: cap top [0, a], underside [a, b], stalk [b, c], foot [c, 1], each
  // as wide in u as it is long (mushroomBreaks). Each piece lies in its own band of
  // heights, so the curve never meets itself.
  const auto [a, b, c] = breaks;
  const float H = o.height;
  if (u <= a) return capTop(o, u / a);
  if (u <= b) return capUnder(o, (u - a) / (b - a));
  if (u <= c) {
    const float s = (u - b) / (c - b);
    return {o.stalkRadius, (H - o.capUnder) * (1.0f - s)};
  }
  // The foot spreads from the stalk to the footprint's edge, easing into the ground: its
  // radius g(s) = k s + (1 - k) s^2 reaches the edge with slope 1 in rho (k = 2 - m, m the
  // slope g must end with), so the displacement rho -> c.x - rho ends with value and slope 0
  // there. Subdivision then barely moves the ground outside the footprint, which the
  // feature does not touch; with a kink there it pulled that ground inward past the foot's
  // outer vertices and folded the mesh (found by the self-intersection test).
  const float s = (u - c) / (1.0f - c);
  const float m = (1.0f - c) * o.footprint / (o.footprint - o.stalkRadius);
  const float k = std::clamp(2.0f - m, 0.0f, 2.0f);
  return {o.stalkRadius + (o.footprint - o.stalkRadius) * (k * s + (1.0f - k) * s * s), 0.0f};
}

}  // namespace

MushroomCurve::MushroomCurve(const MushroomOptions& o) : footprint_(o.footprint), breaks_(mushroomBreaks(o)) {
  // The pieces sampled finely (kFine per table step), their running sums, then each table
  // point the mean over u ± kMushroomRounding (a box filter along the curve: u is
  // proportional to arc length), eased back to the pieces themselves within 2·w of either
  // end, so the apex stays on the axis and the foot ends with value and slope 0.
  constexpr int kFine = 8;
  const int fine = kTableSteps * kFine;
  std::vector<Vec2> sharp(size_t(fine) + 1);
  std::vector<glm::dvec2> sum(size_t(fine) + 2, glm::dvec2(0.0));
  for (int i = 0; i <= fine; ++i) {
    sharp[size_t(i)] = mushroomPieces(o, breaks_, float(i) / float(fine));
    sum[size_t(i) + 1] = sum[size_t(i)] + glm::dvec2(sharp[size_t(i)]);
  }
  const int half = int(std::lround(kMushroomRounding * fine));
  table_.resize(kTableSteps + 1);
  for (int i = 0; i <= kTableSteps; ++i) {
    const int j = i * kFine, lo = std::max(j - half, 0), hi = std::min(j + half, fine);
    const Vec2 mean(glm::dvec2(sum[size_t(hi) + 1] - sum[size_t(lo)]) / double(hi - lo + 1));
    const float u = float(i) / float(kTableSteps), edge = std::min(u, 1.0f - u) / kMushroomRounding;
    const float blend = std::clamp(edge - 2.0f, 0.0f, 1.0f);
    table_[size_t(i)] = sharp[size_t(j)] + blend * blend * (3.0f - 2.0f * blend) * (mean - sharp[size_t(j)]);
  }
}

Vec2 MushroomCurve::operator()(float rho) const {
  const float x = std::clamp(rho / footprint_, 0.0f, 1.0f) * float(kTableSteps);
  const int i = std::min(int(x), kTableSteps - 1);
  return glm::mix(table_[size_t(i)], table_[size_t(i) + 1], x - float(i));
}

Vec2 mushroomProfile(const MushroomOptions& o, float rho) { return MushroomCurve(o)(rho); }

std::shared_ptr<const DetailProcedure> makeRock(const RockOptions& o) { return std::make_shared<Rock>(o); }
std::shared_ptr<const DetailProcedure> makeBerry(const BerryOptions& o) { return std::make_shared<Berry>(o); }
std::shared_ptr<const DetailProcedure> makeTentacle(const TentacleOptions& o) { return std::make_shared<Tentacle>(o); }
std::shared_ptr<const DetailProcedure> makeSpur(const SpurOptions& o) { return std::make_shared<Spur>(o); }
std::shared_ptr<const DetailProcedure> makeMushroom(const MushroomOptions& o) { return std::make_shared<Mushroom>(o); }
std::shared_ptr<const DetailProcedure> makeStoredDetail(std::vector<std::vector<Vec3>> offsets) {
  return std::make_shared<StoredDetail>(std::move(offsets));
}

}  // namespace sprig::organisms
