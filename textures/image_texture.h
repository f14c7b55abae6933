#pragma once
/// Image textures through OpenImageIO's TextureSystem: mip-mapped, filtered lookups.
///
/// This is texture filtering, not image file I/O: reading and writing image files is
/// core/image.h's alone (the header probe in open() goes through readImageInfo there). The
/// TextureSystem itself is reached through textures/detail/texture_backend.h, implemented in
/// backends/oiio_texture.cpp.
///
/// One process-wide TextureSystem (OIIO's shared instance, thread-safe) serves every
/// ImageTexture; untiled images are mip-mapped on first use ("automip"). Coordinates are
/// OIIO's (s, t): u = 0 is the image's left edge, v = 0 its top row, and both wrap
/// periodically. 8-bit sRGB files (PNG, JPEG) are converted to linear after filtering;
/// float files (EXR) are taken as linear already. Gray images give gray RGB.

#include <memory>
#include <string>

#include "core/diagnostics.h"
#include "core/types.h"

namespace sprig::textures {

/// A handle to one image file in the shared texture system. Cheap to copy; thread-safe.
class ImageTexture {
 public:
  /// Opens `path` and reads its header. A missing or unreadable file throws InputError at
  /// `where` (the location of the value that named the file, e.g. a species file's
  /// `texture:` entry): "cannot read texture 'PATH': REASON".
  static ImageTexture open(const std::string& path, const SourceLoc& where);

  /// Filtered color at (u, v). duvdx/duvdy are the lookup footprint (change of uv per
  /// pixel along x and y); zero means the finest mip level with bilinear filtering.
  Vec3 color(Vec2 uv, Vec2 duvdx = Vec2(0), Vec2 duvdy = Vec2(0)) const;

  /// Width of the file's finest level, in pixels.
  int width() const;
  /// Height of the file's finest level, in pixels.
  int height() const;
  /// Channels in the file (1 gray, 3 RGB, 4 RGBA, ...); lookups use the first three.
  int channels() const;
  /// True when the file's values are sRGB-encoded (converted to linear on lookup).
  bool srgb() const;
  /// The path given to open().
  const std::string& path() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace sprig::textures
