#include "blobtree/tracer.h"

#include "blobtree/detail/field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

namespace sprig::blobtree {

namespace {

/// The recursive batched tracer of one span (see the file comment of tracer.h). Misses are
/// negative parameters internally, so a crossing at t < 0 counts as none.
class BatchTracer {
 public:
  BatchTracer(const CompiledBlob& blob, const Ray& ray, float lipschitz, Crossing mode)
      : blob_(blob), o_(ray.origin), d_(ray.direction), L_(lipschitz), mode_(mode) {}

  /// First crossing in [t0, t1], or a negative value.
  float trace(float t0, float t1, float tolerance) {
    // A tolerance below the spacing of floats near t can never be reached (the samples
    // stop moving): far from the camera, 8 float steps at t bound it from below.
    tol_ = std::max(tolerance, 8.0f * std::numeric_limits<float>::epsilon() * std::max(std::abs(t0), std::abs(t1)));
    return first(t0, t1, 0);
  }

 private:
  /// Samples kTraceLanes evenly spaced parameters from a to b (b exactly); returns the spacing.
  float evaluate(float a, float b, float* ts, float* f) const {
    Vec3 pts[kTraceLanes];
    float step = (b - a) / static_cast<float>(kTraceLanes - 1);
    for (int i = 0; i < kTraceLanes; ++i) {
      ts[i] = i == kTraceLanes - 1 ? b : a + step * static_cast<float>(i);
      pts[i] = o_ + ts[i] * d_;
    }
    blob_.values(pts, std::span<float>(f, kTraceLanes));
    return step;
  }

  /// True when the sample interval [i, i+1] may hide a double crossing: the Lipschitz
  /// bound lets the field reach 0.5 between two samples on the same side.
  bool mayHide(const float* f, int i, float step, int depth) const {
    return depth < kMaxDepth && step > tol_ && std::abs(f[i] - kIso) + std::abs(f[i + 1] - kIso) <= L_ * step;
  }

  float first(float a, float b, int depth) {
    float ts[kTraceLanes], f[kTraceLanes];
    float step = evaluate(a, b, ts, f);
    for (int i = 0; i + 1 < kTraceLanes; ++i) {
      if ((f[i] > kIso) != (f[i + 1] > kIso))
        return mode_ == Crossing::Any ? ts[i] : refine(ts[i], ts[i + 1], f[i], f[i + 1], depth);
      if (mayHide(f, i, step, depth)) {
        float t = first(ts[i], ts[i + 1], depth + 1);
        if (t >= 0.0f) return t;
      }
    }
    return -1.0f;
  }

  /// Shrinks the straddling interval [lo, hi] to the tolerance, then interpolates. In
  /// Crossing::First mode the sub-intervals ahead of each sign change are searched for
  /// hidden double crossings first.
  float refine(float lo, float hi, float flo, float fhi, int depth) {
    float ts[kTraceLanes], f[kTraceLanes];
    const bool insideLo = flo > kIso;
    while (hi - lo > tol_) {
      float step = evaluate(lo, hi, ts, f);
      int k = 0;
      while (k + 2 < kTraceLanes && (f[k + 1] > kIso) == insideLo) ++k;
      if (mode_ == Crossing::First)
        for (int j = 0; j < k; ++j)
          if (mayHide(f, j, step, depth + 1)) {
            float t = first(ts[j], ts[j + 1], depth + 1);
            if (t >= 0.0f) return t;
          }
      lo = ts[k];
      hi = ts[k + 1];
      flo = f[k];
      fhi = f[k + 1];
    }
    float w = flo != fhi ? (flo - kIso) / (flo - fhi) : 0.5f;
    return lo + std::clamp(w, 0.0f, 1.0f) * (hi - lo);
  }

