#include "blobtree/detail/marching_tets.h"

namespace sprig::blobtree::detail {

const std::array<uint8_t, 256> kTriangleCount = [] {
  std::array<uint8_t, 256> n{};
  for (int m = 0; m < 256; ++m)
    for (const auto& t : kTets) {
      int in = ((m >> t[0]) & 1) + ((m >> t[1]) & 1) + ((m >> t[2]) & 1) + ((m >> t[3]) & 1);
      n[size_t(m)] = uint8_t(n[size_t(m)] + (in == 2 ? 2 : (in == 1 || in == 3 ? 1 : 0)));
    }
  return n;
}();

void TetEmitter::run(const int t[4], const bool in[4]) {
  int count = in[0] + in[1] + in[2] + in[3];
  if (count == 0 || count == 4) return;
  if (count == 1 || count == 3) {
    // The lone vertex s against the other three.
    bool loneInside = count == 1;
    int s = 0;
    while (in[s] != loneInside) ++s;
    int o[3], n = 0;
    for (int k = 0; k < 4; ++k)
      if (k != s) o[n++] = k;
    Vec3 ps = Vec3(cornerOffset(t[s]));
    Vec3 po = (Vec3(cornerOffset(t[o[0]])) + Vec3(cornerOffset(t[o[1]])) + Vec3(cornerOffset(t[o[2]]))) / 3.0f;
    Vec3 outward = loneInside ? po - ps : ps - po;
    uint32_t e[3];
    for (int k = 0; k < 3; ++k) e[k] = edge(t[s], t[o[k]]);
    emit(e[0], e[1], e[2], mid(t[s], t[o[0]]), mid(t[s], t[o[1]]), mid(t[s], t[o[2]]), outward);
    return;
  }
  // Two inside (a, b), two outside (c, d): the quad ac, ad, bd, bc.
  int ins[2], outs[2], ni = 0, no = 0;
  for (int k = 0; k < 4; ++k) (in[k] ? ins[ni++] : outs[no++]) = t[k];
  int a = ins[0], b = ins[1], c = outs[0], d = outs[1];
  Vec3 outward = 0.5f * (Vec3(cornerOffset(c)) + Vec3(cornerOffset(d))) -
                 0.5f * (Vec3(cornerOffset(a)) + Vec3(cornerOffset(b)));
  uint32_t ac = edge(a, c), ad = edge(a, d), bd = edge(b, d), bc = edge(b, c);
  emit(ac, ad, bd, mid(a, c), mid(a, d), mid(b, d), outward);
  emit(ac, bd, bc, mid(a, c), mid(b, d), mid(b, c), outward);
}

}  // namespace sprig::blobtree::detail
