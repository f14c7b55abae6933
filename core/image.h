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

/// How writeImage compresses what it writes.
struct ImageWriteOptions {
  /// zlib level of a PNG, 0 (stored) to 9 (smallest, slowest); -1: OpenImageIO's default,
  /// 6. Every level decodes to the same pixels; the files differ in size and in the time
  /// their encoding takes (docs/PERFORMANCE.md "The Murex's glb in 30 s").
  int pngLevel = -1;
};

/// Writes image atomically to path in the format its extension names.
/// Throws std::invalid_argument for an unknown extension or an empty or malformed image,
/// std::runtime_error when the folder is missing or the writer fails.
void writeImage(const Image& image, const std::filesystem::path& path,
                ImageEncoding encoding = ImageEncoding::Picture, const ImageWriteOptions& options = {});

/// The byte the TextureMap encoding stores for a linear colour value in an 8-bit file, as
/// OpenImageIO 2.4 (Debian's build) makes it from writeImage's float: s =
/// float(linearToSrgb(double(linear))), y = s·255 in float, round(y) (half away from zero)
/// clamped to [0, 255]; NaN gives 0. OpenImageIO converts the last (up to 3) values of each
/// chunk of a row one by one, as int(y + 0.5f) clamped, where the chunks follow its thread
/// count; the two roundings differ for one float y alone, 0.49999997f, which one linear float
/// alone gives, 0x1.3e4566p-13 (both checked over every float): 0 here, 1 in such a place.
/// Cost: a binary search over the 255 values where the byte steps up (found once, by this
/// formula), no pow(); the same bytes as the formula for every float (checked over all).
uint8_t textureMapByte(float linear);
/// The byte the Data encoding stores: lround(255·v) of v clamped to [0, 1].
uint8_t dataByte(float v);

/// An image as an 8-bit file holds it: `channels` bytes per pixel (3: RGB; 4: RGBA), row-major
/// from the top-left pixel, each the very byte the PNG stores, in `encoding`'s meaning:
/// TextureMap colour bytes from textureMapByte, Data bytes from dataByte, Picture bytes
/// from toSrgb8 (alpha linear). An RGB texel takes 3 bytes where Image takes 16: export
/// atlases and normal maps are baked straight into it (model/mesh_parts.h bakeAtlases),
/// converted once, and written without another pass.
struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  ImageEncoding encoding = ImageEncoding::TextureMap;
  std::vector<uint8_t> values;  ///< channels · width · height bytes

  Image8() = default;
  /// A w x h image of `channels` (3 or 4) zero bytes per pixel, in encoding.
  Image8(int w, int h, int channels, ImageEncoding encoding);
  bool empty() const { return values.empty(); }
  /// Sets pixel (x, y) to the bytes of linear colour rgb (alpha 1 where there are 4
  /// channels) in the image's encoding; no bounds check.
  void set(int x, int y, const Vec3& rgb);
  /// Pixel (x, y) decoded to linear values: colour srgbToLinear(byte / 255) in TextureMap and
  /// Picture, byte / 255 in Data; alpha byte / 255, 1 without an alpha channel. No bounds check.
  Vec4 at(int x, int y) const;
};

/// image's 8-bit values in encoding: the bytes writeImage(image, "X.png", encoding) stores
/// (Picture: RGBA). O(pixels).
Image8 toImage8(const Image& image, ImageEncoding encoding);

/// Writes an 8-bit image atomically as a PNG (path must end in .png) holding its values as
/// they are: the file writeImage writes for the float image they were made from (its colour
/// space tag too: sRGB for TextureMap and Picture, none for Data). Throws as writeImage, and
/// std::invalid_argument for another extension.
void writeImage(const Image8& image, const std::filesystem::path& path, const ImageWriteOptions& options = {});

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
