#include "blobtree/detail/batch_eval.h"

#include "blobtree/detail/traverse.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace sprig::blobtree::detail {

namespace {

constexpr int kBlock = 256;  ///< points per batch (a multiple of 8)

struct Pts {
  const float* x;
  const float* y;
  const float* z;
  int n;   ///< real count
  int n8;  ///< padded count (multiple of 8, <= kBlock)
};

// The walk comes in two widths: W = 0, any padded count up to kBlock (pts.n8), and W = 8,
// exactly 8 padded lanes (the tracer's batches, kTraceLanes). Each lane's operations are
// the same in both, so the same bits; the fixed width unrolls the per-node loops and fills
// and keeps the walk's stack frames small.

/// Lanes per array of a walk of width W.
template <int W>
inline constexpr int kCap = W > 0 ? W : kBlock;

/// The padded count of pts in a walk of width W.
template <int W>
inline int lanes(const Pts& pts) {
  if constexpr (W > 0) return W;
  else return pts.n8;
}

/// out[0, lanes) = v.
template <int W>
inline void fillLanes(float* out, const Pts& pts, float v) {
  std::fill(out, out + lanes<W>(pts), v);
}

/// g(s) for 4 lanes, s already clamped to [0, 1].
template <Kernel K>
inline __m128 kernel4(__m128 s) {
  const __m128 one = _mm_set1_ps(1.0f);
  if constexpr (K == Kernel::Wyvill) {
    __m128 u = _mm_sub_ps(one, s);
    return _mm_mul_ps(_mm_mul_ps(u, u), u);
  } else {
    __m128 q = _mm_sub_ps(_mm_set1_ps(17.0f / 9.0f), _mm_mul_ps(s, _mm_set1_ps(4.0f / 9.0f)));
    q = _mm_add_ps(_mm_set1_ps(-22.0f / 9.0f), _mm_mul_ps(s, q));
    return _mm_add_ps(one, _mm_mul_ps(s, q));
  }
}

/// out[i] (+)= cone/segment field over the batch, 4 points per SSE step (the batch is
/// padded to a multiple of 8).
template <int W, Kernel K, bool Add>
inline void coneBatch(const Prim& P, const Pts& pts, float* __restrict out) {
  const __m128 ax = _mm_set1_ps(P.a.x), ay = _mm_set1_ps(P.a.y), az = _mm_set1_ps(P.a.z);
  const __m128 bx = _mm_set1_ps(P.ab.x), by = _mm_set1_ps(P.ab.y), bz = _mm_set1_ps(P.ab.z);
  const __m128 il = _mm_set1_ps(P.invLen2), R0 = _mm_set1_ps(P.R0), dR = _mm_set1_ps(P.dR), w = _mm_set1_ps(P.weight);
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  for (int i = 0; i < lanes<W>(pts); i += 4) {
    __m128 px = _mm_sub_ps(_mm_loadu_ps(pts.x + i), ax);
    __m128 py = _mm_sub_ps(_mm_loadu_ps(pts.y + i), ay);
    __m128 pz = _mm_sub_ps(_mm_loadu_ps(pts.z + i), az);
    __m128 t = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(px, bx), _mm_mul_ps(py, by)), _mm_mul_ps(pz, bz)), il);
    t = _mm_min_ps(_mm_max_ps(t, zero), one);
    __m128 dx = _mm_sub_ps(px, _mm_mul_ps(t, bx));
    __m128 dy = _mm_sub_ps(py, _mm_mul_ps(t, by));
    __m128 dz = _mm_sub_ps(pz, _mm_mul_ps(t, bz));
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    __m128 R = _mm_add_ps(R0, _mm_mul_ps(dR, t));
    __m128 s = _mm_min_ps(_mm_div_ps(d2, _mm_mul_ps(R, R)), one);
    __m128 f = _mm_mul_ps(w, kernel4<K>(s));
    if constexpr (Add) f = _mm_add_ps(f, _mm_loadu_ps(out + i));
    _mm_storeu_ps(out + i, f);
  }
}

