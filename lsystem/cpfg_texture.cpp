#include "lsystem/cpfg_texture.h"

#include <algorithm>
#include <cmath>

namespace sprig::lsystem {

namespace {

/// x wrapped into [0, n) (GL_REPEAT).
int wrap(long long x, int n) {
  const long long m = x % n;
  return static_cast<int>(m < 0 ? m + n : m);
}

}  // namespace

Vec4 CpfgTexture::sample(double s, double t, bool minified) const {
  if (!image || image->width <= 0 || image->height <= 0) return Vec4(1.0f);
  const int w = image->width, h = image->height;
  if (!std::isfinite(s) || !std::isfinite(t)) return image->at(0, h - 1);
  s -= std::floor(s);
  t -= std::floor(t);
  // Texel (x, y) counted from the bottom row covers [x/w, (x+1)/w] x [y/h, (y+1)/h].
  const double x = s * w, y = t * h;
  auto texel = [&](long long tx, long long ty) { return image->at(wrap(tx, w), h - 1 - wrap(ty, h)); };
  if (!(minified ? minLinear : magLinear)) return texel(static_cast<long long>(std::floor(x)), static_cast<long long>(std::floor(y)));
  const double fx = x - 0.5, fy = y - 0.5;
  const long long x0 = static_cast<long long>(std::floor(fx)), y0 = static_cast<long long>(std::floor(fy));
  const float ax = static_cast<float>(fx - static_cast<double>(x0)), ay = static_cast<float>(fy - static_cast<double>(y0));
  const Vec4 bottom = glm::mix(texel(x0, y0), texel(x0 + 1, y0), ax);
  const Vec4 top = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), ax);
  return glm::mix(bottom, top, ay);
}

Vec4 CpfgTexture::fragment(double s, double t, const Vec3& base, bool minified) const {
  const Vec4 c = sample(s, t, minified);
  if (decal) return Vec4(glm::mix(base, Vec3(c), std::clamp(c.a, 0.0f, 1.0f)), 1.0f);
  return Vec4(Vec3(c) * base, c.a);
}

}  // namespace sprig::lsystem
