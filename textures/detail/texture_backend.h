#pragma once
/// Filtered image texture lookups (OpenImageIO's TextureSystem) as a table of functions:
/// textures/image_texture.cpp's one dependency on OpenImageIO. Like core's image backend
/// (core/detail/image_backend.h, whose file comment says why), the table is implemented in
/// backends/ and reached through textureBackend(), which the program provides.

#include <string>

namespace sprig::textures::detail {

/// An image file registered with the texture system (opaque; lives as long as the process).
struct TextureHandle;

/// The texture system's operations. Every function is thread-safe.
struct TextureBackend {
  /// The handle of path (the file's header is read, its pixels on first lookup); null with
  /// the texture system's message in error when the file cannot be used.
  TextureHandle* (*handle)(const std::string& path, std::string& error);
  /// Filtered lookup of the first `channels` (1-3) channels at (s, t), both wrapping
  /// periodically, trilinear over mip levels, into out[0..channels).
  void (*lookup)(TextureHandle* texture, int channels, float s, float t, float dsdx, float dtdx, float dsdy, float dtdy,
                 float* out);
};

/// The texture operations of this program (core/detail/image_backend.h explains who
/// provides it). Throws std::runtime_error when the `sprig` binary cannot load
/// libsprig_backends.so.
const TextureBackend& textureBackend();

}  // namespace sprig::textures::detail