template <int W, Kernel K, bool Add>
inline void pointBatch(const Prim& P, const Pts& pts, float* __restrict out) {
  const __m128 ax = _mm_set1_ps(P.a.x), ay = _mm_set1_ps(P.a.y), az = _mm_set1_ps(P.a.z);
  const __m128 iR2 = _mm_set1_ps(1.0f / (P.R0 * P.R0)), w = _mm_set1_ps(P.weight), one = _mm_set1_ps(1.0f);
  for (int i = 0; i < lanes<W>(pts); i += 4) {
    __m128 dx = _mm_sub_ps(_mm_loadu_ps(pts.x + i), ax);
    __m128 dy = _mm_sub_ps(_mm_loadu_ps(pts.y + i), ay);
    __m128 dz = _mm_sub_ps(_mm_loadu_ps(pts.z + i), az);
    __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    __m128 s = _mm_min_ps(_mm_mul_ps(d2, iR2), one);
    __m128 f = _mm_mul_ps(w, kernel4<K>(s));
    if constexpr (Add) f = _mm_add_ps(f, _mm_loadu_ps(out + i));
    _mm_storeu_ps(out + i, f);
  }
}

template <int W, bool Add>
void primBatch(const Prim& P, const Pts& pts, float* out) {
  bool wy = P.kernel == Kernel::Wyvill;
  switch (P.kind) {
    case NodeKind::Segment:
    case NodeKind::Cone:
      if (wy) coneBatch<W, Kernel::Wyvill, Add>(P, pts, out);
      else coneBatch<W, Kernel::SoftObject, Add>(P, pts, out);
      return;
    case NodeKind::Point:
      if (wy) pointBatch<W, Kernel::Wyvill, Add>(P, pts, out);
      else pointBatch<W, Kernel::SoftObject, Add>(P, pts, out);
      return;
    default:
      for (int i = 0; i < pts.n; ++i) {
        float f = primValue(P, Vec3(pts.x[i], pts.y[i], pts.z[i]), nullptr);
        if constexpr (Add) out[i] += f;
        else out[i] = f;
      }
      return;
  }
}

/// The box of count points (count a multiple of 4, > 0) given as coordinate arrays: the
/// same box as Box3::extend point by point, four lanes per SSE min/max.
Box3 boxOfPoints(const float* x, const float* y, const float* z, int count) {
  __m128 lx = _mm_loadu_ps(x), ly = _mm_loadu_ps(y), lz = _mm_loadu_ps(z);
  __m128 hx = lx, hy = ly, hz = lz;
  for (int i = 4; i < count; i += 4) {
    const __m128 px = _mm_loadu_ps(x + i), py = _mm_loadu_ps(y + i), pz = _mm_loadu_ps(z + i);
    lx = _mm_min_ps(lx, px);
    ly = _mm_min_ps(ly, py);
    lz = _mm_min_ps(lz, pz);
    hx = _mm_max_ps(hx, px);
    hy = _mm_max_ps(hy, py);
    hz = _mm_max_ps(hz, pz);
  }
  alignas(16) float a[6][4];
  _mm_store_ps(a[0], lx);
  _mm_store_ps(a[1], ly);
  _mm_store_ps(a[2], lz);
  _mm_store_ps(a[3], hx);
  _mm_store_ps(a[4], hy);
  _mm_store_ps(a[5], hz);
  Box3 b;
  b.lo = Vec3(std::min(std::min(a[0][0], a[0][1]), std::min(a[0][2], a[0][3])),
              std::min(std::min(a[1][0], a[1][1]), std::min(a[1][2], a[1][3])),
              std::min(std::min(a[2][0], a[2][1]), std::min(a[2][2], a[2][3])));
  b.hi = Vec3(std::max(std::max(a[3][0], a[3][1]), std::max(a[3][2], a[3][3])),
              std::max(std::max(a[4][0], a[4][1]), std::max(a[4][2], a[4][3])),
              std::max(std::max(a[5][0], a[5][1]), std::max(a[5][2], a[5][3])));
  return b;
}

