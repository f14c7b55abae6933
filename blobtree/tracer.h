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
#include <optional>

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
  /// The start of the first straddling interval, unrefined (shadow rays: a crossing exists).
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
