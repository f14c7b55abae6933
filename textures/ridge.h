#pragma once
/// Bark along a branch bark ridge: compressed, darker bark on the crest and folds of bunched
/// bark that run parallel to the seam ("BlobTree Trees" §5: "the deformed fields resulting
/// from PCM may be used as input to a procedural texturing algorithm to modify the texture on
/// the branch bark ridge, where a discolouration is observed").
///
/// The input is the PCM contact c in [0, 1] (blobtree::Attributes::contact: 0 at the outer
/// edge of the propagation band, 1 on the seam). The folds are level sets of c, so they
/// follow the ridge around the branch, and their phase φ(c) = lines·c^1.5 (+ a wander drawn
/// from noise at the world point) crowds them toward the crest, where the bark is pushed
/// together. The relief is a height profile H(c) in units of the band's width (1/|∇c|): a
/// rounded crest smoothstep(c) with the folds cut into it. Measured in the band's width, the
/// world slope along ∇c is dH/dc itself, whatever the branch's size, so the crest reads alike
/// on a twig and on the trunk; a shader tilts its normal by it.

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "core/types.h"
#include "textures/noise.h"

namespace sprig::textures {

/// How the bark of a branch bark ridge looks; the defaults change nothing.
struct RidgeOptions {
  double darkening = 0.0;  ///< crest darkening: colour × (1 − darkening·c³), in [0, 1]
  int lines = 0;           ///< bark folds across the band, parallel to the seam (0: none)
  double relief = 0.0;     ///< slope of the crest's flanks at c = 1/2 is 1.5·relief (0: flat)
  double wanderScale = 20.0;  ///< frequency of the folds' wander along the ridge, per world unit
  uint64_t seed = 0;
};

/// Where a branch leaves its parent, as the branch bark ridge arc needs it (world units).
struct RidgeArc {
  Vec3 point{0.0f};               ///< the branching point P, on the parent's axis
  Vec3 parentAxis{0, 1, 0};       ///< unit direction of the parent's axis above P
  Vec3 branchAxis{1, 0, 0};       ///< unit direction of the branch leaving P
  float parentRadius = 0.1f;      ///< the parent's 0.5-iso radius at P
  float branchRadius = 0.05f;     ///< the branch's 0.5-iso radius at its base
};

/// The shape and look of the branch bark ridge arcs; lengths in branch radii r_B.
/// The arc lies on the parent's bark, in the chart (x around the parent from the branch's
/// azimuth, z along the parent from where the branch's axis pierces the parent's surface):
/// its crest follows z_c(x) = z_apex − droop·(√(x² + k²) − k), k = 0.8, with the apex
/// `rise` above the top of the branch's footprint (1/sin α for a branch at angle α), so it
/// arches over the branch and runs down both sides of it, fading out at |x| = spread. It
/// keeps to the parent's front and bark: not within 1.2 r_B of the branch's axis (the
/// branch's own surface), not 1.5 r_B outside the parent's radius.
struct RidgeArcOptions {
  double darkening = 0.0;  ///< colour × (1 − darkening) on the crest, in [0, 1]
  double relief = 0.0;     ///< the crest's flanks slope by up to 1.54·relief (shading only)
  double rise = 0.6;       ///< apex above the top of the branch's footprint
  double droop = 0.8;      ///< slope of the arms (z per x, far from the apex)
  double spread = 3.0;     ///< half-length of the arc around the parent
  double width = 0.35;     ///< half-width of the band at the apex (half that at the ends)
  /// The raised ridge (geometry, not shading): the surface over the crest rises by
  /// height·r_B at the apex, fading with the band toward the ends and near the branch
  /// (organisms::raisedRidgeArc). 0: the geometry stays as it is.
  double height = 0.0;
};

/// One point of an arc's crest on its parent's bark (world units).
struct RidgeCrestPoint {
  Vec3 position{0.0f};     ///< on the parent's cylinder of radius RidgeArc::parentRadius
  Vec3 normal{0.0f};       ///< unit, away from the parent's axis
  float halfWidth = 0.0f;  ///< the band's half-width there
  float weight = 0.0f;     ///< [0, 1]: the fade toward the ends, off the parent's front and near the branch
};

/// The branch bark ridge arcs of a tree: dark, raised arcs of compressed bark above each
/// branch, curving down both sides of it (the marks over the branches of a poplar,
/// "BlobTree Trees" Fig. 1 and 18). Looked up through a uniform grid over the arcs' bounds.
/// Immutable; thread-safe.
class RidgeArcs {
 public:
  /// Arcs that are degenerate (zero radius or direction, a branch along its parent) are left out.
  RidgeArcs(const std::vector<RidgeArc>& arcs, const RidgeArcOptions& options);
  const RidgeArcOptions& options() const { return options_; }
  size_t size() const { return arcs_.size(); }

