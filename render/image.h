#pragma once
/// Float RGBA images in linear light and their output through OpenImageIO.
///
/// Pixels are stored row-major from the top-left, four floats each (linear RGB and
/// alpha, not premultiplied). PNG and JPEG receive 8-bit sRGB (JPEG drops alpha), EXR
/// receives linear half floats. Every write is atomic: a temporary file beside the
/// destination is renamed into place only after the writer closed it successfully.

#include <cstdint>
#include <filesystem>
#include <vector>

#include "core/types.h"

namespace sprig::render {

/// A width x height image of linear RGBA floats.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< 4 * width * height floats, row-major, top row first

  Image() = default;
  /// An image filled with `fill`.
  Image(int w, int h, Vec4 fill = Vec4(0, 0, 0, 1));

  /// Pixel (x, y), (0, 0) top-left; no bounds check.
  Vec4 at(int x, int y) const;
  /// Sets pixel (x, y); no bounds check.
  void set(int x, int y, const Vec4& v);
};

/// Linear to sRGB transfer (IEC 61966-2-1), input clamped to [0, 1].
float linearToSrgb(float v);

/// 8-bit sRGB bytes with `channels` (3 or 4) per pixel; alpha is stored linearly.
std::vector<uint8_t> toSrgb8(const Image& image, int channels);

/// Output encodings chosen from the file extension.
enum class ImageFormat {
  Png,   ///< 8-bit sRGB RGBA
  Jpeg,  ///< 8-bit sRGB RGB, quality 92
  Exr,   ///< linear half-float RGBA, zip compression
};

/// Format for a path's extension (.png, .jpg/.jpeg, .exr; case-insensitive).
/// Throws std::invalid_argument naming the extension and the supported ones.
ImageFormat imageFormatFor(const std::filesystem::path& path);

/// Writes image atomically to path in the format its extension names.
/// Throws std::invalid_argument for an unknown extension, std::runtime_error when the
/// folder is missing or the writer fails; the destination is then left untouched.
void writeImage(const Image& image, const std::filesystem::path& path);

}  // namespace sprig::render
