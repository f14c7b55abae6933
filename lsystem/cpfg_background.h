#pragma once
/// cpfg's background scene files (a view file's `background scene: FILE[, FILE...]`; CPFG
/// reference manual, section 8.3; vlab's background.c is the specification where the manual
/// is silent): geometry drawn with the plant, in the plant's coordinates.
///
/// A file is run through cpfg's preprocessor `preproc` (`/* */` comments and `#define NAME
/// text`; it removes no `//` comment), then read as words: a command
/// followed by its numbers. Commands, in the plant's coordinates under a matrix stack that
/// starts at the identity for each drawing and runs on across the files:
///   material a a a a  d d d d  [s s s s  [e e e e  [shininess]]]   (ambient, diffuse, ...)
///   pushmatrix, popmatrix, translate x y z, rotate deg x y z, scale x y z,
///   multmatrix m0 ... m15   (OpenGL's column-major order: m12 m13 m14 is the translation)
///   polygon x y z ... (n >= 3 vertices, a fan from the first), polygonuv x y z nx ny nz ...,
///   rectangle a b [x0 y0], mesh (4 + 2k vertices, a strip of quads), box|prism a b c,
///   sphere r, cylinder r h (axis +y), cone r1 r2 h (axis +y), each cylinder and cone capped.
/// Each command applies in the local frame the earlier ones made (OpenGL's order).
///
/// Sprig draws a material's diffuse red, green and blue, as it draws cpfg's materials files;
/// a diffuse alpha below 1 (cpfg draws translucently) is drawn opaque, with a warning.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "core/types.h"

namespace sprig::lsystem {

/// Most primitives and transformations of one view file's background scene (cpfg has none).
inline constexpr size_t kMaxBackgroundCommands = 100000;
/// Most triangles of one view file's background scene (a sphere is 2,208, a cylinder or cone
/// at most 188): about 900 spheres.
inline constexpr size_t kMaxBackgroundTriangles = 2000000;
/// Characters that macros write into one background file (the words they replace, expanded;
/// cpfg has no limit; a macro that names itself, or a chain of doubling macros, grows
/// without bound). Words without macros do not count.
inline constexpr size_t kMaxBackgroundExpansion = 100000;
/// Characters written by all rescans of one file's macro expansions (each of up to 32
/// rounds that replaced a macro writes its whole word again): bounds the preprocessor's time.
inline constexpr size_t kMaxBackgroundExpansionWork = 1000000;
/// Deepest matrix stack (cpfg's STACK_SIZE 50: 49 pushes above the identity).
inline constexpr int kMaxBackgroundStack = 49;

/// One drawn primitive of a background scene, with the matrix stack's top when it is drawn.
struct CpfgBackgroundPrimitive {
  enum class Kind { Polygon, PolygonUV, Rectangle, Mesh, Box, Sphere, Cylinder, Cone };
  Kind kind = Kind::Polygon;
  glm::dmat4 sceneFromLocal{1.0};  ///< column-vector matrix: a local point p is drawn at sceneFromLocal * (p, 1)
  std::vector<double> numbers;     ///< the command's numbers as written, in its local frame
  int material = 0;                ///< index into CpfgBackground::materials
  SourceLoc loc;                   ///< the command's word
};

/// A background material: what Sprig draws of it.
struct CpfgBackgroundMaterial {
  Vec3 diffuse{1.0f};
  float alpha = 1;  ///< the diffuse alpha (cpfg draws < 1 translucently; Sprig opaque)
};

/// The triangles of a background scene in the plant's coordinates, per triangle its material.
struct CpfgBackgroundMesh {
  std::vector<DVec3> positions;
  std::vector<DVec3> normals;            ///< unit, one per position
  std::vector<uint32_t> triangles;       ///< 3 indices per triangle
  std::vector<int> triangleMaterials;    ///< one per triangle
};

/// A background scene read from its files.
struct CpfgBackground {
  std::vector<CpfgBackgroundMaterial> materials;
  std::vector<CpfgBackgroundPrimitive> primitives;
  /// The first cylinder or cone, if any: cpfg draws them as its line style draws `F`, which
  /// only the cylinder style makes a solid (ViewFile checks it).
  std::optional<SourceLoc> firstTube;
  /// The first cone, if any: cpfg tapers it only with `tapered lines: on` (the default).
  std::optional<SourceLoc> firstCone;

  /// The scene's triangles: polygons as fans, rectangles, mesh quads and box faces as two
  /// triangles each, spheres as 24 x 48 quads of latitude and longitude, cylinders and cones
  /// as 48 side quads and two capping discs. Positions go through sceneFromLocal; normals
  /// through its inverse transpose.
  CpfgBackgroundMesh triangulate() const;
};

/// Reads the background scene files' texts (texts[i] named fileNames[i] in diagnostics) as
/// cpfg does, one scene across them. Throws InputError (every error at its
/// `file:line:col`): an unknown command or preprocessor directive, a word that is not a
/// number where numbers go, a wrong count of numbers, a primitive before the first material,
/// a popmatrix without its pushmatrix, a stack deeper than kMaxBackgroundStack, a rotation
/// about the zero vector, a projective multmatrix (last row not 0 0 0 1), a rectangle's
/// fifth number (its emission factor), more than kMaxBackgroundCommands commands or
/// kMaxBackgroundTriangles triangles.
/// warnings gets a translucent material's warning.
CpfgBackground parseCpfgBackground(const std::vector<std::string>& texts, const std::vector<std::string>& fileNames,
                                   std::vector<Diagnostic>& warnings);

}  // namespace sprig::lsystem
