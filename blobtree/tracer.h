#pragma once
/// The one ray tracer of compiled BlobTrees: batched segment tracing.
///
/// Method: a span [t0, t1] of a ray is sampled at kTraceLanes points per batched field
/// evaluation (CompiledBlob::values). Between neighbouring samples i, i+1 at spacing Δ a
/// surface point can exist only if the samples straddle 0.5 or
/// |fᵢ − 0.5| + |fᵢ₊₁ − 0.5| <= L·Δ (L: a Lipschitz bound of F along the ray, per unit of
/// t), the guarantee segment tracing rests on, tested eight samples at a time. Intervals
/// that may hide a double crossing are searched recursively, front to back; the first
/// straddling interval is shrunk by batched subdivision to the tolerance, then
/// interpolated linearly (Crossing says whether hidden double crossings ahead of the sign
/// change inside that interval are searched too).
///
/// Users: the renderer's Embree user geometry (one surface cell per primitive, the cell's
/// stored bound: traceCell), CompiledBlob::intersectCell (the same) and
/// CompiledBlob::intersect (whole rays: empty space skipped by interval bounds over growing
/// windows, each remaining window traced with its local bound: traceRay).

#include "blobtree/compiled.h"

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace sprig::blobtree {

/// Points per batched field evaluation of the tracer.
inline constexpr int kTraceLanes = 8;

/// What the tracer returns for the first sample interval that straddles 0.5.
enum class Crossing : uint8_t {
  /// The interval shrunk to its first sign change between samples, interpolated. A double
  /// crossing hidden inside that interval ahead of its sign change can be missed (the
  /// renderer's surface cells, whose spans are short; kept for its exact output).
  FirstStraddle,
  /// As FirstStraddle, but the sub-intervals ahead of each sign change are searched for
  /// hidden double crossings too (the Lipschitz test, recursively): the first crossing the
  /// bound admits. CompiledBlob::intersect and intersectCell.
  First,
  /// The start of a straddling interval, unrefined (shadow rays: a crossing exists): of
  /// the first batch with a sign change between its samples, the first such interval,
  /// without searching the intervals ahead of it for hidden double crossings. Found
  /// whenever FirstStraddle finds a crossing; the parameter may lie past FirstStraddle's.
  Any,
};

/// Clips [t0, t1] of origin + t·direction to box (slab test); false when the clipped span is
/// empty. An axis with a zero direction component keeps the span when the origin lies in
/// the slab.
bool clipToBox(const Box3& box, Vec3 origin, Vec3 direction, float& t0, float& t1);

/// The first crossing of F = 0.5 (either direction) on the ray for t in [t0, t1], t0 >= 0,
/// by batched segment tracing with `lipschitz` a Lipschitz bound of t ↦ F(o + t·d) over the
/// span. `tolerance` is the root's accuracy in t; it is raised to 8 float spacings of the
/// span's end, which is the most that can be resolved. mode: see Crossing. Returns the ray
/// parameter.
std::optional<float> traceSegment(const CompiledBlob& blob, const Ray& ray, float t0, float t1, float lipschitz,
                                  float tolerance, Crossing mode = Crossing::First);

/// traceSegment over the part of [t0, t1] inside cell.box, with the cell's stored Lipschitz
/// bound (SurfaceCellOptions::lipschitz must have been on).
std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode = Crossing::First);

/// Bounds of F over the sub-cells of a CellSet's cells, for the tracer: each cell is split
/// into k x k x k sub-cells, and each sub-cell (widened by kMarginCells of the cell's edge)
/// gets an interval bound of F and a Lipschitz bound from its cell's tape, computed the first
/// time a ray needs it and kept (a float per sub-cell; racing threads compute the same bits).
/// A cell uses them only from its kWarmTraces-th trace on: the bounds of a sub-cell cost
/// several batches of field values, which pay back only over many rays (a full-size render,
/// not a gallery thumbnail).
///
/// Why: a ray crosses many surface cells and misses most of them, and a cell's bounds, taken
/// over the whole cube, admit far more than the thin part a ray passes. Over the sub-cells
/// the ray actually crosses, the interval often excludes 0.5 (no surface: no samples at all)
/// and the Lipschitz bound is often several times the cell's smaller (fewer subdivisions).
/// Both bounds are sound, so the tracer finds the same crossings from the same samples.
/// Thread-safe. Reserves 4·k³ + 4 bytes per cell, zero pages until used. The CellSet and
/// blob must outlive it.
class SubCellBounds {
 public:
  /// Margin of a sub-cell's box, in cells' edges (within the pruned tapes' 1/64 margin).
  static constexpr float kMarginCells = 1.0f / 256.0f;
  /// Traces of a cell before its sub-cells are used (warm()).
  static constexpr uint32_t kWarmTraces = 256;

