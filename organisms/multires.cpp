#include "organisms/multires.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>

#include <tbb/parallel_invoke.h>

#include "core/parallel.h"

namespace sprig::organisms {

namespace {

constexpr size_t kGrain = 2048;

float smoothstep01(float x) {
  x = std::clamp(x, 0.0f, 1.0f);
  return x * x * (3.0f - 2.0f * x);
}

/// Any unit vector orthogonal to n.
Vec3 anyPerpendicular(const Vec3& n) {
  Vec3 a = std::abs(n.x) < 0.9f ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
  return glm::normalize(glm::cross(n, a));
}

/// Edge hops from source to every vertex, up to maxHops (-1 beyond).
std::vector<int> hopDistances(const VertexNeighbours& nb, uint32_t source, int maxHops) {
  std::vector<int> hops(nb.offsets.size() - 1, -1);
  std::deque<uint32_t> queue{source};
  hops[source] = 0;
  while (!queue.empty()) {
    uint32_t v = queue.front();
    queue.pop_front();
    if (hops[v] >= maxHops) continue;
    for (uint32_t i = nb.offsets[v]; i < nb.offsets[v + 1]; ++i) {
      uint32_t w = nb.items[i];
      if (hops[w] < 0) hops[w] = hops[v] + 1, queue.push_back(w);
    }
  }
  return hops;
}

/// Multiplies out.offset (and scalar) by the modifications' gains at view.level.
void applyModifications(const LevelView& view, const std::vector<Modification>& mods, LevelDetail& out) {
  if (mods.empty()) return;
  std::optional<VertexNeighbours> nb;
  for (const Modification& m : mods) {
    const size_t l = size_t(view.level);
    if (l >= m.gains.size() || m.gains[l] == 1.0f || m.radius <= 0) continue;
    if (!nb) nb = vertexNeighbours(*view.topology);
    const uint32_t centre = nearestPosition(view.reference, m.center);
    const int maxHops = int(std::ceil(m.radius / std::max(view.sampleSize, 1e-30f)));
    const std::vector<int> hops = hopDistances(*nb, centre, maxHops);
    for (size_t v = 0; v < hops.size(); ++v) {
      if (hops[v] < 0) continue;
      const float x = float(hops[v]) * view.sampleSize / m.radius;
      if (x >= 1) continue;
      const float k = 1.0f - 3.0f * x * x + 2.0f * x * x * x;  // cubic drop-off (§5.2)
      const float g = 1.0f + (m.gains[l] - 1.0f) * k;
      out.offset[v] *= g;
      if (!out.scalar.empty()) out.scalar[v] *= g;
    }
  }
}

bool anyScalar(const DetailSet& set) {
  return std::any_of(set.begin(), set.end(), [](const auto& p) { return p->writesScalar(); });
}

}  // namespace

void LevelDetail::reset(size_t n, bool withScalar) {
  offset.assign(n, Vec3(0.0f));
  if (withScalar) scalar.assign(n, 0.0f);
  else scalar.clear();
}

void computeFrames(const LevelTopology& topo, std::span<const Vec3> p, std::span<Frame> frames) {
  parallelFor(0, topo.vertexCount(), [&](size_t v) {
    Vec3 n(0.0f);
    const uint32_t f0 = topo.vertexFaceOffsets[v], f1 = topo.vertexFaceOffsets[v + 1];
    for (uint32_t i = f0; i < f1; ++i) {
      const uint32_t f = topo.vertexFaces[i];
      const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
      for (uint32_t c = c0; c < c1; ++c) {  // Newell's normal: twice the face's vector area
        const Vec3& a = p[topo.faceVertices[c]];
        const Vec3& b = p[topo.faceVertices[c + 1 < c1 ? c + 1 : c0]];
        n += glm::cross(a, b);
      }
    }
    Frame& fr = frames[v];
    const float len = glm::length(n);
    fr.n = len > 0 ? n / len : Vec3(0, 0, 1);
    Vec3 t(0.0f);
    if (f1 > f0) {  // toward the next vertex of the first incident face
      const uint32_t f = topo.vertexFaces[f0];
      const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
      for (uint32_t c = c0; c < c1; ++c)
        if (topo.faceVertices[c] == v) t = p[topo.faceVertices[c + 1 < c1 ? c + 1 : c0]] - p[v];
    }
    t -= glm::dot(t, fr.n) * fr.n;
    const float tl = glm::length(t);
    fr.t = tl > 1e-30f ? t / tl : anyPerpendicular(fr.n);
    fr.b = glm::cross(fr.n, fr.t);
  }, kGrain);
}

VertexNeighbours vertexNeighbours(const LevelTopology& topo) {
  const size_t n = topo.vertexCount();
  VertexNeighbours nb;
  nb.offsets.assign(n + 1, 0);
  std::vector<std::vector<uint32_t>> lists(n);
  for (size_t f = 0; f < topo.faceCount(); ++f) {
    const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
    for (uint32_t c = c0; c < c1; ++c) {
      const uint32_t a = topo.faceVertices[c], b = topo.faceVertices[c + 1 < c1 ? c + 1 : c0];
      lists[a].push_back(b);
      lists[b].push_back(a);
    }
  }
  for (size_t v = 0; v < n; ++v) {
    auto& l = lists[v];
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    nb.offsets[v + 1] = nb.offsets[v] + uint32_t(l.size());
  }
  nb.items.reserve(nb.offsets[n]);
  for (auto& l : lists) nb.items.insert(nb.items.end(), l.begin(), l.end());
  return nb;
}

namespace {

/// Triangles of a level's faces: quads along their shorter diagonal, others as fans.
void triangulateFaces(const LevelTopology& topo, std::span<const Vec3> p, Mesh& mesh) {
  mesh.triangles.reserve(topo.faceCount() * 2);
  for (size_t f = 0; f < topo.faceCount(); ++f) {
    const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
    const uint32_t* v = &topo.faceVertices[c0];
    if (c1 - c0 == 4) {
      if (glm::length(p[v[0]] - p[v[2]]) <= glm::length(p[v[1]] - p[v[3]])) {
        mesh.triangles.emplace_back(v[0], v[1], v[2]);
        mesh.triangles.emplace_back(v[0], v[2], v[3]);
      } else {
        mesh.triangles.emplace_back(v[0], v[1], v[3]);
        mesh.triangles.emplace_back(v[1], v[2], v[3]);
      }
      continue;
    }
    for (uint32_t c = 1; c + 1 < c1 - c0; ++c) mesh.triangles.emplace_back(v[0], v[c], v[c + 1]);
  }
}

}  // namespace

Mesh limitMesh(const Subdivision& sub, std::span<const Vec3> finest) {
  const size_t n = finest.size();
  Mesh mesh;
  mesh.positions.resize(n);
  std::vector<Vec3> du(n), dv(n);
  sub.limit(finest, mesh.positions, du, dv);
  const LevelTopology& topo = sub.topology(sub.levels());
  std::vector<Frame> faceFrames(n);
  computeFrames(topo, mesh.positions, faceFrames);  // the faces' orientation at each vertex
  mesh.normals.resize(n);
  parallelFor(0, n, [&](size_t v) {
    Vec3 c = glm::cross(du[v], dv[v]);
    const float len = glm::length(c);
    // The limit tangents vanish or are parallel at some boundary corners: use the faces there.
    Vec3 nrm = len > 1e-20f ? c / len : faceFrames[v].n;
    if (glm::dot(nrm, faceFrames[v].n) < 0) nrm = -nrm;
    mesh.normals[v] = nrm;
  }, kGrain);
  triangulateFaces(topo, mesh.positions, mesh);
  return mesh;
}

Mesh controlMeshOf(const LevelTopology& topo, std::span<const Vec3> positions) {
  Mesh mesh;
  mesh.positions.assign(positions.begin(), positions.end());
  std::vector<Frame> frames(positions.size());
  computeFrames(topo, positions, frames);
  mesh.normals.resize(positions.size());
  for (size_t v = 0; v < positions.size(); ++v) mesh.normals[v] = frames[v].n;
  triangulateFaces(topo, positions, mesh);
  return mesh;
}

uint32_t nearestPosition(std::span<const Vec3> positions, const Vec3& p) {
  uint32_t best = 0;
  float bestD = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < positions.size(); ++i) {
    const Vec3 d = positions[i] - p;
    const float dd = glm::dot(d, d);
    if (dd < bestD) bestD = dd, best = uint32_t(i);
  }
  return best;
}

