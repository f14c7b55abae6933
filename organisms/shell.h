#pragma once
/// Seashells as structured implicit surfaces: the helico-spiral generator of Galbraith,
/// Prusinkiewicz, Wyvill, "Modeling a Murex cabritii sea shell with a structured implicit
/// surface modeler" (seed 000), built on the BlobTree.
///
/// A shell is a function of its parameters and its age θ_end (the final angle along the
/// spiral, degrees). Every part is placed on the spiral by P(B, θ) (Eq. 8):
///  - the main body: generating surfaces every Δθ (Eq. 9), summed per section (one section
///    between two varices), sections joined by controlled blending so each blends only with
///    its neighbours along the spiral and adjacent whorls meet in a crease (Eq. 10);
///  - varices every `spacingDeg` (116° for the Murex): rows of bent cone spines sized per
///    whorl (Table 1), two concentric tori joining them, thicker tips on short spines and
///    σ_max across the varix (Eq. 11-13);
///  - bumps between varices, randomly scaled, blended with the super-elliptic blend n = 400;
///  - axial rows of canal spines below the last varices (Table 2), randomly bent;
///  - the opening: (B_shell − (B_inside − B_previous)) ∪ B_insidewall (Eq. 14-15).
/// A young shell is the same shell stopped at a smaller θ_end: its aperture and a varix lie
/// at the growing edge, and parts that follow the edge (canal, axial spines, opening) move
/// with it.
///
/// Frames: "shell coordinates" are those of HelicoSpiral (axis y, apex towards −y, as in
/// the paper). The model's root places the shell in world space with the apex up
/// (`ShellModel::worldFromShell`). The generating surface is modelled in a unit frame:
/// x away from the axis, y along the axis (towards the aperture's anterior, away from the
/// apex), size 1 = D(θ). Varix and bump angles α are measured in the generating plane from
/// the horizontal, positive towards the apex (Table 1's convention).
///
/// Texture ids on primitives (see ShellPart) let a painter blend part textures where parts
/// meet (Σ fᵢ·Tᵢ / Σ fᵢ); organisms/shell_paint.h colours them.

#include <cstdint>
#include <optional>
#include <vector>

#include <glm/mat4x4.hpp>

#include "blobtree/blobtree.h"
#include "blobtree/compiled.h"
#include "core/types.h"
#include "organisms/shell_spiral.h"

namespace sprig::organisms {

/// The part of a shell a primitive belongs to; also its texture id.
enum class ShellPart : uint16_t { Whorl = 0, VarixSpine = 1, AxialSpine = 2, Bump = 3, Inside = 4 };

/// One primitive of a generating surface, in the unit generating frame.
struct GeneratingPrimitive {
  enum class Kind : uint8_t { Point, Cone };
  Kind kind = Kind::Point;
  Vec3 a{0.0f};                  ///< centre (point) or start (cone)
  Vec3 b{0.0f};                  ///< cone end
  float radiusA = 1.0f;          ///< 0.5-iso radius at a
  float radiusB = 1.0f;          ///< 0.5-iso radius at b (cone)
  float bendDeg = 0.0f;          ///< cone bend angle (endpoint-preserving warp); 0 = straight
  Vec3 bendDirection{1.0f, 0.0f, 0.0f};  ///< direction the bent cone bulges towards
  /// When > 0 the primitive is only swept over the last `lastDeg` degrees before θ_end (the
  /// paper models the canal only in the last 1⅓ whorls).
  double lastDeg = 0.0;
  bool canal = false;            ///< the siphonal canal (carries the axial spines)
};

/// A generating surface: primitives summed at each placement along the spiral.
struct GeneratingSurface {
  std::vector<GeneratingPrimitive> primitives;