  /// What the sub-cells that a segment crosses admit.
  struct Bound {
    float lipschitz = 0.0f;    ///< the largest of their Lipschitz bounds (world units)
    bool maySurface = false;   ///< false: no interval of them contains 0.5, so F != 0.5 on the segment
  };

  SubCellBounds() = default;
  /// For the cells of `cells` (each with its pruned tape, else blob), k sub-cells per axis
  /// (1..8, else std::invalid_argument). Reserves the memory; computes nothing yet.
  SubCellBounds(const CellSet& cells, const CompiledBlob& blob, int k);

  /// Sub-cells per axis (0 for a default-constructed, unusable object).
  int divisions() const { return k_; }
  /// Counts a trace of cell `cellIndex`; true from its kWarmTraces-th on.
  bool warm(uint32_t cellIndex) const;
  /// The bound over the sub-cells of cell `cellIndex` that origin + t·direction, t in [a, b],
  /// crosses (tested against their widened boxes). Computes the sub-cells it needs. A
  /// segment that crosses none (it lies outside the cell) gets the cell's own bound and
  /// maySurface.
  Bound segment(uint32_t cellIndex, const Ray& ray, float a, float b) const;

 private:
  struct Free {
    void operator()(uint32_t* p) const;
  };
  /// The value of sub-cell s of cell c: its Lipschitz bound, negated (sign bit set) when its
  /// interval excludes 0.5.
  float entry(uint32_t c, int s) const;
  /// Box of sub-cell (i, j, l) of cell c, widened by the margin.
  Box3 subBox(const Cell& c, int i, int j, int l) const;

  const CellSet* cells_ = nullptr;
  const CompiledBlob* blob_ = nullptr;
  int k_ = 0;
  /// Per sub-cell: 0 until computed, then the bits of entry()'s value plus 1 (zeroed pages
  /// from calloc, read and written through std::atomic_ref).
  std::unique_ptr<uint32_t[], Free> slots_;
  std::unique_ptr<uint32_t[], Free> traces_;  ///< per cell, saturating at kWarmTraces
};

/// The sub-cells of each surface cell on which F provably stays off 0.5: each cell is split
/// into 4 x 4 x 4 sub-cells, F is evaluated at their 64 centres with the cell's tape (one
/// batched walk), and a sub-cell is free of the surface when |F(centre) − 0.5| exceeds L·r
/// plus kValueMargin, with L the tape's Lipschitz bound over the cell widened by
/// kMarginCells of its edge and r the half diagonal of the sub-cell widened by twice that.
/// The widening covers the tracer's samples, which rounding can put just outside the cell;
/// kValueMargin covers the rounding of the field's values and the pruned tape's differences
/// from the whole one.
///
/// Why: a cell's interval bound admits many cells the surface never enters (38 % of the
/// PCM poplar's), and many rays cross only the free parts of the others; such a span holds
/// no sign change of the sampled field, so the tracer would return nothing after a batch or
/// more. With the proof a span proven free (spanFree) costs no batch: the same hits, bit
/// for bit.
///
/// When: a proof costs about as much as five batches of the tracer, so it pays only in a
/// cell that many rays cross. Proved eagerly (every cell when the object is made) the
/// renderer can leave wholly free cells out of the scene (dropWhole); proved lazily, a cell
/// is proved when its proveAt-th trace enters it (enter()), once, so cells that few rays
/// reach never pay. The mask is a pure function of the cell, so either way, at any thread
/// count, the tracer returns the same bits. Per cell: 16 bytes.
class FreeSubCells {
 public:
  static constexpr int kDivisions = 4;
  /// Margin of a sub-cell's box, in cells' edges, when testing which sub-cells a span crosses.
  static constexpr float kMarginCells = 1.0f / 256.0f;
  /// How far F must stay from 0.5 beyond the Lipschitz bound.
  static constexpr float kValueMargin = 1e-4f;
  /// Every sub-cell free.
  static constexpr uint64_t kWhole = ~uint64_t(0);

