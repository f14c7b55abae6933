#pragma once
/// BlobTree trees: a Skeleton becomes a skeletal implicit tree ("BlobTree Trees",
/// Galbraith, MacMurchy, Wyvill), and its leaf organs become a textured leaf Mesh.
///
/// Structure of the BlobTree (built from the TreePlan of tree_plan.h):
///   root  = Σ( ∪_J F_J ,  −w·f_scar … )                    scars dent everything near them
///   F_J   = f_A + PCM(f_B0 … f_Bm−1) + Σ f_stub             PCM junction (Eq. 5-6)
///   F_J   = f_A + Σ f_Bi                                     smooth junction (§3.3)
/// where J runs over the junctions (a basal internode A and the branches at its tip). An
/// internode belongs to at most two groups (as a branch at its base, as the basal at its
/// tip); the union (max) over groups is the controlled blend: internodes that are not
/// neighbours in the skeleton meet in a crease. Each f is a cone primitive (Fig. 7),
/// wrapped in an endpoint-preserving bend (§3.6) when the plan bends it and intersected
/// with a half-space when it is pruned (§3.5). Every cone carries its bark coordinates:
/// u around the axis from the turtle's up vector, v = distance from the root (§3.7).

#include <cstdint>
#include <optional>

#include "blobtree/blobtree.h"
#include "core/mesh.h"
#include "core/shapes.h"
#include "lsystem/skeleton.h"
#include "organisms/tree_options.h"
#include "organisms/tree_plan.h"
#include "textures/ridge.h"

namespace sprig::organisms {

/// A built tree: the BlobTree pool, its root node and the plan it came from.
struct TreeBlob {
  blobtree::BlobTree tree;
  blobtree::NodeId root = 0;
  TreePlan plan;
  /// Node of each plan part (the cone after its bend / cut), for tests and tools.
  std::vector<blobtree::NodeId> partNodes;
  /// The bark classes the cones use (texture id options.bark.texture + index), in order of
  /// first use; one class {pattern.furrows, pattern.maturity} when neither ridgeWidth nor
  /// matureRadius is set. Empty when bark is disabled.
  std::vector<BarkClass> barkClasses;
};

/// The bark class of a cone of mean 0.5-iso radius r (BarkOptions).
BarkClass barkClassFor(const BarkOptions& bark, double r);

/// Builds the implicit tree of `skeleton`. Throws InputError when the skeleton has no
/// internode. Cost: O(internodes) nodes; evaluation cost is the compiled tape's.
TreeBlob buildTreeBlob(const lsystem::Skeleton& skeleton, const TreeOptions& options);

/// The axes of the tree's internode cones as round curves with the cones' 0.5-iso radii
/// (bent cones as arcs of four segments through the same bend): what the renderer draws at
/// a minimum pixel width where the cones are thinner than a pixel. Pruned parts and stubs
/// are left out. O(parts).
CurveSet treeAxes(const TreeBlob& blob);

/// The branch bark ridge arcs of the tree (textures::RidgeArcs): one per branch that leaves
/// a junction beside its leader (the branch closest in direction to the basal internode),
/// on the leader's bark above P, with the leader's direction and the larger of A's and the
/// leader's radius at P, and the branch's start tangent and base radius. Stubs (scars)
/// keep theirs: the ridge outlives the branch. O(parts).
std::vector<textures::RidgeArc> ridgeArcs(const TreeBlob& blob);

/// The raised branch bark ridge over `arc` (options.height > 0; buildTreeBlob sums it into
/// each junction's group, F_J + ridge): cones along the arc's crest
/// (textures::RidgeArcs::crest), their iso radius the band's half-width, each crest point's
/// axis sunk below the surface of `field` (found along the parent's normal there) so that,
/// summed with `field`, the surface over the crest rises by height·r_B·weight (the shading's
/// weight: full at the apex, fading toward the ends and near the branch), capped at the
/// raise the cone gives with its axis on the surface. United, the cones act as one tube
/// along the crest. They are relief primitives (TextureAttr::relief): the bark keeps its
/// texture and the cell sizes their limbs. nullopt when height is 0, the arc degenerate
/// or no crest point raised. Cost: about 80 reference evaluations of `field` per raised
/// crest point (40 to find the bark, 49 samples above it; crest points a quarter branch
/// radius apart).
std::optional<blobtree::NodeId> raisedRidgeArc(blobtree::BlobTree& tree, blobtree::NodeId field,
                                               const textures::RidgeArc& arc, const textures::RidgeArcOptions& options);

/// Leaf geometry for the skeleton's organs: polygons `{ . }` are fan-triangulated, spheres
/// become small UV spheres, named surfaces `~` become an ovate leaf blade in the turtle frame
/// (heading along the midrib, up as the normal). uvs map the blade's unit square; colours
/// are a seeded green per organ; every triangle gets options.leaves.material. Empty when
/// leaves are disabled or there are no organs. Deterministic. A cpfg surface with a texture
/// (Organ::texture) is left out: its images are the view file's (model/tree_kind.cpp).
Mesh buildLeafMesh(const lsystem::Skeleton& skeleton, const TreeOptions& options);

/// Which organs buildOrganMesh builds.
enum class OrganSet {
  Leaves,  ///< polygons and named surfaces
  Fruit,   ///< spheres
};

/// buildLeafMesh restricted to one set of organs (each organ keeps the colour it has in
/// buildLeafMesh), so an export can keep leaves and fruit apart.
Mesh buildOrganMesh(const lsystem::Skeleton& skeleton, const TreeOptions& options, OrganSet set);

}  // namespace sprig::organisms
