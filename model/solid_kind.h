#pragma once
/// `kind: solid` species: layered solid models as tetrahedral meshes with materials
/// (Cutler, Dorsey, McMillan, Müller, Jagnow, "A procedural approach to authoring solid
/// models", §2 and §4; solids/solid.h). The paper's script becomes YAML with the names of
/// its appendix:
///
/// ```
///   kind: solid
///   materials:                                   # named materials (built-ins need none)
///     striped_chocolate: {select: "y > 0.2", choices: [white_chocolate, chocolate]}
///   solid:
///     grid: {cell: 0.03}                         # optional: default from bounds and the thinnest layer
///     precedence:                                # or one `volume:`
///       - volume:
///           distance_field: {surface_mesh: {file: meshes_solid/almond.obj}}
///           layers:
///             - interior_layer: {material: nut, thickness: fill}
///       - volume:
///           distance_field: {union: [{sphere: {radius: 1}}, {box: {size: [1, 1, 3]}}]}
///           layers:
///             - interior_layer: {material: chocolate, thickness: fill}
///             - exterior_layer: {material: white_chocolate, thickness: 0.1}
/// ```
/// docs/SOLIDS.md lists every key, default and unit, and what is not built yet (interface
/// velocity, from_volume_surface): those keys are errors at their file:line:col, never
/// ignored. `extrude_2d` and `species` fields: solids/extrude_field.h, model/species_field.h.

#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/shapes.h"
#include "model/kinds.h"
#include "model/solid_operations.h"
#include "model/yaml_reader.h"
#include "solids/improve.h"
#include "solids/solid.h"

namespace sprig {

/// The keys of a solid species, read and checked; the grid is resolved at read time.
class SolidSpec : public KindSpec {
 public:
  solids::Solid solid;
  solids::Grid grid;
  int smoothRounds = 0;  ///< `solid.smooth`: rounds of solids::smoothInterior after meshing
  int coarsenLevels = 0; ///< `solid.coarsen`: octree levels merged where no interface crosses (solids/octree.h)
  double coarsenTolerance = 0;  ///< `solid.coarsen_tolerance`, cells: merge across interfaces where fields are affine to it
  /// `solid.improve`: flips, collapses and smoothing after meshing (solids/improve.h); the
  /// tolerance is in world units (the file gives it in cells).
  std::optional<solids::ImproveOptions> improve;
  std::vector<SolidOperation> operations;  ///< `solid.operations`, applied in order after smoothing
  SourceLoc loc;

  std::string checkSummary(const Species& species) const override;
  std::unique_ptr<KindModel> makeModel(const Species& species, const ModelOptions& options) const override;
};

/// Reads the `solid:` section and the top-level `materials:` of a species file, adding every error to diags.
std::shared_ptr<const KindSpec> readSolidSpec(MapReader& top, Species& species, DiagnosticList& diags);

/// The visible interface of mesh as a render mesh: one part per material with its colour,
/// smooth normals: at each vertex the area-weighted mean of the face normals around it
/// within 60° of each other, over every material's faces (so the shading is continuous
/// where two materials meet on a smooth surface; sharper edges stay creased). When mesh has tints (the weathering tools and polish)
/// and materials is given, every part gets vertex colours mix(base colour, tint rgb,
/// tint amount), the base colour the area-weighted mean of the colours of the materials
/// around the vertex; otherwise none (the part's material colour applies).
/// normalRounds rounds of smoothSurfaceNormals follow (0: the area-weighted means alone).
/// The tetrahedra's own faces: visibleParts without subdivision.
std::vector<Mesh> visibleMeshes(const solids::TetMesh& mesh, std::vector<uint16_t>* partMaterials = nullptr,
                                const std::vector<solids::Material>* materials = nullptr, int normalRounds = 2);

/// How visibleParts shapes the surface.
struct VisibleMeshOptions {
  int normalRounds = 2;  ///< rounds of smoothSurfaceNormals after the area-weighted means
  /// Levels of Loop subdivision with infinitely sharp creases (OpenSubdiv's Loop scheme,
  /// organisms::Subdivision) before the normals, each a quarter of every triangle (none
  /// that would pass kMaxSubdividedTriangles): a tetrahedral surface's triangles are a cell
  /// wide and tilt up to 40° from the surface they stand for, which shows as facets
  /// wherever shading reads a triangle's own plane (silhouettes, the sky's horizon,
  /// shadows). Edges between smooth groups stay creases and their corners stay put (a box
  /// keeps its flat faces and straight edges); curved parts shrink by a fraction of a cell.
  /// 0: the tetrahedra's faces.
  int subdivisions = 0;
};

/// The most triangles visibleParts' subdivision makes: a level that would pass it is not
/// taken (a fine tetrahedral mesh's facets are small in the picture already).
inline constexpr size_t kMaxSubdividedTriangles = 400000;

/// Levels of subdivision of a solid's render surface (pictures; `sprig mesh` and exports
/// keep the tetrahedra's faces, and so does a wireframe, which draws them).
inline constexpr int kRenderSubdivisions = 2;

/// visibleParts' result: the parts, their materials and, with materials, each vertex's
/// render surface.
struct VisibleParts {
  std::vector<Mesh> meshes;                 ///< one per material present
  std::vector<uint16_t> materials;          ///< each mesh's material
  /// With materials: per vertex of each mesh, (roughness, specular, metallic 0), the
  /// area-weighted mean over the materials of the faces around the vertex's smooth group
  /// (subdivided: the coarse surface's values, interpolated). Where two materials meet
  /// (polish's shiny bronze among plain bronze: one material per tetrahedron, so the shine
  /// is a step along triangle edges) the highlight fades across one ring of the
  /// tetrahedra's triangles instead of following them. Empty without materials.
  std::vector<std::vector<Vec3>> surfaces;
};

/// The visible interface of mesh as render parts (visibleMeshes, with options.subdivisions
/// levels of smoothing subdivision). Deterministic; cost O(T log T) in the boundary
/// triangles, and O(4^levels T) for the subdivision.
VisibleParts visibleParts(const solids::TetMesh& mesh, const std::vector<solids::Material>* materials,
                          const VisibleMeshOptions& options);

/// Smooths the normals of a surface's smooth groups (visibleMeshes): in each of `rounds`
/// rounds every group takes the normalized sum, over the faces it is a corner of, of face
/// area times the sum of the face's three corner normals (a Jacobi step of the area-weighted
/// umbrella average). Only faces a group belongs to contribute, so creases stay creased.
/// A tetrahedral surface's triangles tilt up to 40° from the smooth surface (the cut's
/// facets are a cell wide); two rounds spread a vertex's normal over its neighbours' and
/// hide the facets in the shading. corner[f]: the groups of face f's corners; area[f]: its
/// area. Normals of groups no face touches are kept.
void smoothSurfaceNormals(const std::vector<std::array<uint32_t, 3>>& corner, const std::vector<float>& area,
                          std::vector<Vec3>& normals, int rounds);

/// The distinct edges of parts' triangles as round linear curve segments (two vertices
/// each, no joins), for `render.wireframe`. Edges are keyed by their ends' positions, so
/// an edge shared by two triangles, or by two parts or normal groups that each hold a copy
/// of its vertices, is drawn once; segments come in the keys' sorted order. radiusAt gives
/// the world radius at a point. Cost: O(E log E) for E triangle edges.
CurveSet wireframeCurves(const std::vector<Mesh>& parts, const std::function<float(const Vec3&)>& radiusAt);

}  // namespace sprig
