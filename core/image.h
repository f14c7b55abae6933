#pragma once
/// Sprig's one image type and all of its file I/O (the only OpenImageIO still-image code;
/// GIFs through Sprig's encoder, core/gif_encoder.h; textures/image_texture.cpp uses OIIO's
/// TextureSystem for filtered lookups).
///
/// An Image holds linear-light RGBA floats, not premultiplied, row-major from the top-left
/// pixel: the renderer writes it, the gallery composes it, textures bake into it. Files:
/// PNG and JPEG hold 8-bit sRGB (JPEG drops alpha), EXR holds linear half floats, GIF
/// animations hold 8-bit sRGB RGB frames. Every write is atomic (core/atomic_file.h): a
/// temporary file beside the destination is renamed into place only after the writer
/// closed it successfully, so a failed write leaves the destination untouched.

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/types.h"

namespace sprig {

/// A width x height image of linear RGBA floats.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< 4 * width * height floats, row-major, top row first

  Image() = default;
  /// An image of w x h pixels, each `fill`.
  Image(int w, int h, Vec4 fill = Vec4(0, 0, 0, 1));

  /// Pixel (x, y), (0, 0) top-left; no bounds check.
  Vec4 at(int x, int y) const;
  /// Sets pixel (x, y); no bounds check.
  void set(int x, int y, const Vec4& v);
};

/// 8-bit bytes with `channels` (3 or 4) per pixel: color through linearToSrgb(float),
/// alpha stored linearly; each value clamped to [0, 1] (NaN gives 0) and rounded with lround.
std::vector<uint8_t> toSrgb8(const Image& image, int channels);

/// Still-image file formats, chosen from the file extension.
enum class ImageFormat {
  Png,   ///< 8-bit sRGB
  Jpeg,  ///< 8-bit sRGB RGB
  Exr,   ///< linear half floats
};

/// Format for a path's extension (.png, .jpg/.jpeg, .exr; case-insensitive).
/// Throws std::invalid_argument naming the path, the extension and the supported ones.
ImageFormat imageFormatFor(const std::filesystem::path& path);

/// How writeImage turns an Image into file values. The two encodings exist so that
/// renders and the shipped texture maps keep the bytes they were made with.
enum class ImageEncoding {
  /// Rendered pictures: RGBA (JPEG: RGB, quality 92); 8-bit values from toSrgb8; EXR
  /// with zip compression.
  Picture,
  /// Texture maps: RGB only; 8-bit values are linearToSrgb(double) of each channel,
  /// rounded by OpenImageIO; files tagged sRGB (8-bit) or Linear (EXR); OIIO's default
  /// compression and JPEG quality.
  TextureMap,
  /// Data maps (tangent-space normal maps): RGB only; 8-bit values are round(255·v) of
  /// each channel clamped to [0,1], no sRGB curve and no colour-space tag (PNG, JPEG); EXR
  /// as TextureMap.
  Data,
};

/// Writes image atomically to path in the format its extension names.
/// Throws std::invalid_argument for an unknown extension or an empty or malformed image,
/// std::runtime_error when the folder is missing or the writer fails.
void writeImage(const Image& image, const std::filesystem::path& path,
                ImageEncoding encoding = ImageEncoding::Picture);

/// Writes frames (all of one size) as an animated GIF that loops forever (oiio:LoopCount
/// 0), each frame shown round(100 / fps) centiseconds, colour bytes from toSrgb8, through
/// Sprig's encoder (core/gif_encoder.h: a palette per frame by median cut over distinct
/// colours, dithered). Atomic. Throws std::runtime_error when there are no frames, the
/// frames differ in size, or the file cannot be written.
void writeAnimatedGif(const std::vector<Image>& frames, double fps, const std::filesystem::path& path);

/// A file that could not be read as an image. what() is "cannot read image 'PATH':
/// REASON"; reason() is REASON alone.
class ImageReadError : public std::runtime_error {
 public:
  /// An error about path for reason.
  ImageReadError(const std::filesystem::path& path, std::string reason);
  /// Why the file could not be read (OpenImageIO's message, or Sprig's own).
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

/// What an image file's header says.
struct ImageInfo {
  int width = 0;
  int height = 0;
  int channels = 0;
  /// Values are sRGB-encoded: the file says so (oiio:ColorSpace "sRGB", any case), or it
  /// names no color space and holds 8- or 16-bit integers.
  bool srgb = false;
};

/// Reads the header of an image file (not its pixels). Throws ImageReadError when the file
/// is not an image OpenImageIO can open.
ImageInfo readImageInfo(const std::filesystem::path& path);

/// Most pixels an image file may hold to be read (readImage): 2^26, 8192 x 8192.
inline constexpr uint64_t kMaxImagePixels = uint64_t(1) << 26;
/// Most channels an image file may hold to be read.
inline constexpr int kMaxImageChannels = 16;

/// Writes text over image as a window system draws screen text: the glyphs of fontFile (a
/// TrueType file, rasterized by FreeType through OpenImageIO's ImageBufAlgo::render_text)
/// at sizePixels (the em), the baseline starting at pixel (x, y) (x right, y down), in
/// srgbColor (the colour the image file shows), each pixel blended with the glyphs'
/// coverage in sRGB values; what falls outside the image is clipped. Throws InputError
/// (`sprig: error: ...`) when fontFile does not exist, std::runtime_error when the text
/// cannot be rasterized. Cost: the text's box of pixels.
void drawText(Image& image, int x, int y, const std::string& text, const Vec3& srgbColor, const std::string& fontFile,
              int sizePixels);

/// image resized to width x height by OpenImageIO's ImageBufAlgo::resize with a box filter
/// one output pixel wide: each output pixel is the mean of the input pixels whose centres
/// it covers (halving a dimension averages pairs of pixels exactly), channel by channel,
/// in the values as stored (no sRGB decoding, no alpha weighting). Throws
/// std::invalid_argument for an empty or malformed image or a size below 1,
/// std::runtime_error when OpenImageIO fails.
Image resizeImage(const Image& image, int width, int height);

/// Reads an image file into linear RGBA. sRGB files (ImageInfo::srgb) are read as 8-bit
/// values, color decoded with srgbToLinear(float) of value / 255 and alpha taken as
/// value / 255; other files are read as floats and taken as linear. A gray file gives gray
/// RGB; alpha is 1 where the file has none. Alpha follows OpenImageIO's default: color
/// comes back multiplied by alpha (its PNG writer divides color by alpha), so an image whose
/// color is already premultiplied, as the renderer's is, survives a PNG round trip.
/// Throws ImageReadError when the file cannot be read or exceeds kMaxImagePixels or
/// kMaxImageChannels (checked from the header, before the pixels are allocated).
Image readImage(const std::filesystem::path& path);

}  // namespace sprig
