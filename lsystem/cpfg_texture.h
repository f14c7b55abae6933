#pragma once
/// cpfg's textures (CPFG reference manual 6.7.4 and the view file's `texture:` lines; vlab's
/// textures.c and patches.c are the specification where the manual is silent).
///
/// A view file's `texture:` line names an image and how it is applied:
///   texture: F: NAME.png [H: n|l] [L: n|l] [E: m|d] [S] [R: ratio]
/// F: the image (beside the view file or in a folder below it), H: the magnification filter
/// (n nearest, the default; l bilinear), L: the minification filter (n, the default, or l;
/// mipmaps, `m`, are not supported): each lookup uses the one its texel footprint calls for
/// (render::ImageMap), E: how the texture meets the surface's colour (m modulate, the
/// default: texture times colour, the texel's alpha the fragment's; d decal: the texture
/// laid over the colour by its alpha, the fragment opaque; cpfg's `b` blend is not
/// supported), S: one image over the whole surface instead of one
/// per patch, R: the height/width ratio cpfg uses on cylinders. The lines are numbered from
/// 1 in file order; `@Tx(n)` selects texture n for the surfaces `~X` drawn after it (on its
/// branch), and a `surface:` line's texture number overrides the turtle's (0: none).
///
/// Texture coordinates (s, t) run from (0, 0) at the image's bottom-left corner to (1, 1)
/// at its top-right, repeating outside [0, 1] (cpfg's GL_REPEAT).
///
/// Transparency (control.c: glAlphaFunc(GL_GREATER, 0.1), GL_BLEND with GL_SRC_ALPHA): a
/// fragment whose alpha is at or below 0.1 is left out, one above it is blended over what
/// lies behind by its alpha. The fragment's alpha is the texel's under modulate and 1 under
/// decal (OpenGL's texture environment), so only modulated textures cut out.

#include <memory>
#include <string>

#include "core/image.h"
#include "core/types.h"

namespace sprig::lsystem {

/// One `texture:` line of a view file, with its image read.
struct CpfgTexture {
  std::string file;                    ///< the image's path
  std::shared_ptr<const Image> image;  ///< linear RGB with straight (not premultiplied) alpha
  bool magLinear = false;              ///< H: l (bilinear magnification); else nearest texel
  bool minLinear = false;              ///< L: l (bilinear minification); else nearest texel
  bool decal = false;                  ///< E: d; else modulate
  bool perSurface = false;             ///< S: one image over the whole surface
  double ratio = 1.0;                  ///< R: (cylinders; read, not used by surfaces)
  bool transparent = false;            ///< some texel has alpha below 1

  /// The texel at (s, t), repeating; RGBA, straight alpha. Filtered by the minification
  /// filter (`minLinear`) when `minified` (the lookup's pixel covers more than one texel),
  /// else by the magnification filter (`magLinear`): nearest texel or bilinear.
  Vec4 sample(double s, double t, bool minified = false) const;
  /// The fragment of a surface of colour `base` with this texture at (s, t): modulate gives
  /// texel * base with the texel's alpha, decal base blended toward the texel by its alpha,
  /// alpha 1.
  Vec4 fragment(double s, double t, const Vec3& base, bool minified = false) const;
  /// fragment's colour.
  Vec3 shade(double s, double t, const Vec3& base, bool minified = false) const {
    return Vec3(fragment(s, t, base, minified));
  }
  /// True when some fragment can be cut out or blended: a modulated image with a texel of
  /// alpha below 1.
  bool cutsOut() const { return transparent && !decal; }
};

/// cpfg's alpha test: fragments with alpha at or below this are left out (GL_GREATER).
inline constexpr float kCpfgAlphaCutoff = 0.1f;

/// Most `texture:` lines of a view file (cpfg's NUMTEXTURES).
inline constexpr size_t kMaxCpfgTextures = 20;

}  // namespace sprig::lsystem
