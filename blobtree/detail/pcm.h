#pragma once
/// Private: Precise Contact Modeling constants and the deformation function (tree paper
/// Eq. 3 with Cani-Gascuel's propagation function).

#include "blobtree/blobtree.h"

#include <algorithm>

namespace sprig::blobtree::detail {

/// Derived PCM constants.
struct PcmDerived {
  float c = 0.5f, w = 0.15f, k = 1.0f, a0 = 0.0375f;
  float maxSlope = 1.0f;  ///< max |d'| over all f_other
};
PcmDerived derivePcm(const PcmParams& p);

/// h(x) and h'(x) on [0, w] (tree paper Eq. 3 with Cani-Gascuel's propagation function).
inline float pcmH(const PcmDerived& d, float x, float* dh) {
  float half = 0.5f * d.w;
  if (x <= half) {
    // Cubic Hermite: h(0)=0, h'(0)=k, h(half)=a0, h'(half)=0.
    float t = x / half;
    float t2 = t * t, t3 = t2 * t;
    float H10 = t3 - 2.0f * t2 + t, H01 = -2.0f * t3 + 3.0f * t2;
    float val = d.k * half * H10 + d.a0 * H01;
    if (dh) *dh = (d.k * half * (3.0f * t2 - 4.0f * t + 1.0f) + d.a0 * (-6.0f * t2 + 6.0f * t)) / half;
    return val;
  }
  // Cubic Hermite: h(half)=a0, h'(half)=0, h(w)=0, h'(w)=0.
  float t = (x - half) / half;
  float t2 = t * t, t3 = t2 * t;
  float H00 = 2.0f * t3 - 3.0f * t2 + 1.0f;
  if (dh) *dh = d.a0 * (6.0f * t2 - 6.0f * t) / half;
  return d.a0 * H00;
}

/// Deformation d(f_other) and its derivative with respect to f_other.
inline float pcmD(const PcmDerived& d, float fOther, float* dd) {
  float x = d.c - fOther;
  if (x < 0.0f) { if (dd) *dd = -1.0f; return x; }
  if (x >= d.w) { if (dd) *dd = 0.0f; return 0.0f; }
  float dh;
  float v = pcmH(d, x, dd ? &dh : nullptr);
  if (dd) *dd = -dh;
  return v;
}

/// The PCM combination of a node's children, accumulated one child at a time (tree paper
/// Eq. 3, Gascuel's contact surfaces kept with any number of objects):
///   F = f_max + Σ_{j≠max, f_j < c} h(c − f_j) + min(0, c − f_second)
/// Every bulge adds; of the compressions only the deepest one counts, the one by the second
/// strongest child. The object of f_max is compressed back to its contact surface with each
/// object j (f_max = f_j) by c − f_j alone; summing the compressions of several objects that
/// interpenetrate at one point would push F below c deeper inside (a gap between the
/// deformed objects: a void inside a junction of three or more branches). With this form
/// F >= min(f_max, c): inside any child, F >= c. `add` takes the child's clamped field f >= 0
/// and its d = pcmD(f).
struct PcmAccum {
  float f1 = 0.0f, d1 = 0.0f;  ///< the strongest child's field and deformation
  float f2 = 0.0f, d2 = 0.0f;  ///< the second strongest's
  float bulge = 0.0f;          ///< Σ max(0, d) over all children

  void add(float f, float d) {
    bulge += std::max(0.0f, d);
    if (f > f1) {
      f2 = f1;
      d2 = d1;
      f1 = f;
      d1 = d;
    } else if (f > f2) {
      f2 = f;
      d2 = d;
    }
  }
  /// F, clamped to >= 0; 0 where no child reaches.
  float value() const {
    if (f1 <= 0.0f) return 0.0f;
    // (f1 + compression) first: >= c whenever f1 >= f2 > c; the bulges (>= 0) only add.
    return std::max(0.0f, (f1 + std::min(0.0f, d2)) + (bulge - std::max(0.0f, d1)));
  }
};

}  // namespace sprig::blobtree::detail
