#pragma once
/// cpfg's surface files (`.s`), which a view file names on its `surface:` lines and a grammar
/// draws with `~X` or `~X(scale)` (CPFG reference manual, "Surfaces"; vlab's patches.c is the
/// specification where the manual is silent).
///
/// A surface file holds a header and bicubic Bezier patches:
///   xmin xmax ymin ymax zmin zmax            (read, not used: cpfg ignores them too)
///   [PRECISION S: s T: t]                    (optional; without it 5)
///   CONTACT POINT X: x Y: y Z: z             (the point placed at the turtle)
///   END POINT X: x Y: y Z: z                 (where the turtle goes after drawing)
///   HEADING X: x Y: y Z: z                   (the surface's heading)
///   UP X: x Y: y Z: z                        (its up vector)
///   SIZE: d                                  (the size that the view file's size scales to)
/// then per patch: a name, `TOP COLOR: i DIFFUSE: f BOTTOM COLOR: i DIFFUSE: f`, the
/// neighbour names `AL: A: AR:`, `L: R:`, `BL: B: BR:` (`~` for none), and 16 control points
/// `x y z`, four rows of four.
///
/// As cpfg does, a control point f becomes p = M ((f - contact) * size / SIZE), where M's
/// columns are the surface's left (heading x up), heading and up (made orthonormal), and a
/// surface drawn at a turtle with scales (sx, sy, sz) puts p at
/// position + sx p.x L + sy p.y H + sz p.z Uc, with Uc cpfg's up vector (-U in Sprig's frame).
/// The patch point at (s, t) is sum B_i(s) B_j(t) P[i][j] (row i, column j; B the cubic
/// Bernstein polynomials), sampled at s = k / sPrecision and t = l / tPrecision.

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace sprig::lsystem {

/// One surface file, read and tessellated in cpfg's surface frame.
class CpfgSurface {
 public:
  /// Largest patch precision (cpfg's S_COUNT and T_COUNT).
  static constexpr int kMaxPrecision = 10;
  /// Precision without a PRECISION line or a view file value (S_COUNT / 2).
  static constexpr int kDefaultPrecision = 5;
  /// Most patches per surface (cpfg's PATCHES - 1).
  static constexpr int kMaxPatches = 64;

  struct Patch {
    std::string name;
    DVec3 points[4][4];  ///< control points after cpfg's transform, [row][column]
  };

  CpfgSurface() = default;

  /// Reads a surface file's text (fileName for diagnostics). size is the view file's size
  /// (cpfg: a size <= 0 means 1); sPrecision and tPrecision the view file's precisions, 0
  /// when it gives none: then both are the file's S precision (cpfg's patches.c reads the
  /// file's T precision but uses its S precision for both), or kDefaultPrecision. Throws
  /// InputError (`file:line:col`) for a malformed file, a zero SIZE, a zero or parallel
  /// heading and up, more than kMaxPatches patches, or a neighbour name that names no patch
  /// of the file or whose patch does not name this one back.
  static CpfgSurface parse(const std::string& text, const std::string& fileName, double size, int sPrecision,
                           int tPrecision);

  /// The patch point at (s, t) in [0, 1]^2, in the surface frame.
  DVec3 point(size_t patch, double s, double t) const;
  /// The unit normal there: dP/dt x dP/ds, as cpfg computes it ((0, 1, 0) where degenerate).
  DVec3 normal(size_t patch, double s, double t) const;

  const std::vector<Patch>& patches() const { return patches_; }
  DVec3 endPoint() const { return end_; }
  int sPrecision() const { return sPrecision_; }
  int tPrecision() const { return tPrecision_; }
  const std::string& file() const { return file_; }

  /// The tessellation: per patch (sPrecision + 1) x (tPrecision + 1) vertices, row-major in
  /// s, with their normals, and two triangles per grid cell wound so that their normals agree
  /// with normal().
  const std::vector<DVec3>& vertices() const { return vertices_; }
  const std::vector<DVec3>& normals() const { return normals_; }
  const std::vector<uint32_t>& triangles() const { return triangles_; }
  /// Texture coordinates of vertices() (patches.c, set_texture_coordinates): per patch
  /// (s, t) = the vertex's (k / sPrecision, l / tPrecision); per surface (perSurface) its x
  /// and y in the surface frame, mapped from the tessellation's bounds to [0, 1].
  const std::vector<glm::dvec2>& uvs(bool perSurface) const { return perSurface ? surfaceUvs_ : patchUvs_; }

 private:
  void tessellate();

  std::string file_;
  std::vector<Patch> patches_;
  DVec3 end_{0};
  int sPrecision_ = kDefaultPrecision;
  int tPrecision_ = kDefaultPrecision;
  std::vector<DVec3> vertices_;
  std::vector<DVec3> normals_;
  std::vector<uint32_t> triangles_;
  std::vector<glm::dvec2> patchUvs_;
  std::vector<glm::dvec2> surfaceUvs_;
};

/// A surface of the view file with its id (the letter after `~`).
struct CpfgSurfaceEntry {
  char id = 0;
  CpfgSurface surface;
  /// The `surface:` line's texture number: -1 (none given) the turtle's texture (`@Tx`),
  /// 0 no texture, n the view file's texture n (patches.c, s_textures).
  int texture = -1;
};

}  // namespace sprig::lsystem
