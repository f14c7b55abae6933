#include "solids/extrude_field.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <tuple>

#include "core/parallel.h"

namespace sprig::solids {

namespace {

/// Squared distance standing in for "no such pixel" (finite, so the envelope's
/// intersections stay finite), unless the grid's own distances come near it (farFor).
constexpr double kFar = 1e20;

/// The "no such pixel" of a w x h grid of pixels pu x pv: above every squared distance
/// within the grid. With pixel sides in [kMinExtrudePixel, kMaxExtrudePixel] it stays far
/// below the point where the envelope's intersections (far / pixel) overflow.
double farFor(int w, int h, double pu, double pv) {
  const double span = std::max(pu, pv) * (double(w) + double(h));
  return std::max(kFar, 4 * span * span);
}

/// The 1-D squared-distance transform of f over n samples spaced w apart (Felzenszwalb &
/// Huttenlocher 2012, Algorithm 1): d[q] = min_p (w(q - p))² + f[p], the lower envelope of
/// parabolas rooted at each sample. v, z are scratch of n and n + 1 entries.
void transform1d(const double* f, int n, double w, double* d, std::vector<int>& v, std::vector<double>& z) {
  // (k > 0 below: z[0] = -inf stops the walk back for every finite crossing; the test keeps
  // a non-finite one, which extrudeScaleProblem rules out, from writing before v.)
  int k = 0;
  v[0] = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  auto cross = [&](int q, int p) {  // where the parabolas of q and p meet (world units)
    const double xq = w * q, xp = w * p;
    return ((f[q] + xq * xq) - (f[p] + xp * xp)) / (2 * (xq - xp));
  };
  for (int q = 1; q < n; ++q) {
    double s = cross(q, v[k]);
    while (k > 0 && s <= z[k]) {
      --k;
      s = cross(q, v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < w * q) ++k;
    const double dx = w * (q - v[k]);
    d[q] = dx * dx + f[v[k]];
  }
}

/// Squared Euclidean distance from every sample of a w x h grid to the nearest sample with
/// target set: columns first, then rows (the transform is separable).
std::vector<double> squaredDistance(const std::vector<uint8_t>& target, int w, int h, double pu, double pv) {
  std::vector<double> g(size_t(w) * h);
  const double far = farFor(w, h, pu, pv);
  for (size_t i = 0; i < g.size(); ++i) g[i] = target[i] ? 0.0 : far;
  // Columns (along v), one per task.
  parallelForRange(0, size_t(w), [&](size_t b, size_t e) {
    std::vector<double> f(h), d(h), z(h + 1);
    std::vector<int> v(h);
    for (size_t x = b; x < e; ++x) {
      for (int y = 0; y < h; ++y) f[y] = g[size_t(y) * w + x];
      transform1d(f.data(), h, pv, d.data(), v, z);
      for (int y = 0; y < h; ++y) g[size_t(y) * w + x] = d[y];
    }
  }, 16);
  // Rows (along u).
  parallelForRange(0, size_t(h), [&](size_t b, size_t e) {
    std::vector<double> d(w), z(w + 1);
    std::vector<int> v(w);
    for (size_t y = b; y < e; ++y) {
      double* row = g.data() + y * w;
      transform1d(row, w, pu, d.data(), v, z);
      std::copy(d.begin(), d.end(), row);
    }
  }, 16);
  return g;
}

/// The smallest rotation taking +y to unit a, applied to q (Rodrigues).
DVec3 fromYTo(const DVec3& a, const DVec3& q) {
  const DVec3 y(0, 1, 0);
  const double c = glm::dot(y, a);
  if (c > 1 - 1e-12) return q;
  if (c < -1 + 1e-12) return DVec3(q.x, -q.y, -q.z);  // half a turn about x
  const DVec3 k = glm::normalize(glm::cross(y, a));
  const double angle = std::acos(std::clamp(c, -1.0, 1.0));
  return q * std::cos(angle) + glm::cross(k, q) * std::sin(angle) + k * glm::dot(k, q) * (1 - std::cos(angle));
}

class ExtrudeField final : public DistanceField {
 public:
  ExtrudeField(const Mask2d& mask, const ExtrudeOptions& o) : o_(o) {
    if (mask.width <= 0 || mask.height <= 0 || mask.inside.size() != size_t(mask.width) * mask.height)
      throw std::invalid_argument("the mask has no pixels");
    if (!(o.size.x > 0 && o.size.y > 0)) throw std::invalid_argument("'size' must be positive");
    if (!(o.heightHi > o.heightLo)) throw std::invalid_argument("'height' needs lo < hi");
    if (std::string why = extrudeScaleProblem(mask.width, mask.height, o); !why.empty()) throw std::invalid_argument(why);
    axis_ = glm::normalize(o.axis);
    std::tie(u_, v_) = imagePlaneAxes(axis_);
    pu_ = o.size.x / mask.width;
    pv_ = o.size.y / mask.height;
    pad_ = (std::max(mask.width, mask.height) + 1) / 2;
    w_ = mask.width + 2 * pad_;
    h_ = mask.height + 2 * pad_;
    d2_ = signedDistance2d(mask, pu_, pv_, pad_);
    empty_ = std::find(mask.inside.begin(), mask.inside.end(), uint8_t(1)) == mask.inside.end();
    // Plane coordinates of the padded grid's first sample centre.
    u0_ = o.center.x - o.size.x / 2 + (0.5 - pad_) * pu_;
    v0_ = o.center.y - o.size.y / 2 + (0.5 - pad_) * pv_;
  }

  std::vector<float> sample(const std::vector<Vec3>& points, double, double) const override {
    std::vector<float> out(points.size());
    parallelFor(0, points.size(), [&](size_t i) { out[i] = float(at(DVec3(points[i]))); }, 4096);
    return out;
  }

  std::optional<DBox3> bounds() const override {
    DBox3 box;
    for (int k = 0; k < 8; ++k) {
      const double u = o_.center.x + ((k & 1) ? 0.5 : -0.5) * o_.size.x;
      const double v = o_.center.y + ((k & 2) ? 0.5 : -0.5) * o_.size.y;
      const double h = (k & 4) ? o_.heightHi : o_.heightLo;
      box.extend(u * u_ + v * v_ + h * axis_);
    }
    return box;
  }

 private:
  /// The 2-D signed distance at plane point (u, v).
  double distance2d(double u, double v) const {
    if (empty_) return 1e6;
    // Step 1: continuous sample coordinates, clamped to the padded grid.
    const double fx = (u - u0_) / pu_, fy = (v - v0_) / pv_;
    const double cx = std::clamp(fx, 0.0, double(w_ - 1)), cy = std::clamp(fy, 0.0, double(h_ - 1));
    // Step 2: bilinear interpolation of the transform.
    const int x0 = std::min(int(cx), w_ - 2), y0 = std::min(int(cy), h_ - 2);
    const double tx = cx - x0, ty = cy - y0;
    auto g = [&](int x, int y) { return double(d2_[size_t(y) * w_ + x]); };
    const double d = (1 - ty) * ((1 - tx) * g(x0, y0) + tx * g(x0 + 1, y0)) + ty * ((1 - tx) * g(x0, y0 + 1) + tx * g(x0 + 1, y0 + 1));
    // Step 3: beyond the padding, add the distance to the padded rectangle.
    return d + std::hypot((fx - cx) * pu_, (fy - cy) * pv_);
  }

  double at(const DVec3& p) const {
    const double d2 = distance2d(glm::dot(p, u_), glm::dot(p, v_));
    const double mid = 0.5 * (o_.heightLo + o_.heightHi), half = 0.5 * (o_.heightHi - o_.heightLo);
    const double dh = std::abs(glm::dot(p, axis_) - mid) - half;
    return std::hypot(std::max(d2, 0.0), std::max(dh, 0.0)) + std::min(std::max(d2, dh), 0.0);
  }

  ExtrudeOptions o_;
  DVec3 axis_, u_, v_;
  double pu_ = 1, pv_ = 1, u0_ = 0, v0_ = 0;
  int pad_ = 0, w_ = 0, h_ = 0;
  bool empty_ = false;
  std::vector<float> d2_;
};

}  // namespace

std::pair<DVec3, DVec3> imagePlaneAxes(const DVec3& axis) { return {fromYTo(axis, DVec3(1, 0, 0)), fromYTo(axis, DVec3(0, 0, 1))}; }

std::string extrudeScaleProblem(int width, int height, const ExtrudeOptions& o) {
  const double pu = o.size.x / width, pv = o.size.y / height;
  if (pu >= kMinExtrudePixel && pu <= kMaxExtrudePixel && pv >= kMinExtrudePixel && pv <= kMaxExtrudePixel) return {};
  char buf[256];
  std::snprintf(buf, sizeof buf, "'size' [%g, %g] over %d x %d pixels makes pixels of %g x %g world units; each side must lie in [%g, %g]",
                o.size.x, o.size.y, width, height, pu, pv, kMinExtrudePixel, kMaxExtrudePixel);
  return buf;
}

std::vector<float> signedDistance2d(const Mask2d& mask, double pixelU, double pixelV, int pad) {
  if (!(pixelU >= kMinExtrudePixel && pixelU <= kMaxExtrudePixel && pixelV >= kMinExtrudePixel && pixelV <= kMaxExtrudePixel))
    throw std::invalid_argument("signedDistance2d: pixel sides must lie in [1e-12, 1e12]");
  const int w = mask.width + 2 * pad, h = mask.height + 2 * pad;
  std::vector<uint8_t> in(size_t(w) * h, 0), out(size_t(w) * h, 1);
  for (int y = 0; y < mask.height; ++y)
    for (int x = 0; x < mask.width; ++x) {
      const size_t i = size_t(y + pad) * w + (x + pad);
      in[i] = mask.inside[size_t(y) * mask.width + x] ? 1 : 0;
      out[i] = 1 - in[i];
    }
  const std::vector<double> toInside = squaredDistance(in, w, h, pixelU, pixelV);
  const std::vector<double> toOutside = squaredDistance(out, w, h, pixelU, pixelV);
  // The boundary lies half a pixel from each centre next to it.
  const double halfPixel = 0.5 * std::min(pixelU, pixelV);
  std::vector<float> d(size_t(w) * h);
  for (size_t i = 0; i < d.size(); ++i)
    d[i] = in[i] ? float(-(std::sqrt(toOutside[i]) - halfPixel)) : float(std::sqrt(toInside[i]) - halfPixel);
  return d;
}

FieldPtr extrudeField(const Mask2d& mask, const ExtrudeOptions& options) {
  return std::make_shared<ExtrudeField>(mask, options);
}

}  // namespace sprig::solids
