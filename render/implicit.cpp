// Exact implicit geometry: compiled BlobTrees as Embree user geometry, and polygonized
// BlobTrees (mesh mode) with the same texture blend. Kept apart from scene.cpp so the
// skeleton preview links without the BlobTree evaluator.

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>

#include "blobtree/polygonize.h"
#include "render/detail/scene_impl.h"
#include "render/scene.h"

namespace sprig::render {

namespace detail {

struct ImplicitData {
  blobtree::CompiledBlob blob;
  blobtree::CellSet cells;
  blobtree::TraceOptions trace;
  bool batched = true;    ///< CellTracer (true) or CompiledBlob::intersectCell (false)
  float tolerance = 0;    ///< absolute root tolerance along t (unit-direction rays)
};

}  // namespace detail

namespace {

using detail::ImplicitData;

constexpr float kIso = 0.5f;
constexpr int kLanes = 8;  ///< points per batched field evaluation

/// Clips [t0, t1] of o + t·d to box; false when empty.
bool clipToBox(const Box3& b, const Vec3& o, const Vec3& d, float& t0, float& t1) {
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return false;
      continue;
    }
    float inv = 1.0f / d[a];
    float ta = (b.lo[a] - o[a]) * inv, tb = (b.hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1;
}

/// Batched segment tracing inside one cell. The chord is sampled at kLanes points per
/// batched evaluation (CompiledBlob::valuesInCell). Between neighbouring samples i, i+1 at
/// spacing Δ a surface point can exist only if the samples straddle 0.5 or
/// |fᵢ − 0.5| + |fᵢ₊₁ − 0.5| <= L·Δ (L: the cell's Lipschitz bound per unit of t), the
/// guarantee segment tracing with the local bound rests on, tested eight samples at a
/// time. Intervals that may hide a double crossing are searched recursively, front to back;
/// the first straddling interval is shrunk by batched subdivision to `tolerance`, then
/// interpolated linearly.
class CellTracer {
 public:
  CellTracer(const ImplicitData& data, const blobtree::Cell& cell, const Vec3& o, const Vec3& d, bool anyHit)
      : data_(data), cell_(cell), o_(o), d_(d), L_(std::max(cell.lipschitz, 1e-30f) * glm::length(d)), anyHit_(anyHit) {}

  /// First crossing in [t0, t1] (clipped to the cell), or a negative value.
  float trace(float t0, float t1) {
    if (!clipToBox(cell_.box, o_, d_, t0, t1)) return -1.0f;
    // A tolerance below the spacing of floats near t can never be reached (the samples
    // stop moving): far from the camera, 8 float steps at t bound it from below.
    tol_ = std::max(data_.tolerance, 8.0f * std::numeric_limits<float>::epsilon() * std::max(std::abs(t0), std::abs(t1)));
    return first(t0, t1, 0);
  }

 private:
  float evaluate(float a, float b, float* ts, float* f) const {
    Vec3 pts[kLanes];
    float step = (b - a) / static_cast<float>(kLanes - 1);
    for (int i = 0; i < kLanes; ++i) {
      ts[i] = i == kLanes - 1 ? b : a + step * static_cast<float>(i);
      pts[i] = o_ + ts[i] * d_;
    }
    data_.blob.valuesInCell(cell_, pts, std::span<float>(f, kLanes));
    return step;
  }

  float first(float a, float b, int depth) {
    float ts[kLanes], f[kLanes];
    float step = evaluate(a, b, ts, f);
    for (int i = 0; i + 1 < kLanes; ++i) {
      if ((f[i] > kIso) != (f[i + 1] > kIso)) return anyHit_ ? ts[i] : refine(ts[i], ts[i + 1], f[i], f[i + 1]);
      if (depth < kMaxDepth && step > tol_ &&
          std::abs(f[i] - kIso) + std::abs(f[i + 1] - kIso) <= L_ * step) {
        float t = first(ts[i], ts[i + 1], depth + 1);
        if (t >= 0.0f) return t;
      }
    }
    return -1.0f;
  }

