#include "organisms/analysis.h"

#include "core/parallel.h"

namespace sprig::organisms {

namespace {

constexpr size_t kGrain = 1024;

/// One umbrella step: p += 1/2 (mean of the edge neighbours - p). Boundary vertices stay
/// (an open mesh keeps its rim).
void umbrella(const VertexNeighbours& nb, const LevelTopology& topo, std::vector<Vec3>& p) {
  std::vector<Vec3> q(p.size());
  parallelFor(0, p.size(), [&](size_t v) {
    const uint32_t a = nb.offsets[v], b = nb.offsets[v + 1];
    if (b == a || topo.boundaryVertex[v]) {
      q[v] = p[v];
      return;
    }
    Vec3 mean(0.0f);
    for (uint32_t i = a; i < b; ++i) mean += p[nb.items[i]];
    mean /= float(b - a);
    q[v] = p[v] + 0.5f * (mean - p[v]);
  }, kGrain);
  p.swap(q);
}

}  // namespace

AnalysisResult decompose(const Subdivision& sub, std::vector<Vec3> finest, int smoothing) {
  const int L = sub.levels();
  AnalysisResult out;
  out.resampled = finest;
  // Coarse levels, finest first: P_{l-1} = decimate(smooth(P_l)).
  std::vector<std::vector<Vec3>> P(size_t(L) + 1);
  P[size_t(L)] = std::move(finest);
  for (int l = L; l >= 1; --l) {
    std::vector<Vec3> s = P[size_t(l)];
    if (smoothing > 0) {
      const VertexNeighbours nb = vertexNeighbours(sub.topology(l));
      for (int i = 0; i < smoothing; ++i) umbrella(nb, sub.topology(l), s);
    }
    s.resize(sub.vertexCount(l - 1));
    P[size_t(l) - 1] = std::move(s);
  }
  // Details in the frames synthesis will compute: replay synthesis level by level, so the
  // frames come from exactly the surface synthesis will subdivide.
  out.control = P[0];
  out.details.assign(size_t(L) + 1, {});
  out.details[0].assign(P[0].size(), Vec3(0.0f));
  std::vector<Vec3> current = P[0], smooth;
  std::vector<Frame> frames;
  for (int l = 1; l <= L; ++l) {
    const size_t n = sub.vertexCount(l);
    smooth.resize(n);
    sub.interpolate(l, current, smooth);
    frames.resize(n);
    computeFrames(sub.topology(l), smooth, frames);
    auto& d = out.details[size_t(l)];
    d.resize(n);
    current.resize(n);
    parallelFor(0, n, [&](size_t v) {
      d[v] = frames[v].toLocal(P[size_t(l)][v] - smooth[v]);
      current[v] = smooth[v] + frames[v].toWorld(d[v]);  // what synthesis will have
    }, kGrain);
  }
  return out;
}

AnalysisResult analyze(const Subdivision& sub, std::span<const Vec3> baseControl, const SurfaceProbe& probe,
                       const AnalysisOptions& options) {
  const std::vector<std::vector<Vec3>> ref = referenceLevels(sub, baseControl);
  const std::vector<Vec3>& fine = ref.back();
  std::vector<Frame> frames(fine.size());
  computeFrames(sub.topology(sub.levels()), fine, frames);
  std::vector<Vec3> samples(fine.size());
  std::vector<uint8_t> missed(fine.size(), 0);
  parallelFor(0, fine.size(), [&](size_t v) {
    const std::optional<float> t = probe(fine[v], frames[v].n, options.maxDistance);
    samples[v] = t ? fine[v] + *t * frames[v].n : fine[v];
    missed[v] = t ? 0 : 1;
  }, kGrain);
  AnalysisResult out = decompose(sub, std::move(samples), options.smoothing);
  for (uint8_t m : missed) out.misses += m;
  return out;
}

}  // namespace sprig::organisms
