#include "lsystem/cpfg_texture.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/srgb.h"

namespace sprig::lsystem {

namespace {

/// x wrapped into [0, n) (GL_REPEAT).
int wrap(long long x, int n) {
  const long long m = x % n;
  return static_cast<int>(m < 0 ? m + n : m);
}

/// GLU's nearestPower (mipmap.c): the power of two nearest to n (3 -> 4, 5 -> 4, 6 -> 8).
int nearestPower(int n) {
  int p = 1;
  for (unsigned v = static_cast<unsigned>(n);; v >>= 1, p *= 2) {
    if (v <= 1) return p;
    if (v == 3) return p * 4;
  }
}

/// The texel of level at (s, t), repeating; nearest or bilinear.
Vec4 sampleLevel(const Image& image, double s, double t, bool linear) {
  const int w = image.width, h = image.height;
  if (!std::isfinite(s) || !std::isfinite(t)) return image.at(0, h - 1);
  s -= std::floor(s);
  t -= std::floor(t);
  // Texel (x, y) counted from the bottom row covers [x/w, (x+1)/w] x [y/h, (y+1)/h].
  const double x = s * w, y = t * h;
  auto texel = [&](long long tx, long long ty) { return image.at(wrap(tx, w), h - 1 - wrap(ty, h)); };
  if (!linear) return texel(static_cast<long long>(std::floor(x)), static_cast<long long>(std::floor(y)));
  const double fx = x - 0.5, fy = y - 0.5;
  const long long x0 = static_cast<long long>(std::floor(fx)), y0 = static_cast<long long>(std::floor(fy));
  const float ax = static_cast<float>(fx - static_cast<double>(x0)), ay = static_cast<float>(fy - static_cast<double>(y0));
  const Vec4 bottom = glm::mix(texel(x0, y0), texel(x0 + 1, y0), ax);
  const Vec4 top = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), ax);
  return glm::mix(bottom, top, ay);
}

}  // namespace

Vec4 CpfgTexture::sample(double s, double t, bool minified) const {
  if (!image || image->width <= 0 || image->height <= 0) return Vec4(1.0f);
  return sampleLevel(*image, s, t, minified ? minLinear : magLinear);
}

Vec4 CpfgTexture::sampleFootprint(double s, double t, double texelsPerPixel) const {
  if (!image || image->width <= 0 || image->height <= 0) return Vec4(1.0f);
  // OpenGL 2.1, 3.8.8: λ = log2 ρ; magnification up to c.
  const double lambda = texelsPerPixel > 0 ? std::log2(texelsPerPixel) : -std::numeric_limits<double>::infinity();
  const double c = mipmap && magLinear && !minLinear ? 0.5 : 0.0;
  if (!(lambda > c)) return sampleLevel(*image, s, t, magLinear);
  if (!mipmap || levels.empty()) return sampleLevel(*image, s, t, minLinear);
  const int q = static_cast<int>(levels.size());  // the last level
  auto level = [&](int d) -> const Image& { return d <= 0 ? *image : *levels[static_cast<size_t>(std::min(d, q)) - 1]; };
  if (!mipLinear) {
    const int d = lambda <= 0.5 ? 0 : static_cast<int>(std::min<double>(std::ceil(lambda + 0.5) - 1, q));
    return sampleLevel(level(d), s, t, minLinear);
  }
  const double d1 = std::floor(lambda);
  if (d1 >= q) return sampleLevel(level(q), s, t, minLinear);
  const float frac = static_cast<float>(lambda - d1);
  const int d = static_cast<int>(d1);
  return glm::mix(sampleLevel(level(d), s, t, minLinear), sampleLevel(level(d + 1), s, t, minLinear), frac);
}

void CpfgTexture::buildMipmaps(bool srgbFile) {
  levels.clear();
  if (!image || image->width <= 0 || image->height <= 0) return;
  // In the file's encoding, as GLU averages the stored values (alpha is linear in both).
  auto encode = [srgbFile](Image img, bool toFile) {
    if (srgbFile)
      for (size_t p = 0; p + 3 < img.pixels.size(); p += 4)
        for (size_t k = 0; k < 3; ++k) img.pixels[p + k] = toFile ? linearToSrgb(img.pixels[p + k]) : srgbToLinear(img.pixels[p + k]);
    return img;
  };
  Image current = encode(*image, true);
  const int w0 = nearestPower(image->width), h0 = nearestPower(image->height);
  if (w0 != image->width || h0 != image->height) {
    current = resizeImage(current, w0, h0);
    image = std::make_shared<const Image>(encode(current, false));
  }
  while (current.width > 1 || current.height > 1) {
    current = resizeImage(current, std::max(1, current.width / 2), std::max(1, current.height / 2));
    levels.push_back(std::make_shared<const Image>(encode(current, false)));
  }
}

Vec4 CpfgTexture::combine(const Vec4& c, const Vec3& base) const {
  if (decal) return Vec4(glm::mix(base, Vec3(c), std::clamp(c.a, 0.0f, 1.0f)), 1.0f);
  if (blend) return Vec4(base * (Vec3(1.0f) - Vec3(c)), c.a);  // + Cc Ct, Cc = (0, 0, 0)
  return Vec4(Vec3(c) * base, c.a);
}

Vec4 CpfgTexture::fragment(double s, double t, const Vec3& base, bool minified) const {
  return combine(sample(s, t, minified), base);
}

}  // namespace sprig::lsystem