  float refine(float lo, float hi, float flo, float fhi) const {
    float ts[kLanes], f[kLanes];
    const bool insideLo = flo > kIso;
    while (hi - lo > tol_) {
      evaluate(lo, hi, ts, f);
      int k = 0;
      while (k + 2 < kLanes && (f[k + 1] > kIso) == insideLo) ++k;
      lo = ts[k];
      hi = ts[k + 1];
      flo = f[k];
      fhi = f[k + 1];
    }
    float w = flo != fhi ? (flo - kIso) / (flo - fhi) : 0.5f;
    return lo + std::clamp(w, 0.0f, 1.0f) * (hi - lo);
  }

  static constexpr int kMaxDepth = 12;
  const ImplicitData& data_;
  const blobtree::Cell& cell_;
  Vec3 o_, d_;
  float L_;
  bool anyHit_;
  float tol_ = 0.0f;
};

void cellBounds(const RTCBoundsFunctionArguments* args) {
  const auto* data = static_cast<const ImplicitData*>(args->geometryUserPtr);
  const Box3& b = data->cells.cells[args->primID].box;
  args->bounds_o->lower_x = b.lo.x;
  args->bounds_o->lower_y = b.lo.y;
  args->bounds_o->lower_z = b.lo.z;
  args->bounds_o->upper_x = b.hi.x;
  args->bounds_o->upper_y = b.hi.y;
  args->bounds_o->upper_z = b.hi.z;
}

// Embree calls user geometry with N = 1 for rtcIntersect1/rtcOccluded1, the only entry
// points Scene uses; the ray then has the single-ray layout.
void cellIntersect(const RTCIntersectFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  const auto* data = static_cast<const ImplicitData*>(args->geometryUserPtr);
  const blobtree::Cell& cell = data->cells.cells[args->primID];
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  Vec3 o(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z), d(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z);
  std::optional<blobtree::Hit> hit;
  if (data->batched) {
    float t = CellTracer(*data, cell, o, d, false).trace(rh->ray.tnear, rh->ray.tfar);
    if (t >= 0.0f) {
      blobtree::Hit h;
      h.t = t;
      h.point = o + t * d;
      blobtree::Sample smp = data->blob.sample(h.point);
      float gl = glm::length(smp.gradient);
      h.normal = gl > 0.0f ? -smp.gradient / gl : -glm::normalize(d);
      h.attributes = smp.attributes;
      hit = h;
    }
  } else {
    hit = data->blob.intersectCell(cell, blobtree::Ray{o, d}, rh->ray.tnear, rh->ray.tfar, data->trace);
  }
  if (!hit || !(hit->t < rh->ray.tfar) || hit->t < rh->ray.tnear) return;
  rh->ray.tfar = hit->t;
  rh->hit.Ng_x = hit->normal.x;
  rh->hit.Ng_y = hit->normal.y;
  rh->hit.Ng_z = hit->normal.z;
  rh->hit.u = 0.0f;
  rh->hit.v = 0.0f;
  rh->hit.primID = args->primID;
  rh->hit.geomID = args->geomID;
  rh->hit.instID[0] = args->context->instID[0];
  reinterpret_cast<detail::HitContext*>(args->context)->implicitHit = *hit;
}

void cellOccluded(const RTCOccludedFunctionNArguments* args) {
  if (args->N != 1 || !args->valid[0]) return;
  const auto* data = static_cast<const ImplicitData*>(args->geometryUserPtr);
  const blobtree::Cell& cell = data->cells.cells[args->primID];
  auto* r = reinterpret_cast<RTCRay*>(args->ray);
  Vec3 o(r->org_x, r->org_y, r->org_z), d(r->dir_x, r->dir_y, r->dir_z);
  bool blocked = data->batched ? CellTracer(*data, cell, o, d, true).trace(r->tnear, r->tfar) >= 0.0f
                               : data->blob.intersectCell(cell, blobtree::Ray{o, d}, r->tnear, r->tfar, data->trace).has_value();
  if (blocked) r->tfar = -std::numeric_limits<float>::infinity();
}

/// Automatic cell size: 1.5x the smallest feature radius within [diagonal/1000, diagonal/40].
/// Smaller cells carry shorter primitive lists and tighter Lipschitz bounds; on a
/// 3,280-cone tree, cells of about one twig radius trace 1.3x faster than cells of two.
float autoCellSize(const blobtree::CompiledBlob& blob) {
  Box3 b = blob.bounds();
  float diag = glm::length(b.size());
  float feature = blob.smallestFeature();
  if (!(feature > 0)) return diag / 64.0f;
  return std::clamp(1.5f * feature, diag / 1000.0f, diag / 40.0f);
}

/// Shrinks box (which holds the whole F = 0.5 surface) face by face: bisection finds the
/// thickest slab at each face whose interval bound stays below 0.5, which is sound (no
/// surface there). Brings the bounds from the cells' outer faces to within about the
/// interval bound's slack of the surface, so exact and mesh modes frame alike.
Box3 tightenBounds(const blobtree::CompiledBlob& blob, Box3 box) {
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      float lo = 0.0f, hi = box.hi[axis] - box.lo[axis];
      for (int it = 0; it < 24; ++it) {
        float mid = 0.5f * (lo + hi);
        Box3 slab = box;
        if (side == 0) slab.hi[axis] = box.lo[axis] + mid;
        else slab.lo[axis] = box.hi[axis] - mid;
        (blob.valueBounds(slab).hi < kIso ? lo : hi) = mid;
      }
      if (side == 0) box.lo[axis] += lo;
      else box.hi[axis] -= lo;
    }
  }
  return box;
}

}  // namespace

