#pragma once
/// cpfg's textures (CPFG reference manual 6.7.4 and the view file's `texture:` lines; vlab's
/// textures.c and patches.c are the specification where the manual is silent).
///
/// A view file's `texture:` line names an image and how it is applied:
///   texture: F: NAME.png [H: n|l] [L: n|l|m[n|l][n|l]] [E: m|d|b] [S] [R: ratio]
/// F: the image (beside the view file or in a folder below it), H: the magnification filter
/// (n nearest, the default; l bilinear), L: the minification filter (n, the default, or l;
/// m mipmaps: cpfg's GL_LINEAR_MIPMAP_LINEAR, `mXY` GL_X_MIPMAP_Y with n NEAREST and l
/// LINEAR, as textures.c reads them): each lookup uses the one its texel footprint calls
/// for (render::ImageMap), E: how the texture meets the surface's colour (m modulate, the
/// default: texture times colour, the texel's alpha the fragment's; d decal: the texture
/// laid over the colour by its alpha, the fragment opaque; b blend: OpenGL's GL_BLEND with
/// cpfg's texture environment colour, which it never sets, so GL's default black: the
/// colour times one minus the texel, the texel's alpha the fragment's), S: one image over
/// the whole surface instead of one per patch, R: the height/width ratio cpfg uses on
/// cylinders. The lines are numbered from
/// 1 in file order; `@Tx(n)` selects texture n for the surfaces `~X` drawn after it (on its
/// branch), and a `surface:` line's texture number overrides the turtle's (0: none).
///
/// Texture coordinates (s, t) run from (0, 0) at the image's bottom-left corner to (1, 1)
/// at its top-right, repeating outside [0, 1] (cpfg's GL_REPEAT).
///
/// Transparency (control.c: glAlphaFunc(GL_GREATER, 0.1), GL_BLEND with GL_SRC_ALPHA): a
/// fragment whose alpha is at or below 0.1 is left out, one above it is blended over what
/// lies behind by its alpha. The fragment's alpha is the texel's under modulate and blend
/// and 1 under decal (OpenGL's texture environment), so decal textures never cut out.
///
/// Mipmaps (textures.c: gluBuild2DMipmaps): an image whose sides are not powers of two is
/// first scaled to the nearest ones (GLU's nearestPower, 3 -> 4, 5 -> 4, 6 -> 8), then each
/// level halves the one before (a side of 1 stays 1) down to 1 x 1, every texel the mean
/// of the ones it covers, in the file's encoding (GLU averages the stored bytes). A lookup
/// of footprint ρ (texels per pixel) has λ = log2 ρ (OpenGL 2.1, 3.8.8): λ <= c magnifies
/// (c = 0.5 for H: l with a NEAREST_MIPMAP filter, else 0); otherwise MIPMAP_NEAREST takes
/// level ceil(λ + 1/2) - 1 (0 for λ <= 1/2) and MIPMAP_LINEAR mixes levels floor(λ) and
/// floor(λ) + 1 by the fraction of λ, both clamped to the last level, each level sampled
/// by the first letter's filter.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnostics.h"
#include "core/image.h"
#include "core/types.h"

namespace sprig::lsystem {

/// One `texture:` line of a view file, with its image read.
struct CpfgTexture {
  std::string file;                    ///< the image's path
  std::shared_ptr<const Image> image;  ///< linear RGB with straight (not premultiplied) alpha
  /// The error of an image that could not be read (image is null then). cpfg reads images
  /// only to draw (its -g mode reads none), so this error is given when a drawn organ takes
  /// the texture is rendered or exported, not when the view file is read.
  std::optional<Diagnostic> unreadable;
  bool magLinear = false;              ///< H: l (bilinear magnification); else nearest texel
  bool minLinear = false;              ///< L: l (bilinear minification); else nearest texel
                                       ///< (with mipmaps: the filter within a level)
  bool mipmap = false;                 ///< L: m...: minification through the mip levels
  bool mipLinear = false;              ///< L: m.l, m: mix the two nearest levels; else the nearest level
  bool decal = false;                  ///< E: d; else modulate (or blend)
  bool blend = false;                  ///< E: b (OpenGL's GL_BLEND)
  bool perSurface = false;             ///< S: one image over the whole surface
  double ratio = 1.0;                  ///< R: (cylinders; read, not used by surfaces)
  bool transparent = false;            ///< some texel has alpha below 1

  /// The mip levels after the image (level 1, 2, ... down to 1 x 1; level 0 is image),
  /// filled by buildMipmaps; empty without mipmaps.
  std::vector<std::shared_ptr<const Image>> levels;

  /// The texel at (s, t), repeating; RGBA, straight alpha. Filtered by the minification
  /// filter (`minLinear`) when `minified` (the lookup's pixel covers more than one texel),
  /// else by the magnification filter (`magLinear`): nearest texel or bilinear. Without
  /// mipmaps this is sampleFootprint with ρ > 1 for minified; with them, a minified
  /// lookup here takes level 0 through the minification filter.
  Vec4 sample(double s, double t, bool minified = false) const;
  /// The texel at (s, t) for a lookup whose pixel covers texelsPerPixel texels (GL's ρ;
  /// 0 or less magnifies): the magnification or minification filter, through the mip
  /// levels when `mipmap` (see the file comment).
  Vec4 sampleFootprint(double s, double t, double texelsPerPixel) const;
  /// Builds `levels` from image (cpfg's gluBuild2DMipmaps, see the file comment); an image
  /// whose sides are not powers of two is replaced by its scaled copy, GL's level 0.
  /// srgbFile: the file's values are sRGB-encoded (levels are averaged in that encoding).
  /// Throws std::runtime_error when OpenImageIO cannot resize.
  void buildMipmaps(bool srgbFile);
  /// The fragment of a surface of colour `base` with this texture at (s, t): modulate gives
  /// texel * base with the texel's alpha, decal base blended toward the texel by its alpha,
  /// alpha 1.
  Vec4 fragment(double s, double t, const Vec3& base, bool minified = false) const;
  /// The fragment from the texel texel (sample's or sampleFootprint's): modulate texel *
  /// base with the texel's alpha, decal base blended toward the texel by its alpha with
  /// alpha 1, blend base * (1 - texel) (cpfg's environment colour is GL's default black)
  /// with the texel's alpha.
  Vec4 combine(const Vec4& texel, const Vec3& base) const;
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
