#pragma once
/// Layered solid models (Cutler, Dorsey, McMillan, Müller, Jagnow, "A procedural approach to
/// authoring solid models", §2 and §4) and their tetrahedral meshes.
///
/// A Solid is a list of volumes in precedence order (§2.3): the first volume claims its
/// space, the next fills what is left. A volume is a signed distance field and layers:
/// interior layers stack inward from the zero set (the last may `fill` the interior),
/// exterior layers outward; each is a range of distance with a material (§2.1). Ranges
/// between adjacent layers are kept as boundaries b_0 < b_1 < ...: region r lies between
/// b_{r-1} and b_r and has one material id, kUnclaimed (no layer: later volumes may fill
/// it) or kNothing (a `material: nothing` layer: air that claims its space).
///
/// meshSolid (§4.3) samples every volume's field on the grid's nodes, splits each cubic
/// cell into five tetrahedra with alternating orientation, then cuts the tetrahedra at
/// every layer boundary (the zero set of d_v - b_k, linear in each tetrahedron) by
/// splitting crossing edges, subdivides tetrahedra of procedural layers where the procedure's
/// choice changes, and gives each tetrahedron the material of the first volume that claims it.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "solids/distance_field.h"
#include "solids/material.h"

namespace sprig::solids {

/// Material ids of a region besides concrete (>= 0) and procedural (<= kProcedural0) ones.
constexpr int kUnclaimed = -1;
constexpr int kNothing = -2;
/// Procedural material p of the MaterialTable has id kProcedural0 - p.
constexpr int kProcedural0 = -3;

/// One layered volume: its field and its regions.
struct Volume {
  FieldPtr field;
  std::vector<double> boundaries;  ///< ascending distances between regions
  std::vector<int> regions;        ///< boundaries.size() + 1 material ids, from inside out

  /// The material id of the region holding distance d (at a boundary: the outer region).
  int regionAt(double d) const;
  /// Lowest and highest distance claimed (kUnclaimed elsewhere); lo may be -inf.
  std::pair<double, double> claimed() const;
};

/// The outermost interface of volumes in precedence order (§2.3, Fig. 2c: the paper's
/// `from_volume_surface`): a field negative in the space their materials fill and zero on
/// its boundary. Each volume's material is a union of ranges (a, b] of its distance; a
/// `nothing` range of an earlier volume is carved out of later ones, as meshSolid does.
/// The value is a combination by min and max, a distance only near the zero set: wrap it
/// in a front (solids/front_field.h) to measure distance from the interface again.
FieldPtr volumeSurfaceField(std::vector<Volume> volumes);

/// For a volume wrapped around earlier ones (from_volume_surface): when the region just
/// inside its zero set is unclaimed, the material just outside reaches `margin` inward, so
/// the wrapper meets the earlier volumes without a gap (its zero set is their boundary only
/// to within the front's discretization). Earlier volumes keep precedence: the margin only
/// fills what they leave. A margin deeper than the unclaimed region is cut to half of it.
void closeInward(Volume& v, double margin);

/// A layer as written: a thickness (or fill) and a material id.
struct Layer {
  bool interior = true;
  bool fill = false;        ///< interior only: to the end of the inside
  double thickness = 1.0;   ///< world units, > 0
  int material = kNothing;
};

/// The regions of a volume with these layers (interior layers inward from 0 in order,
/// exterior outward). Adjacent regions of one material merge. Throws std::invalid_argument
/// for a fill layer that is not the last interior layer or is exterior.
Volume makeVolume(FieldPtr field, const std::vector<Layer>& layers);

/// The lattice the fields are sampled on: node (i, j, k) is at origin + cell·(i, j, k).
struct Grid {
  DVec3 origin{0.0};
  double cell = 0.1;  ///< world units
  std::array<int, 3> cells{1, 1, 1};
  size_t nodeCount() const { return size_t(cells[0] + 1) * size_t(cells[1] + 1) * size_t(cells[2] + 1); }
};

/// A solid: volumes in precedence order and their materials.
struct Solid {
  std::vector<Volume> volumes;
  MaterialTable materials;
};

/// A tetrahedral mesh with a concrete material per tetrahedron. Every tetrahedron is
/// positively oriented (det(v1-v0, v2-v0, v3-v0) > 0); faces between two tetrahedra match.
struct TetMesh {
  std::vector<DVec3> positions;
  std::vector<std::array<uint32_t, 4>> tets;
  std::vector<uint16_t> materials;  ///< per tetrahedron, ids into the solid's MaterialTable
  /// Optional surface tint per vertex (the weathering tools' dirt and lichen, the polish's
  /// shine; solids/particles.h): linear RGB and an amount a in [0, 1]; a face shows
  /// mix(material colour, rgb, a) at the vertex. Empty = no tint anywhere; otherwise one per
  /// position. Splits interpolate it linearly.
  std::vector<Vec4> tints;

