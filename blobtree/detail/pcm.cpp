#include "blobtree/detail/pcm.h"

#include <cmath>

namespace sprig::blobtree::detail {

PcmDerived derivePcm(const PcmParams& p) {
  PcmDerived d;
  d.c = p.iso;
  d.w = p.width;
  d.k = p.slope;
  d.a0 = p.bulgeScale * p.slope * p.width * 0.25f;
  float m = 1.0f;
  for (int i = 0; i <= 256; ++i) {
    float dh;
    pcmH(d, d.w * float(i) / 256.0f, &dh);
    m = std::max(m, std::abs(dh));
  }
  d.maxSlope = m * 1.05f;
  return d;
}

}  // namespace sprig::blobtree::detail
