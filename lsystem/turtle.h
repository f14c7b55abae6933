#pragma once
/// The 3D turtle: reads a module string and draws a Skeleton.
///
/// Frame convention (docs/TURTLE.md has the full table): the turtle carries a
/// right-handed orthonormal frame H (heading), L (left), U (up) with H x L = U. It
/// starts at the origin with H = +Y, L = -X, U = +Z, so a 2D ABOP figure grows upward
/// in the XY plane and `+` turns counter-clockwise as seen from +Z. Every rotation
/// command is a right-handed rotation about one frame axis:
///   `+` about U by +a, `-` about U by -a, `&` about L by +a (pitch down, H toward -U),
///   `^` about L by -a, `\` about H by +a, `/` about H by -a, `|` about U by 180.
///
/// Interpretation is one pass over the structure-of-arrays string with a per-symbol
/// command table built once from the SymbolTable; branch state lives on an explicit
/// stack, so there is no allocation per module beyond the output vectors.

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/types.h"
#include "lsystem/cpfg_contour.h"
#include "lsystem/cpfg_surface.h"
#include "lsystem/cpfg_texture.h"
#include "lsystem/module_string.h"
#include "lsystem/skeleton.h"

namespace sprig::lsystem {

/// How internode radii are chosen.
enum class RadiusModel {
  Width,  ///< from the turtle's line width (`!`): radius = 0.5 * width * widthScale
  Pipe,   ///< pipe model: parent radius^e = sum of child radii^e, tips get tipRadius
};

/// Most tropisms a cpfg view file may define (cpfg's MAXMOVEMENTS).
inline constexpr int kMaxTropisms = 10;

/// Organ::name of cpfg's textured tubes, drawn as Surface organs (triangles, normals and
/// uvs; docs/GRAMMAR.md, "Textures"): an `F` cylinder and a generalized cylinder's segment.
/// (No surface file's name has a space.)
inline constexpr const char* kTexturedCylinderName = "F cylinder";
inline constexpr const char* kTexturedGcName = "@Gc cylinder";

/// One tropism of a cpfg view file (`tropism: T: x y z A: angle I: intensity E: e S: step`),
/// applied by cpfg's own rule (docs/TURTLE.md, "cpfg tropisms").
struct CpfgTropism {
  DVec3 direction{0, -1, 0};  ///< T: made unit length, times the intensity clamped to [-1, 1]
  double angleDeg = 0;        ///< A: the angle to T that segments try to reach (0: toward T)
  double elasticity = 0;      ///< E: initial elasticity
  double step = 0;            ///< S: elasticity step of `@Ti` and `@Td` without a value
  bool torque = false;        ///< a `torque:` line: turns U about H toward T instead of bending H
};

/// Turtle options; defaults are documented per field.
struct TurtleSettings {
  double stepLength = 1.0;        ///< length of `F f G g` without a parameter (world units)
  double angleDeg = 90.0;         ///< turn of `+ - & ^ \ /` without a parameter (the grammar's `angle:`)
  double initialWidth = 0.1;      ///< line width (diameter, ABOP's `!` units) at the start
  double widthScale = 1.0;        ///< world units per width unit; radius = 0.5 * width * widthScale
  double widthFactor = 0.7;       ///< `!` without a parameter multiplies the width by this
  DVec3 tropism{0, -1, 0};        ///< tropism vector T (ABOP section 2.2); need not be unit length
  double elasticity = 0.0;        ///< initial susceptibility e to tropism; `@Ts(e)` changes it
  RadiusModel radii = RadiusModel::Width;  ///< where radii come from
  double pipeExponent = 2.0;      ///< e of the pipe model (2 = da Vinci's rule)
  double tipRadius = 0.01;        ///< pipe model: radius of every branch tip (world units)
  bool taper = true;              ///< width model: an internode's tip radius is its continuation's base radius
  /// Width model: when > 0, no internode is drawn thicker (diameter) than this times its
  /// length; 0 (the default) leaves radii alone. For bare grammars whose `!` widths are
  /// ABOP's pixel widths (figure 2.6 starts at `!(10)` with `F(1)`): 0.12 draws them as the
  /// shipped species files do. Local to each internode, so every growth stage agrees.
  double maxWidthToLength = 0.0;
  double surfaceScale = 1.0;      ///< scale of a `~` surface without a parameter
  /// cpfg's own command meanings (a `.l` grammar, Grammar::cpfgNotation): `!` and `#`
  /// step the width by widthIncrement, `;` and `,` step the color by colorIncrement,
  /// `@O(d)` and `@o(d)` take a diameter, `'` is no command, lengths and sizes are scaled by
  /// the turtle scale (`@D`), and only the `tropisms` bend (cpfg's rule, before each move).
  bool cpfg = false;
  /// cpfg: a `%` is no command for the turtle, which draws and queries the rest of its
  /// branch (the cut is made at the next step); false (`.lsys`, or cpfg's view file
  /// `interpretation past %: off`): the turtle skips the rest of the branch.
  bool interpretPastCut = false;
  /// cpfg: `twist of cylinders: on` (view file): a generalized cylinder's ring at each control
  /// point is in the turtle's frame there, the rings between turning smoothly to it; false
  /// (cpfg's default): each point's ring is the previous one's frame carried along the
  /// curve without twist (general.c, adjust_up_and_leftS), so a roll between points
  /// does not turn the cross-section.
  bool gcTwist = false;
  /// cpfg: the grammar's strings (Grammar::strings), which `@L`'s first parameter numbers;
  /// null: a label reached is an error.
  std::shared_ptr<const std::vector<std::string>> labelFormats;
  double widthIncrement = 0.0;    ///< cpfg: `line width increment:` (view file)
  int colorIncrement = 1;         ///< `color increment:` (view file)
  int initialColor = 0;           ///< `initial color:` (view file; cpfg's default is 128)
  double initialScale = 1.0;      ///< cpfg: `initial scale:` (view file), the turtle scale at the start
  double scaleMultiplier = 1.0;   ///< cpfg: `scale multiplier:` (view file), of `@Di` and `@Dd`
  std::vector<CpfgTropism> tropisms;  ///< cpfg: the view file's `tropism:` lines (at most kMaxTropisms)
  /// cpfg: the view file's surfaces (`surface:` lines), which `~X` draws as meshes; null for none.
  std::shared_ptr<const std::vector<CpfgSurfaceEntry>> cpfgSurfaces;
  /// cpfg: the view file's textures (`texture:` lines), which `@Tx(n)` selects for the
  /// surfaces `~X` draws; null for none.
  std::shared_ptr<const std::vector<CpfgTexture>> cpfgTextures;
  /// cpfg: `@Tx(n)` naming no texture is an error when true (the turtle draws); when false
  /// (the turtle only answers query modules and environmental programs, which draw
  /// nothing) it selects none, as cpfg's turtle does (blackbox.c).
  bool checkTextures = true;
  /// cpfg: the view file's contours (`contour:` lines), which `@#(id)` selects as the
  /// cross-section of generalized cylinders; null for none.
  std::shared_ptr<const std::vector<CpfgContourEntry>> cpfgContours;
  int contourSides = CpfgContour::kDefaultSides;  ///< cpfg: `contour sides:` (view file), points around a contour
  /// cpfg's old tropism (view file `tropism direction:`, `initial elasticity:`, `elasticity
  /// increment:`, module `_`): with `cpfg`, `tropism` (made unit length) and `elasticity`
  /// are its direction and initial elasticity, bent by cpfg's old rule after every move.
  double elasticityIncrement = 0.0;
  DVec3 origin{0};                ///< start position
  /// Growth animation (docs/GRAMMAR.md, "Growth over time"): modules whose birth step is
  /// growthStep are drawn partly grown, scaled by growthScale(); modules born later are
  /// not drawn. -1 (the default) draws every module at full size.
  int growthStep = -1;
  double growthFraction = 1.0;    ///< how far the modules of growthStep have grown, 0..1
  double growthStart = 0.0;       ///< their scale at fraction 0 (0 = they grow from nothing)

