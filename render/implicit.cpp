// Exact implicit geometry: compiled BlobTrees as Embree user geometry, and polygonized
// BlobTrees (mesh mode) with the same texture blend. Kept apart from scene.cpp so the
// skeleton preview links without the BlobTree evaluator.

#include <embree3/rtcore.h>

#include <algorithm>
#include <limits>
#include <optional>
#include <stdexcept>

#include "blobtree/cell_size.h"
#include "blobtree/polygonize.h"
#include "blobtree/tracer.h"
#include "core/phases.h"
#include "render/detail/scene_impl.h"
#include "render/scene.h"

namespace sprig::render {

namespace detail {

struct ImplicitData {
  blobtree::CompiledBlob blob;
  blobtree::CellSet cells;
  blobtree::TraceOptions trace;
  bool batched = true;    ///< blobtree::traceCell (true) or CompiledBlob::intersectCell (false)
  float tolerance = 0;    ///< absolute root tolerance along t (unit-direction rays)
  blobtree::SubCellBounds sub;  ///< bounds over the cells' sub-cells (batched tracing only)
  blobtree::FreeSubCells free;  ///< the cells' sub-cells free of the surface (batched tracing only)
};

}  // namespace detail

namespace {

using detail::ImplicitData;

constexpr float kIso = 0.5f;

/// The first hit in [tnear, tfar] inside one surface cell, by the blobtree tracer (see
/// blobtree/tracer.h); anyHit stops at the first bracketed crossing (shadow rays). Camera
/// rays use Crossing::FirstStraddle, the mode this renderer has always traced with.
std::optional<blobtree::Hit> traceCell(const ImplicitData& data, const blobtree::Cell& cell, const blobtree::Ray& ray,
                                       float tnear, float tfar, bool anyHit) {
  if (!data.batched) return data.blob.intersectCell(cell, ray, tnear, tfar, data.trace);
  // The cell's pruned tape when it has one: exact at the cell's points, a shorter walk.
  const blobtree::CompiledBlob& blob = data.cells.tapeOf(cell, data.blob);
  const auto mode = anyHit ? blobtree::Crossing::Any : blobtree::Crossing::FirstStraddle;
  const auto index = uint32_t(&cell - data.cells.cells.data());
  const bool warm = data.sub.divisions() > 0 && data.sub.warm(index);
  std::optional<float> t = blobtree::traceCell(blob, cell, ray, tnear, tfar, data.tolerance, mode, data.free,
                                               warm ? &data.sub : nullptr, index);
  if (!t) return std::nullopt;
  if (anyHit) return blobtree::Hit{.t = *t};
  return blobtree::hitAt(blob, ray, *t);
}

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
  auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
  blobtree::Ray ray{Vec3(rh->ray.org_x, rh->ray.org_y, rh->ray.org_z), Vec3(rh->ray.dir_x, rh->ray.dir_y, rh->ray.dir_z)};
  std::optional<blobtree::Hit> hit = traceCell(*data, data->cells.cells[args->primID], ray, rh->ray.tnear, rh->ray.tfar, false);
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
  auto* r = reinterpret_cast<RTCRay*>(args->ray);
  blobtree::Ray ray{Vec3(r->org_x, r->org_y, r->org_z), Vec3(r->dir_x, r->dir_y, r->dir_z)};
  if (traceCell(*data, data->cells.cells[args->primID], ray, r->tnear, r->tfar, true))
    r->tfar = -std::numeric_limits<float>::infinity();
}

/// The renderer's automatic cell size: 1.5x the smallest feature radius within
/// [diagonal/1000, diagonal/40], diagonal/64 without sized primitives. Smaller cells carry
/// shorter primitive lists and tighter Lipschitz bounds; on a 3,280-cone tree, cells of
/// about one twig radius trace 1.3x faster than cells of two.
constexpr blobtree::CellSizeRule kTracerCells{
    .featureFraction = 1.5f, .coarsestDivisions = 40.0f, .finestDivisions = 1000.0f, .noFeatureDivisions = 64.0f};

/// ImplicitOptions::subCells for `cells` cells: halved until the bounds fit
/// kSubCellBudgetBytes, 0 (off) below 2 sub-cells per axis.
int subCellDivisions(int requested, size_t cells) {
  if (requested < 0 || requested > 8) throw std::invalid_argument("ImplicitOptions::subCells must be in 0..8");
  int k = requested;
  while (k >= 2 && cells * size_t(k * k * k) * sizeof(float) > kSubCellBudgetBytes) k /= 2;
  return k >= 2 ? k : 0;
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

/// The lowest y of blob's solid, found within the surface cells from the lowest up: in each
/// cell whose field bound reaches the surface, the field at an 8 x 8 x 8 grid of points
/// (cell-centred), layer by layer upward; the first point inside (F >= 0.5) is a point of
/// the solid, so the surface reaches at least that low, and the true lowest point lies less
/// than a grid step below it unless a feature thinner than the step reaches lower. Stops at
/// the first cell starting above the best; +inf when no point is inside. Deterministic.
float cellsBase(const blobtree::CompiledBlob& blob, const std::vector<blobtree::Cell>& cells) {
  constexpr int kGrid = 8;
  std::vector<size_t> order(cells.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return cells[a].box.lo.y != cells[b].box.lo.y ? cells[a].box.lo.y < cells[b].box.lo.y : a < b;
  });
  float best = std::numeric_limits<float>::infinity();
  for (size_t i : order) {
    const Box3& c = cells[i].box;
    if (c.lo.y >= best) break;
    if (blob.valueBounds(c).hi < kIso) continue;
    const Vec3 step = (c.hi - c.lo) / float(kGrid);
    for (int k = 0; k < kGrid; ++k) {
      const float y = c.lo.y + (k + 0.5f) * step.y;
      if (y >= best) break;
      bool inside = false;
      for (int j = 0; j < kGrid && !inside; ++j)
        for (int l = 0; l < kGrid && !inside; ++l)
          inside = blob.value(Vec3(c.lo.x + (l + 0.5f) * step.x, y, c.lo.z + (j + 0.5f) * step.z)) >= kIso;
      if (inside) {
        best = y;
        break;
      }
    }
  }
  return best;
}

/// Whether the centre of box b projects into e's image (within half the box's diagonal).
bool inView(const detail::ExpectedSamples& e, const Box3& b) {
  const Vec3 d = b.center() - e.view.eye;
  const float depth = glm::dot(d, e.view.forward);
  if (!(depth > 0.0f)) return false;
  const float pixel = e.view.pixelPerDepth * depth;  // world size of a pixel at the box
  const float reach = 0.87f * (b.hi.x - b.lo.x) / pixel;
  return std::abs(glm::dot(d, e.view.right)) / pixel <= 0.5f * float(e.width) + reach &&
         std::abs(glm::dot(d, e.view.up)) / pixel <= 0.5f * float(e.height) + reach;
}

/// The cells to prove when made: those in view when the expected camera samples per cell
/// in view reach `samples` (all cells for samples <= 0; none without an expectation).
/// Camera samples per cell in view measure how many rays a cell will see: the image's
/// samples shared among the cells they can reach, so a crown many cells deep shares them
/// among more cells than a bare frame of branches.
std::vector<uint32_t> denseCells(const blobtree::CellSet& cells, const std::optional<detail::ExpectedSamples>& expected,
                                 float samples) {
  std::vector<uint32_t> dense;
  if (samples > 0.0f && !expected) return dense;
  for (uint32_t i = 0; i < cells.cells.size(); ++i)
    if (samples <= 0.0f || inView(*expected, cells.cells[i].box)) dense.push_back(i);
  if (samples <= 0.0f) return dense;
  const double perCell = double(expected->width) * double(expected->height) * double(expected->spp) /
                         double(std::max<size_t>(dense.size(), 1));
  if (perCell < double(samples)) dense.clear();
  return dense;
}

/// The batched tracer's proofs over data's cells: the sub-cells free of the surface
/// (blobtree::FreeSubCells: the dense cells proved now, the wholly free among them left out
/// of data.cells, the others when rays come), and the sub-cell bounds
/// (ImplicitOptions::subCells, checked either way) of the cells kept. Returns the cells
/// left out.
size_t prepareTracing(ImplicitData& data, const ImplicitOptions& options,
                      const std::optional<detail::ExpectedSamples>& expected) {
  size_t dropped = 0;
  if (data.batched && options.freeSubCells) {
    data.free = blobtree::FreeSubCells(data.cells, data.blob, options.freeSubCellsLazy);
    data.free.prove(denseCells(data.cells, expected, options.freeSubCellsEager));
    dropped = data.free.dropWhole(data.cells);
  }
  const int subK = subCellDivisions(options.subCells, data.cells.cells.size());
  if (data.batched && subK > 0) data.sub = blobtree::SubCellBounds(data.cells, data.blob, subK);
  return dropped;
}

}  // namespace