  /// A unit point primitive: a circular aperture (Fig. 4-5).
  static GeneratingSurface point();
};

/// The siphonal canal of the Murex generating surface (Fig. 6): below the point, a cone
/// bent on a circular arc that leaves the aperture's lower inner side heading `turnDeg`
/// away from the axis direction and turns until it runs parallel to the shell axis,
/// `axisOffset` beside it, continued by a straight cone down to the tip. Every swept copy
/// ends along the axis, so the copies overlap into one long, slender, straight canal
/// (Fig. 13-14) instead of fanning out into a funnel. Unit generating frame (x away from
/// the axis, y along the axis away from the apex, 1 = D(θ)); the tip's x is
/// −R/D + axisOffset, taken from the spiral (−2.93 + offset for the Murex), so the canal
/// follows λ and β.
struct CanalOptions {
  Vec2 start{-0.45f, 0.7f};   ///< where the canal leaves the generating point (unit frame)
  float length = 8.0f;        ///< axial extent from `start` to the tip, unit frame
  float axisOffset = 0.1f;    ///< distance of the straight part from the shell axis, unit frame
  float radiusStart = 0.25f;  ///< 0.5-iso radius at the start (before size calibration)
  float radiusEnd = 0.2f;     ///< 0.5-iso radius at the tip
  float turnDeg = 75.0f;      ///< the canal's direction at its start, from the axis direction (0, 90]
  double sweepDeg = 464.0;    ///< swept over the last sweepDeg before θ_end (1⅓ whorls)

