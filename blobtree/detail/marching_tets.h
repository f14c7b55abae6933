#pragma once
/// Private: marching tetrahedra over the Kuhn split of a grid cell, as the polygonizer
/// (blobtree/polygonize.cpp) uses it. Vertices are named by the crossing grid edge they lie
/// on; an edge belongs to the active cell whose low corner is the edge's low end.

#include "core/types.h"

#include <array>
#include <bit>
#include <cstdint>
#include <stdexcept>

namespace sprig::blobtree::detail {

/// "No cell here" in owner tables and cell hashes.
inline constexpr uint32_t kNoCell = ~0u;

/// Corner c of a cell (bit 0: +x, bit 1: +y, bit 2: +z) as an integer offset.
inline glm::ivec3 cornerOffset(int c) { return {c & 1, (c >> 1) & 1, (c >> 2) & 1}; }

/// The six Kuhn tetrahedra of a cube: monotone corner paths 0 -> 7, one per axis order.
/// Every face of the cube is split along the diagonal from its lowest to its highest
/// corner, so neighbouring cubes agree.
inline constexpr int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};

/// Triangles marching tetrahedra emit for a cell, by its inside-corner mask: a tetrahedron
/// with 1 or 3 corners inside gives one, with 2 gives two.
extern const std::array<uint8_t, 256> kTriangleCount;

/// Triangles of one tetrahedron (corner codes t, inside flags), as vertex indices, oriented
/// from inside to outside using the edges' midpoints (never degenerate).
struct TetEmitter {
  /// This cell's owner cells by low-corner code (entry 0 is the cell itself), indices into
  /// vertexBase/crossMask, or kNoCell where no active cell has that low corner.
  const uint32_t* owners;
  const uint32_t* vertexBase;  ///< per active cell: index of its first vertex
  const uint8_t* crossMask;    ///< per active cell: bit d set when edge 0 -> d crosses
  glm::uvec3* out;             ///< next triangle slot

  /// Vertex of the crossing edge a-b (corner codes of this cell): owned by the cell whose
  /// low corner is the edge's low end, numbered vertexBase + rank of its direction.
  /// Throws std::logic_error when no active cell owns the edge or the owner has no
  /// crossing there (a broken invariant of the caller's tables).
  uint32_t edge(int a, int b) const {
    int lo = a & b, d = (a | b) ^ lo;
    uint32_t owner = owners[lo];
    if (owner == kNoCell) throw std::logic_error("polygonize: crossing edge without an owner cell");
    uint8_t m = crossMask[owner];
    if (!((m >> d) & 1)) throw std::logic_error("polygonize: crossing edge without an owner cell");
    return vertexBase[owner] + uint32_t(std::popcount(unsigned(m) & ((1u << d) - 1u)));
  }

  /// Emits the 0, 1 or 2 triangles of tetrahedron t (corner codes) with inside flags in.
  void run(const int t[4], const bool in[4]);

 private:
  static Vec3 mid(int a, int b) { return 0.5f * Vec3(cornerOffset(a) + cornerOffset(b)); }
  /// Emits triangle (e0,e1,e2) with midpoints (m0,m1,m2), flipped so its normal points along outward.
  void emit(uint32_t e0, uint32_t e1, uint32_t e2, Vec3 m0, Vec3 m1, Vec3 m2, Vec3 outward) {
    Vec3 n = glm::cross(m1 - m0, m2 - m0);
    *out++ = glm::dot(n, outward) >= 0.0f ? glm::uvec3(e0, e1, e2) : glm::uvec3(e0, e2, e1);
  }
};

}  // namespace sprig::blobtree::detail
