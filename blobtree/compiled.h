#pragma once
/// Compiled BlobTree: the evaluation form used by the polygonizer, the renderer and tests.
///
/// Representation: the nodes reachable from the root are flattened into a tape (an array
/// of compiled nodes, children stored as contiguous index ranges, parameters pre-derived:
/// support radii, inverse transforms, PCM a₀, bend frames). Every compiled node carries its
/// support box and global Lipschitz bound. Every n-ary operator with many children owns a
/// BVH over its children's support boxes, so a point (or a batch of points, or a box)
/// visits only the children whose support can reach it: an n-ary blend of 10,000 cones
/// costs about what one of 100 with the same local overlap costs.
///
/// Modes (libfive style), one evaluator each under blobtree/detail/: value
/// (point_eval), value+gradient+attributes (`sample`, gradient_eval), interval bounds and
/// local Lipschitz bounds over a box (interval_eval), batched values (batch_eval: node by
/// node over SoA point arrays, vectorized inner loops). Ray intersection is the batched
/// segment tracer of blobtree/tracer.h; surface cells are found in surface_cells.cpp.
///
/// Thread safety: a CompiledBlob is immutable after compile(); every const member function
/// may be called from many threads at once.

#include "blobtree/blobtree.h"
#include "core/types.h"

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace sprig::blobtree {

/// A closed interval of field values.
struct Interval {
  float lo = 0.0f, hi = 0.0f;
  /// True when v lies in [lo, hi].
  bool contains(float v) const { return lo <= v && v <= hi; }
};

/// A ray origin + t·direction. direction need not be unit length; t is in its units.
struct Ray {
  Vec3 origin{0.0f};
  Vec3 direction{0.0f, 0.0f, 1.0f};
};

/// Surface attributes blended by field weight (Σ fᵢ·Tᵢ / Σ fᵢ over the contributing
/// primitives; a union/intersection/difference takes its winning/first operand's
/// attributes; cutters and negative nodes contribute none).
struct Attributes {
  static constexpr int kMaxTextures = 4;
  Vec2 uv{0.0f};  ///< blended natural (u,v) after each primitive's uv transform
  std::array<uint16_t, kMaxTextures> textureIds{};  ///< by decreasing weight
  std::array<float, kMaxTextures> textureWeights{}; ///< sum to 1 over textureCount
  uint8_t textureCount = 0;  ///< 0 when no primitive contributes

  /// One contributing primitive: its texture, its own natural (u,v) after its uv transform,
  /// and its share of the field weight.
  struct Layer {
    Vec2 uv{0.0f};
    uint16_t textureId = 0;
    float weight = 0.0f;
  };
  static constexpr int kMaxLayers = 4;
  /// The heaviest contributing primitives (up to kMaxLayers, by decreasing weight; weights
  /// sum to 1 over layerCount). Colouring each at its own uv and blending the colours
  /// (tree paper §3.7: "each contributing primitive uses its native 2D coordinates")
  /// avoids blending angles of different axes, which swirls, and blending u across its
  /// wrap at 0/1, which leaves a seam.
  std::array<Layer, kMaxLayers> layers{};
  uint8_t layerCount = 0;
  /// Closeness to a PCM contact in [0, 1]: over the PCM nodes reached, the largest
  /// 1 − (c − f_j)/w of a child j that is not the node's strongest (1 on the seam where two
  /// primitives press together, 0 beyond the propagation width w). Marks the branch bark
  /// ridge, where real bark is compressed and darker (tree paper §5).
  float contact = 0.0f;
  /// ∇contact (1/world units; zero where contact is 0 or 1): points toward the seam. Its
  /// component in the tangent plane gives the ridge's direction on the surface (the seam runs
  /// perpendicular to it), for shading the ridge (render::Material::ridgeRelief).
  Vec3 contactGradient{0.0f};
};

/// Field value, analytic gradient and attributes at a point.
struct Sample {
  float value = 0.0f;
  Vec3 gradient{0.0f};  ///< ∇F; the outward surface normal is −∇F/|∇F|
  Attributes attributes;
};

/// A ray-surface hit.
struct Hit {
  float t = 0.0f;       ///< ray parameter of the hit
  Vec3 point{0.0f};     ///< origin + t·direction, on the F = 0.5 surface
  Vec3 normal{0.0f};    ///< outward unit normal −∇F/|∇F|
  Attributes attributes;
};

/// A cell that may hold the surface (its interval bound contains 0.5).
struct Cell {
  Box3 box;                   ///< the cell, a cube of CellSet::cellSize
  std::array<int32_t, 3> index{};  ///< integer grid coordinates: box.lo = origin + index·cellSize
  Interval bounds;            ///< interval of F over box
  float lipschitz = 0.0f;     ///< local Lipschitz bound of F over box
  uint32_t firstPrimitive = 0;  ///< into CellSet::primitives
  uint32_t primitiveCount = 0;  ///< primitives whose support overlaps box
  static constexpr uint32_t kNoTape = 0xffffffffu;
  uint32_t tape = kNoTape;      ///< into CellSet::tapes (SurfaceCellOptions::prunedTapes)
};

struct CellSet;

/// Options of CompiledBlob::intersect and intersectCell (blobtree/tracer.h).
struct TraceOptions {
  /// Convergence tolerance of the hit along the ray, relative to the model size
  /// (bounds' diagonal). The hit's |F − 0.5| / |∇F| is below this times the size.
  float relativeTolerance = 1e-6f;
  /// Upper bound on the windows intersect() traces per ray (a safety net; a miss is
  /// returned when hit). Within a window or a cell the tracer's recursion depth bounds the work.
  int maxSteps = 100000;
};

/// What CompiledBlob::surfaceCells computes besides the cells themselves.
struct SurfaceCellOptions {
  /// Cells of exactly the requested edge: the root cube grows to cellSize·2^k around the
  /// bounds. false: the bounds' cube divided by 2^k (an edge between half and all of the
  /// request).
  bool exactCellSize = false;
  /// Fill Cell::lipschitz (the renderer's tracer needs it; the polygonizer does not).
  bool lipschitz = true;
  /// Fill Cell::firstPrimitive/primitiveCount and CellSet::primitives.
  bool primitiveLists = true;
  /// Fill Cell::tape and CellSet::tapes: each cell's tape pruned to the nodes whose support
  /// reaches it (libfive's approach; blobtree/detail/prune.h), identical tapes of different
  /// cells stored once. Exact: at points in the cell the pruned tape gives the full tape's
  /// value (bit for bit where the child order agrees, else to the rounding of the sums).
  /// Costs about one more interval walk per cell.
  bool prunedTapes = false;
  /// Fill only CellSet::indices, each cell's integer grid coordinates (12 bytes a cell
  /// instead of a Cell's 60: all the polygonizer needs), and leave CellSet::cells empty.
  /// lipschitz, primitiveLists and prunedTapes must be off with it (std::invalid_argument).
  bool indicesOnly = false;
};

namespace detail { struct Tape; }

/// The compiled, immutable evaluation form of a BlobTree node. Cheap to move; copies share
/// the tape.
class CompiledBlob {
 public:
  /// An empty blob: F = 0 everywhere.
  CompiledBlob();
  ~CompiledBlob();
  CompiledBlob(const CompiledBlob&);
  CompiledBlob& operator=(const CompiledBlob&);
  CompiledBlob(CompiledBlob&&) noexcept;
  CompiledBlob& operator=(CompiledBlob&&) noexcept;

  /// F(p). Cost: the primitives whose support contains p, plus one point-grid lookup per
  /// n-ary node with many children (nodes with few children test each child's box).
  float value(Vec3 p) const;
  /// ∇F(p), analytic everywhere (warps by their Jacobians). Where F is not differentiable
  /// (max/min switches, clamp kinks) a one-sided gradient is returned.
  Vec3 gradient(Vec3 p) const;
  /// Value, gradient and attributes at p.
  Sample sample(Vec3 p) const;
  /// out[i] = F(points[i]). Fastest when points are spatially coherent (a cell, a tile):
  /// the tree is walked once per block of points, culled by the block's bounding box, and
  /// each primitive is evaluated over the block in a vectorized loop.
  void values(std::span<const Vec3> points, std::span<float> out) const;
  /// out[i] = F(points[i]) and gradients[i] = ∇F(points[i]) (as gradient()), batched like
  /// values(): one tree walk per block of 64 points. No attributes: where those are not
  /// needed, several times cheaper per point than sample(). Values and gradients equal
  /// sample()'s up to the rounding of sums taken in a different child order.
  void valuesAndGradients(std::span<const Vec3> points, std::span<float> out, std::span<Vec3> gradients) const;
  /// values() for points inside cell.box, culled by the cell's box.
  void valuesInCell(const Cell& cell, std::span<const Vec3> points, std::span<float> out) const;

  /// Support box of the root: F = 0 outside it (may be unbounded for bare cutters).
  Box3 bounds() const;
  /// Sound interval of F over box: for every p in box, lo <= F(p) <= hi.
  Interval valueBounds(const Box3& box) const;
  /// Sound Lipschitz bound of F over box (|F(p) − F(q)| <= L·|p − q| for p, q in box).
  float lipschitz(const Box3& box) const;
  /// Global Lipschitz bound.
  float lipschitz() const;

  /// The first surface crossing (F = 0.5, either direction) on the ray for t in
  /// [tmin, tmax], or nothing: blobtree::traceRay (empty space skipped by interval bounds,
  /// the rest by batched segment tracing with local Lipschitz bounds), then hitAt.
  /// Never steps over a sign change: a cone of radius 0.01 in a model of size 10 is hit.
  std::optional<Hit> intersect(const Ray& ray, float tmin, float tmax, const TraceOptions& opt = {}) const;
  /// intersect() restricted to the part of the ray inside cell.box, with the cell's stored
  /// Lipschitz bound: blobtree::traceCell, then hitAt.
  std::optional<Hit> intersectCell(const Cell& cell, const Ray& ray, float tmin, float tmax,
                                   const TraceOptions& opt = {}) const;
  /// The cells of a regular grid over bounds() (cube cells of edge <= cellSize, or exactly
  /// cellSize with options.exactCellSize) whose interval bound may contain 0.5, found by
  /// recursive octree subdivision from the root: work proportional to the surface area.
  /// Parallel and deterministic. Throws std::invalid_argument when cellSize <= 0 or
  /// bounds() is unbounded.
  CellSet surfaceCells(float cellSize, const SurfaceCellOptions& options = {}) const;

  /// Number of primitives (leaves) in the tape (0 for a cell's pruned tape).
  size_t primitiveCount() const;
  /// Number of nodes in the tape (operators and primitives; a cell's pruned tape counts
  /// only its own).
  size_t nodeCount() const;
  /// The smallest 0.5-iso radius of any point/segment/cone/torus primitive (0 if none):
  /// a natural scale for default cell sizes.
  float smallestFeature() const;
  /// The smallest, over the point/segment/cone/torus primitives, of each one's largest
  /// 0.5-iso radius (a cylinder's radius, a cone's thick end; 0 if none): every primitive
  /// is at least this thick somewhere, where smallestFeature() may be a tapered tip.
  float thinnestLimb() const;
  /// F(p) visiting every primitive of the tape with no culling (the brute-force baseline
  /// of benchmarks and tests).
  float valueNoCulling(Vec3 p) const;

 private:
  friend CompiledBlob compile(const BlobTree& tree, NodeId root);
  std::shared_ptr<const detail::Tape> tape_;
};

/// The surface cells of a compiled blob on a regular grid (found sparsely).
struct CellSet {
  Vec3 origin{0.0f};     ///< grid origin (the root bounds' low corner)
  float cellSize = 0.0f; ///< actual edge length (<= the requested size: root cube / 2^k)
  std::vector<Cell> cells;           ///< in deterministic (Morton-like recursive) order
  /// With SurfaceCellOptions::indicesOnly, the cells' Cell::index in the same order (and
  /// cells empty); otherwise empty.
  std::vector<glm::ivec3> indices;
  std::vector<uint32_t> primitives;  ///< primitive instance indices (a primitive under its chain of warps)
  /// Pruned tapes (SurfaceCellOptions::prunedTapes), shared by the cells whose pruned form
  /// is the same; each is a CompiledBlob of its own (all evaluators work on it) valid at
  /// points of its cells only.
  std::vector<CompiledBlob> tapes;
  /// The primitive list of one cell.
  std::span<const uint32_t> primitivesOf(const Cell& c) const {
    return {primitives.data() + c.firstPrimitive, c.primitiveCount};
  }
  /// The cell's pruned tape, or fallback (the full blob) when the cell has none.
  const CompiledBlob& tapeOf(const Cell& c, const CompiledBlob& fallback) const {
    return c.tape < tapes.size() ? tapes[c.tape] : fallback;
  }
};

/// Compiles the subtree at root. O(n log n) in the number of reachable nodes.
CompiledBlob compile(const BlobTree& tree, NodeId root);

}  // namespace sprig::blobtree