  static constexpr int kMaxDepth = 12;
  const CompiledBlob& blob_;
  Vec3 o_, d_;
  float L_;
  Crossing mode_;
  float tol_ = 0.0f;
};

/// The size tolerances are relative to: the bounds' diagonal (1 for unbounded blobs).
float modelSize(const Box3& b) {
  if (b.empty() || detail::isHuge(b)) return 1.0f;
  return std::max(glm::length(b.size()), 1e-20f);
}

}  // namespace

bool clipToBox(const Box3& box, Vec3 origin, Vec3 direction, float& t0, float& t1) {
  for (int a = 0; a < 3; ++a) {
    if (direction[a] == 0.0f) {
      if (origin[a] < box.lo[a] || origin[a] > box.hi[a]) return false;
      continue;
    }
    float inv = 1.0f / direction[a];
    float ta = (box.lo[a] - origin[a]) * inv, tb = (box.hi[a] - origin[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

std::optional<float> traceSegment(const CompiledBlob& blob, const Ray& ray, float t0, float t1, float lipschitz,
                                  float tolerance, Crossing mode) {
  float t = BatchTracer(blob, ray, lipschitz, mode).trace(t0, t1, tolerance);
  if (t >= 0.0f) return t;
  return std::nullopt;
}

std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode) {
  if (!clipToBox(cell.box, ray.origin, ray.direction, t0, t1)) return std::nullopt;
  float lipschitz = std::max(cell.lipschitz, 1e-30f) * glm::length(ray.direction);
  return traceSegment(blob, ray, t0, t1, lipschitz, tolerance, mode);
}

std::optional<float> traceRay(const CompiledBlob& blob, const Ray& ray, float tmin, float tmax,
                              const TraceOptions& options) {
  const float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f)) return std::nullopt;
  const Vec3 o = ray.origin, d = ray.direction;
  const Box3 root = blob.bounds();
  if (root.empty()) return std::nullopt;
  const bool unbounded = detail::isHuge(root);
  float t0 = tmin, t1 = tmax;
  if (!unbounded && !clipToBox(root, o, d, t0, t1)) return std::nullopt;
  if (!(t1 >= t0)) return std::nullopt;
  const float size = unbounded ? std::max(1.0f, (t1 - t0) * dirLen) : modelSize(root);
  const float tol = std::max(options.relativeTolerance * size, 1e-30f) / dirLen;  // in units of t
  const float wMin = 4.0f * tol;
  float s = t0, f = blob.value(o + s * d);
  float W = std::max(t1 - t0, tol);
  for (int step = 0; step < options.maxSteps && s < t1; ++step) {
    W = std::min(W, t1 - s);
    const bool inside = f > kIso;
    Vec3 pa = o + s * d, pb = o + (s + W) * d;
    Box3 box{glm::min(pa, pb), glm::max(pa, pb)};
    Interval iv = blob.valueBounds(box);
    if (!((!inside && iv.hi < kIso) || (inside && iv.lo > kIso))) {
      // The window may hold the surface: shrink it to a few safe steps, then trace it.
      float L = blob.lipschitz(box) * dirLen;
      float safe = L > 0.0f ? std::abs(f - kIso) / L : W;
      if (safe < W) {
        if (W > 4.0f * safe && W > wMin) {
          W = std::max(4.0f * safe, wMin);
          continue;
        }
        if (auto t = traceSegment(blob, ray, s, s + W, L, tol, Crossing::First)) return t;
      }
    }
    s += W;
    if (s >= t1) break;
    f = blob.value(o + s * d);
    W *= 2.0f;
  }
  return std::nullopt;
}

Hit hitAt(const CompiledBlob& blob, const Ray& ray, float t) {
  Hit h;
  h.t = t;
  h.point = ray.origin + t * ray.direction;
  Sample smp = blob.sample(h.point);
  float gl = glm::length(smp.gradient);
  h.normal = gl > 0.0f ? -smp.gradient / gl : -glm::normalize(ray.direction);
  h.attributes = smp.attributes;
  return h;
}

// ---- CompiledBlob's ray queries ------------------------------------------------------------

std::optional<Hit> CompiledBlob::intersect(const Ray& ray, float tmin, float tmax, const TraceOptions& opt) const {
  std::optional<float> t = traceRay(*this, ray, tmin, tmax, opt);
  if (!t) return std::nullopt;
  return hitAt(*this, ray, *t);
}

std::optional<Hit> CompiledBlob::intersectCell(const Cell& cell, const Ray& ray, float tmin, float tmax,
                                               const TraceOptions& opt) const {
  const float dirLen = glm::length(ray.direction);
  if (!(dirLen > 0.0f) || bounds().empty()) return std::nullopt;
  const float tol = std::max(opt.relativeTolerance * modelSize(bounds()), 1e-30f) / dirLen;
  std::optional<float> t = traceCell(*this, cell, ray, tmin, tmax, tol, Crossing::First);
  if (!t) return std::nullopt;
  return hitAt(*this, ray, *t);
}

}  // namespace sprig::blobtree
