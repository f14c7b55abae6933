#pragma once
/// Options of the BlobTree tree builder ("BlobTree Trees", Galbraith, MacMurchy, Wyvill),
/// with their documented defaults. The species file's `tree:` section fills this struct
/// (app/species_tree.h); every field here has a key of the same name in snake_case.

#include <cstdint>
#include <optional>
#include <vector>

#include "core/types.h"
#include "textures/bark_look.h"

namespace sprig::organisms {

/// How the branches of a junction combine with each other (§3.3 vs §3.4).
enum class JunctionModel {
  Smooth,  ///< summation blend of basal and branches, δA of Eq. 4 (§3.2-3.3)
  Pcm,     ///< branches combined by Precise Contact Modeling, then summed with the basal (Eq. 5-8)
};

/// How terminal internodes end.
enum class TipStyle {
  Hemisphere,  ///< the cone's own cap of the tip radius, as in the paper
  Taper,       ///< the tip radius shrinks to tipTaper·r and the cap ends at the end point
};

/// Which lateral branches a rule (pruning, scars) applies to. A lateral branch is named by
/// its first internode: one whose order is higher than its parent's.
struct BranchSelector {
  std::vector<int> orders;       ///< branch orders it applies to; empty = every order >= 1
  double belowHeight = 1e300;    ///< only branches whose base lies below this height (world Y)
  double aboveHeight = -1e300;   ///< only branches whose base lies above this height
  double probability = 0.0;      ///< chance each candidate is chosen (seeded per internode)
  std::vector<int> internodes;   ///< skeleton indices always chosen (figure files, tests)
};

/// CSG pruning (§3.5, Fig. 14): the branch is sawn off, leaving a flat face.
struct PruneOptions {
  bool fromGrammar = true;       ///< honour internodes the grammar marked `cut`
  BranchSelector select;         ///< branches the species file prunes
  double cutFraction = 0.5;      ///< where along the branch's first internode the saw cuts (0..1)
  double minCutDistance = 2.0;   ///< the cut lies at least this many base radii from the junction
};

/// Negative-field scars where a branch was lost (§3.5, Fig. 15).
/// How a scar's stub sits on its parent (§3.5, Fig. 15).
enum class ScarStyle {
  /// The stub runs from the branching point straight out to the parent's bark (radially)
  /// and the negative field is centred where it meets the bark: beyond the bark the two
  /// fields nearly cancel, leaving a round, shallow scar flush with the bark.
  Flush,
  /// The stub of stubLength base radii along the branch, dented at its end: a raised knob.
  Knob,
};

struct ScarOptions {
  BranchSelector select;         ///< branches replaced by a scar
  ScarStyle style = ScarStyle::Flush;
  double stubLength = 1.5;       ///< Knob: stub length in units of the branch's base radius
  double stubRadius = 0.8;       ///< stub radius in units of the branch's base radius (at most 0.9 of the parent's)
  double negativeRadius = 0.9;   ///< radius of the negative field in units of the branch's base radius
  double negativeWeight = 1.0;   ///< weight of the negative field (field subtracted = w·f)
};

/// Endpoint-preserving bends per internode (§3.6, Fig. 16).
struct BendOptions {
  double angleDeg = 0.0;         ///< bend angle (tangent turn at the start) for order-1 laterals; 0 = off
  double orderScale = 1.0;       ///< factor per extra order: angle·orderScale^(order-1)
  double randomness = 0.0;       ///< relative random spread of the angle, uniform in ±randomness
  double minBranchAngleDeg = 5;  ///< internodes within this angle of their basal axis are not bent
  bool trunk = false;            ///< also bend order-0 internodes (in a seeded random plane)
};

/// Bark texture mapping (§3.7) and the bark pattern per girth.
///
/// Every cone is textured in its own coordinates (u around its axis, v along the skeleton
/// from the root), so furrows run along each branch. A cone's bark class (furrow count and
/// age) follows its mean 0.5-iso radius r: furrows = max(3, round(2π r / ridgeWidth)) when
/// ridgeWidth > 0 (ridges keep their width as a branch thickens), and maturity =
/// min(1, r / matureRadius) in steps of 1/8 when matureRadius > 0 (young twigs smooth with
/// lenticels, the trunk furrowed). Each class is one texture (textureIds texture,
/// texture + 1, …, in TreeBlob::barkClasses order).
/// The look (pattern, colours, ridge and arcs) is textures::BarkLook, read by the same keys
/// as a blob species' bark texture; the rest maps it onto the tree's cones.
struct BarkOptions : textures::BarkLook {
  bool enabled = true;
  int texture = 0;               ///< texture id of the first bark class, 0..16383 (0: a fresh scene's first texture)
  double uScale = 1.0;           ///< texture u per full turn around the branch
  double vScale = 1.0;           ///< texture v per world unit along the axis (continuous from the root)
  double ridgeWidth = 0.0;       ///< world width of a bark ridge (> 0); 0: pattern.furrows on every cone
  double matureRadius = 0.0;     ///< branch radius with fully furrowed bark (> 0); 0: pattern.maturity everywhere
  // pattern.furrows and pattern.maturity are replaced per class as above; colours left
  // unset take the wood color (furrows 0.3 of it).
};

/// One bark class: the furrow count and age shared by the cones of similar girth.
struct BarkClass {
  int furrows = 9;
  double maturity = 1.0;
  bool operator==(const BarkClass&) const = default;
};

/// Leaf geometry from the grammar's organs.
struct LeafOptions {
  bool enabled = true;
  double scale = 1.0;            ///< size multiplier for `~` surfaces
  uint32_t material = 2;         ///< material id of leaf triangles
};

/// Everything the tree builder reads.
struct TreeOptions {
  JunctionModel junctions = JunctionModel::Smooth;
  double deltaA = 1.75;          ///< Eq. 4 factor: δA = deltaA·r_B at one-child joints
  double deltaAMulti = 2.75;     ///< Eq. 8 factor: δA = deltaAMulti·max(r_i) − r_A (PCM, several branches)
  bool basalOffset = true;       ///< apply δA at all (off re-creates the bulge of Fig. 9 left)
  bool branchOffset = true;      ///< PCM: displace branches by δB_i = r_A − r_i (Eq. 7; off = Fig. 12 left)
  /// PCM propagation width w in field units (blobtree::PcmParams::width). With the Wyvill
  /// kernel, w = 0.25 reaches from the other branch's surface out to 1.3x its radius.
  double pcmWidth = 0.25;
  /// PCM bulge scale: a₀ = pcmBulge·w/4 (blobtree::PcmParams::bulgeScale). The default
  /// a₀ = 0.125 raises a visible branch bark ridge between the branches (a crest along
  /// their seam) while the basal internode below P keeps its radius (docs/TREES.md).
  double pcmBulge = 2.0;
  bool softKernel = false;       ///< use the soft-object kernel instead of Wyvill's (1−s)³
  bool controlledBlend = true;   ///< non-neighbour internodes meet as a union, not a blend
  TipStyle tips = TipStyle::Taper;
  double tipTaper = 0.35;        ///< Taper: tip radius as a fraction of the terminal internode's base radius
  double radiusScale = 1.0;      ///< multiplies every skeleton radius
  double minRadius = 0.0;        ///< radii below this are raised to it (world units)
  uint64_t seed = 1;             ///< seed of every random choice (pruning, scars, bends)
  PruneOptions prune;
  ScarOptions scars;
  BendOptions bends;
  BarkOptions bark;
  LeafOptions leaves;
};

}  // namespace sprig::organisms