  /// Scale of modules born in growthStep: start + (1 - start) * fraction, clamped to [0, 1].
  double growthScale() const;
};

/// Position and orientation of the turtle.
struct TurtleFrame {
  DVec3 position{0};
  DVec3 heading{0, 1, 0};   ///< H
  DVec3 left{-1, 0, 0};     ///< L
  DVec3 up{0, 0, 1};        ///< U = H x L
};

/// Everything `[` saves and `]` restores.
struct TurtleState {
  TurtleFrame frame;
  double width = 0.1;         ///< current line width (diameter units, see TurtleSettings::widthScale)
  double elasticity = 0.0;    ///< current tropism susceptibility
  int color = 0;              ///< color index (`'`)
  int order = 0;              ///< branch order: +1 per `[` entered
  int32_t internode = -1;     ///< last internode drawn on this branch (parent of the next), -1 for none
  double scale = 1.0;         ///< cpfg: the turtle scale (`@D`), multiplies lengths and sizes
  DVec3 prevHeading{0, 1, 0}; ///< cpfg: H at the last `F`/`G` (or `@Tf`), for twist-free frames
  DVec3 prevUp{0, 0, 1};      ///< cpfg: U at the last `F`/`G` (or `@Tf`)
  std::array<double, kMaxTropisms> elasticities{};  ///< cpfg: the current elasticity of each tropism
  int contour = 0;            ///< cpfg: the contour id `@#(id)` selected (0: the circle)
  int contourSides = 0;       ///< cpfg: points around a contour, `@!(n)` (0: the view file's)
  int texture = -1;           ///< cpfg: the texture `@Tx(n)` selected, 0-based (-1: none)
  /// cpfg's tex_t (interpret.c, textures.c update_segment_texture): the texture's t along
  /// the branch, accumulated by every move while a texture is selected; 0 at the start.
  double texT = 0.0;
};

/// Interprets module strings of one grammar. Construction builds the symbol -> command
/// table; run() may be called many times (not concurrently on one object).
class Turtle {
 public:
  /// Binds the turtle commands to the symbols of `symbols` by name ("F", "+", "@Ts", ...).
  /// Symbols that are no command are ignored when read. `symbols` must outlive the turtle
  /// (surface names are read from it).
  explicit Turtle(const SymbolTable& symbols, TurtleSettings settings = {});