  FreeSubCells() = default;
  /// Proves every cell of `cells` (each with its pruned tape, else blob) now, in parallel.
  FreeSubCells(const CellSet& cells, const CompiledBlob& blob);
  /// Proves nothing yet: cell c is proved when its proveAt-th trace enters it (enter();
  /// 0: never, only by prove() and mask()). The CellSet and blob must outlive the object and
  /// stay where they are.
  FreeSubCells(const CellSet& cells, const CompiledBlob& blob, uint32_t proveAt);

  /// Proves the listed cells now (those not proven yet), in parallel.
  void prove(std::span<const uint32_t> cells);

  /// Bit i + 4·(j + 4·l) set: sub-cell (i, j, l) of cell c is free of the surface. Proves
  /// cell c now if it is not yet (without counting a trace).
  uint64_t mask(uint32_t c) const;
  /// Cells with a mask (proved or not).
  size_t size() const { return entries_.size(); }
  /// Whether cell c has been proved.
  bool proven(uint32_t c) const;
  /// Cells proved so far.
  size_t provenCount() const;
  /// Counts a trace entering cell c and returns the mask to use for it: the cell's mask once
  /// it is proven (at the proveAt-th trace, proved by that trace's thread), else 0 (nothing
  /// known free). Thread-safe; each cell is proved once.
  uint64_t enter(uint32_t c) const;
  /// True when every sub-cell of cell c in the range of sub-cells that origin + t·direction,
  /// t in [a, b], spans per axis (widened slabs; a superset of those it crosses) is free:
  /// F != 0.5 on the segment. Proves cell c if it is not yet. (Testing the crossed sub-cells
  /// alone, by slab tests, proved 11 % more spans free and cost more than the batches it saved.)
  bool spanFree(const Cell& c, uint32_t cellIndex, const Ray& ray, float a, float b) const;
  /// spanFree with the mask `free` of cell c.
  static bool spanFree(const Cell& c, uint64_t free, const Ray& ray, float a, float b);
  /// Removes from cells (and from the masks) the proven cells whose sub-cells are all free,
  /// in order; returns how many. The cells must be those the object was made for.
  size_t dropWhole(CellSet& cells);

 private:
  /// A cell's mask and the traces counted, kProven set once the mask is written. Read and
  /// written through std::atomic_ref.
  struct Entry {
    uint64_t mask = 0;
    uint32_t traces = 0;
  };
  static constexpr uint32_t kProven = uint32_t(1) << 31;
  /// Proves cell c and publishes its mask; returns it.
  uint64_t proveOne(uint32_t c) const;

  const CellSet* cells_ = nullptr;
  const CompiledBlob* blob_ = nullptr;
  uint32_t proveAt_ = 1;
  mutable std::vector<Entry> entries_;
};

/// traceCell with bounds over the sub-cells the ray crosses (SubCellBounds; the caller
/// decides when, see SubCellBounds::warm): a span whose
/// sub-cells exclude 0.5 is a miss without samples; the span and every sub-interval the
/// Lipschitz test would search are first tested with the smaller of the cell's bound and
/// their sub-cells'. Returns what traceCell returns, with fewer field evaluations.
std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode, const SubCellBounds& sub, uint32_t cellIndex);

/// traceCell with the proofs the renderer keeps per cell: the trace enters cell cellIndex of
/// `free` (FreeSubCells::enter, when `free` has masks), and a span that the mask proves free
/// is a miss without samples; sub, when not null, is used as by the overload above. The same
/// result as traceCell without them.
std::optional<float> traceCell(const CompiledBlob& blob, const Cell& cell, const Ray& ray, float t0, float t1,
                               float tolerance, Crossing mode, const FreeSubCells& free, const SubCellBounds* sub,
                               uint32_t cellIndex);

/// The first crossing on the whole ray for t in [tmin, tmax]: the ray is clipped to the
/// blob's bounds, windows whose interval bound excludes 0.5 are skipped (the window doubles
/// after each), windows longer than four safe steps shrink, and each remaining window is
/// traced by traceSegment with its local Lipschitz bound. The tolerance is
/// options.relativeTolerance times the model size; at most options.maxSteps windows.
std::optional<float> traceRay(const CompiledBlob& blob, const Ray& ray, float tmin, float tmax,
                              const TraceOptions& options = {});

/// The hit at ray parameter t: point o + t·d, the outward normal −∇F/|∇F| (−d/|d| where
/// the gradient vanishes) and the blended attributes, from CompiledBlob::sample.
Hit hitAt(const CompiledBlob& blob, const Ray& ray, float t);

}  // namespace sprig::blobtree
