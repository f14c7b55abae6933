#pragma once
/// cpfg's view file (`NAME.v` beside a `NAME.l` grammar; CPFG reference manual, section
/// 8.1): the turtle's settings it holds (angle, line width, color, scale, tropisms) read
/// into TurtleSettings. Keys that only change how cpfg's window shows the model (viewpoint,
/// lights, render mode, ...) are warnings; keys that would change the geometry and that
/// Sprig does not implement are errors naming them (docs/GRAMMAR.md, "The view file").

#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "lsystem/cpfg_background.h"
#include "lsystem/cpfg_contour.h"
#include "lsystem/cpfg_curve.h"
#include "lsystem/cpfg_function.h"
#include "lsystem/cpfg_surface.h"
#include "lsystem/cpfg_texture.h"
#include "lsystem/turtle.h"

namespace sprig::lsystem {

/// How cpfg draws `F` (`line style:`, or the style word of `initial line width:`).
enum class CpfgLineStyle {
  Pixel,     ///< widths are screen pixels (cpfg's default)
  Polygon,   ///< widths are world units
  Cylinder,  ///< widths are world units
};

/// What a view file sets. Unset fields keep cpfg's defaults (kCpfgDefaults...).
struct ViewFile {
  std::string file;                     ///< the path it was read from
  std::optional<double> angleDeg;       ///< `angle increment: x` or `angle factor: n` (360/n)
  std::optional<double> lineWidth;      ///< `initial line width: x [style]`
  std::optional<CpfgLineStyle> lineStyle;  ///< `line style:` or the style word of `initial line width:`
  std::optional<double> widthIncrement;    ///< `line width increment: x`
  std::optional<int> initialColor;      ///< `initial color: i [i2]` (the front index)
  std::optional<int> colorIncrement;    ///< `color increment: i [i2]`
  std::optional<double> initialScale;   ///< `initial scale: x`
  std::optional<double> scaleMultiplier;  ///< `scale multiplier: x`
  std::vector<CpfgTropism> tropisms;    ///< `tropism: T: x y z ...`, in file order
  std::optional<DVec3> oldTropismDirection;    ///< `tropism direction: x,y,z` (cpfg's old tropism)
  std::optional<double> oldElasticity;         ///< `initial elasticity: e`
  std::optional<double> oldElasticityIncrement;  ///< `elasticity increment: d` (the step of `_`)
  /// `function: NAME.func [samples]`: the function files, in file order (`func(1, x)` is
  /// the first), read when the view file is.
  std::vector<CpfgFunction> functions;
  /// After a `function set: NAME.fset` line (not followed by `function:` lines): its
  /// functions' names without their suffix, which cpfg's preprocessor defines as 1, 2, ...
  std::vector<std::string> functionNames;
  /// `surface: X NAME.s [size [s t]] [texture]`: the surface files, read and tessellated when
  /// the view file is, which `~X` draws.
  std::vector<CpfgSurfaceEntry> surfaces;
  /// `texture: F: NAME.png [options]`: the textures, in file order (`@Tx(1)` selects the
  /// first), their images read when the view file is.
  std::vector<CpfgTexture> textures;
  /// `curve: NAME [samples]`: the curve files, in file order (`curveX(1, t)` reads the first).
  std::vector<CpfgCurve> curves;
  /// `contour: id NAME.con`: the contours `@#(id)` selects for generalized cylinders.
  std::vector<CpfgContourEntry> contours;
  std::optional<int> contourSides;  ///< `contour sides: n` (default CpfgContour::kDefaultSides)
  /// A `box:` line (the view volume): cpfg -g then does not interpret the final string to
  /// size its window, so that string's query modules keep the values they had before the
  /// last step (DeriveOptions::queriesAfterLastStep).
  bool box = false;
  /// `environment display: before`: cpfg exchanges `?E` modules with its environmental
  /// program after every step (and for the axiom) instead of before it
  /// (DeriveOptions::environmentAfterEachStep).
  bool environmentBefore = false;
  /// `interpretation past %: off`: cpfg's turtle then skips the rest of a branch at a
  /// `%` awaiting its cut; by default it interprets (draws, queries) past it
  /// (TurtleSettings::interpretPastCut).
  bool interpretPastCut = true;
  /// `twist of cylinders: on`: a generalized cylinder's ring at a control point is in the
  /// turtle's own frame there, twisting smoothly from the previous point's; off (cpfg's
  /// default) carries the previous ring's frame along without twist (TurtleSettings::gcTwist).
  bool twistCylinders = false;
  /// The ids of the `tsurface:` lines (cpfg's triangulated surfaces, not read): a `~X` of
  /// one is an error in the grammar (GrammarOverrides::cpfgUndrawnSurfaceIds).
  std::string tsurfaceIds;
  /// `font:` (an X11 font name, `-foundry-family-weight-slant-...-size-...`), the font of the
  /// `@L` labels; empty: cpfg's default, `-*-courier-bold-r-*-*-12-*-*-*-*-*-*-*`.
  std::string font;
  /// `background scene: FILE[, FILE...]`: the scene read from its files (lsystem/cpfg_background.h),
  /// drawn with the plant when the object has a colour map or materials file (cpfg draws
  /// none without one).
  std::optional<CpfgBackground> background;
  /// `tapered lines: on|off` (default on): whether cpfg tapers a background cone.
  bool taperedLines = true;
  /// The first error of what only drawing needs (a background scene file's, or a background
  /// cylinder or cone under a line style other than cylinder): thrown when the plant is
  /// drawn, not when it is only derived (the string does not depend on it, as `cpfg -g` shows).
  std::optional<Diagnostic> unsupportedDrawing;
  /// Warnings about keys read but not used (viewer settings), each at its line.
  std::vector<Diagnostic> warnings;
};

/// cpfg's defaults when the view file is absent or silent (interpret.c, InitializeParameters).
inline constexpr double kCpfgDefaultAngleDeg = 45.0;
inline constexpr double kCpfgDefaultLineWidth = 1.0;
inline constexpr int kCpfgDefaultColor = 128;

/// Parses view file text (named fileName in diagnostics). Throws InputError with every
/// error (an unknown key with "did you mean", a malformed value, a key that changes the
/// geometry and that Sprig does not implement).
ViewFile parseViewFile(const std::string& text, const std::string& fileName);

/// Reads and parses path; an unreadable file is an InputError at path.
ViewFile loadViewFile(const std::string& path);

/// The turtle settings of a cpfg grammar with view (or without one: nullptr), on top of
/// base: cpfg's command meanings, the angle, width, color, scale and tropisms, each from the
/// view file or cpfg's default. Pixel widths (cpfg's default style) are not world units, so
/// they keep base's widthScale and width cap; world-unit styles set widthScale 1 and no cap.
TurtleSettings cpfgTurtleSettings(const ViewFile* view, TurtleSettings base);

/// The names and values of cpfg's defaults that a grammar read without (or with a silent)
/// view file used, for a note: "angle increment 45, initial line width 1 (pixels), ...".
std::string cpfgDefaultsUsed(const ViewFile* view);

}  // namespace sprig::lsystem
