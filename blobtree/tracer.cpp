#include "blobtree/tracer.h"

#include "blobtree/detail/field.h"
#include "core/parallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstdlib>
#include <new>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace sprig::blobtree {

namespace {

/// The recursive batched tracer of one span (see the file comment of tracer.h). Misses are
/// negative parameters internally, so a crossing at t < 0 counts as none. With sub-cell
/// bounds (SubCellBounds) the span and each interval to be searched are first narrowed to
/// the bounds of the sub-cells they cross.
class BatchTracer {
 public:
  BatchTracer(const CompiledBlob& blob, const Ray& ray, float lipschitz, Crossing mode,
              const SubCellBounds* sub = nullptr, uint32_t cell = 0)
      : blob_(blob), ray_(ray), L_(lipschitz), mode_(mode), sub_(sub), cell_(cell),
        dirLen_(sub ? glm::length(ray.direction) : 1.0f) {}

  /// First crossing in [t0, t1], or a negative value.
  float trace(float t0, float t1, float tolerance) {
    // A tolerance below the spacing of floats near t can never be reached (the samples
    // stop moving): far from the camera, 8 float steps at t bound it from below.
    tol_ = std::max(tolerance, 8.0f * std::numeric_limits<float>::epsilon() * std::max(std::abs(t0), std::abs(t1)));
    const float L = narrowed(t0, t1, L_);
    return L < 0.0f ? -1.0f : first(t0, t1, 0, L);
  }

 private:
  /// Samples kTraceLanes evenly spaced parameters from a to b (b exactly); returns the spacing.
  float evaluate(float a, float b, float* ts, float* f) const {
    Vec3 pts[kTraceLanes];
    float step = (b - a) / static_cast<float>(kTraceLanes - 1);
    for (int i = 0; i < kTraceLanes; ++i) {
      ts[i] = i == kTraceLanes - 1 ? b : a + step * static_cast<float>(i);
      pts[i] = ray_.origin + ts[i] * ray_.direction;
    }
    blob_.values(pts, std::span<float>(f, kTraceLanes));
    return step;
  }

  /// True when the sample interval [i, i+1] may hide a double crossing: the Lipschitz
  /// bound L lets the field reach 0.5 between two samples on the same side.
  bool mayHide(const float* f, int i, float step, int depth, float L) const {
    return depth < kMaxDepth && step > tol_ && std::abs(f[i] - kIso) + std::abs(f[i + 1] - kIso) <= L * step;
  }

  /// The bound to search [a, b] with: L, or the smaller bound of the sub-cells the
  /// interval crosses; negative when their intervals exclude 0.5 (nothing to find there).
  float narrowed(float a, float b, float L) const {
    if (!sub_) return L;
    const SubCellBounds::Bound s = sub_->segment(cell_, ray_, a, b);
    if (!s.maySurface) return -1.0f;
    return std::min(L, std::max(s.lipschitz, 1e-30f) * dirLen_);
  }

  /// Searches the interval [ts[i], ts[i+1]] between two samples on one side, at recursion
  /// depth `into`, when the Lipschitz test at `depth` says it may hide a double crossing;
  /// negative otherwise.
  float searchHidden(const float* ts, const float* f, int i, float step, int depth, int into, float L) {
    if (!mayHide(f, i, step, depth, L)) return -1.0f;
    const float Li = narrowed(ts[i], ts[i + 1], L);
    if (Li < 0.0f || !mayHide(f, i, step, depth, Li)) return -1.0f;
    return first(ts[i], ts[i + 1], into, Li);
  }

  float first(float a, float b, int depth, float L) {
    float ts[kTraceLanes], f[kTraceLanes];
    float step = evaluate(a, b, ts, f);
    // Crossing::Any: a sign change anywhere in the batch answers, before any search of the
    // intervals ahead of it.
    if (mode_ == Crossing::Any)
      for (int i = 0; i + 1 < kTraceLanes; ++i)
        if ((f[i] > kIso) != (f[i + 1] > kIso)) return ts[i];
    for (int i = 0; i + 1 < kTraceLanes; ++i) {
      if ((f[i] > kIso) != (f[i + 1] > kIso)) return refine(ts[i], ts[i + 1], f[i], f[i + 1], depth, L);
      float t = searchHidden(ts, f, i, step, depth, depth + 1, L);
      if (t >= 0.0f) return t;
    }
    return -1.0f;
  }

