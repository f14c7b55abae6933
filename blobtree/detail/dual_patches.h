#pragma once
/// Private: the surface patches of one grid cell for dual marching cubes (Nielson, "Dual
/// marching cubes", IEEE Visualization 2004), as the polygonizer (blobtree/polygonize.cpp)
/// uses them.
///
/// The marching-cubes surface inside a cell is a set of closed polygons whose corners lie
/// on the cell's crossing edges. Each face of the cell with a sign change holds one or two
/// segments of it: one when two of its edges cross; two when all four cross (the ambiguous
/// face), paired by the asymptotic decider (Nielson and Hamann 1991): the inside corners
/// are joined when the bilinear interpolant's saddle value is inside. The decision reads
/// only the face's four grid values, in a fixed order, so the two cells that share a face
/// always agree. Every crossing edge lies on two faces and so has two neighbours along
/// the polygons: the segments form disjoint cycles, and each cycle is one patch. Dual
/// marching cubes places one mesh vertex per patch and one quad per crossing grid edge
/// (joining the patches of that edge in the four cells around it).

#include <array>
#include <cstdint>

namespace sprig::blobtree::detail {

/// Cell edge e = 4·axis + k runs along axis from its low corner lowCorner(e) (corner bits:
/// 0 +x, 1 +y, 2 +z); k's bit 0 and 1 are the low corner's bits on the next two axes in
/// cyclic order (axis + 1, axis + 2 mod 3).
inline int edgeAxis(int e) { return e >> 2; }
inline int lowCorner(int e) {
  int a = e >> 2, k = e & 3;
  return ((k & 1) << ((a + 1) % 3)) | (((k >> 1) & 1) << ((a + 2) % 3));
}
/// The edge of corners a and b (adjacent along one axis).
inline int edgeOf(int a, int b) {
  int lo = a & b, axis = (a ^ b) == 1 ? 0 : (a ^ b) == 2 ? 1 : 2;
  return 4 * axis + ((lo >> ((axis + 1) % 3)) & 1) + 2 * ((lo >> ((axis + 2) % 3)) & 1);
}

/// The patches of a cell: patch[e] is the patch of crossing edge e (0-based, in order of
/// each patch's lowest edge), -1 where e does not cross; count patches in all.
struct CellPatches {
  std::array<int8_t, 12> patch;
  int count = 0;
};

/// The patches of a cell from its corner values relative to the iso level (inside > 0).
/// forced, when given, decides ambiguous face 2·axis + side: 1 joins its inside corners,
/// 0 separates them, -1 leaves it to the asymptotic decider.
CellPatches cellPatches(const float f[8], const int8_t* forced = nullptr);

/// True when corners a and b of a cell, both inside (or both outside, per inside), are
/// joined by a path of cell edges whose corners are all on that side.
bool cornersJoined(const float f[8], int a, int b, bool inside);

/// The decision dual marching cubes must take on an ambiguous face whose diagonal corners
/// are joined through both cells sharing it (fA and fB, each in its own corner codes; the
/// face is the side of axis where fA's corners have bit axis = sideA): one vertex per patch
/// would join the two patches twice, an edge of four quads. Joining the corners the cells
/// already join removes it (Nielson 2004 and the manifold condition of Schaefer, Ju and
/// Warren 2007). -1 when no decision is forced.
int8_t forcedFaceDecision(const float fA[8], const float fB[8], int axis, int sideA);

}  // namespace sprig::blobtree::detail
