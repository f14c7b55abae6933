#pragma once
/// The image file operations core/image.cpp needs from OpenImageIO, as a table of functions.
///
/// OpenImageIO brings some 250 shared libraries whose loading and relocation cost a
/// process about 0.15-0.25 s before main: the `sprig` binary therefore does not link it.
/// The table is implemented in backends/oiio_image.cpp and reached through imageBackend(),
/// which the program provides: every test, bench and fuzz target links the implementation
/// (backends/linked.cpp); the `sprig` binary loads libsprig_backends.so beside it on the
/// first call (backends/loader.cpp), so commands that touch no image file never pay for it.
///
/// Only standard types and plain structs cross the table: error messages come back as
/// strings, everything Sprig-specific (atomic temporaries, sRGB conversion, limits,
/// ImageReadError) stays in core/image.cpp.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace sprig::detail {

/// Element type of a pixel buffer or of the values a file holds.
enum class PixelType { UInt8, Half, Float };

/// What a still image file is written as.
struct ImageFileSpec {
  int width = 0;
  int height = 0;
  int channels = 0;
  PixelType fileType = PixelType::UInt8;
  std::string colorSpace;   ///< "oiio:ColorSpace" ("sRGB", "Linear"); empty = not set
  std::string compression;  ///< "compression" ("zip"); empty = the writer's default
  int quality = 0;          ///< "CompressionQuality" (JPEG); 0 = the writer's default
  int pngLevel = -1;        ///< "png:compressionLevel" (zlib 0-9); -1 = the writer's default (6)
};

/// What an image file's header says, uninterpreted.
struct ImageFileHeader {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::string colorSpace;        ///< "oiio:ColorSpace" as the file gives it ("" when absent)
  bool integer8or16 = false;     ///< values are 8- or 16-bit unsigned integers
};

/// An image file opened for reading.
class ImageFileReader {
 public:
  virtual ~ImageFileReader() = default;
  /// The file's header.
  virtual const ImageFileHeader& header() const = 0;
  /// Reads every pixel's header().channels values as `type` (UInt8 or Float) into out;
  /// false with the reader's message (possibly empty) in error. Closes the file.
  virtual bool read(PixelType type, void* out, std::string& error) = 0;
};

/// The image file operations. Every function is thread-safe.
struct ImageBackend {
  /// Writes width x height x channels values of dataType from data to path, as spec says
  /// (the format follows path's extension). False with the library's message (possibly
  /// empty) in error when it fails.
  bool (*write)(const std::string& path, const ImageFileSpec& spec, PixelType dataType, const void* data,
                std::string& error);
  /// Opens path for reading; null with the library's message (possibly empty) in error.
  std::unique_ptr<ImageFileReader> (*open)(const std::string& path, std::string& error);
  /// Resizes width x height pixels of 4 floats (in) to outWidth x outHeight (out, which
  /// holds 4 * outWidth * outHeight floats) with a box filter one output pixel wide (each
  /// output pixel the mean of the input pixels whose centres it covers). False with the
  /// library's message in error when it fails.
  bool (*resizeBox)(const float* in, int width, int height, float* out, int outWidth, int outHeight, std::string& error);
  /// Rasterizes text in the TrueType font fontFile at sizePixels (FreeType, through the
  /// library's text rendering): coverage receives width x height values in [0, 1], row-major,
  /// top row first, of a box holding every glyph, whose pixel (originX, originY) is where
  /// the text's baseline starts. False with the library's message (possibly empty) in error.
  bool (*textCoverage)(const std::string& text, const std::string& fontFile, int sizePixels, std::vector<float>& coverage,
                       int& width, int& height, int& originX, int& originY, std::string& error);
};

/// The image file operations of this program (see the file comment). Throws
/// std::runtime_error when the `sprig` binary cannot load libsprig_backends.so.
const ImageBackend& imageBackend();

}  // namespace sprig::detail