  /// Draws `modules`. `moduleSteps`, when not empty, holds for each module the derivation
  /// step that created it (copied into Internode::step / Organ::step); when empty, the
  /// string's own birthSteps are used if it has them, else steps are 0.
  /// Cost: O(modules), one pass, no per-module allocation.
  Skeleton run(const ModuleString& modules, std::span<const int32_t> moduleSteps = {});
  /// As above, drawing into `out` (cleared first, capacity kept): repeated runs reuse memory.
  void run(const ModuleString& modules, Skeleton& out, std::span<const int32_t> moduleSteps = {});

  /// What run() would draw, without storing the internodes: their count, total length and
  /// bounds (equal to Skeleton::bounds and totalLength of run()'s skeleton), and the organs.
  /// Memory O(organs + bracket depth) instead of 112 bytes per internode.
  SkeletonSummary summarize(const ModuleString& modules, std::span<const int32_t> moduleSteps = {});

  /// One of cpfg's query modules (`?P ?H ?L ?U`) reached by the turtle: its index in the
  /// string and the turtle's frame there.
  struct QueryHit {
    size_t index;
    TurtleFrame frame;
  };
  /// The frame at every query module of `modules` the turtle reaches (a `%` skips the rest
  /// of its branch), in string order; the same walk as summarize(), nothing drawn.
  std::vector<QueryHit> query(const ModuleString& modules);

  /// The turtle's state after the last module of the last run() or summarize().
  const TurtleState& endState() const { return end_; }

  const TurtleSettings& settings() const { return settings_; }

  /// What each symbol does. Public so tests and tools can ask how a symbol is read.
  enum class Command : uint8_t {
    None, Forward, Move, ForwardNoVertex, MoveNoVertex, TurnLeft, TurnRight, PitchDown, PitchUp,
    RollLeft, RollRight, TurnAround, RollToVertical, Push, Pop, Width, Color, PolygonBegin, Vertex,
    PolygonEnd, Surface, SurfaceNamed, Cut, Tropism, Sphere, WidthUp, ColorUp, ColorDown, Circle, Disc,
    TropismUp, TropismDown, TwistAdjust, TwistForce, MoveTo, SetHeading, ScaleSet, ScaleUp, ScaleDown, OldElasticity,
    Query, SubCall, SubEnd, GcStart, GcPoint, GcEnd, GcTangents, Contour, ContourSides, GcRadiusTangents,
    Texture, Label
  };
  /// The command bound to symbol id `s` (None for ids outside the table).
  Command commandOf(SymbolId s) const { return s < commands_.size() ? commands_[s] : Command::None; }

 private:
  const SymbolTable& symbols_;
  TurtleSettings settings_;
  std::vector<Command> commands_;
  TurtleState end_;
};

/// Convenience: Turtle(symbols, settings).run(modules, moduleSteps).
Skeleton interpret(const ModuleString& modules, const SymbolTable& symbols, const TurtleSettings& settings = {},
                   std::span<const int32_t> moduleSteps = {});

/// ABOP's `$`: rolls about H so that L is horizontal (L = V x H / |V x H|, V = +Y),
/// U = H x L. Leaves the frame unchanged when H is vertical.
void rollToVertical(TurtleFrame& frame);
/// ABOP section 2.2 tropism: rotates the frame about H x T by e * |H x T| radians,
/// bending the heading toward T. No-op when H is parallel to T or e = 0.
void applyTropism(TurtleFrame& frame, const DVec3& tropism, double elasticity);

}  // namespace sprig::lsystem
