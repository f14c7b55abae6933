#include "blobtree/detail/dual_patches.h"

namespace sprig::blobtree::detail {

bool cornersJoined(const float f[8], int a, int b, bool inside) {
  auto side = [&](int c) { return (f[c] > 0.0f) == inside; };
  if (!side(a) || !side(b)) return false;
  unsigned seen = 1u << a;
  int stack[8], sp = 0;
  stack[sp++] = a;
  while (sp > 0) {
    int c = stack[--sp];
    if (c == b) return true;
    for (int axis = 0; axis < 3; ++axis) {
      int n = c ^ (1 << axis);
      if (!((seen >> n) & 1) && side(n)) {
        seen |= 1u << n;
        stack[sp++] = n;
      }
    }
  }
  return false;
}

int8_t forcedFaceDecision(const float fA[8], const float fB[8], int axis, int sideA) {
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  const int c00 = sideA << axis, c11 = c00 | (1 << p) | (1 << q), c10 = c00 | (1 << p), c01 = c00 | (1 << q);
  const int flip = 1 << axis;  // the same grid point's corner code in the other cell
  const bool in00 = fA[c00] > 0.0f;
  // The face is ambiguous: c00 and c11 on one side, c10 and c01 on the other.
  if ((fA[c11] > 0.0f) != in00 || (fA[c10] > 0.0f) == in00 || (fA[c01] > 0.0f) == in00) return -1;
  const bool diag00A = cornersJoined(fA, c00, c11, in00), diag00B = cornersJoined(fB, c00 ^ flip, c11 ^ flip, in00);
  if (diag00A && diag00B) return int8_t(in00 ? 1 : 0);  // join c00 and c11
  const bool diag10A = cornersJoined(fA, c10, c01, !in00), diag10B = cornersJoined(fB, c10 ^ flip, c01 ^ flip, !in00);
  if (diag10A && diag10B) return int8_t(in00 ? 0 : 1);  // join c10 and c01
  return -1;
}

CellPatches cellPatches(const float f[8], const int8_t* forced) {
  auto inside = [&](int c) { return f[c] > 0.0f; };
  auto crosses = [&](int a, int b) { return inside(a) != inside(b); };
  // Up to two neighbours of each crossing edge along the polygons, one per face.
  std::array<std::array<int8_t, 2>, 12> nb;
  std::array<int8_t, 12> deg{};
  for (auto& n : nb) n = {-1, -1};
  auto link = [&](int e0, int e1) {
    nb[e0][deg[e0]++] = int8_t(e1);
    nb[e1][deg[e1]++] = int8_t(e0);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      // The face's corners in a fixed order: c00 its lowest, then +p, +q, +p+q, with p, q
      // the next axes in cyclic order (the same order in both cells sharing the face).
      const int p = (axis + 1) % 3, q = (axis + 2) % 3;
      const int c00 = side << axis, c10 = c00 | (1 << p), c01 = c00 | (1 << q), c11 = c10 | (1 << q);
      const int eBottom = edgeOf(c00, c10), eTop = edgeOf(c01, c11), eLeft = edgeOf(c00, c01), eRight = edgeOf(c10, c11);
      const bool xb = crosses(c00, c10), xt = crosses(c01, c11), xl = crosses(c00, c01), xr = crosses(c10, c11);
      const int n = int(xb) + int(xt) + int(xl) + int(xr);
      if (n == 2) {
        int e[2], k = 0;
        if (xb) e[k++] = eBottom;
        if (xt) e[k++] = eTop;
        if (xl) e[k++] = eLeft;
        if (xr) e[k++] = eRight;
        link(e[0], e[1]);
      } else if (n == 4) {
        // c00 and c11 agree, c10 and c01 agree. Saddle of the bilinear interpolant.
        const float den = f[c00] + f[c11] - f[c10] - f[c01];
        const float saddle = den != 0.0f ? (f[c00] * f[c11] - f[c10] * f[c01]) / den : 0.0f;
        const int8_t decision = forced ? forced[2 * axis + side] : int8_t(-1);
        const bool joinInside = decision >= 0 ? decision == 1 : saddle > 0.0f;
        // Cut off each corner of the separated state: its two face edges pair up.
        const bool cutDiagonal00 = inside(c00) != joinInside;  // c00 and c11 are cut off
        if (cutDiagonal00) {
          link(eBottom, eLeft);   // around c00
          link(eTop, eRight);     // around c11
        } else {
          link(eBottom, eRight);  // around c10
          link(eTop, eLeft);      // around c01
        }
      }
    }
  CellPatches out;
  out.patch.fill(-1);
  for (int e = 0; e < 12; ++e) {
    if (deg[e] == 0 || out.patch[e] >= 0) continue;
    // Walk the cycle through e.
    int prev = -1, cur = e;
    do {
      out.patch[cur] = int8_t(out.count);
      int next = nb[cur][0] != prev ? nb[cur][0] : nb[cur][1];
      prev = cur;
      cur = next;
    } while (cur != e && cur >= 0);
    ++out.count;
  }
  return out;
}

}  // namespace sprig::blobtree::detail