  /// Shrinks the straddling interval [lo, hi] to the tolerance, then interpolates. In
  /// Crossing::First mode the sub-intervals ahead of each sign change are searched for
  /// hidden double crossings first.
  float refine(float lo, float hi, float flo, float fhi, int depth, float L) {
    float ts[kTraceLanes], f[kTraceLanes];
    const bool insideLo = flo > kIso;
    while (hi - lo > tol_) {
      float step = evaluate(lo, hi, ts, f);
      int k = 0;
      while (k + 2 < kTraceLanes && (f[k + 1] > kIso) == insideLo) ++k;
      if (mode_ == Crossing::First)
        for (int j = 0; j < k; ++j) {
          float t = searchHidden(ts, f, j, step, depth + 1, depth + 1, L);
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
  Ray ray_;
  float L_;
  Crossing mode_;
  const SubCellBounds* sub_;
  uint32_t cell_;
  float dirLen_;
  float tol_ = 0.0f;
};

/// The sub-cells along axis ax, first and last (0..k−1), of box split k per axis whose
/// slabs, widened by margin, the segment origin + t·direction, t in [a, b], overlaps.
std::pair<int, int> subRange(const Box3& box, int k, float margin, const Ray& ray, float a, float b, int ax) {
  const float edge = (box.hi[ax] - box.lo[ax]) / float(k);
  const float o = ray.origin[ax], d = ray.direction[ax];
  const float pa = o + a * d, pb = o + b * d;
  const float qlo = std::floor((std::min(pa, pb) - margin - box.lo[ax]) / edge);
  const float qhi = std::floor((std::max(pa, pb) + margin - box.lo[ax]) / edge);
  return {int(std::clamp(qlo, 0.0f, float(k - 1))), int(std::clamp(qhi, 0.0f, float(k - 1)))};
}

/// kSubCellRange[ax][lo][hi]: the bits of FreeSubCells' masks whose sub-cell lies in
/// [lo, hi] along axis ax.
constexpr auto kSubCellRange = [] {
  constexpr int k = FreeSubCells::kDivisions;
  std::array<std::array<std::array<uint64_t, k>, k>, 3> r{};
  for (int ax = 0; ax < 3; ++ax)
    for (int lo = 0; lo < k; ++lo)
      for (int hi = lo; hi < k; ++hi)
        for (int s = 0; s < k * k * k; ++s) {
          const int i = ax == 0 ? s % k : ax == 1 ? (s / k) % k : s / (k * k);
          if (i >= lo && i <= hi) r[ax][lo][hi] |= uint64_t(1) << s;
        }
  return r;
}();

/// Calls fn(i, j, l) for each sub-cell (i, j, l) of box split k per axis (k <= 8) whose box,
/// widened by margin, the segment origin + t·direction, t in [a, b], meets: per axis the
/// widened slabs the segment's extent overlaps and the part of [a, b] inside each (the slab
/// test of clipToBox on the sub-grid's planes), then the cells where all three parts overlap.
template <class Fn>
void forCrossedSubCells(const Box3& box, int k, float margin, const Ray& ray, float a, float b, Fn&& fn) {
  const Vec3 edge = (box.hi - box.lo) / float(k);
  int lo[3], hi[3];
  float enter[3][8], leave[3][8];
  for (int ax = 0; ax < 3; ++ax) {
    const float o = ray.origin[ax], d = ray.direction[ax];
    std::tie(lo[ax], hi[ax]) = subRange(box, k, margin, ray, a, b, ax);
    const float inv = 1.0f / d;
    for (int i = lo[ax]; i <= hi[ax]; ++i) {
      const float s0 = box.lo[ax] + float(i) * edge[ax];
      const float s1 = (i + 1 == k ? box.hi[ax] : s0 + edge[ax]) + margin;
      float t0 = a, t1 = b;
      if (d == 0.0f) {
        if (o < s0 - margin || o > s1) t0 = std::numeric_limits<float>::infinity();
      } else {
        float ta = (s0 - margin - o) * inv, tb = (s1 - o) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      enter[ax][i] = t0;
      leave[ax][i] = t1;
    }
  }
  for (int l = lo[2]; l <= hi[2]; ++l)
    for (int j = lo[1]; j <= hi[1]; ++j)
      for (int i = lo[0]; i <= hi[0]; ++i)
        if (std::max(std::max(enter[0][i], enter[1][j]), enter[2][l]) <=
            std::min(std::min(leave[0][i], leave[1][j]), leave[2][l]))
          fn(i, j, l);
}

/// FreeSubCells' mask of one cell (see tracer.h): its 64 sub-cells' centres in one batch of
/// the cell's tape, each tested against the tape's Lipschitz bound over the widened cell.
uint64_t freeMask(const Cell& cell, const CompiledBlob& tape) {
  constexpr int k = FreeSubCells::kDivisions;
  const Vec3 size = cell.box.hi - cell.box.lo;
  Vec3 centres[k * k * k];
  float f[k * k * k];
  for (int l = 0; l < k; ++l)
    for (int j = 0; j < k; ++j)
      for (int i = 0; i < k; ++i)
        centres[i + k * (j + k * l)] = cell.box.lo + (Vec3(float(i), float(j), float(l)) + 0.5f) * size / float(k);
  tape.values(centres, f);
  float farthest = 0.0f;
  for (float v : f) farthest = std::max(farthest, std::abs(v - kIso));
  // Sub-cells widened by twice the crossing test's margin: their centres, computed with
  // rounding, still see the whole widened box of the test within r.
  const float w = 2.0f * FreeSubCells::kMarginCells * std::max(size.x, std::max(size.y, size.z));
  const float r = glm::length(size / float(2 * k) + Vec3(w));
  // The bound over the widened cell is about the cell's own or more: when even the cell's
  // would prove nothing, the walk is saved (a zero mask proves nothing, which is sound).
  if (!(farthest > cell.lipschitz * r + FreeSubCells::kValueMargin)) return 0;
  const float reach = tape.lipschitz(cell.box.expanded(w)) * r + FreeSubCells::kValueMargin;
  if (!(reach < std::numeric_limits<float>::infinity())) return 0;
  uint64_t mask = 0;
  for (int s = 0; s < k * k * k; ++s)
    if (std::abs(f[s] - kIso) > reach) mask |= uint64_t(1) << s;
  return mask;
}

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

// ---- SubCellBounds -------------------------------------------------------------------------

void SubCellBounds::Free::operator()(uint32_t* p) const { std::free(p); }

SubCellBounds::SubCellBounds(const CellSet& cells, const CompiledBlob& blob, int k)
    : cells_(&cells), blob_(&blob), k_(k) {
  if (k < 1 || k > 8) throw std::invalid_argument("SubCellBounds: k must be in 1..8");
  const size_t n = std::max<size_t>(cells.cells.size(), 1);
  // calloc: large blocks come as zero pages, committed only where rays reach.
  slots_.reset(static_cast<uint32_t*>(std::calloc(n * size_t(k * k * k), sizeof(uint32_t))));
  traces_.reset(static_cast<uint32_t*>(std::calloc(n, sizeof(uint32_t))));
  if (!slots_ || !traces_) throw std::bad_alloc();
}

bool SubCellBounds::warm(uint32_t cellIndex) const {
  std::atomic_ref<uint32_t> count(traces_[cellIndex]);
  if (count.load(std::memory_order_relaxed) >= kWarmTraces) return true;
  return count.fetch_add(1, std::memory_order_relaxed) + 1 >= kWarmTraces;
}

Box3 SubCellBounds::subBox(const Cell& c, int i, int j, int l) const {
  const Vec3 edge = (c.box.hi - c.box.lo) / float(k_);
  const Vec3 lo = c.box.lo + Vec3(float(i), float(j), float(l)) * edge;
  const Vec3 hi(i + 1 == k_ ? c.box.hi.x : lo.x + edge.x, j + 1 == k_ ? c.box.hi.y : lo.y + edge.y,
                l + 1 == k_ ? c.box.hi.z : lo.z + edge.z);
  return Box3{lo, hi}.expanded(kMarginCells * (c.box.hi.x - c.box.lo.x));
}

float SubCellBounds::entry(uint32_t c, int s) const {
  std::atomic_ref<uint32_t> slot(slots_[size_t(c) * size_t(k_ * k_ * k_) + size_t(s)]);
  const uint32_t v = slot.load(std::memory_order_relaxed);
  if (v != 0) return std::bit_cast<float>(v - 1);
  const Cell& cell = cells_->cells[c];
  const Box3 box = subBox(cell, s % k_, (s / k_) % k_, s / (k_ * k_));
  const CompiledBlob& tape = cells_->tapeOf(cell, *blob_);
  const float L = tape.lipschitz(box);
  const float e = tape.valueBounds(box).contains(kIso) ? L : -L;
  slot.store(std::bit_cast<uint32_t>(e) + 1, std::memory_order_relaxed);
  return e;
}

SubCellBounds::Bound SubCellBounds::segment(uint32_t cellIndex, const Ray& ray, float a, float b) const {
  const Cell& c = cells_->cells[cellIndex];
  Bound r;
  int crossed = 0;
  forCrossedSubCells(c.box, k_, kMarginCells * (c.box.hi.x - c.box.lo.x), ray, a, b, [&](int i, int j, int l) {
    const float e = entry(cellIndex, i + k_ * (j + k_ * l));
    r.lipschitz = std::max(r.lipschitz, std::abs(e));
    r.maySurface = r.maySurface || !std::signbit(e);
    ++crossed;
  });
  if (crossed == 0) return {c.lipschitz, true};
  return r;
}

// ---- FreeSubCells --------------------------------------------------------------------------

FreeSubCells::FreeSubCells(const CellSet& cells, const CompiledBlob& blob)
    : cells_(&cells), blob_(&blob), entries_(cells.cells.size()) {
  parallelFor(0, cells.cells.size(), [&](size_t i) {
    const Cell& c = cells.cells[i];
    entries_[i] = {freeMask(c, cells.tapeOf(c, blob)), kProven};
  }, 256);
}

FreeSubCells::FreeSubCells(const CellSet& cells, const CompiledBlob& blob, uint32_t proveAt)
    : cells_(&cells), blob_(&blob), proveAt_(proveAt), entries_(cells.cells.size()) {}

void FreeSubCells::prove(std::span<const uint32_t> cells) {
  parallelFor(0, cells.size(), [&](size_t i) {
    if (!proven(cells[i])) proveOne(cells[i]);
  }, 256);
}

uint64_t FreeSubCells::proveOne(uint32_t c) const {
  const Cell& cell = cells_->cells[c];
  const uint64_t m = freeMask(cell, cells_->tapeOf(cell, *blob_));
  Entry& e = entries_[c];
  std::atomic_ref<uint64_t>(e.mask).store(m, std::memory_order_relaxed);
  std::atomic_ref<uint32_t>(e.traces).fetch_or(kProven, std::memory_order_release);
  return m;
}

bool FreeSubCells::proven(uint32_t c) const {
  return (std::atomic_ref<uint32_t>(entries_[c].traces).load(std::memory_order_acquire) & kProven) != 0;
}

size_t FreeSubCells::provenCount() const {
  size_t n = 0;
  for (uint32_t c = 0; c < entries_.size(); ++c) n += proven(c);
  return n;
}

uint64_t FreeSubCells::mask(uint32_t c) const {
  if (!proven(c)) return proveOne(c);
  return std::atomic_ref<uint64_t>(entries_[c].mask).load(std::memory_order_relaxed);
}

uint64_t FreeSubCells::enter(uint32_t c) const {
  Entry& e = entries_[c];
  std::atomic_ref<uint32_t> traces(e.traces);
  uint32_t n = traces.load(std::memory_order_acquire);
  if (!(n & kProven)) {
    if (proveAt_ == 0) return 0;
    // Only the trace that brings the count to proveAt proves; the traces racing it, or
    // coming before it is done, use no mask (the same result, with batches).
    n = traces.fetch_add(1, std::memory_order_acq_rel) + 1;
    if (n == proveAt_) return proveOne(c);
    if (!(n & kProven)) return 0;
  }
  return std::atomic_ref<uint64_t>(e.mask).load(std::memory_order_relaxed);
}

bool FreeSubCells::spanFree(const Cell& c, uint64_t free, const Ray& ray, float a, float b) {
  if (free == 0) return false;
  const float margin = kMarginCells * (c.box.hi.x - c.box.lo.x);
  uint64_t inRange = ~uint64_t(0);
  for (int ax = 0; ax < 3; ++ax) {
    const auto [lo, hi] = subRange(c.box, kDivisions, margin, ray, a, b, ax);
    inRange &= kSubCellRange[ax][lo][hi];
  }
  return (inRange & ~free) == 0;
}

bool FreeSubCells::spanFree(const Cell& c, uint32_t cellIndex, const Ray& ray, float a, float b) const {
  return spanFree(c, mask(cellIndex), ray, a, b);
}

size_t FreeSubCells::dropWhole(CellSet& cells) {
  size_t kept = 0;
  for (size_t i = 0; i < cells.cells.size(); ++i) {
    if (proven(uint32_t(i)) && entries_[i].mask == kWhole) continue;
    cells.cells[kept] = cells.cells[i];
    entries_[kept] = entries_[i];
    ++kept;
  }
  const size_t dropped = cells.cells.size() - kept;
  cells.cells.resize(kept);
  entries_.resize(kept);
  return dropped;
}

std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode, const SubCellBounds& sub, uint32_t cellIndex) {
  return traceCell(blob, cell, ray, t0, t1, tolerance, mode, FreeSubCells{}, &sub, cellIndex);
}

std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode, const FreeSubCells& free, const SubCellBounds* sub,
                               uint32_t cellIndex) {
  if (!clipToBox(cell.box, ray.origin, ray.direction, t0, t1)) return std::nullopt;
  if (free.size() > 0 && FreeSubCells::spanFree(cell, free.enter(cellIndex), ray, t0, t1)) return std::nullopt;
  float lipschitz = std::max(cell.lipschitz, 1e-30f) * glm::length(ray.direction);
  float t = BatchTracer(blob, ray, lipschitz, mode, sub, cellIndex).trace(t0, t1, tolerance);
  if (t >= 0.0f) return t;
  return std::nullopt;
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