float meanEdgeLength(const LevelTopology& topo, std::span<const Vec3> p) {
  double sum = 0;
  size_t count = 0;
  for (size_t f = 0; f < topo.faceCount(); ++f) {
    const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
    for (uint32_t c = c0; c < c1; ++c) {
      sum += glm::length(p[topo.faceVertices[c]] - p[topo.faceVertices[c + 1 < c1 ? c + 1 : c0]]);
      ++count;
    }
  }
  return count ? float(sum / double(count)) : 0.0f;
}

float PlaneAlpha::widthAt(int level) const {
  return sharp && level >= 1 ? width / float(1u << unsigned(level - 1)) : width;
}

void PlaneAlpha::evaluate(const LevelView& view, std::span<float> alpha) const {
  const Vec3 n = glm::normalize(normal);
  const float w = widthAt(view.level);
  const float o = offset + float(double(speed) * view.time);
  parallelFor(0, alpha.size(), [&](size_t v) {
    const float s = glm::dot(n, view.reference[v]) - o;
    alpha[v] = w > 0 ? smoothstep01(s / w + 0.5f) : (s >= 0 ? 1.0f : 0.0f);
  }, kGrain);
}

void FunctionAlpha::evaluate(const LevelView& view, std::span<float> alpha) const {
  parallelFor(0, alpha.size(), [&](size_t v) {
    alpha[v] = std::clamp(f(view.reference[v], view.level, view.time), 0.0f, 1.0f);
  }, kGrain);
}