  /// The arcs at world point p: the largest darkness in [0, 1] and the summed gradient of
  /// the crest's height (rise per world unit, times relief). Cost: the arcs of p's grid cell.
  struct Sample {
    double darkness = 0.0;
    Vec3 heightGradient{0.0f};
  };
  Sample sample(const Vec3& p) const;

  /// The crest of `arc` (the line the shading darkens most) sampled at `count` >= 2 points
  /// evenly in x from −spread to spread, with the same weights the shading applies on the
  /// parent's cylinder: 0 at both ends. Empty for an arc the constructor leaves out.
  static std::vector<RidgeCrestPoint> crest(const RidgeArc& arc, const RidgeArcOptions& options, int count);

 private:
  struct Arc {
    RidgeArc in;
    Vec3 side{0.0f}, out{0.0f};  ///< unit: around the parent (x), from the parent's axis to the branch
    double sinAlpha = 1, zPierce = 0, zApex = 0;
    Vec3 lo{0.0f}, hi{0.0f};     ///< box of influence
  };
  /// The chart of one arc; nullopt when it is degenerate.
  static std::optional<Arc> chart(const RidgeArc& in, const RidgeArcOptions& o);
  /// Darkness and height (in branch radii) of one arc at the chart point (x, z) in branch
  /// radii, before the weights that do not depend on x and z.
  void profile(const Arc& a, double x, double z, double& dark, double& height) const;

  RidgeArcOptions options_;
  std::vector<Arc> arcs_;
  Vec3 gridLo_{0.0f};
  float cell_ = 1.0f;
  glm::ivec3 dims_{0};
  std::vector<uint32_t> cellStart_, cellArcs_;  ///< CSR lists of arc indices per grid cell
};

/// The ridge shading of RidgeOptions. Immutable; thread-safe; a pure function of its inputs.
class RidgeShade {
 public:
  /// No ridge: changes nothing.
  RidgeShade() : RidgeShade(RidgeOptions{}) {}
  explicit RidgeShade(const RidgeOptions& options, std::shared_ptr<const RidgeArcs> arcs = nullptr)
      : options_(options), noise_(options.seed), arcs_(std::move(arcs)) {}
  const RidgeOptions& options() const { return options_; }
  /// The branch bark ridge arcs (null: none).
  const std::shared_ptr<const RidgeArcs>& arcs() const { return arcs_; }
  /// True when the ridge changes neither colour nor shading.
  bool none() const { return !(options_.darkening > 0) && !(options_.relief > 0) && !arcs_; }
  /// True when shadingNormal may change a normal (relief on the seams or on the arcs).
  bool tilts() const { return options_.relief > 0 || (arcs_ && arcs_->options().relief > 0); }
  /// How much darker the bark is at contact c and world point p, in [0, 1]: the colour is
  /// multiplied by 1 − darkness (the seam's and the arcs' darkening combined as
  /// 1 − (1 − d_seam)(1 − d_arc)). Cost: one noise lookup when lines > 0, plus the arcs near p.
  double darkness(double contact, const Vec3& p) const;
  /// The ridge's surface slope toward the seam (rise per world unit along ∇c): relief·dH/dc.
  /// Cost: one noise lookup and two profile evaluations.
  double slope(double contact, const Vec3& p) const;
  /// The unit shading normal: n tilted away from the seam by the ridge's slope, given the
  /// contact c and its gradient (blobtree::Attributes::contactGradient), and by the arcs'
  /// crests near p. n when no relief applies.
  Vec3 shadingNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const;

 private:
  double fold(double contact, double wander) const;
  Vec3 seamNormal(const Vec3& n, double contact, const Vec3& contactGradient, const Vec3& p) const;
  double wander(const Vec3& p) const;

  RidgeOptions options_;
  PerlinNoise noise_;
  std::shared_ptr<const RidgeArcs> arcs_;
};

}  // namespace sprig::textures
