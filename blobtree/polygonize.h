#pragma once
/// Polygonization of a compiled BlobTree: sparse, near-surface only, watertight.
///
/// Method (work proportional to surface area, not volume):
///  1. Cells: CompiledBlob::surfaceCells(cellSize) finds, by interval bounds and octree
///     subdivision, the cube cells (of exactly the requested edge) of a regular grid that
///     may hold the F = 0.5 surface. No other cell is visited.
///  2. Samples: the field is sampled once at every distinct corner of those cells. A grid
///     point belongs to the kept cell holding it with the smallest corner code (found in a
///     hash of cell keys, no sort); points are numbered by owner cell, and the cells come
///     in octree order, so each run of 128 consecutive points is a compact cluster
///     evaluated in one batched values() call (one tree walk, each nearby primitive over
///     the whole batch, vectorized). One value per grid point keeps neighbouring cells
///     consistent.
///  3. Closure: a kept cell whose face shows a sign change gets its neighbour across that
///     face added when the bounds dropped it (rounding at corners exactly on F = 0.5).
///  4. Marching tetrahedra: each cell with a sign change is split into the six Kuhn
///     tetrahedra around its main diagonal (the split of every cube face matches its
///     neighbour's), and each tetrahedron yields 0, 1 or 2 triangles. A vertex belongs to
///     its grid edge, and the edge to the cell whose low corner is the edge's low end, so
///     vertices are numbered once (owner cell order, then edge direction) and shared
///     exactly: the result is closed and 2-manifold by construction for a closed surface.
///     Triangles are oriented from inside (F > 0.5) to outside, decided combinatorially on
///     edge midpoints (degenerate triangles get the right orientation too).
///  5. Projection: every vertex is moved onto the exact F = 0.5 surface by a bracketed
///     root search (Illinois regula falsi) along its grid edge (batched values() over
///     fixed blocks of 64 vertices), so it never leaves its edge or its cell. Normals are −∇F/|∇F| and uv the blended
///     primitive (u,v) from CompiledBlob::sample. Vertices whose roots met on a grid corner
///     (one on the surface to within rounding) move 16 float spacings out along their own
///     edges, so that no two vertices share a position and a weld by position leaves the
///     mesh a 2-manifold (PolygonizeResult::separatedVertices).
/// Every step runs in parallel over fixed index blocks and merges in sorted or index order:
/// the same blob and options give the same mesh bytes at any thread count.
///
/// Cells with an edge exactly on the surface lean outward (a corner with F = 0.5 counts
/// as outside), which keeps the topology well defined.

#include <cstddef>
#include <vector>

#include "blobtree/compiled.h"
#include "core/mesh.h"

