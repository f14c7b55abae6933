#pragma once
/// Proportions of a built shell, measured on its implicit surface: the lengths a
/// conchologist quotes (shell without the canal, body whorl, siphonal canal, aperture,
/// spines), so a model can be held against the real animal's (docs/SHELLS.md, "Measured").
///
/// Lengths are in shell units along the shell axis (y, growing away from the apex), measured
/// on the surface field (0.5 iso) where the surface decides them: the apex's top, the canal's
/// tip and the aperture's hollow are found by marching the field; the aperture's base and
/// the suture (where the lip's whorl meets the previous one) are the spiral's closed forms.

#include "blobtree/compiled.h"
#include "organisms/shell.h"

namespace sprig::organisms {

struct ShellMeasures {
  double apexY = 0.0;          ///< top of the first whorl (surface, marched along +y)
  double sutureY = 0.0;        ///< top of the body whorl at the lip: H(θe) − D(θe)·cos β (tangent whorls)
  double apertureBaseY = 0.0;  ///< anterior end of the lip's generating curve: H(θe) + D(θe)
  double canalTipY = 0.0;      ///< farthest surface point of the canal (surface; = apertureBaseY without a canal)
  double restLength = 0.0;       ///< apertureBaseY − apexY: the shell without its canal
  double bodyWhorlLength = 0.0;  ///< apertureBaseY − sutureY
  double canalLength = 0.0;      ///< canalTipY − apertureBaseY
  double totalLength = 0.0;      ///< canalTipY − apexY
  double apertureHeight = 0.0;   ///< hollow's extent along the axis in the lip's plane, 10° inside the lip (surface)
  double apertureWidth = 0.0;    ///< hollow's extent across (away from the axis) in the same plane (surface)
  int varixSpines = 0, axialSpines = 0;
  double longestVarixSpine = 0.0;  ///< shell units (table size · spine_length · D(θ))
  double longestAxialSpine = 0.0;  ///< shell units
};

/// Measures `model` whose shell-space surface is `shellSpace` (compile(model.tree,
/// model.shellRoot)). `params` are the ones it was built from.
ShellMeasures measureShell(const ShellParams& params, const ShellModel& model, const blobtree::CompiledBlob& shellSpace);

}  // namespace sprig::organisms
