#pragma once
/// cpfg's textures (CPFG reference manual 6.7.4 and the view file's `texture:` lines; vlab's
/// textures.c and patches.c are the specification where the manual is silent).
///
/// A view file's `texture:` line names an image and how it is applied:
///   texture: F: NAME.png [H: n|l] [L: n|l] [E: m|d] [S] [R: ratio]
/// F: the image (beside the view file or in a folder below it), H: the magnification filter
/// (n nearest, the default; l bilinear), L: the minification filter (n or l; mipmaps, `m`,
/// are not supported), E: how the texture meets the surface's colour (m modulate, the
/// default: texture times colour; d decal: the texture laid over the colour by its alpha;
/// cpfg's `b` blend is not supported), S: one image over the whole surface instead of one
/// per patch, R: the height/width ratio cpfg uses on cylinders. The lines are numbered from
/// 1 in file order; `@Tx(n)` selects texture n for the surfaces `~X` drawn after it (on its
/// branch), and a `surface:` line's texture number overrides the turtle's (0: none).
///
/// Texture coordinates (s, t) run from (0, 0) at the image's bottom-left corner to (1, 1)
/// at its top-right, repeating outside [0, 1] (cpfg's GL_REPEAT).

#include <memory>
#include <string>

#include "core/image.h"
#include "core/types.h"

namespace sprig::lsystem {

/// One `texture:` line of a view file, with its image read.
struct CpfgTexture {
  std::string file;                    ///< the image's path
  std::shared_ptr<const Image> image;  ///< linear RGB with straight (not premultiplied) alpha
  bool linear = false;                 ///< H: l (bilinear); else nearest texel
  bool decal = false;                  ///< E: d; else modulate
  bool perSurface = false;             ///< S: one image over the whole surface
  double ratio = 1.0;                  ///< R: (cylinders; read, not used by surfaces)
  bool transparent = false;            ///< some texel has alpha below 1

  /// The texel at (s, t), repeating, nearest or bilinear by `linear`; RGBA, straight alpha.
  Vec4 sample(double s, double t) const;
  /// The colour of a surface of colour `base` with this texture at (s, t): modulate gives
  /// texel * base, decal base blended toward the texel by its alpha.
  Vec3 shade(double s, double t, const Vec3& base) const;
};

/// Most `texture:` lines of a view file (cpfg's NUMTEXTURES).
inline constexpr size_t kMaxCpfgTextures = 20;

}  // namespace sprig::lsystem