/// Bits 0-3: which of the four points x[0..3], y[0..3], z[0..3] lie in world box b and, when
/// the frame is bounded, in the bend's oriented support box (BendFrame::mayReach's test).
inline int mayReach4(const BendFrame& f, const Box3& b, const float* x, const float* y, const float* z) {
  const __m128 px = _mm_loadu_ps(x), py = _mm_loadu_ps(y), pz = _mm_loadu_ps(z);
  __m128 in = _mm_and_ps(_mm_and_ps(_mm_cmpge_ps(px, _mm_set1_ps(b.lo.x)), _mm_cmple_ps(px, _mm_set1_ps(b.hi.x))),
                         _mm_and_ps(_mm_cmpge_ps(py, _mm_set1_ps(b.lo.y)), _mm_cmple_ps(py, _mm_set1_ps(b.hi.y))));
  in = _mm_and_ps(in, _mm_and_ps(_mm_cmpge_ps(pz, _mm_set1_ps(b.lo.z)), _mm_cmple_ps(pz, _mm_set1_ps(b.hi.z))));
  if (f.bounded) {
    const __m128 rx = _mm_sub_ps(px, _mm_set1_ps(f.C.x)), ry = _mm_sub_ps(py, _mm_set1_ps(f.C.y)),
                 rz = _mm_sub_ps(pz, _mm_set1_ps(f.C.z));
    auto dot = [&](const Vec3& a) {
      return _mm_add_ps(_mm_add_ps(_mm_mul_ps(rx, _mm_set1_ps(a.x)), _mm_mul_ps(ry, _mm_set1_ps(a.y))),
                        _mm_mul_ps(rz, _mm_set1_ps(a.z)));
    };
    const __m128 uu = dot(f.u), vv = dot(f.n), ww = dot(f.z);
    in = _mm_and_ps(in, _mm_and_ps(_mm_cmpge_ps(uu, _mm_set1_ps(f.uLo)), _mm_cmple_ps(uu, _mm_set1_ps(f.uHi))));
    in = _mm_and_ps(in, _mm_and_ps(_mm_cmpge_ps(vv, _mm_set1_ps(f.vLo)), _mm_cmple_ps(vv, _mm_set1_ps(f.vHi))));
    in = _mm_and_ps(in, _mm_and_ps(_mm_cmpge_ps(ww, _mm_set1_ps(f.wLo)), _mm_cmple_ps(ww, _mm_set1_ps(f.wHi))));
  }
  return _mm_movemask_ps(in);
}

/// One child's step of PcmAccum (pcmD, then PcmAccum::add) for four points in SSE: the
/// scalar code's operations in the same order, branches as blends, so the same bits.
struct PcmStep4 {
  explicit PcmStep4(const PcmDerived& d)
      : c(_mm_set1_ps(d.c)), w(_mm_set1_ps(d.w)), half(_mm_set1_ps(0.5f * d.w)),
        kHalf(_mm_set1_ps(d.k * (0.5f * d.w))), a0(_mm_set1_ps(d.a0)) {}

  /// Adds child values fc[0..3] to the accumulators (f1, d1, f2, d2, bulge).
  void add(const float* fc, float* f1p, float* d1p, float* f2p, float* d2p, float* bulgep) const {
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f), two = _mm_set1_ps(2.0f), three = _mm_set1_ps(3.0f);
    const __m128 f = _mm_max_ps(_mm_loadu_ps(fc), zero);  // std::max(0, f): +0 for −0 and NaN
    const __m128 x = _mm_sub_ps(c, f);
    // pcmH on [0, half]: kHalf·H10 + a0·H01 with t = x / half.
    __m128 t = _mm_div_ps(x, half);
    __m128 t2 = _mm_mul_ps(t, t), t3 = _mm_mul_ps(t2, t);
    const __m128 H10 = _mm_add_ps(_mm_sub_ps(t3, _mm_mul_ps(two, t2)), t);
    const __m128 H01 = _mm_add_ps(_mm_mul_ps(_mm_set1_ps(-2.0f), t3), _mm_mul_ps(three, t2));
    const __m128 near = _mm_add_ps(_mm_mul_ps(kHalf, H10), _mm_mul_ps(a0, H01));
    // pcmH on (half, w]: a0·H00 with t = (x − half) / half.
    t = _mm_div_ps(_mm_sub_ps(x, half), half);
    t2 = _mm_mul_ps(t, t);
    t3 = _mm_mul_ps(t2, t);
    const __m128 far = _mm_mul_ps(a0, _mm_add_ps(_mm_sub_ps(_mm_mul_ps(two, t3), _mm_mul_ps(three, t2)), one));
    __m128 d = _mm_blendv_ps(far, near, _mm_cmple_ps(x, half));
    d = _mm_blendv_ps(d, zero, _mm_cmpge_ps(x, w));
    d = _mm_blendv_ps(d, x, _mm_cmplt_ps(x, zero));
    // PcmAccum::add.
    _mm_storeu_ps(bulgep, _mm_add_ps(_mm_loadu_ps(bulgep), _mm_max_ps(d, zero)));
    const __m128 f1 = _mm_loadu_ps(f1p), d1 = _mm_loadu_ps(d1p), f2 = _mm_loadu_ps(f2p), d2 = _mm_loadu_ps(d2p);
    const __m128 gt1 = _mm_cmpgt_ps(f, f1), gt2 = _mm_cmpgt_ps(f, f2);
    _mm_storeu_ps(f2p, _mm_blendv_ps(_mm_blendv_ps(f2, f, gt2), f1, gt1));
    _mm_storeu_ps(d2p, _mm_blendv_ps(_mm_blendv_ps(d2, d, gt2), d1, gt1));
    _mm_storeu_ps(f1p, _mm_blendv_ps(f1, f, gt1));
    _mm_storeu_ps(d1p, _mm_blendv_ps(d1, d, gt1));
  }

  __m128 c, w, half, kHalf, a0;
};