namespace sprig::blobtree {

/// Options of polygonize(); defaults give a mesh within 1% of a sphere's volume.
struct PolygonizeOptions {
  /// How active cells become triangles. MarchingTetrahedra: six Kuhn tetrahedra per cell,
  /// a vertex on every crossing grid edge (including the cells' diagonals), exact on the
  /// surface; the reference. DualMarchingCubes (Nielson 2004; blobtree/detail/dual_patches.h):
  /// a vertex per surface patch of each cell (the mean of its edge crossings, moved onto
  /// F = 0.5 by Newton steps kept inside the cell), a quad per crossing axis edge; about a
  /// third of the triangles, closed and 2-manifold by construction.
  enum class Mesher { MarchingTetrahedra, DualMarchingCubes };
  Mesher mesher = Mesher::MarchingTetrahedra;
  /// DualMarchingCubes only: the patch vertices' Newton steps evaluate F and ∇F for blocks
  /// of vertices at once (CompiledBlob::valuesAndGradients), then one sample() per vertex
  /// for its uv and attributes (none when normals come from the last step and
  /// vertexData is None). false: one scalar sample() per step, the path it replaced, kept for comparison
  /// (same vertices to rounding; bench_polygonize runs both).
  bool batchedNewton = true;
  /// Requested cell edge length in world units; 0 = automatic: the smaller of
  /// featureFraction · smallestFeature() (so the thinnest twig gets several cells across)
  /// and the model's bounds diagonal / sizeDivisions, but never finer than the diagonal /
  /// maxDivisions, unless the thinnest limb needs it (limbFraction). The grid's cells have
  /// exactly this edge (blobtree/cell_size.h has the rule).
  float cellSize = 0.0f;
  /// Automatic cell size as a fraction of the smallest primitive radius.
  float featureFraction = 0.5f;
  /// Automatic cell size at most the bounds diagonal divided by this.
  float sizeDivisions = 64.0f;
  /// Automatic cell size at least the bounds diagonal divided by this. The tapered tips
  /// of a tree reach radii of 1/4000 of the tree; cells of half that made the arbutus
  /// 69 M triangles (1.9 GB of glTF, 150 s); at diagonal/2500 it is about 5 M triangles
  /// in about ten seconds. A twig of radius diagonal/1000 still gets the default
  /// featureFraction (2.5 cells per radius); only thinner tips end early. An explicit
  /// cellSize is never clamped.
  float maxDivisions = 2500.0f;
  /// The floor above is lowered to limbFraction · thinnestLimb() where that is finer, so
  /// that every primitive keeps at least its thick end in one piece (a twig thinner than a
  /// cell fell apart into specks; CellSizeRule explains the bound); 0 turns this off.
  float limbFraction = 1.1f;
  /// ... but only where that edge is at least the diagonal / limbMaxDivisions (at most
  /// 2.56 times the triangles of the maxDivisions floor); a thinner limb leaves the floor
  /// alone, may fall apart, and the mesh cleaning then removes its pieces as specks.
  float limbMaxDivisions = 4000.0f;
  /// Maximum root-search iterations per vertex (0 = keep the linear interpolation).
  int refineSteps = 12;
  /// Root search stops when |F − 0.5| falls below this.
  float fieldTolerance = 1e-5f;
  /// Fill Mesh::normals from the gradient.
  bool normals = true;
  /// What each vertex carries besides its position and normal, all from the field's
  /// CompiledBlob::sample at the vertex:
  /// - None: nothing (no sample at all where normals are off or come from the last step);
  /// - Uvs: Mesh::uvs, the field-blended primitive (u,v) (the default);
  /// - Blend: also PolygonizeResult::attributes, the vertex's blended texture ids, layers
  ///   and PCM contact (blobtree::Attributes), which painting the mesh reads
  ///   (model::paintPolygonized, render::Scene::addPolygonized with textures or a tilting
  ///   ridge). They are 120 bytes a vertex, four times the mesh's own vertex data: 315 MB
  ///   on the 2,000-cone benchmark, where allocating them was a third of the dual mesher's
  ///   time (docs/PERFORMANCE.md), so only callers that paint ask for them.
  enum class VertexData : uint8_t { None, Uvs, Blend };
  VertexData vertexData = VertexData::Uvs;
  /// Report progress on a terminal (core/progress.h); cancellation throws Cancelled.
  bool progress = false;
};

/// A mesh with per-vertex attributes and statistics.
struct PolygonizeResult {
  Mesh mesh;
  std::vector<Attributes> attributes;  ///< per vertex with VertexData::Blend, else empty
  float cellSize = 0.0f;        ///< the grid's actual cell edge
  size_t surfaceCells = 0;      ///< cells the interval bounds kept
  size_t activeCells = 0;       ///< cells with a sign change (the ones triangulated)
  size_t extraCells = 0;        ///< neighbours added where rounding left a face's sign change uncovered
  size_t gridSamples = 0;       ///< distinct grid points sampled
  /// Marching tetrahedra: vertices that shared a position with another (their roots on a
  /// grid corner that lies on the surface to within rounding), each moved 16 float spacings
  /// out along its own edge, so that no two vertices share a position (polygonize.cpp,
  /// kCornerSpacings).
  size_t separatedVertices = 0;
  size_t fieldEvaluations = 0;  ///< every field value computed (grid + root search + samples)
  double cellSeconds = 0;         ///< time in surfaceCells
  double sampleSeconds = 0;       ///< grid corner sampling (with the corner table)
  double triangulateSeconds = 0;  ///< closure, marching tetrahedra, vertex merge
  double vertexSeconds = 0;       ///< root search, normals and attributes
  /// CPU seconds of the process (all threads) in each of the four phases above: against
  /// the wall seconds they show how much of a phase ran on one core.
  double cellCpuSeconds = 0, sampleCpuSeconds = 0, triangulateCpuSeconds = 0, vertexCpuSeconds = 0;
};

/// The cell size polygonize() requests for these options (resolves the automatic size).
/// Throws std::invalid_argument when the blob is empty or unbounded and no size is given.
float resolveCellSize(const CompiledBlob& blob, const PolygonizeOptions& options = {});

/// Polygonizes the F = 0.5 surface of blob (see the file comment). An empty blob gives an
/// empty mesh. Throws std::invalid_argument for an unbounded blob or a grid over 2^20
/// cells on an axis, and Cancelled when cancellation is requested with progress on.
PolygonizeResult polygonizeDetailed(const CompiledBlob& blob, const PolygonizeOptions& options = {});

/// polygonizeDetailed(...).mesh.
Mesh polygonize(const CompiledBlob& blob, const PolygonizeOptions& options = {});

}  // namespace sprig::blobtree