  /// Signed volume of tetrahedron t (world units³).
  double volume(size_t t) const;
};

/// Counts of one meshing.
struct MeshStats {
  size_t cubes = 0;        ///< octree leaves kept (some volume may claim them)
  size_t coarseCubes = 0;  ///< of them, leaves of more than one cell (coarsening)
  size_t transitionCubes = 0;  ///< of them, leaves meshed as a fan from their centre (next to finer leaves)
  size_t cellTets = 0;     ///< tetrahedral cells before splitting (5 per plain cube)
  size_t splits = 0;       ///< edges split at interface crossings
  size_t tets = 0;         ///< tetrahedra with a material in the result
  size_t sealedSpecks = 0; ///< sealed pockets of unclaimed space under a cell's volume, filled (step 6b)
  double fieldSeconds = 0; ///< sampling the distance fields
  double meshSeconds = 0;  ///< cells, splits, materials
};

/// Options of meshSolid.
struct MeshOptions {
  /// Node values this close to a boundary (as a fraction of the cell) snap onto it, so no
  /// split lands nearer than this to a grid node (no needle tetrahedra of near-zero volume).
  double snapFraction = 0.05;
  /// Rounds of splitting tetrahedra of procedural layers where the chosen material changes
  /// along an edge (0 = each tetrahedron takes the choice at its centroid).
  int proceduralRounds = 2;
  /// Octree levels of coarsening (§4.4, Fig. 4; solids/octree.h): cubes of up to 2^levels
  /// cells where no interface crosses, neighbours at most one level apart (0 = uniform).
  /// Volumes whose region indices need more than 63 bits together are not coarsened.
  int coarsenLevels = 0;
  /// Fraction of the cell by which coarsening may move an interface: blocks an interface
  /// crosses merge where every field is affine to within it (0 = only blocks no interface
  /// crosses, the interfaces exactly the uniform grid's).
  double coarsenTolerance = 0;
};

/// The tetrahedral mesh of solid on grid (§4.3). Deterministic: the same bytes at any
/// thread count. Cost O(nodes · volumes + tets · boundaries).
TetMesh meshSolid(const Solid& solid, const Grid& grid, const MeshOptions& options = {}, MeshStats* stats = nullptr);

/// The part of mesh on the side n·x <= offset of a plane (a cut-away, Fig. 3e-f): tetrahedra
/// crossing the plane are split exactly there, by the same edge splits as meshSolid.
TetMesh clipByPlane(const TetMesh& mesh, const DVec3& normal, double offset);

/// Cuts tetrahedra at the zero set of an exact field (CSG against an implicit solid,
/// §5.1's "subdivision"): every edge of a tetrahedron with splittable[t] whose ends have
/// field values of strictly opposite signs, and that is no edge of a tetrahedron without
/// splittable[t], gets a vertex where the field along it crosses zero (bisection of the
/// field itself to 1e-12 of the edge, so for a sphere the vertex lies on the sphere), and
/// every tetrahedron having such edges is split there, smallest vertex-id pair first (the
/// same conforming splits as meshSolid). Tetrahedra without splits and every vertex keep
/// their order, ids and bytes; new vertices are appended (tints interpolated) and pieces
/// take their parent's place and material. parent, when given, receives each output
/// tetrahedron's input index. Crossings nearer an end than `snap` of the edge are not split
/// (no slivers; that end lies within snap of the zero set). Returns the number of edges split.
size_t cutByField(TetMesh& mesh, const std::vector<uint8_t>& splittable, const std::function<double(const DVec3&)>& field,
                  std::vector<uint32_t>* parent = nullptr, double snap = 0.05);

/// The paper's tetrahedron quality (§4.4, α = 0.7), 0..10:
/// Quality(t) = α·A(t) + (1 − α)·V(t), A(t) = 10·min(1, sqrt(2·min solid angle(t))),
/// V(t) = 10·min(1, sqrt(volume(t) / ideal volume)), ideal = total volume / target count.
struct QualityStats {
  double minQuality = 0, meanQuality = 0;
  double minSolidAngle = 0;  ///< steradians (a regular tetrahedron: 0.551)
};

/// Quality of every tetrahedron of mesh against targetCount tetrahedra (0 = the mesh's own count).
QualityStats measureQuality(const TetMesh& mesh, size_t targetCount = 0);

/// The paper's quality (above) of tetrahedron (a, b, c, d) against an ideal volume; -1 when
/// it is not positively oriented.
double tetQuality(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d, double idealVolume);

/// Quality before and after smoothInterior, and the vertex moves it made.
struct SmoothStats {
  QualityStats before, after;
  size_t moved = 0;
};

/// Quality improvement by smoothing (the third of §4.4's operations; flips and half-edge
/// collapses are not built): each vertex on no interface (neither the visible interface
/// nor a face between two materials) moves toward the centroid of its neighbours, by the
/// largest of the steps 1, 1/2, 1/4, 1/8 that raises the worst quality of the tetrahedra
/// around it, for up to `rounds` sweeps. Interfaces do not move; no tetrahedron inverts;
/// the minimum quality never falls. Sequential and deterministic. Cost O(rounds · tets).
SmoothStats smoothInterior(TetMesh& mesh, int rounds = 3);

/// The smallest of the four solid angles of tetrahedron (a, b, c, d), steradians
/// (Van Oosterom and Strackee 1983).
double minSolidAngle(const DVec3& a, const DVec3& b, const DVec3& c, const DVec3& d);

/// The lattice nodes of grid, x fastest.
std::vector<Vec3> gridNodes(const Grid& grid);

/// A triangle of a tetrahedral mesh's boundary: three vertices (outward, counter-clockwise)
/// and the material of the tetrahedron it bounds.
struct InterfaceTriangle {
  std::array<uint32_t, 3> v;
  uint16_t material;
};

/// The visible interface (§4.1): faces of tetrahedra with no tetrahedron on their other
/// side (material against nothing), oriented outward. A closed surface; sorted by vertex
/// ids. Also reports faces shared by more than two tetrahedra (a broken mesh) in badFaces.
std::vector<InterfaceTriangle> visibleInterface(const TetMesh& mesh, size_t* badFaces = nullptr);

/// The interfaces between different materials: for each pair of tetrahedra of materials
/// A != B sharing a face, the face oriented out of A and then once more out of B (entries
/// 2k and 2k + 1 are one face), so the triangles of one material together with its visible
/// faces bound it closed.
std::vector<InterfaceTriangle> materialInterfaces(const TetMesh& mesh);

/// The boundary of a set of tetrahedra as a closed 2-manifold: its triangles (faces of a
/// selected tetrahedron with no selected tetrahedron on their other side, oriented outward,
/// in visibleInterface's order) on surface vertices of their own. The boundary of a union
/// of tetrahedra is in general only a pseudo-manifold: pieces that touch along an edge
/// only (four or more triangles at the edge) or at a vertex only (more than one fan of
/// triangles around it) are left by removals (polish and erode between two bronze
/// tetrahedra, a fracture), by snapping in meshSolid, and in one material's boundary
/// wherever other materials alternate with it around an edge (the shine of polish,
/// procedural materials). Here
///  1. every such mesh vertex gets one surface vertex per sheet of solid around it: at an
///     edge, the two triangles bounding one wedge of the tetrahedra around it (joined
///     through their faces at the edge) are paired; at a vertex, the triangles joined
///     through paired edges make one fan;
///  2. an edge whose wedges are still joined around both its ends (the solid meets itself
///     there through other sheets, as a material between two others around an edge does)
///     keeps its first wedge; each other wedge's two triangles are split at a surface
///     vertex of their own at the edge's midpoint;
///  3. each surface vertex of a split mesh vertex, or at a midpoint, is moved `pull` times
///     the shortest edge of its triangles at it toward the centroids of their tetrahedra
///     (into its own sheet of solid), so the sheets that touched are apart by a positive
///     distance: a consumer that welds vertices at equal positions gets the same manifold.
/// Where nothing touches, the surface vertices are the mesh's boundary vertices in
/// ascending order at their exact positions, and the triangles are visibleInterface's.
struct BoundarySurface {
  std::vector<InterfaceTriangle> triangles;  ///< v: ids into positions / sources; material of the tetrahedron
  std::vector<DVec3> positions;              ///< one per surface vertex
  /// The mesh vertices each surface vertex stands for (for tints): {v, v}, or the ends
  /// {a, b} of the edge at whose midpoint it was inserted.
  std::vector<std::array<uint32_t, 2>> sources;
  size_t splitVertices = 0;  ///< mesh vertices with more than one surface vertex (step 1)
  size_t splitEdges = 0;     ///< midpoint vertices inserted (step 2)
};

/// The boundary surface of the tetrahedra with selected[t] (empty: every tetrahedron, so
/// the visible interface; one material's tetrahedra: that material's closed boundary,
/// visible faces and interfaces to other materials). pull >= 0 (see BoundarySurface).
/// Deterministic. Cost O(T log T) in the boundary triangles, plus the tetrahedra around
/// the pinched edges.
BoundarySurface boundarySurface(const TetMesh& mesh, const std::vector<uint8_t>& selected = {}, double pull = 1e-3);

/// Tetrahedron faces in local vertex order, oriented outward for a positive tetrahedron.
constexpr std::array<std::array<int, 3>, 4> kTetFaces = {{{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}}};

}  // namespace sprig::solids
