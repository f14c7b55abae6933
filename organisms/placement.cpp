#include "organisms/placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "core/rng.h"

namespace sprig::organisms {

namespace {

/// The index of the cell of side `cell` holding coordinate x, computed in double and clamped
/// to +-2^30: a far or non-finite point lands in an edge cell instead of overflowing int (the
/// grids' keys wrap at 2^21 anyway, which costs only extra distance tests).
int cellIndex(float x, float cell) {
  constexpr double kMax = 1073741824.0;
  const double c = std::floor(double(x) / double(cell));
  return c >= -kMax && c <= kMax ? int(c) : c > 0 ? int(kMax) : -int(kMax);
}

/// Closest point of triangle abc to p and its barycentric weights (Ericson, Real-Time
/// Collision Detection, §5.1.5).
Vec3 closestOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c, Vec3& bary) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return bary = {1, 0, 0}, a;
  const Vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return bary = {0, 1, 0}, b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const float v = d1 / (d1 - d3);
    return bary = {1 - v, v, 0}, a + v * ab;
  }
  const Vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return bary = {0, 0, 1}, c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const float w = d2 / (d2 - d6);
    return bary = {1 - w, 0, w}, a + w * ac;
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return bary = {0, 1 - w, w}, b + w * (c - b);
  }
  const float denom = 1.0f / (va + vb + vc);
  const float v = vb * denom, w = vc * denom;
  return bary = {1 - v - w, v, w}, a + ab * v + ac * w;
}

/// Projects seed.point onto the faces around its nearest vertex (fan-triangulated).
void projectSurfaceSeed(Seed& s, const LevelView& view) {
  const LevelTopology& topo = *view.topology;
  s.vertex = nearestPosition(view.smooth, s.point);
  float best = std::numeric_limits<float>::infinity();
  Vec3 bestPoint = view.smooth[s.vertex];
  for (uint32_t i = topo.vertexFaceOffsets[s.vertex]; i < topo.vertexFaceOffsets[s.vertex + 1]; ++i) {
    const uint32_t f = topo.vertexFaces[i];
    const uint32_t c0 = topo.faceOffsets[f], c1 = topo.faceOffsets[f + 1];
    for (uint32_t c = c0 + 1; c + 1 < c1; ++c) {
      const uint32_t ia = topo.faceVertices[c0], ib = topo.faceVertices[c], ic = topo.faceVertices[c + 1];
      Vec3 bary;
      const Vec3 q = closestOnTriangle(s.point, view.smooth[ia], view.smooth[ib], view.smooth[ic], bary);
      const float d = glm::dot(q - s.point, q - s.point);
      if (d < best) {
        best = d, bestPoint = q;
        s.corners[0] = ia, s.corners[1] = ib, s.corners[2] = ic;
        s.weights[0] = bary.x, s.weights[1] = bary.y, s.weights[2] = bary.z;
        s.cornerCount = 3;
      }
    }
  }
  s.point = bestPoint;
  // Weights w_i / sum w^2: interpolating the corners' offsets back at the point gives the
  // feature's displacement exactly.
  float sumSq = 0;
  for (int i = 0; i < s.cornerCount; ++i) sumSq += s.weights[i] * s.weights[i];
  for (int i = 0; i < s.cornerCount; ++i) s.weights[i] /= sumSq;
}

Seed vertexSeed(uint32_t v, const LevelView& view) {
  Seed s;
  s.vertex = v;
  s.point = view.smooth[v];
  s.corners[0] = v;
  return s;
}

}  // namespace

PointGrid::PointGrid(std::span<const Vec3> points, float cell) : points_(points), cell_(cell) {
  std::vector<std::pair<uint64_t, uint32_t>> entries(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const glm::ivec3 c = cellOf(points[i]);
    entries[i] = {key(c.x, c.y, c.z), uint32_t(i)};
  }
  std::sort(entries.begin(), entries.end());
  for (size_t i = 0; i < entries.size(); ++i) {
    if (keys_.empty() || keys_.back() != entries[i].first) {
      keys_.push_back(entries[i].first);
      starts_.push_back(uint32_t(i));
    }
    items_.push_back(entries[i].second);
  }
  starts_.push_back(uint32_t(items_.size()));
}