template <int W>
void evalB(const Tape& T, uint32_t ni, const Pts& pts, const Box3& pbox, float* out);

/// A Ricci blend of n's children: out = m·S^(1/k) per point (RicciAcc).
template <int W>
void evalRicciB(const Tape& T, const TNode& n, const Pts& pts, const Box3& pbox, float* out) {
  alignas(32) float tmp[kCap<W>];
  alignas(32) float S[kCap<W>];
  fillLanes<W>(out, pts, 0.0f);  // running max m
  fillLanes<W>(S, pts, 0.0f);
  // S >= 1 once a child contributes, so a term (f/m)^n < 2^-25 cannot change it in float:
  // f < m·2^(-25/n) skips the pow with the same bits (most points of a shell with small
  // bumps under n = 400). Likewise S == 1 (one contributor) gives m exactly.
  const float negligible = std::exp2(-25.0f / n.exponent);
  childrenIn(T, n, pbox, [&](uint32_t c) {
    evalB<W>(T, c, pts, pbox, tmp);
    for (int i = 0; i < pts.n; ++i) {
      if (tmp[i] < out[i] * negligible) continue;
      RicciAcc a{out[i], S[i]};
      a.add(tmp[i], n.exponent);
      out[i] = a.m;
      S[i] = a.s;
    }
  });
  for (int i = 0; i < pts.n; ++i)
    out[i] = out[i] > 0.0f ? (S[i] == 1.0f ? out[i] : out[i] * std::pow(S[i], 1.0f / n.exponent)) : 0.0f;
}

/// A PCM junction of n's children (PcmAccum per point, as structure of arrays).
template <int W>
void evalPcmB(const Tape& T, const TNode& n, const Pts& pts, const Box3& pbox, float* out) {
  alignas(32) float tmp[kCap<W>];
  // PcmAccum per point, as structure of arrays: out holds f1.
  alignas(32) float d1[kCap<W>], f2[kCap<W>], d2[kCap<W>], bulge[kCap<W>];
  fillLanes<W>(out, pts, 0.0f);
  fillLanes<W>(d1, pts, 0.0f);
  fillLanes<W>(f2, pts, 0.0f);
  fillLanes<W>(d2, pts, 0.0f);
  fillLanes<W>(bulge, pts, 0.0f);
  const PcmStep4 step(params(T, n).pcm);
  childrenIn(T, n, pbox, [&](uint32_t c) {
    evalB<W>(T, c, pts, pbox, tmp);
    for (int i = 0; i < lanes<W>(pts); i += 4) step.add(tmp + i, out + i, d1 + i, f2 + i, d2 + i, bulge + i);
  });
  for (int i = 0; i < pts.n; ++i) {
    const PcmAccum acc{out[i], d1[i], f2[i], d2[i], bulge[i]};
    out[i] = acc.value();
  }
}