uint32_t Scene::addImplicit(const blobtree::CompiledBlob& blob, uint32_t material, const ImplicitOptions& options) {
  if (impl_->committed) throw std::logic_error("Scene::addImplicit after commit");
  if (material >= impl_->materials.size()) throw std::invalid_argument("Scene::addImplicit: unknown material id");
  subCellDivisions(options.subCells, 0);  // its range checked before anything is added
  auto data = std::make_shared<ImplicitData>();
  data->blob = blob;
  data->trace = options.trace;
  data->batched = options.batched;
  data->tolerance = std::max(options.trace.relativeTolerance * glm::length(blob.bounds().size()), 1e-30f);
  Box3 support = blob.bounds();
  if (!support.empty()) {
    float cellSize = options.cellSize > 0 ? options.cellSize : blobtree::autoCellSize(blob, kTracerCells);
    const std::optional<detail::PixelView>& view = impl_->cellView ? impl_->cellView : impl_->view;
    if (view && options.followPixels) {
      PixelScale pixels;
      pixels.eye = view->eye;
      pixels.forward = view->forward;
      pixels.pixelPerDepth = view->pixelPerDepth;
      const float own = cellSize;
      cellSize = pixelCellSize(own, pixels, support);
      impl_->followedCells.push_back({own, cellSize, support});  // another camera may give another cell
    }
    blobtree::SurfaceCellOptions cellOptions;
    cellOptions.prunedTapes = options.batched && options.prunedTapes && impl_->prunedTapes;
    const Phase phase("cells");
    data->cells = blob.surfaceCells(cellSize, cellOptions);
  }
  // The bounds and the counts from every surface cell, before free cells are left out.
  Box3 cellBox;
  for (const auto& c : data->cells.cells) cellBox.extend(c.box);
  if (!cellBox.empty()) {
    Box3 tight = tightenBounds(blob, cellBox.intersected(support));
    if (options.tightBase) {
      const float base = cellsBase(blob, data->cells.cells);
      if (base > tight.lo.y && base <= tight.hi.y) tight.lo.y = base;
    }
    impl_->bounds.extend(tight);
  }
  impl_->stats.implicitCells += data->cells.cells.size();
  impl_->stats.implicitCellSize = std::max(impl_->stats.implicitCellSize, data->cells.cellSize);
  impl_->stats.implicitTapes += data->cells.tapes.size();
  for (const auto& c : data->cells.cells)
    impl_->stats.implicitTapeNodes += c.tape < data->cells.tapes.size() ? data->cells.tapes[c.tape].nodeCount() : 0;
  if (!support.empty()) {
    const Phase phase("cells");
    impl_->stats.implicitFreeCells += prepareTracing(*data, options, impl_->expected);
  }
  RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(g, static_cast<unsigned>(data->cells.cells.size()));
  rtcSetGeometryUserData(g, data.get());
  rtcSetGeometryBoundsFunction(g, cellBounds, nullptr);
  rtcSetGeometryIntersectFunction(g, cellIntersect);
  rtcSetGeometryOccludedFunction(g, cellOccluded);
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
  const Material& m = impl_->materials[material];
  const bool tilt = m.ridge.tilts() && mesh.normals.size() == mesh.positions.size();
  const size_t count = textureCount == kAllTextures ? impl_->textures.size() : textureCount;
  if ((tilt || count > 0) && result.attributes.size() != mesh.positions.size())
    throw std::invalid_argument("Scene::addPolygonized: textures and ridges need the vertices' attributes "
                                "(PolygonizeOptions::VertexData::Blend)");
  // The ridge's relief tilts the vertex normals as it tilts exact hits' (Scene::intersect).
  if (tilt)
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
      const blobtree::Attributes& a = result.attributes[i];
      mesh.normals[i] = m.ridge.shadingNormal(mesh.normals[i], a.contact, a.contactGradient, mesh.positions[i]);
    }
  if (count > 0) {
    mesh.colors.resize(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      mesh.colors[i] = attributeColor(result.attributes[i], mesh.positions[i], impl_->materials[material], textureBase,
                                     textureCount);
  }
  return addMesh(mesh, material);
}

}  // namespace sprig::render