  /// The tip's x in the unit frame for `spiral`.
  double tipX(const HelicoSpiral& spiral) const;
  /// Axial extent of the bent part: (start.x − tipX)·sin(turn)/(1 − cos(turn)).
  double arcHeight(const HelicoSpiral& spiral) const;
  /// Arc length of the centre line (bent part plus straight part).
  double centreLength(const HelicoSpiral& spiral) const;
  /// Point of the centre line at arc-length fraction t in [0, 1] (unit frame, z = 0).
  Vec3 pointAt(const HelicoSpiral& spiral, double t) const;
  /// The canal as generating primitives (canal = true): the bent cone and the straight one.
  std::vector<GeneratingPrimitive> primitives(const HelicoSpiral& spiral) const;
};

/// One spine of a varix row: its angle in the generating plane and its relative size σ.
struct VarixSpine {
  float angleDeg = 0.0f;  ///< from the horizontal, positive towards the apex
  float size = 1.0f;      ///< σᵢ of Eq. 11 / Table 1
};

/// Varices (Eq. 11-13, Fig. 7).
struct VarixOptions {
  bool enabled = false;
  double spacingDeg = 116.0;  ///< angle between successive varices; the first at spacingDeg
  /// Spine rows per whorl (Table 1): row w−1 for whorl w; whorls past the end use the last row.
  std::vector<std::vector<VarixSpine>> spinesByWhorl;
  float spineLength = 0.9f;       ///< unit-frame length of a σ = 1 spine (from the shell edge)
  float baseRadius = 0.11f;       ///< spine cone radius at the base
  float tipRadius = 0.02f;        ///< spine tip radius
  float shortTipRadius = 0.045f;  ///< tip radius of short spines ("thicker tips", Fig. 7)
  float shortSize = 0.7f;         ///< spines with σ below this get shortTipRadius
  float bendDeg = 30.0f;          ///< spine curvature (towards the apex side)
  float edge = 0.92f;             ///< x_k: where spine bases sit (unit frame, 1 = shell edge)
  bool widenAcross = true;        ///< scale each spine by σ_max across the varix (Eq. 12)
  bool tori = true;               ///< the two concentric tori joining the spines (Fig. 7)
  float torusRadius = 0.07f;      ///< tube radius of the tori (unit frame)
  float torusOuter = 1.1f;        ///< major radius of the outer torus (the inner one sits at 1)
  bool lipVarix = true;           ///< a varix at the growing edge θ_end (growth)
};

/// Bumps between varices (Fig. 8).
struct BumpOptions {
  bool enabled = false;
  int setsPerSection = 5;   ///< rows of bumps between two varices
  float size = 0.1f;        ///< s: mean bump radius, unit frame
  float sdFraction = 0.1f;  ///< σ of the normal distribution as a fraction of s
  float elongation = 0.8f;  ///< added to the scale along the spiral (σ_z + 0.8); bumps are capsules of these extents
  float blendN = 400.0f;    ///< super-elliptic blend exponent with the shell; 1 = plain sum
  bool random = true;       ///< draw sizes from n(s, s/10); false: all equal
  float edge = 0.95f;       ///< distance of bump centres from the generating centre
};

/// Axial rows of canal spines (Fig. 9, Table 2).
struct AxialSpineOptions {
  bool enabled = false;
  /// Relative sizes per row, oldest varix first (Table 2); one row below each of the last
  /// rows.size() varices.
  std::vector<std::vector<float>> rows;
  float length = 1.0f;        ///< unit-frame length of a size 1 spine
  float baseRadius = 0.1f;
  float tipRadius = 0.025f;
  float firstT = 0.2f;        ///< first spine's position along the canal (0 = canal start)
  float lastT = 0.9f;         ///< last spine's position along the canal
  float downTilt = 0.35f;     ///< spine direction = normalize(1, downTilt, 0) in the unit frame
  bool randomBends = true;    ///< bend each spine 1-3 times by 3°-9°
  float bendMinDeg = 3.0f, bendMaxDeg = 9.0f;
  int bendsMin = 1, bendsMax = 3;
};

/// The opening (Eq. 14-15, Fig. 10-11).
struct OpeningOptions {
  bool enabled = false;
  float innerScale = 0.8f;   ///< inside generating surface size relative to the main one
  double depthDeg = 300.0;   ///< how far back from θ_end the hollow reaches
  double extendDeg = 40.0;   ///< how far past θ_end the cutter reaches (opens the lip)
  bool insideWall = true;    ///< add the inside wall back (Eq. 15): a rounded lip ring
  bool subtractPrevious = true;  ///< B_inside − B_previous-whorl (Eq. 14)
  /// Fig. 10's construction surfaces: instead of the shell, the model is one of them.
  enum class Show : uint8_t {
    Shell,          ///< the shell with its opening (Eq. 14-15)
    InsideSurface,  ///< the inside generating surface (inner_scale times the main one) at θ_end
    InsideWhorl,    ///< B_inside: that surface swept over the opening's depth and extension
    Cutter,         ///< B_opening = B_inside − B_previous, the solid cut out of the shell
  };
  Show show = Show::Shell;
};

/// Everything that defines a shell.
struct ShellParams {
  HelicoSpiral spiral;          ///< λ, β, R₀
  int whorls = 7;               ///< whorls of a fully grown shell
  double whorlDeg = 348.0;      ///< angle of one whorl (three varices of 116° for the Murex)
  double sectionDeg = 116.0;    ///< angle of one section (between varices)
  int surfacesPerSection = 6;   ///< generating surfaces per section: Δθ = sectionDeg / this
  double startDeg = 0.0;        ///< angle of the first generating surface (apex)
  std::optional<double> ageDeg; ///< θ_end; default whorls·whorlDeg
  GeneratingSurface generating = GeneratingSurface::point();
  /// The Murex canal (`generating: murex`), added to the generating surface by the builder
  /// from the spiral's proportions; nullopt: none.
  std::optional<CanalOptions> canal;
  bool controlledBlending = true;  ///< Eq. 10; false: every section blends with every other
  /// Shrink and shift generating primitives so the summed field of the row spaced Δθ apart
  /// along the curved spiral has a cross-section of mean radius D(θ) centred on the spiral
  /// (overlapping fields otherwise fatten the tube, most on the side facing the axis).
  bool calibrateSize = true;
  VarixOptions varices;
  BumpOptions bumps;
  AxialSpineOptions axialSpines;
  OpeningOptions opening;
  uint64_t seed = 1;
  bool apexUp = true;  ///< world = shell rotated 180° about x (apex up, aperture below)
  /// A rigid motion applied after apexUp: world = pose · (apex-up turn) · shell. Identity
  /// for the model itself (exports, measures); the renderer's resting pose (`render.rest`,
  /// model/shell_kind.h) sets it for pictures only.
  glm::dmat4 pose{1.0};