/// bend.localFromWorld of lanes [0, n8) whose lanes [n, n8) repeat lane n - 1 (n >= 1): only
/// the groups of four that hold real lanes are mapped, the rest copy lane n - 1's image (the
/// same point maps to the same bits), so a batch of at most four real points maps half of
/// its eight lanes.
inline void mapLanes(const BendFrame& bend, const float* x, const float* y, const float* z, float* lx, float* ly,
                     float* lz, int n, int n8) {
  const int n4 = (n + 3) & ~3;
  bend.localFromWorld(x, y, z, lx, ly, lz, n4);
  for (int i = n4; i < n8; ++i) {
    lx[i] = lx[n - 1];
    ly[i] = ly[n - 1];
    lz[i] = lz[n - 1];
  }
}

/// A bend of n's child. Only the points that may reach the child's support (inside the
/// bend's world box and its oriented box, BendFrame::mayReach) are mapped, an atan2 and a
/// square root each, and evaluated; the others get 0, as evalS's culling gives them (the
/// child is 0 outside its support's image).
template <int W>
void evalBendB(const Tape& T, const TNode& n, const Pts& pts, const Box3& /*pbox*/, float* out) {
  alignas(32) float tmp[kCap<W>];
  const BendFrame& bend = params(T, n).bend;
  alignas(32) float lx[kCap<W>], ly[kCap<W>], lz[kCap<W>];
  alignas(32) float cx[kCap<W>], cy[kCap<W>], cz[kCap<W>];
  uint64_t bits[(kCap<W> + 63) / 64] = {};
  for (int i = 0; i < lanes<W>(pts); i += 4)
    bits[i >> 6] |= uint64_t(mayReach4(bend, n.box, pts.x + i, pts.y + i, pts.z + i)) << (i & 63);
  if (pts.n & 63) bits[pts.n >> 6] &= (uint64_t(1) << (pts.n & 63)) - 1;  // padding lanes
  int m = 0;
  for (uint64_t w : bits) m += __builtin_popcountll(w);
  if (m == pts.n) {
    mapLanes(bend, pts.x, pts.y, pts.z, lx, ly, lz, pts.n, lanes<W>(pts));
    const Box3 lb = boxOfPoints(lx, ly, lz, lanes<W>(pts));
    Pts lp{lx, ly, lz, pts.n, lanes<W>(pts)};
    evalB<W>(T, T.kids[n.first], lp, lb, out);
    return;
  }
  fillLanes<W>(out, pts, 0.0f);
  if (m == 0) return;
  uint16_t at[kCap<W>];
  m = 0;
  for (int k = 0; k < (kCap<W> + 63) / 64; ++k)
    for (uint64_t w = bits[k]; w != 0; w &= w - 1) {
      const int i = k * 64 + __builtin_ctzll(w);
      cx[m] = pts.x[i];
      cy[m] = pts.y[i];
      cz[m] = pts.z[i];
      at[m++] = uint16_t(i);
    }
  const int m8 = (m + 7) & ~7;
  for (int i = m; i < m8; ++i) {
    cx[i] = cx[m - 1];
    cy[i] = cy[m - 1];
    cz[i] = cz[m - 1];
  }
  mapLanes(bend, cx, cy, cz, lx, ly, lz, m, m8);
  const Box3 lb = boxOfPoints(lx, ly, lz, m8);  // lanes m..m8 repeat lane m - 1
  Pts lp{lx, ly, lz, m, m8};
  evalB<W>(T, T.kids[n.first], lp, lb, tmp);
  for (int k = 0; k < m; ++k) out[at[k]] = tmp[k];
}

/// A transform, twist or taper of n's child: the points mapped into its frame.
template <int W>
void evalWarpB(const Tape& T, const TNode& n, const Pts& pts, const Box3& /*pbox*/, float* out) {
  alignas(32) float lx[kCap<W>], ly[kCap<W>], lz[kCap<W>];
  Box3 lb;
  for (int i = 0; i < lanes<W>(pts); ++i) {
    Vec3 q = warpLocal(T, n, Vec3(pts.x[i], pts.y[i], pts.z[i]), nullptr);
    lx[i] = q.x;
    ly[i] = q.y;
    lz[i] = q.z;
    lb.extend(q);
  }
  Pts lp{lx, ly, lz, pts.n, lanes<W>(pts)};
  evalB<W>(T, T.kids[n.first], lp, lb, out);
}