uint64_t PointGrid::key(int x, int y, int z) const {
  // 21 bits per axis, offset to be non-negative: cells up to +-2^20 from the origin.
  const auto u = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1fffffu); };
  return (u(x) << 42) | (u(y) << 21) | u(z);
}

glm::ivec3 PointGrid::cellOf(const Vec3& p) const {
  return glm::ivec3(cellIndex(p.x, cell_), cellIndex(p.y, cell_), cellIndex(p.z, cell_));
}

const uint32_t* PointGrid::find(uint64_t k, size_t& count) const {
  auto it = std::lower_bound(keys_.begin(), keys_.end(), k);
  if (it == keys_.end() || *it != k) return count = 0, nullptr;
  const size_t i = size_t(it - keys_.begin());
  count = starts_[i + 1] - starts_[i];
  return items_.data() + starts_[i];
}

int64_t PointGrid::nearest(const Vec3& p, float radius) const {
  int64_t best = -1;
  float bestD = std::numeric_limits<float>::infinity();
  near(p, radius, [&](uint32_t i, float dd) {
    if (dd < bestD || (dd == bestD && int64_t(i) < best)) bestD = dd, best = i;
  });
  return best;
}

std::vector<uint32_t> poissonDisk(std::span<const Vec3> positions, std::span<const uint32_t> candidates,
                                  float minDistance, uint64_t seed) {
  std::vector<uint32_t> order(candidates.begin(), candidates.end());
  Rng rng(seed);
  for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(uint32_t(i))]);
  std::vector<Vec3> accepted;
  std::vector<uint32_t> out;
  // A growing grid: cell = minDistance, so a conflict lies in the 27 cells around.
  std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
  const auto cellKey = [&](const glm::ivec3& c) {
    const auto u = [](int v) { return uint64_t(uint32_t(v + (1 << 20)) & 0x1fffffu); };
    return (u(c.x) << 42) | (u(c.y) << 21) | u(c.z);
  };
  const float r2 = minDistance * minDistance;
  for (uint32_t v : order) {
    const Vec3& p = positions[v];
    const glm::ivec3 c(cellIndex(p.x, minDistance), cellIndex(p.y, minDistance), cellIndex(p.z, minDistance));
    bool free = true;
    for (int dx = -1; dx <= 1 && free; ++dx)
      for (int dy = -1; dy <= 1 && free; ++dy)
        for (int dz = -1; dz <= 1 && free; ++dz) {
          auto it = cells.find(cellKey(c + glm::ivec3(dx, dy, dz)));
          if (it == cells.end()) continue;
          for (uint32_t a : it->second)
            if (glm::dot(accepted[a] - p, accepted[a] - p) < r2) {
              free = false;
              break;
            }
        }
    if (!free) continue;
    cells[cellKey(c)].push_back(uint32_t(accepted.size()));
    accepted.push_back(p);
    out.push_back(v);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<Seed> placeSeeds(const Placement& placement, const LevelView& view) {
  std::vector<Seed> seeds;
  switch (placement.kind) {
    case Placement::Kind::ControlVertices: {
      const size_t n = view.subdivision ? view.subdivision->vertexCount(0) : view.smooth.size();
      for (uint32_t v = 0; v < n; ++v) seeds.push_back(vertexSeed(v, view));
      break;
    }
    case Placement::Kind::Spacing: {
      std::vector<uint32_t> all(view.smooth.size());
      std::iota(all.begin(), all.end(), 0u);
      for (uint32_t v : poissonDisk(view.smooth, all, placement.spacing, placement.seed))
        seeds.push_back(vertexSeed(v, view));
      break;
    }
    case Placement::Kind::Points:
      for (const Vec3& p : placement.points) {
        if (placement.surfaceFootprint) {
          Seed s;
          s.point = p;
          s.surface = true;
          projectSurfaceSeed(s, view);
          seeds.push_back(s);
        } else {
          seeds.push_back(vertexSeed(nearestPosition(view.smooth, p), view));
        }
      }
      break;
  }
  return seeds;
}

void followSeeds(std::vector<Seed>& seeds, const LevelView& view) {
  for (Seed& s : seeds) {
    if (s.surface) projectSurfaceSeed(s, view);
    else s.point = view.smooth[s.vertex];
  }
}

}  // namespace sprig::organisms
