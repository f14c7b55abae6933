#pragma once
/// The branching skeleton a turtle draws: internodes and organs.
///
/// This is the neutral hand-off between the L-system and every geometry builder
/// (preview renderer, BlobTree tree builder). Positions are world units, Y up.

#include <cstdint>
#include <string>
#include <vector>

#include "core/types.h"

namespace sprig::lsystem {

/// One drawn segment (an `F` or `G`... that draws).
struct Internode {
  DVec3 start{0};
  DVec3 end{0};
  double baseRadius = 0;   ///< radius at start
  double tipRadius = 0;    ///< radius at end
  int32_t parent = -1;     ///< index of the internode this one grows from; -1 for a root
  int order = 0;           ///< branch order: 0 for the trunk, +1 per `[` entered
  int step = 0;            ///< derivation step that created the module that drew it
  uint32_t module = 0;     ///< index of the drawing module in the final string
  DVec3 up{0, 0, 1};       ///< turtle's up vector when it was drawn (for bark orientation)
  bool cut = false;        ///< marked by the grammar as pruned (`%`-style cut module, see docs/GRAMMAR.md)

  double length() const;
};

/// A non-internode part: leaf polygon, sphere, or a named surface: a predefined one (drawn
/// by the geometry builders from position, frame and radius), or, in cpfg's notation, a
/// surface file's mesh already placed in world units (triangles not empty).
struct Organ {
  enum class Kind { Polygon, Sphere, Surface };
  Kind kind = Kind::Polygon;
  std::vector<DVec3> points;   ///< polygon vertices in order (Polygon), or a surface file's mesh vertices (Surface)
  std::vector<DVec3> normals;  ///< Surface from a cpfg surface file, or a textured Polygon: unit normal per vertex of points
  std::vector<uint32_t> triangles;  ///< Surface from a cpfg surface file, or a textured Polygon (a fan): 3 indices into points per triangle
  DVec3 position{0};           ///< center (Sphere) or turtle position (Surface)
  DVec3 heading{0, 1, 0};      ///< turtle frame when created (Surface)
  DVec3 left{-1, 0, 0};
  DVec3 up{0, 0, 1};
  double radius = 0;           ///< sphere radius, or the surface's scale
  std::string name;            ///< surface name for `~`
  int32_t internode = -1;      ///< internode it is attached to, -1 if none
  int step = 0;
  int color = 0;               ///< turtle color index (`'`) when created
  /// cpfg: the view file's texture (0-based: `@Tx(1)` is 0) on a surface file's mesh or a polygon,
  /// -1 for none; then uvs holds the texture coordinates of points (lsystem/cpfg_texture.h).
  int texture = -1;
  std::vector<Vec2> uvs;
};

/// cpfg's `@L("format", values)`: text the renderer writes over the picture, screen-aligned,
/// its baseline starting at the projected position (docs/GRAMMAR.md, "Labels").
struct Label {
  DVec3 position{0};  ///< the turtle's position, world units
  std::string text;   ///< the format filled with the values, as cpfg's sprintf fills it
  int color = 0;      ///< the turtle's colour index (cpfg colours the text by its colour map)
  int step = 0;       ///< derivation step that created the module
};

/// A whole plant skeleton.
struct Skeleton {
  std::vector<Internode> internodes;
  std::vector<Organ> organs;
  std::vector<Label> labels;  ///< cpfg's `@L` texts; they add nothing to bounds()

  /// Bounds of internodes (including radii) and organs.
  DBox3 bounds() const;
  /// Sum of internode lengths.
  double totalLength() const;
  /// children[i] lists internodes whose parent is i, in drawing order.
  std::vector<std::vector<int32_t>> children() const;
};

/// A skeleton's internodes reduced to what a report needs (Turtle::summarize), and its organs.
struct SkeletonSummary {
  size_t internodes = 0;
  double totalLength = 0;  ///< as Skeleton::totalLength
  DBox3 bounds;            ///< as Skeleton::bounds: internodes with radii, and organs
  std::vector<Organ> organs;
};

}  // namespace sprig::lsystem
