#pragma once
/// Where detail procedures put their features (Velho et al. 2002, §5.1): seed points,
/// placed globally (evenly over the whole surface) or locally (at given points), at a level.
///
/// Two footprints, the paper's two options:
/// - vertex: a seed snaps to the nearest vertex of its level and stays that vertex at every
///   finer level (vertex v of level l is vertex v of level l+1). Simple and fast; where the
///   parametrization is not uniform, features follow it (they land on vertices, and a
///   one-vertex feature's width is the local vertex spacing).
/// - surface: a seed is an arbitrary point of the surface. Radial features (berry domes,
///   mushrooms) are centred at the point itself; a one-vertex feature (tentacle, spur) is
///   spread over the corners of the triangle containing the point with weights w_i / sum w^2
///   (barycentric w), so the surface at the point itself moves by exactly the feature's
///   displacement. The point is re-projected onto the surface at every level.

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "core/types.h"
#include "organisms/multires.h"

namespace sprig::organisms {

/// How seeds are chosen.
struct Placement {
  enum class Kind {
    Spacing,          ///< Poisson-disk points over the whole surface, `spacing` apart (global)
    ControlVertices,  ///< every vertex of the control mesh (global)
    Points,           ///< the given points, each projected to the surface (local)
  };
  Kind kind = Kind::Spacing;
  float spacing = 0.3f;       ///< Spacing: least distance between seeds, world units
  std::vector<Vec3> points;   ///< Points: where, world units
  bool surfaceFootprint = false;
  uint64_t seed = 1;          ///< Spacing: the order of dart throwing
};

/// One seed: its point, and the vertices (with weights) a one-vertex feature moves.
struct Seed {
  Vec3 point{0.0f};
  uint32_t vertex = 0;  ///< nearest vertex (vertex footprint: the only corner)
  uint32_t corners[3] = {0, 0, 0};
  float weights[3] = {1, 0, 0};
  int cornerCount = 1;
  bool surface = false;
};

/// Seeds of placement on the level view shows (its smooth surface).
std::vector<Seed> placeSeeds(const Placement& placement, const LevelView& view);

/// Moves surface seeds onto view's surface (nearest point among the faces around the
/// nearest vertex) and refreshes their corners; vertex seeds keep their vertex. Call once
/// per level before using seeds placed at a coarser level.
void followSeeds(std::vector<Seed>& seeds, const LevelView& view);

/// Poisson-disk subset of candidates (indices into positions): dart throwing in a seeded
/// random order, accepting a candidate when no accepted one lies within minDistance.
/// Deterministic for a seed; O(candidates) with a hash grid.
std::vector<uint32_t> poissonDisk(std::span<const Vec3> positions, std::span<const uint32_t> candidates,
                                  float minDistance, uint64_t seed);

/// A hash grid of points for radius queries.
class PointGrid {
 public:
  /// Indexes points (kept by reference) with cells of edge cell (> 0).
  PointGrid(std::span<const Vec3> points, float cell);
  /// Calls f(index, squaredDistance) for every point within radius of p (radius <= cell
  /// visits the 27 cells around p).
  template <class F>
  void near(const Vec3& p, float radius, F&& f) const;
  /// The nearest point within radius of p, or -1.
  int64_t nearest(const Vec3& p, float radius) const;

 private:
  uint64_t key(int x, int y, int z) const;
  glm::ivec3 cellOf(const Vec3& p) const;
  std::span<const Vec3> points_;
  float cell_;
  std::vector<uint64_t> keys_;       // sorted cell keys, one per occupied cell
  std::vector<uint32_t> starts_;     // items of keys_[i]: items_[starts_[i] .. starts_[i+1])
  std::vector<uint32_t> items_;
  const uint32_t* find(uint64_t k, size_t& count) const;
};

template <class F>
void PointGrid::near(const Vec3& p, float radius, F&& f) const {
  const int reach = int(std::ceil(radius / cell_));
  const glm::ivec3 c = cellOf(p);
  const float r2 = radius * radius;
  for (int x = c.x - reach; x <= c.x + reach; ++x)
    for (int y = c.y - reach; y <= c.y + reach; ++y)
      for (int z = c.z - reach; z <= c.z + reach; ++z) {
        size_t count = 0;
        const uint32_t* it = find(key(x, y, z), count);
        for (size_t i = 0; i < count; ++i) {
          const Vec3 d = points_[it[i]] - p;
          const float dd = glm::dot(d, d);
          if (dd <= r2) f(it[i], dd);
        }
      }
}

}  // namespace sprig::organisms
