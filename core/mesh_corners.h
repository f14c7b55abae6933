#pragma once
/// Per-corner normals and texture coordinates of a welded mesh, for file formats whose
/// vertices carry one normal and one uv each (glTF) or index them per corner (OBJ).
///
/// A Sprig mesh is welded: a vertex has one normal and one uv, so it stays closed and
/// manifold for the checks and for slicers. Two places need a vertex to carry more:
/// - a crease: when the faces around a vertex have normals more than 90° apart, one
///   normal cannot face all of them (a viewer shades one side black); the vertex gets one
///   normal per side (splitCreaseNormals);
/// - a texture seam: where u wraps from 1 back to 0 (a repeating texture around a branch)
///   a triangle would interpolate across the whole image; its corners past the seam get
///   u + 1 instead (cornerUvs), and a triangle across a jump of the parameterization
///   (between two whorls of a shell) takes one corner's uv on all three corners.
/// unweld() then makes one vertex per distinct (vertex, normal, uv) for glTF.

#include <cstdint>
#include <limits>
#include <vector>

#include "core/mesh.h"
#include "core/types.h"

namespace sprig {

/// A table of per-corner values: corner k of triangle t uses values[index[3t + k]].
template <class T>
struct CornerTable {
  std::vector<T> values;
  std::vector<uint32_t> index;  ///< 3 per triangle
};

/// Normals split at creases, and how many vertices were split.
struct CreaseNormals {
  CornerTable<Vec3> normals;  ///< values[v] is vertex v's normal; split sides are appended
  size_t splitVertices = 0;   ///< vertices that got more than one normal
  size_t extraNormals = 0;    ///< normals appended (Σ sides − 1 over split vertices)
};

/// Splits the normals of mesh where the faces around a vertex fold by more than 90°: a
/// vertex whose incident (non-degenerate) faces have two normals with a negative dot
/// product is a crease; its faces are grouped greedily (largest face first) into sides
/// whose faces are pairwise within 90° (dot >= 0), and each side's corners get the side's
/// area-weighted normal, which is within 90° of each of its faces. Other vertices keep mesh.normals[v] (or the
/// area-weighted face normal when the mesh has none). Afterwards every face's corner
/// normals are within 90° of its winding normal at crease vertices. O(T log T).
CreaseNormals splitCreaseNormals(const Mesh& mesh);

/// How cornerUvs treats a texture's parameterization.
struct UvSeamOptions {
  bool repeatU = false;  ///< u is periodic with period 1 (the texture repeats in u)
  bool repeatV = false;  ///< v is periodic with period 1
  /// The uvs already run on across the repeats (cpfg's textured tubes, whose t grows along
  /// a branch beyond 1): the sampler repeats the axes above, and no corner is shifted.
  bool continuous = false;
  /// A triangle whose corners span more than this in u or v (after wrapping) straddles a
  /// discontinuity of the parameterization: all its corners take its first corner's uv.
  Vec2 maxSpan{std::numeric_limits<float>::infinity()};
};

/// Per-corner uvs of mesh (which must have uvs): values[v] is mesh.uvs[v]; a triangle
/// crossing the seam of a repeating axis (corners more than 0.5 apart; not when
/// options.continuous) gets value + 1 on
/// its low corners (appended values, shared per vertex); then a triangle spanning more than
/// maxSpan takes its first corner's uv everywhere. O(T).
CornerTable<Vec2> cornerUvs(const Mesh& mesh, const UvSeamOptions& options);

/// The mesh with one vertex per distinct (vertex, corner normal, corner uv): vertex v keeps
/// index v with the values its first corner (in triangle order) uses; other combinations
/// are appended in triangle order, copying position and colour. An empty table leaves
/// that array as it is. Materials are kept. origin, when given, receives the vertex of
/// mesh each output vertex copies. O(T).
Mesh unweld(const Mesh& mesh, const CornerTable<Vec3>& normals, const CornerTable<Vec2>& uvs,
            std::vector<uint32_t>* origin = nullptr);

/// The tangent of a triangle's corner for a tangent-space normal map (glTF TANGENT): the
/// direction of increasing u of the triangle's uv → position mapping (positions p, texture
/// coordinates uv with t = 0 at the image's bottom row, as Mesh::uvs), made perpendicular to
/// the corner's normal (Gram-Schmidt) and unit; w = +1 when cross(normal, tangent) points
/// towards increasing t (up in the image: the +Y of glTF's and OpenGL's normal maps), else
/// −1. A degenerate mapping or a tangent along the normal gives a unit vector perpendicular
/// to the normal with w = +1. normal need not be unit.
glm::vec4 cornerTangent(const Vec3 p[3], const Vec2 uv[3], const Vec3& normal);

}  // namespace sprig
