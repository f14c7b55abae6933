#pragma once
/// Polygon meshes and their readers: the base meshes users give Sprig (OBJ, PLY, OFF).
///
/// A PolyMesh keeps faces as they are written (triangles, quads, n-gons), so a quad cage
/// stays a quad cage for subdivision. Faces are flat arrays: faceSizes[f] corners each,
/// their vertex indices one after another in faceVertices (the compressed-row layout
/// OpenSubdiv's TopologyDescriptor takes as it is). faceLocs remembers where each face is
/// written, so a topology error names the user's line.
///
/// Readers collect every error (up to kMaxPolyMeshErrors) and throw one InputError; each
/// prints `file:line:col: error: message` with 1-based line and column. The body of a
/// binary PLY has no lines: its errors carry line 0 and name the element index and the
/// byte offset instead. Text that holds a NUL byte or other control characters is
/// rejected with one error naming the byte's position (the bytes are never printed).
///
/// Limits (PolyMeshLimits): a file of at most 1 GiB, at most 50 million vertices and 50
/// million faces. Counts a file declares (PLY elements, the OFF header) are checked
/// against the limits and against the bytes that follow before anything is allocated.
///
/// Colors are linear RGB in a PolyMesh. OBJ `v x y z r g b` colors are sRGB-encoded floats
/// in [0, 1] (what core/mesh_io's writeObj writes); PLY `uchar` colors are sRGB-encoded
/// bytes and PLY `float` colors linear values in [0, 1]; OFF (COFF) colors are sRGB-encoded,
/// either integers 0-255 or floats in [0, 1], with an optional alpha that is ignored.
/// Face colors of OFF files are ignored.

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "core/diagnostics.h"
#include "core/mesh.h"
#include "core/types.h"

namespace sprig {

/// A polygon mesh: positions, optional colors and faces of three or more corners.
struct PolyMesh {
  std::vector<Vec3> positions;
  std::vector<Vec3> colors;            ///< optional, linear RGB, empty or one per position
  std::vector<uint32_t> faceSizes;     ///< vertices per face (>= 3)
  std::vector<uint32_t> faceVertices;  ///< concatenated, counter-clockwise seen from outside
  /// Where each face is written (line:col of its record); empty for a mesh not read from a
  /// file. Faces of a binary PLY have line 0, col 0 (the file name only).
  std::vector<SourceLoc> faceLocs;

  /// Number of faces.
  size_t faceCount() const { return faceSizes.size(); }
  /// Number of face corners (the length of faceVertices).
  size_t cornerCount() const { return faceVertices.size(); }
  /// Bounding box of the positions (empty box for an empty mesh).
  Box3 bounds() const;
};

/// Reverses the winding of every face of mesh (each face's corners in reverse order, its
/// first corner kept first), turning its normals around. Positions, colours and face
/// locations are unchanged.
void reverseWinding(PolyMesh& mesh);

/// Polygon mesh file formats Sprig reads.
enum class MeshFileFormat { Obj, Ply, Off };

/// Size limits of the readers; a file beyond one fails with a message naming the limit.
struct PolyMeshLimits {
  uint64_t maxFileBytes = uint64_t(1) << 30;  ///< 1 GiB
  uint64_t maxVertices = 50'000'000;
  uint64_t maxFaces = 50'000'000;
};

/// Readers stop collecting errors after this many (the last says so).
constexpr size_t kMaxPolyMeshErrors = kMaxDiagnostics;

/// The format for a path's extension (.obj, .ply, .off; case-insensitive).
/// Throws std::invalid_argument naming the path for any other extension.
MeshFileFormat meshFileFormatFor(const std::filesystem::path& path);

/// Reads a polygon mesh, choosing the format by extension (meshFileFormatFor).
/// displayPath names the file in messages (default: path as given).
/// Throws std::invalid_argument for an unknown extension, InputError with every error
/// (including a file that cannot be read or exceeds limits.maxFileBytes). O(file size).
PolyMesh readPolyMesh(const std::filesystem::path& path, std::string displayPath = {},
                      const PolyMeshLimits& limits = {});

/// Parses a polygon mesh held in memory (tests, fuzzing); displayPath names it in
/// messages. Throws InputError as readPolyMesh.
PolyMesh parsePolyMesh(std::string_view bytes, MeshFileFormat format, std::string displayPath,
                       const PolyMeshLimits& limits = {});

/// Triangle mesh of a polygon mesh by fan triangulation (corner 0 with each later pair);
/// colors are kept. Faces are assumed valid (checkPolyMesh).
Mesh triangulate(const PolyMesh& mesh);

/// A polygon mesh whose faces are the triangles of mesh (positions and colors kept;
/// faceLocs empty).
PolyMesh toPolyMesh(const Mesh& mesh);

/// Edge counts of a base mesh (see checkPolyMesh).
struct PolyTopology {
  size_t boundaryEdges = 0;      ///< edges used by one face (allowed: open meshes)
  size_t nonManifoldEdges = 0;   ///< edges used by more than two faces
  size_t inconsistentEdges = 0;  ///< edges two faces traverse in the same direction
  /// No boundary edges.
  bool closed() const { return boundaryEdges == 0; }
  /// Every edge has at most two faces, traversed in opposite directions.
  bool manifold() const { return nonManifoldEdges == 0 && inconsistentEdges == 0; }
};

/// Edge checks of a base mesh: an edge used by more than two faces (the error is at the
/// third face), two faces that traverse an edge in the same direction (at the second), a
/// face with fewer than three corners, a face repeating a vertex, or an index out of
/// range is an error at that face's location (faceLocs; "face N" when it has no line).
/// Boundary edges are allowed and only counted. Adds errors to diags; returns the counts.
/// O(C log C) for C corners.
PolyTopology checkPolyMesh(const PolyMesh& mesh, DiagnosticList& diags);

}  // namespace sprig
