#pragma once
/// Simulation as a modeling operator (Cutler et al., "A procedural approach to authoring
/// solid models", §3 and §5): tools that change a layered solid's tetrahedral mesh through
/// the linear-elastic model of solids/fem.h.
///
/// hammer (§3.1): a Gaussian sphere of force breaks the tetrahedra of the affected materials
/// whose stress exceeds their strength; pieces that lose their hold fall away. displace
/// (§5.2): the vertices of some materials move by a prescribed offset and the rest settle
/// into static equilibrium. Both leave the mesh conforming and every tetrahedron positively
/// oriented; both are deterministic at any thread count.

#include <cstdint>
#include <functional>
#include <vector>

#include "solids/fem.h"
#include "solids/material.h"
#include "solids/solid.h"

namespace sprig::solids {

/// What breaks a tetrahedron in hammer.
enum class FractureCriterion {
  MaxPrincipal,  ///< largest principal stress > strength (Rankine; brittle materials in tension)
  VonMises       ///< von Mises stress > strength
};

/// Options of hammer. Lengths in metres, force in newtons (solids/fem.h).
struct HammerOptions {
  DVec3 position{0.0};          ///< centre of the blow (the paper's default (0, 0, 0))
  DVec3 orientation{1, 0, 0};   ///< direction of the force, normalized here (the paper's default)
  double magnitude = 1e5;       ///< total force of the blow, N
  /// Radius of the Gaussian sphere, m (the paper's `size`, default 1): a vertex at distance d
  /// from position takes weight exp(−(d/size)²), none beyond 3·size; the total force
  /// magnitude·orientation is shared among the loaded vertices in proportion, so the blow is
  /// the same at any mesh resolution.
  double size = 1.0;
  /// Material ids that may break (the paper's `affects`); empty = every material.
  std::vector<uint16_t> affects;
  /// Per vertex, 1 = held in place (empty = none given). Vertices of tetrahedra of materials
  /// not in `affects` are always held: other materials are not modified (§3.1). When that
  /// leaves nothing held, the ground is: the vertices within 2% of the model's height (along
  /// `up`) of its lowest point (a plane base, or a cap of a round model).
  std::vector<uint8_t> anchored;
  DVec3 up{0, 1, 0};            ///< Sprig's up axis
  FractureCriterion criterion = FractureCriterion::MaxPrincipal;
  /// Solve-and-break rounds: after tetrahedra break, the same blow is solved again on what
  /// is left, until nothing more breaks or this many solves ran.
  int rounds = 1;
  /// After each round that broke something, mend the visible interface: affected
  /// tetrahedra around an edge that more than two visible triangles share, or around a
  /// vertex whose visible triangles form more than one fan (pieces left touching along an
  /// edge or at a vertex only), are removed until no such edge or vertex is left (or only
  /// unaffected tetrahedra meet there); then pieces left loose fall. false: the broken
  /// surface is left as the fracture made it.
  bool manifold = true;
  FemOptions fem;
};

/// What one blow did.
struct HammerStats {
  size_t loaded = 0;   ///< vertices the blow's force reached (first round)
  size_t broken = 0;   ///< tetrahedra removed for exceeding their strength
  size_t fallen = 0;   ///< tetrahedra removed because their piece lost its hold
  size_t mended = 0;   ///< tetrahedra removed where pieces touched along an edge or at a vertex only
  int solves = 0;
  std::vector<FemStats> fem;  ///< one per solve
};

/// Where the visible interface (solids/solid.h) is not a manifold: edges (keys
/// (min << 32) | max of their vertex ids) that more than two visible triangles share, and
/// vertices whose visible triangles form more than one fan (groups joined through the
/// edges at the vertex), both ascending. A closed manifold surface has neither. Cost
/// O(T log T) in the visible triangles.
struct SurfaceDefects {
  std::vector<uint64_t> edges;
  std::vector<uint32_t> vertices;
};
SurfaceDefects surfaceDefects(const TetMesh& mesh);

/// The vertices hammer holds for these options (1 = held): options.anchored and the
/// vertices of unaffected tetrahedra, or else the ground (see HammerOptions::anchored).
std::vector<uint8_t> hammerAnchors(const TetMesh& mesh, const HammerOptions& options);

/// The blow's force at each vertex, N: the Gaussian weights of the vertices used by some
/// tetrahedron and not held, scaled so they sum to magnitude·orientation. All zero when no
/// such vertex lies within 3·size. Throws std::invalid_argument for a non-finite position,
/// orientation or magnitude, a zero orientation, or size <= 0.
std::vector<DVec3> hammerForces(const TetMesh& mesh, const HammerOptions& options, const std::vector<uint8_t>& anchored);

/// Strikes mesh (§3.1): solves the linear-elastic model under the blow (held vertices fixed),
/// removes the tetrahedra of affected materials whose stress exceeds their material's
/// strength, then every face-connected piece whose held vertices do not hold its rigid
/// motions (solids/fem.h, componentsHeld): it falls away. Pieces already loose before the
/// blow fall first. Then, with options.manifold, the surface is mended (see
/// HammerOptions::manifold). Repeats for options.rounds. Tetrahedra keep their order and vertices
/// their ids and positions (vertices no tetrahedron uses any more stay in the list), so the
/// tetrahedra of unaffected materials are the same bytes before and after. Throws
/// std::invalid_argument for bad options (see hammerForces; an `affects` id with no
/// material) and what solveElastic throws. Cost: one FEM solve per round.
HammerStats hammer(TetMesh& mesh, const std::vector<Material>& materials, const HammerOptions& options);

/// Drops the vertices no tetrahedron uses (hammer leaves them so vertex ids stay stable
/// between operations), keeping the others in order and renumbering the tetrahedra.
/// Returns how many went. Cost O(vertices + tets).
size_t compactVertices(TetMesh& mesh);

/// Options of polish (§5.1, the paper's POLISH): CSG subtraction of a sphere from the
/// affected materials, then the material nearby blended toward a shiny one.
struct PolishOptions {
  DVec3 position{0.0};     ///< centre of the sphere, m (the paper's default)
  double size = 1.0;       ///< radius of the sphere, m (the paper's default)
  /// Material ids subtracted inside the sphere (the paper: FIRED_CLAY); required.
  std::vector<uint16_t> affects;
  /// The material blended in (the paper: SHINY_BRONZE); -1 = no blending.
  int shiny = -1;
  /// Material ids that blend toward `shiny` (empty = every material not in affects).
  std::vector<uint16_t> shines;
  DVec3 up{0, 1, 0};       ///< for the fallback support of what is left (see polish)
};

/// What polish did.
struct PolishStats {
  size_t splitEdges = 0;   ///< edges of affected tetrahedra split on the sphere
  size_t removed = 0;      ///< tetrahedra (pieces) removed inside the sphere
  size_t fallen = 0;       ///< tetrahedra of affected materials left loose and removed
  size_t shined = 0;       ///< tetrahedra whose material became `shiny`
  size_t tinted = 0;       ///< vertices whose tint moved toward `shiny`'s colour
};

/// Polishes mesh (§5.1). 1. Subtraction "by subdivision and tetrahedron removal": the
/// tetrahedra of affected materials are cut at the sphere (solids::cutByField on
/// |x − position| − size; edges that also belong to an unaffected tetrahedron are never
/// split, so those are untouched), then every affected piece with a vertex strictly inside
/// the sphere (by more than 1e-9·size) is removed: no tetrahedron of an affected material
/// is left inside the sphere (a piece held to an unaffected tetrahedron by an edge that
/// could not split goes whole, so slightly more than the sphere may go there). Affected
/// pieces no longer held (as hammer decides: the vertices of unaffected tetrahedra hold, or
/// else the ground) fall away. 2. Blending: each tetrahedron of a `shines` material whose
/// centroid lies within size of position has weight w = 1 − d/size; where w ≥ 0.5 its
/// material becomes `shiny` (so it renders with shiny's roughness and specular), and each
/// of its vertices' tints moves toward shiny's colour by w (the largest w of its tetrahedra).
/// Deterministic (sequential blending; the cut is the same bytes at any thread count).
/// Throws std::invalid_argument for empty affects, ids with no material, a non-finite
/// position or size <= 0.
PolishStats polish(TetMesh& mesh, const std::vector<Material>& materials, const PolishOptions& options);

/// CSG subtraction of the region field < 0 from the tetrahedra of the affected materials
/// (polish's first half, and erode's): cutByField on the affected tetrahedra, removal of
/// every affected piece with a vertex where field < −eps, then of the affected tetrahedra
/// around visible edges that more than two visible faces share (pieces left touching along
/// an edge only: the visible interface stays a manifold where the affected material meets
/// itself), then of affected pieces left loose (held: the vertices of unaffected tetrahedra, or else the ground along up).
/// Returns the tetrahedra removed inside; *split and *fallen (when given) get the edges
/// split and the loose tetrahedra removed.
size_t subtractRegion(TetMesh& mesh, size_t materialCount, const std::vector<uint16_t>& affects,
                      const std::function<double(const DVec3&)>& field, double eps, const DVec3& up, size_t* split = nullptr,
                      size_t* fallen = nullptr);

/// Blends vertex v's tint toward colour c by weight w in [0, 1] (the face colour there moves
/// from F to mix(F, c, w), whatever the material under it): mesh.tints is created (all
/// zero) when empty.
void blendTint(TetMesh& mesh, uint32_t v, const Vec3& c, double w);

/// Moves vertex v's face colour back toward its material's own colour by w (the tint's
/// amount is multiplied by 1 − w). No-op without tints.
void clearTint(TetMesh& mesh, uint32_t v, double w);

/// Options of displace.
struct DisplaceOptions {
  /// Material ids whose vertices move by `offset` (the paper's growing tree); required.
  std::vector<uint16_t> moving;
  DVec3 offset{0, 0.1, 0};      ///< displacement of the moving vertices, m
  /// Per vertex, 1 = held at zero displacement (empty = the ground: vertices within 2% of
  /// the model's height along `up` of its lowest point).
  /// A vertex both moving and held moves.
  std::vector<uint8_t> anchored;
  DVec3 up{0, 1, 0};            ///< Sprig's up axis
  /// The offset is applied in at least this many equal steps, each solved on the mesh the
  /// previous one left (large motions then follow the geometry, and invert less). A step
  /// that would crush a tetrahedron is halved (see minStepVolumeRatio).
  int steps = 1;
  /// Jacobian stiffening: a tetrahedron whose volume has fallen to a fraction r of its volume
  /// before the operation solves with its modulus times min(maxStiffening, r^-stiffening),
  /// so crushed soft material pushes what is beyond it rather than folding. 0 = off.
  double stiffening = 2;
  double maxStiffening = 1e3;  ///< cap of the stiffening factor (>= 1)
  /// Also stiffened: a tetrahedron whose mean ratio q = 6√2·V / l_rms³ (1 regular, 0 flat)
  /// is below this, by (stiffenBelow / q)^stiffening (so dirt crushed by an earlier
  /// operation stays stiff). In [0, 1]; 0 = off.
  double stiffenBelow = 0.3;
  /// An increment that leaves a tetrahedron with no more than this fraction of the volume it
  /// had before the increment is undone and retried at half the size, at most `halvings`
  /// times in all (a halved size is kept: down to 1/1024 of a step by default); then
  /// displace throws. In (0, 1).
  double minStepVolumeRatio = 0.5;
  /// How many times an increment may be halved before displace gives up (0: never; with
  /// stiffening 0 that is the plain sequence of `steps` linear solves).
  int halvings = 10;
  /// The solver; its tolerance is 1e-6 here (not 1e-8): displacements to a millionth of the
  /// right-hand side are far below a cell, and each solve takes about half the iterations.
  FemOptions fem{Preconditioner::Jacobi, 1e-6, 0, true};
};

/// What displace did.
struct DisplaceStats {
  size_t moved = 0;       ///< vertices of the moving materials
  size_t anchored = 0;    ///< vertices held at zero
  double minVolumeRatio = 0;  ///< smallest volume after / volume before over all tetrahedra
  int increments = 0;         ///< increments applied (steps, more when some were halved)
  int retries = 0;            ///< increments undone and halved
  std::vector<FemStats> fem;  ///< one per solve (increments + retries)
};

/// Moves the vertices of the `moving` materials by offset and every other vertex to the
/// static equilibrium of the linear-elastic model (§5.2): stiff materials keep their shape,
/// soft ones deform. Throws std::invalid_argument for an empty `moving`, an id with no
/// material, a non-finite offset, steps < 1 or a stiffening option out of range,
/// std::runtime_error when even a step halved `halvings` times would crush a tetrahedron (the mesh is then
/// left as it was), and what solveElastic throws (a piece
/// neither moving nor held makes the system singular).
DisplaceStats displace(TetMesh& mesh, const std::vector<Material>& materials, const DisplaceOptions& options);

}  // namespace sprig::solids