template <int W>
void evalB(const Tape& T, uint32_t ni, const Pts& pts, const Box3& pbox, float* out) {
  const TNode& n = T.nodes[ni];
  if (!pbox.overlaps(n.box)) {
    fillLanes<W>(out, pts, 0.0f);
    return;
  }
  if (isPrimitive(n.kind)) {
    primBatch<W, false>(T.prim(n.prim), pts, out);
    return;
  }
  alignas(32) float tmp[kCap<W>];
  switch (n.kind) {
    case NodeKind::Blend:
      fillLanes<W>(out, pts, 0.0f);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        const TNode& cn = T.nodes[c];
        if (isPrimitive(cn.kind)) {
          primBatch<W, true>(T.prim(cn.prim), pts, out);
        } else {
          evalB<W>(T, c, pts, pbox, tmp);
          for (int i = 0; i < lanes<W>(pts); ++i) out[i] += tmp[i];
        }
      });
      return;
    case NodeKind::Union:
      fillLanes<W>(out, pts, 0.0f);
      childrenIn(T, n, pbox, [&](uint32_t c) {
        evalB<W>(T, c, pts, pbox, tmp);
        for (int i = 0; i < lanes<W>(pts); ++i) out[i] = std::max(out[i], tmp[i]);
      });
      return;
    case NodeKind::Intersect:
      fillLanes<W>(out, pts, std::numeric_limits<float>::max());
      for (uint32_t k = 0; k < n.count; ++k) {
        evalB<W>(T, T.kids[n.first + k], pts, pbox, tmp);
        for (int i = 0; i < lanes<W>(pts); ++i) out[i] = std::min(out[i], tmp[i]);
      }
      for (int i = 0; i < lanes<W>(pts); ++i) out[i] = std::max(0.0f, out[i]);
      return;
    case NodeKind::Difference:
      evalB<W>(T, T.kids[n.first], pts, pbox, out);
      evalB<W>(T, T.kids[n.first + 1], pts, pbox, tmp);
      for (int i = 0; i < lanes<W>(pts); ++i) out[i] = std::max(0.0f, std::min(out[i], 1.0f - tmp[i]));
      return;
    case NodeKind::Ricci: return evalRicciB<W>(T, n, pts, pbox, out);
    case NodeKind::Pcm: return evalPcmB<W>(T, n, pts, pbox, out);
    case NodeKind::Negative:
      evalB<W>(T, T.kids[n.first], pts, pbox, out);
      for (int i = 0; i < lanes<W>(pts); ++i) out[i] *= -n.weight;
      return;
    case NodeKind::Bend: return evalBendB<W>(T, n, pts, pbox, out);
    case NodeKind::Transform:
    case NodeKind::Twist:
    case NodeKind::Taper: return evalWarpB<W>(T, n, pts, pbox, out);
    default: fillLanes<W>(out, pts, 0.0f); return;
  }
}

}  // namespace

void evalBatch(const Tape& T, std::span<const Vec3> points, std::span<float> out) {
  alignas(32) float x[kBlock], y[kBlock], z[kBlock], r[kBlock];
  for (size_t b = 0; b < points.size(); b += kBlock) {
    int n = int(std::min<size_t>(kBlock, points.size() - b));
    int n8 = (n + 7) & ~7;
    Box3 box;
    for (int i = 0; i < n; ++i) {
      const Vec3& p = points[b + size_t(i)];
      x[i] = p.x;
      y[i] = p.y;
      z[i] = p.z;
      box.extend(p);
    }
    for (int i = n; i < n8; ++i) {
      x[i] = x[n - 1];
      y[i] = y[n - 1];
      z[i] = z[n - 1];
    }
    Pts pts{x, y, z, n, n8};
    if (n8 == 8) evalB<8>(T, T.root, pts, box, r);  // the tracer's batches
    else evalB<0>(T, T.root, pts, box, r);
    std::copy(r, r + n, out.begin() + long(b));
  }
}

}  // namespace sprig::blobtree::detail