uint32_t Scene::addImplicit(const blobtree::CompiledBlob& blob, uint32_t material, const ImplicitOptions& options) {
  if (impl_->committed) throw std::logic_error("Scene::addImplicit after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addImplicit: unknown material id");
  auto data = std::make_shared<ImplicitData>();
  data->blob = blob;
  data->trace = options.trace;
  data->batched = options.batched;
  data->tolerance = std::max(options.trace.relativeTolerance * glm::length(blob.bounds().size()), 1e-30f);
  Box3 support = blob.bounds();
  if (!support.empty()) {
    float cellSize = options.cellSize > 0 ? options.cellSize : autoCellSize(blob);
    data->cells = blob.surfaceCells(cellSize);
  }
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(data->cells.cells.size()));
  rtcSetGeometryUserData(g, data.get());
  rtcSetGeometryBoundsFunction(g, cellBounds, nullptr);
  rtcSetGeometryIntersectFunction(g, cellIntersect);
  rtcSetGeometryOccludedFunction(g, cellOccluded);
  Box3 cellBox;
  for (const auto& c : data->cells.cells) cellBox.extend(c.box);
  if (!cellBox.empty()) impl_->bounds.extend(tightenBounds(blob, cellBox.intersected(support)));
  impl_->stats.implicitCells += data->cells.cells.size();
  detail::GeometryRecord rec;
  rec.kind = detail::GeometryRecord::Kind::Implicit;
  rec.material = material;
  rec.implicit = std::move(data);
  return impl_->attach(g, std::move(rec));
}

uint32_t Scene::addPolygonized(const blobtree::PolygonizeResult& result, uint32_t material, uint32_t textureBase,
                               uint32_t textureCount) {
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addPolygonized: unknown material id");
  Mesh mesh = result.mesh;
  const size_t count = textureCount == kAllTextures ? impl_->textures.size() : textureCount;
  if (count > 0 && result.attributes.size() == mesh.positions.size()) {
    mesh.colors.resize(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      mesh.colors[i] = attributeColor(result.attributes[i], mesh.positions[i], impl_->materials[material], textureBase,
                                     textureCount);
  }
  return addMesh(mesh, material);
}

}  // namespace sprig::render
