#pragma once
/// Multiresolution analysis (Velho et al. 2002, §2.2 and Fig. 2): a captured fine surface
/// becomes a coarse control mesh plus per-level details in local frames, so captured and
/// procedural shapes can be blended level by level.
///
/// 1. Resampling: the base mesh is refined to its finest level; from each refined vertex a
///    ray along its normal (both ways) finds the captured surface, whose hit becomes the
///    sample P_L of that vertex (no hit within maxDistance: the vertex keeps its place, and
///    is counted as a miss).
/// 2. Decomposition, for l = L .. 1: P_l is smoothed (umbrella Laplacian, `smoothing`
///    steps of lambda = 1/2; the paper lists Laplacian smoothing, Taubin's, and the
///    quasi-interpolation it prefers: this is the first) and decimated to the vertices of
///    level l-1 (vertex v of level l-1 is vertex v of level l): P_{l-1}. The detail of level
///    l is P_l - subdivide(P_{l-1}) in the local frames of the subdivided surface.
/// Synthesis from P_0 with these details (makeStoredDetail) reproduces P_L up to rounding.

#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "organisms/multires.h"

namespace sprig::organisms {

/// Distance t along the ray origin + t direction (t may be negative: both directions are
/// searched) to the captured surface, within maxDistance; nullopt when none.
using SurfaceProbe = std::function<std::optional<float>(const Vec3& origin, const Vec3& direction, float maxDistance)>;

/// Options of analysis.
struct AnalysisOptions {
  float maxDistance = 0.1f;  ///< world units along the normal
  int smoothing = 2;         ///< umbrella steps before each decimation
};

/// What analysis finds.
struct AnalysisResult {
  std::vector<Vec3> control;                  ///< P_0: the control positions to synthesize from
  std::vector<std::vector<Vec3>> details;     ///< details[l] (local frames), l = 0..L (details[0] is zero)
  std::vector<Vec3> resampled;                ///< P_L: the captured surface on the finest level
  size_t misses = 0;                          ///< finest vertices whose rays found no surface
};

/// Resamples the surface probe finds onto subdivision's finest level (from the base control
/// positions) and decomposes it level by level. Deterministic; parallel over vertices.
AnalysisResult analyze(const Subdivision& subdivision, std::span<const Vec3> baseControl, const SurfaceProbe& probe,
                       const AnalysisOptions& options = {});

/// Decomposition alone (step 2), from samples on the finest level.
AnalysisResult decompose(const Subdivision& subdivision, std::vector<Vec3> finest, int smoothing);

}  // namespace sprig::organisms
