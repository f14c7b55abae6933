#pragma once
/// Wind in a tree's glTF export (`sprig mesh TREE -o OUT.glb [--wind SPEED[,DIR]]`,
/// docs/MESHES.md "Wind").
///
/// Two things, both from the renders' wind model (organisms/wind.h WindRig, which
/// swayInWind evaluates):
/// - `_WIND`, a VEC4 float per vertex an engine's shader can sway the tree with: hierarchy
///   level, phase, weight along the branch, frequency (windAttribute);
/// - the sway itself as morph targets and a looping animation "wind" (windMorph): the
///   displacement of each vertex under swayInWind, linearized in the turning angles. Every
///   angle is a constant plus sinusoids, each rounded to whole cycles per kWindLoopSeconds,
///   so the displacement is a sum over targets of (constant or sin ωt or cos ωt)·target.
///
/// Each vertex rides on one piece of the skeleton (bindToSkeleton): wood on the internode
/// whose cone surface is nearest (axis distance minus the cone's radius there), leaves and
/// fruit on the nearest organ. The still skeleton is the one the parts were built from;
/// offset is what placing the parts added to its positions.

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/mesh_io.h"
#include "lsystem/skeleton.h"
#include "organisms/wind.h"

namespace sprig {

/// The wind animation's period: every frequency is rounded to whole cycles per loop.
inline constexpr double kWindLoopSeconds = 20.0;
/// Keyframes per second of the wind animation (LINEAR between them).
inline constexpr int kWindFps = 30;
/// Branches up to this order sway in the morph targets; thinner ones ride rigidly on their
/// branch there (each order adds two pairs of targets: its sway and its crosswise sway, at
/// their own frequencies), their own sway left to a shader reading `_WIND`.
inline constexpr int kWindMorphMaxOrder = 2;

/// The piece of the skeleton a vertex rides on.
struct WindBinding {
  int32_t internode = -1;  ///< the internode it turns with (an organ's own internode), -1 for none
  int32_t organ = -1;      ///< the organ it flutters with, -1 for wood
  double along = 0;        ///< where on it, 0 (the base or attachment) to 1 (the tip or farthest point)
};

/// Each point's binding: to the nearest internode's cone (organs false) or the nearest
/// organ (organs true; internodes when the skeleton has no organ). Exact nearest through a
/// uniform grid of the pieces' boxes (ties: the lower index). Deterministic, parallel. O(P + S).
std::vector<WindBinding> bindToSkeleton(const std::vector<DVec3>& points, const lsystem::Skeleton& skeleton, bool organs);

/// `_WIND` of a vertex bound by b: x level (the internode's branch order; organs one
/// more), y phase (radians: the branch's sway phase, the trunk's first gust phase, the
/// organ's flutter phase), z weight (the share of its branch's turn accumulated where it
/// sits, 0 at the branch base to 1 at its tip; organs: from the attachment, 0, to the
/// farthest point, 1), w frequency in Hz of that motion.
glm::vec4 windAttribute(const organisms::WindRig& rig, const lsystem::Skeleton& skeleton, const WindBinding& b);

/// The morph targets and the animation "wind" of points (skeleton space) bound by bindings,
/// the sways of branches up to kWindMorphMaxOrder:
/// target `static` (weight 1), `gust` (weight: the gust factor), and per frequency of m
/// cycles per loop `sway_M_sin`, `sway_M_cos` (weights sin, cos of 2π m t / loop). Targets
/// that are zero at every point are left out. Keyframes at kWindFps over one loop, the last
/// repeating the first. rig.options.loopSeconds must be > 0.
PartMorph windMorph(const organisms::WindRig& rig, const lsystem::Skeleton& skeleton, const std::vector<DVec3>& points,
                    const std::vector<WindBinding>& bindings);

/// Adds `_WIND` to every part of every level, and when wind.speed > 0 the morph targets and
/// animation to LOD0's parts (levels[0]). Wood parts ("wood", "textured_wood_*") bind to
/// internodes, the others to organs. wind.loopSeconds is set to kWindLoopSeconds.
void addWind(std::vector<LodLevel>& levels, const lsystem::Skeleton& skeleton, organisms::WindOptions wind,
             const Vec3& offset);

class SpeciesModel;
struct Stage;

/// What `sprig mesh` (and the Python module's export) does for a .glb: when model's kind has
/// wind (trees: KindModel::windSource), addWind with the stage's still skeleton and the
/// species' wind, its speed and direction replaced by wind (m/s, degrees) when given.
/// Returns the wind's options, or nullopt for a kind without wind (levels unchanged).
std::optional<organisms::WindOptions> addModelWind(SpeciesModel& model, const Stage& stage, std::vector<LodLevel>& levels,
                                                   const Vec3& offset,
                                                   const std::optional<std::pair<double, double>>& wind = std::nullopt);

}  // namespace sprig
