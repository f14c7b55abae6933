#pragma once
/// Colours of a shell: one texture per part (main whorl, varix spines, axial spines, bumps,
/// inside), blended where parts meet by the BlobTree's field-weighted attribute blend
/// (Σ fᵢ·Tᵢ / Σ fᵢ, murex paper §3.4, Tigges and Wyvill 1999).
///
/// The main whorl is mapped from helico-spiral coordinates (the angle θ along the spiral and
/// the angle around the generating curve), recovered exactly from the surface point: the
/// point's angle about the axis fixes θ up to whole turns, and the turn whose generating
/// centre is nearest (relative to D(θ)) is the one the point belongs to. The paper pastes
/// painted maps onto a bounding surface (Tigges and Wyvill 1998); we compute ours
/// procedurally: spiral cords, axial growth lines, varix bands, and the reaction-diffusion
/// pigment of textures/pigment_rd.h laid down along the growing edge.

#include <memory>

#include "blobtree/compiled.h"
#include "core/types.h"
#include "organisms/shell.h"
#include "textures/pigment_rd.h"

namespace sprig::organisms {

/// Colours and patterns of the shell parts (linear RGB).
struct ShellTextureOptions {
  Vec3 whorlColor{0.80f, 0.72f, 0.60f};   ///< main whorl ground colour
  Vec3 cordColor{0.50f, 0.36f, 0.26f};    ///< colour of the spiral cords
  int cords = 12;                          ///< spiral cords around the generating curve
  float cordStrength = 0.35f;              ///< 0 = no cords
  float growthLineDeg = 6.0f;              ///< spacing of axial growth lines along θ; 0 = none
  float growthLineStrength = 0.12f;
  Vec3 varixColor{0.88f, 0.84f, 0.78f};    ///< varix spines and ridge
  Vec3 spineTipColor{0.45f, 0.30f, 0.22f}; ///< spine tips (varix and axial)
  Vec3 axialColor{0.84f, 0.80f, 0.74f};    ///< axial canal spines
  Vec3 bumpColor{0.70f, 0.58f, 0.46f};     ///< bumps
  Vec3 insideColor{0.93f, 0.78f, 0.74f};   ///< aperture and inside wall
  /// The whorl's inner surface (the hollow the opening cuts, Eq. 14) takes insideColor:
  /// points nearer the generating centre than this fraction of D(θ), within the opening's
  /// depth of the lip. The cut surface carries the whorl's texture id (a difference keeps
  /// the shell's attributes), so the painter tells it by its place. 0 = off.
  float insideRadial = 0.9f;
  bool pigment = false;                    ///< lay the reaction-diffusion pattern on the whorl
  Vec3 pigmentColor{0.30f, 0.15f, 0.08f};  ///< colour of high activator
  float pigmentStrength = 0.85f;
  textures::PigmentRdOptions pigmentOptions;  ///< rows span the fully grown shell's θ range
};

/// Points of the whorl farther than this from every generating centre (in units of D(θ))
/// are the canal's: the whorl's varix bands stop there (ShellPainter::whorlColorAt).
inline constexpr double kShellCanalRadial = 1.25;

/// Helico-spiral coordinates of a point in shell coordinates.
struct HelicoCoords {
  double thetaDeg = 0.0;   ///< angle along the spiral of the generating curve nearest the point
  double aroundDeg = 0.0;  ///< angle around the generating curve, from outward, positive towards the apex
  double radial = 0.0;     ///< distance from the generating centre / D(θ)
  /// The same against the generating curves grown so far only (θ ≤ θ_end, the lip's for
  /// turns past it): where the canal runs through the place of a whorl not yet grown, the
  /// nearest curve is that whorl's and `radial` is small, yet the point is no aperture.
  double grownThetaDeg = 0.0;
  double grownRadial = 0.0;
};

/// Colours surface points of one shell. Immutable after construction; thread-safe.
class ShellPainter {
 public:
  /// Precomputes the pigment pattern when options.pigment (cost of simulatePigment).
  /// `fullEndDeg` is the θ_end of the fully grown shell, so a young shell shows the same
  /// pattern as the part of the old one it grows into.
  ShellPainter(const ShellParams& params, const ShellModel& model, ShellTextureOptions options);

  /// Colour at world point p with the BlobTree attributes found there.
  Vec3 color(Vec3 worldPoint, const blobtree::Attributes& attributes) const;
  /// Colour of one part at p (world) with natural uv.
  Vec3 partColor(ShellPart part, Vec3 worldPoint, Vec2 uv) const;
  /// Helico-spiral coordinates of a shell-space point (see the file comment).
  HelicoCoords helicoCoords(Vec3 shellPoint) const;
  /// Helico-spiral coordinates of a world point (helicoCoords of its shell-space point).
  HelicoCoords helicoCoordsOfWorld(Vec3 worldPoint) const;
  /// The main whorl's colour at helico-spiral coordinates: partColor(Whorl, p, uv) is
  /// whorlColorAt(helicoCoordsOfWorld(p)). It depends on the radial coordinate in two places
  /// only: the inside of the aperture (insideWeight > 0) and the canal (radial >=
  /// kShellCanalRadial: no varix bands); elsewhere it is whorlSurfaceColor(θ, around, false).
  Vec3 whorlColorAt(const HelicoCoords& coords) const;
  /// The whorl's colour at (θ, around) on its outer wall (canal false: with the varix
  /// bands) or on the canal (canal true: without them), where insideWeight is 0: what
  /// exports bake into an image over (aroundDeg, thetaDeg).
  Vec3 whorlSurfaceColor(double thetaDeg, double aroundDeg, bool canal) const;
  /// Weight in [0, 1] of the inside colour at these coordinates: > 0 only past the opening's
  /// start (θ > θ_end − depth) and within insideRadial + 0.04 of the generating centre.
  double insideWeight(const HelicoCoords& coords) const;
  /// Whether the whorl has pale varix bands (so the canal's colour differs from the wall's).
  bool hasVarixBands() const;
  const ShellTextureOptions& options() const { return options_; }

 private:
  Vec3 whorlColor(Vec3 shellPoint) const;
  Vec3 wallColor(const HelicoCoords& coords) const;  ///< ground, cords, growth lines, pigment
  Vec3 withVarixBand(Vec3 color, double thetaDeg) const;

  ShellTextureOptions options_;
  HelicoSpiral spiral_;
  double startDeg_ = 0.0, endDeg_ = 0.0, fullEndDeg_ = 0.0, varixSpacingDeg_ = 0.0;
  bool varices_ = false;
  bool opening_ = false;
  double openingFromDeg_ = 0.0;  // θ_end − depth
  float spineLength_ = 1.0f, axialLength_ = 1.0f;
  glm::dmat4 shellFromWorld_{1.0};
  std::shared_ptr<const textures::PigmentPattern> pigment_;
};

}  // namespace sprig::organisms