  /// θ_end: ageDeg or whorls·whorlDeg.
  double endDeg() const;
  /// Δθ = sectionDeg / surfacesPerSection.
  double stepDeg() const;
};

/// Where a built spine is, for measurement (shell coordinates).
struct SpineRecord {
  ShellPart part = ShellPart::VarixSpine;
  int varix = 0;          ///< 1-based varix number along the spiral
  int index = 0;          ///< spine index in its row
  float size = 0.0f;      ///< relative size σ from the table
  double thetaDeg = 0.0;  ///< placement angle
  Vec3 base{0.0f};        ///< base point (shell coordinates)
  Vec3 tip{0.0f};         ///< tip point (the bend keeps it where the straight tip is)
  float lengthShell = 0.0f;  ///< |tip − base| in shell units = size·length·D(θ)
  float tipRadius = 0.0f;    ///< tip iso radius in shell units
};

/// A built shell.
struct ShellModel {
  blobtree::BlobTree tree;
  blobtree::NodeId root = 0;       ///< world-space model (apex up when params.apexUp)
  blobtree::NodeId shellRoot = 0;  ///< the same model in shell coordinates
  blobtree::NodeId mainBody = 0;   ///< controlled blend of the sections (plus varices and axial spines)
  std::vector<blobtree::NodeId> sections;  ///< per-section sums of generating surfaces (with their varix)
  std::vector<double> sectionStartDeg;     ///< first angle of each section
  std::vector<double> varixDeg;            ///< angles of the varices, in order
  std::vector<SpineRecord> spines;         ///< every varix and axial spine
  size_t bumpCount = 0;
  double endDeg = 0.0;                     ///< θ_end
  float sizeCalibration = 1.0f;            ///< factor applied to generating radii
  float centreShift = 0.0f;                ///< outward shift of the generating surface (unit frame)
  glm::dmat4 worldFromShell{1.0};
  HelicoSpiral spiral;
};

/// Builds the shell. Throws InputError (at `loc`, e.g. the species file's `shell:` key) when
/// parameters are out of range: λ <= 1, β outside (0°, 90°], R₀ <= 0, no generating
/// primitive, θ_end below the start angle (θ_end = start gives one generating surface). Deterministic: the same params give the same tree.
ShellModel buildShell(const ShellParams& params, const SourceLoc& loc = {});

/// Edge of the surface cells for exact rendering of a compiled shell (render::ImplicitOptions):
/// a fixed fraction of the bounds' diagonal (docs/PERFORMANCE.md, Shells). The renderer's automatic
/// size follows the smallest feature (the apex's tiny spine tips) and makes far more cells.
float shellCellSize(const blobtree::CompiledBlob& blob);

/// Root tolerance for exact renders of shells (blobtree::TraceOptions::relativeTolerance,
/// relative to the bounds' diagonal). 1e-4 brackets each hit within about a quarter pixel
/// at 1536x2048 before the final interpolation, changes 0.03% of a render's pixels by at
/// most 5/255, and traces the Murex 25% faster than the default 1e-6 (docs/PERFORMANCE.md, Shells).
inline constexpr float kShellTraceTolerance = 1e-4f;

/// The Murex cabritii of the paper: λ = 1.3, β = 22.5°, R₀ = 0.2, seven whorls of 348°,
/// three varices per whorl with spines per Table 1, bumps, axial spines per Table 2, the
/// opening. Our reading of Table 1's columns is documented in docs/SHELLS.md.
ShellParams murexCabritii();

/// Table 1 of the paper: varix spines per whorl (7 rows).
std::vector<std::vector<VarixSpine>> murexTable1();
/// Table 2 of the paper: axial spine sizes below the last three varices (oldest first).
std::vector<std::vector<float>> murexTable2();

}  // namespace sprig::organisms