void PaintedAlpha::evaluate(const LevelView& view, std::span<float> alpha) const {
  std::vector<float> m(control), finer;
  for (int l = 1; l <= view.level; ++l) {
    finer.resize(view.subdivision->vertexCount(l));
    view.subdivision->interpolate(l, m, finer);
    m.swap(finer);
  }
  const float gain = (sharp ? float(1u << unsigned(std::max(0, view.level - 1))) : 1.0f) / width;
  parallelFor(0, alpha.size(), [&](size_t v) { alpha[v] = smoothstep01(0.5f + (m[v] - 0.5f) * gain); }, kGrain);
}

std::vector<std::vector<Vec3>> referenceLevels(const Subdivision& sub, std::span<const Vec3> control) {
  std::vector<std::vector<Vec3>> levels(size_t(sub.levels()) + 1);
  levels[0].assign(control.begin(), control.end());
  for (int l = 1; l <= sub.levels(); ++l) {
    levels[size_t(l)].resize(sub.vertexCount(l));
    sub.interpolate(l, levels[size_t(l) - 1], levels[size_t(l)]);
  }
  return levels;
}

SynthesisResult synthesize(const Subdivision& sub, std::span<const Vec3> control, const SynthesisInput& input,
                           const SynthesisOptions& options) {
  SynthesisResult out;
  const bool blending = input.alpha != nullptr;
  const bool scalars = anyScalar(input.shapeA) || (blending && anyScalar(input.shapeB));

  std::vector<std::unique_ptr<DetailRun>> runsA, runsB;
  for (const auto& p : input.shapeA) runsA.push_back(p->start(sub));
  if (blending)
    for (const auto& p : input.shapeB) runsB.push_back(p->start(sub));

  std::vector<Vec3> reference(control.begin(), control.end()), refineRef;
  std::vector<Vec3> current(control.begin(), control.end()), smooth;
  std::vector<float> height, smoothHeight;
  if (scalars) height.assign(control.size(), 0.0f);
  std::vector<Frame> frames;
  LevelDetail detailA, detailB;
  std::vector<float> alpha;

  for (int l = 0; l <= sub.levels(); ++l) {
    const LevelTopology& topo = sub.topology(l);
    const size_t n = topo.vertexCount();
    // S_l = subdivide(P_{l-1}); the reference surface and the scalar channel likewise.
    if (l == 0) {
      smooth = current;
      smoothHeight = height;
    } else {
      smooth.resize(n);
      refineRef.resize(n);
      if (scalars) smoothHeight.resize(n);
      // The three refinements are independent (each is OpenSubdiv's serial loop).
      tbb::parallel_invoke([&] { sub.interpolate(l, current, smooth); },
                           [&] { sub.interpolate(l, reference, refineRef); },
                           [&] { if (scalars) sub.interpolate(l, height, smoothHeight); });
      reference.swap(refineRef);
    }
    frames.resize(n);
    computeFrames(topo, smooth, frames);

    LevelView view;
    view.level = l;
    view.time = options.time;
    view.subdivision = &sub;
    view.topology = &topo;
    view.smooth = smooth;
    view.frames = frames;
    view.reference = reference;
    view.sampleSize = meanEdgeLength(topo, reference);

    detailA.reset(n, scalars);
    for (auto& r : runsA) r->add(view, detailA);
    if (blending) {
      detailB.reset(n, scalars);
      for (auto& r : runsB) r->add(view, detailB);
      alpha.resize(n);
      input.alpha->evaluate(view, alpha);
      parallelFor(0, n, [&](size_t v) {  // Burt's blend: a linear combination per level (§6)
        const float a = alpha[v];
        detailA.offset[v] = (1.0f - a) * detailA.offset[v] + a * detailB.offset[v];
        if (scalars) detailA.scalar[v] = (1.0f - a) * detailA.scalar[v] + a * detailB.scalar[v];
      }, kGrain);
    }
    applyModifications(view, input.modifications, detailA);

    // P_l = S_l + F_l d_l.
    current.resize(n);
    parallelFor(0, n, [&](size_t v) { current[v] = smooth[v] + frames[v].toWorld(detailA.offset[v]); }, kGrain);
    if (scalars) {
      height.resize(n);
      for (size_t v = 0; v < n; ++v) height[v] = smoothHeight[v] + detailA.scalar[v];
    }
    if (options.keepLevels) {
      out.levelPositions.push_back(current);
      out.levelSmooth.push_back(smooth);
      std::vector<Vec3> world(n);
      for (size_t v = 0; v < n; ++v) world[v] = current[v] - smooth[v];
      out.levelDetail.push_back(std::move(world));
      out.levelAlpha.push_back(blending ? alpha : std::vector<float>{});
    }
  }
  out.positions = std::move(current);
  out.scalar = std::move(height);
  if (blending) out.alpha = std::move(alpha);
  return out;
}

}  // namespace sprig::organisms
