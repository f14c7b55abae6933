#include "core/image.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "core/atomic_file.h"
#include "core/diagnostics.h"
#include "core/detail/image_backend.h"
#include "core/gif_encoder.h"
#include "core/paths.h"
#include "core/phases.h"
#include "core/srgb.h"

namespace sprig {

namespace fs = std::filesystem;

Image::Image(int w, int h, Vec4 fill) : width(w), height(h), pixels(static_cast<size_t>(w) * h * 4) {
  for (size_t i = 0; i < pixels.size(); i += 4) {
    pixels[i] = fill.r;
    pixels[i + 1] = fill.g;
    pixels[i + 2] = fill.b;
    pixels[i + 3] = fill.a;
  }
}

Vec4 Image::at(int x, int y) const {
  size_t i = (static_cast<size_t>(y) * width + x) * 4;
  return {pixels[i], pixels[i + 1], pixels[i + 2], pixels[i + 3]};
}

void Image::set(int x, int y, const Vec4& v) {
  size_t i = (static_cast<size_t>(y) * width + x) * 4;
  pixels[i] = v.r;
  pixels[i + 1] = v.g;
  pixels[i + 2] = v.b;
  pixels[i + 3] = v.a;
}

namespace {

// toSrgb8's rounding of a value in [0, 1] (NaN gives 0).
uint8_t quantize(float v) { return v > 0.0f ? static_cast<uint8_t>(std::lround(std::min(v, 1.0f) * 255.0f)) : uint8_t{0}; }

// toSrgb8's byte of a linear colour value.
uint8_t toSrgb8(float linear) { return quantize(linearToSrgb(linear)); }

}  // namespace

std::vector<uint8_t> toSrgb8(const Image& image, int channels) {
  size_t n = static_cast<size_t>(image.width) * image.height;
  std::vector<uint8_t> out(n * channels);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) out[i * channels + c] = quantize(linearToSrgb(image.pixels[i * 4 + c]));
    if (channels == 4) out[i * channels + 3] = quantize(image.pixels[i * 4 + 3]);
  }
  return out;
}

ImageFormat imageFormatFor(const fs::path& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return ImageFormat::Jpeg;
  if (ext == ".exr") return ImageFormat::Exr;
  throw std::invalid_argument("cannot write image '" + path.string() + "': unknown extension '" + ext +
                              "' (supported: .png, .jpg, .jpeg, .exr)");
}

namespace {

// textureMapByte by its definition: a pow() per value.
uint8_t textureMapByteOf(float linear) {
  const float y = static_cast<float>(linearToSrgb(static_cast<double>(linear))) * 255.0f;
  if (std::isnan(y)) return 0;
  return static_cast<uint8_t>(std::clamp(std::round(y), 0.0f, 255.0f));
}

// thresholds[k - 1]: the least float in [0, 1] whose textureMapByteOf is at least k. The
// byte never decreases as the value grows (every step of it is monotone), so a value's byte
// is the number of thresholds at or below it.
const std::array<float, 255>& textureMapThresholds() {
  static const std::array<float, 255> thresholds = [] {
    std::array<float, 255> t{};
    auto bitsOf = [](float f) { uint32_t b = 0; std::memcpy(&b, &f, 4); return b; };
    auto floatOf = [](uint32_t b) { float f = 0; std::memcpy(&f, &b, 4); return f; };
    for (int k = 1; k <= 255; ++k) {
      uint32_t lo = bitsOf(0.0f), hi = bitsOf(1.0f);  // positive floats order as their bits
      while (lo < hi) {
        const uint32_t mid = lo + (hi - lo) / 2;
        if (textureMapByteOf(floatOf(mid)) >= k) hi = mid; else lo = mid + 1;
      }
      t[size_t(k - 1)] = floatOf(lo);
    }
    return t;
  }();
  return thresholds;
}

}  // namespace

uint8_t textureMapByte(float linear) {
  if (std::isnan(linear)) return 0;
  const std::array<float, 255>& t = textureMapThresholds();
  return static_cast<uint8_t>(std::upper_bound(t.begin(), t.end(), linear) - t.begin());
}

uint8_t dataByte(float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

Image8::Image8(int w, int h, int c, ImageEncoding e)
    : width(w), height(h), channels(c), encoding(e), values(static_cast<size_t>(w) * h * c, 0) {}

void Image8::set(int x, int y, const Vec3& rgb) {
  uint8_t* p = &values[(static_cast<size_t>(y) * width + x) * channels];
  for (int c = 0; c < 3; ++c)
    p[c] = encoding == ImageEncoding::Data         ? dataByte(rgb[c])
           : encoding == ImageEncoding::TextureMap ? textureMapByte(rgb[c])
                                                   : toSrgb8(rgb[c]);
  if (channels == 4) p[3] = 255;
}

Vec4 Image8::at(int x, int y) const {
  const uint8_t* p = &values[(static_cast<size_t>(y) * width + x) * channels];
  Vec4 v(0.0f, 0.0f, 0.0f, channels == 4 ? p[3] / 255.0f : 1.0f);
  for (int c = 0; c < 3; ++c) v[c] = encoding == ImageEncoding::Data ? p[c] / 255.0f : srgbToLinear(p[c] / 255.0f);
  return v;
}

Image8 toImage8(const Image& image, ImageEncoding encoding) {
  const int channels = encoding == ImageEncoding::Picture ? 4 : 3;
  Image8 out(image.width, image.height, channels, encoding);
  if (encoding == ImageEncoding::Picture) {
    out.values = toSrgb8(image, 4);
    return out;
  }
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) out.set(x, y, Vec3(image.at(x, y)));
  return out;
}

void writeImage(const Image8& image, const fs::path& path, const ImageWriteOptions& options) {
  const Phase phase("write");
  if (imageFormatFor(path) != ImageFormat::Png)
    throw std::invalid_argument("cannot write image '" + path.string() + "': an 8-bit image is written as .png");
  if (image.width <= 0 || image.height <= 0 || (image.channels != 3 && image.channels != 4) ||
      image.values.size() != static_cast<size_t>(image.width) * image.height * image.channels)
    throw std::invalid_argument("cannot write image '" + path.string() + "': image is empty or malformed");
  const fs::path dir = path.parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw std::runtime_error("cannot write image '" + path.string() + "': folder '" + dir.string() + "' does not exist");
  TempPath temp(path);
  detail::ImageFileSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  spec.channels = image.channels;
  spec.fileType = detail::PixelType::UInt8;
  if (image.encoding != ImageEncoding::Data) spec.colorSpace = "sRGB";
  spec.pngLevel = options.pngLevel;
  std::string error;
  if (!detail::imageBackend().write(temp.path().string(), spec, detail::PixelType::UInt8, image.values.data(), error))
    throw std::runtime_error("cannot write image '" + path.string() + "': " + error);
  temp.commit();
}

void writeImage(const Image& image, const fs::path& path, ImageEncoding encoding, const ImageWriteOptions& options) {
  const Phase phase("write");
  const ImageFormat format = imageFormatFor(path);
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw std::invalid_argument("cannot write image '" + path.string() + "': image is empty or malformed");
  const fs::path dir = path.parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw std::runtime_error("cannot write image '" + path.string() + "': folder '" + dir.string() + "' does not exist");

  using detail::PixelType;
  TempPath temp(path);
  detail::ImageFileSpec spec;
  spec.width = image.width;
  spec.height = image.height;
  if (format == ImageFormat::Png) spec.pngLevel = options.pngLevel;
  std::string error;
  bool ok = false;
  const detail::ImageBackend& io = detail::imageBackend();
  if (encoding == ImageEncoding::Data && format != ImageFormat::Exr) {
    const size_t n = static_cast<size_t>(image.width) * image.height;
    std::vector<uint8_t> rgb(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c)
        rgb[i * 3 + c] = static_cast<uint8_t>(std::lround(std::clamp(image.pixels[i * 4 + c], 0.0f, 1.0f) * 255.0f));
    spec.channels = 3;
    spec.fileType = PixelType::UInt8;
    ok = io.write(temp.path().string(), spec, PixelType::UInt8, rgb.data(), error);
  } else if (encoding != ImageEncoding::Picture) {
    // RGB floats (sRGB-encoded in double for 8-bit files); the writer converts to the file type.
    const bool linear = format == ImageFormat::Exr;
    const size_t n = static_cast<size_t>(image.width) * image.height;
    std::vector<float> rgb(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = image.pixels[i * 4 + c];
        rgb[i * 3 + c] = linear ? v : static_cast<float>(linearToSrgb(static_cast<double>(v)));
      }
    spec.channels = 3;
    spec.fileType = linear ? PixelType::Half : PixelType::UInt8;
    spec.colorSpace = linear ? "Linear" : "sRGB";
    ok = io.write(temp.path().string(), spec, PixelType::Float, rgb.data(), error);
  } else if (format == ImageFormat::Exr) {
    spec.channels = 4;
    spec.fileType = PixelType::Half;
    spec.compression = "zip";
    ok = io.write(temp.path().string(), spec, PixelType::Float, image.pixels.data(), error);
  } else {
    spec.channels = format == ImageFormat::Jpeg ? 3 : 4;
    spec.fileType = PixelType::UInt8;
    spec.colorSpace = "sRGB";
    if (format == ImageFormat::Jpeg) spec.quality = 92;
    const std::vector<uint8_t> bytes = toSrgb8(image, spec.channels);
    ok = io.write(temp.path().string(), spec, PixelType::UInt8, bytes.data(), error);
  }
  if (!ok) throw std::runtime_error("cannot write image '" + path.string() + "': " + error);
  temp.commit();
}

void writeAnimatedGif(const std::vector<Image>& frames, double fps, const fs::path& path) {
  if (frames.empty()) throw std::runtime_error(path.string() + ": no frames to write");
  // GIF frame delays are centiseconds.
  const int delayCs = std::max(1, static_cast<int>(std::lround(100.0 / std::max(fps, 0.01))));
  const Image& first = frames.front();
  for (const Image& f : frames)
    if (f.width != first.width || f.height != first.height)
      throw std::runtime_error(path.string() + ": GIF frames of different sizes");
  writeFileAtomic(path, encodeGif(first.width, first.height, delayCs, frames.size(),
                                  [&](size_t i) { return toSrgb8(frames[i], 3); }));
}

ImageReadError::ImageReadError(const fs::path& path, std::string reason)
    : std::runtime_error("cannot read image '" + path.string() + "': " + reason), reason_(std::move(reason)) {}

namespace {

/// The opened file, or ImageReadError with the reader's message.
std::unique_ptr<detail::ImageFileReader> openInput(const fs::path& path) {
  // The image library opens the file itself: only a regular file is handed to it (a FIFO would block it).
  if (std::string reason = notRegularFileReason(path); !reason.empty()) throw ImageReadError(path, reason);
  std::string err;
  std::unique_ptr<detail::ImageFileReader> in = detail::imageBackend().open(path.string(), err);
  if (!in) throw ImageReadError(path, err.empty() ? "not an image OpenImageIO can read" : err);
  return in;
}

ImageInfo infoOf(const detail::ImageFileHeader& header) {
  ImageInfo info;
  info.width = header.width;
  info.height = header.height;
  info.channels = header.channels;
  const std::string cs = asciiLower(header.colorSpace);
  info.srgb = cs == "srgb" || (cs.empty() && header.integer8or16);
  return info;
}

}  // namespace

ImageInfo readImageInfo(const fs::path& path) { return infoOf(openInput(path)->header()); }

Image resizeImage(const Image& image, int width, int height) {
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw std::invalid_argument("cannot resize an empty or malformed image");
  if (width < 1 || height < 1)
    throw std::invalid_argument("cannot resize an image to " + std::to_string(width) + " x " + std::to_string(height) + " pixels");
  Image out(width, height);
  std::string error;
  if (!detail::imageBackend().resizeBox(image.pixels.data(), image.width, image.height, out.pixels.data(), width, height, error))
    throw std::runtime_error("cannot resize an image: " + error);
  return out;
}

void drawText(Image& image, int x, int y, const std::string& text, const Vec3& srgbColor, const std::string& fontFile,
              int sizePixels) {
  if (text.empty()) return;
  std::error_code ec;
  if (!fs::is_regular_file(fontFile, ec))
    throw InputError(SourceLoc{"sprig", 0, 0}, "the font file '" + fontFile +
                                                   "' of the labels is missing (Debian's package fonts-dejavu-core has it; "
                                                   "scripts/install-deps.sh installs it)");
  std::vector<float> coverage;
  int w = 0, h = 0, ox = 0, oy = 0;
  std::string error;
  if (!detail::imageBackend().textCoverage(text, fontFile, std::max(1, sizePixels), coverage, w, h, ox, oy, error))
    throw std::runtime_error("cannot draw the text '" + text.substr(0, 40) + "': " + error);
  for (int j = 0; j < h; ++j) {
    const int py = y - oy + j;
    if (py < 0 || py >= image.height) continue;
    for (int i = 0; i < w; ++i) {
      const int px = x - ox + i;
      const float a = std::clamp(coverage[static_cast<size_t>(j) * w + i], 0.0f, 1.0f);
      if (px < 0 || px >= image.width || a <= 0.0f) continue;
      float* p = &image.pixels[(static_cast<size_t>(py) * image.width + px) * 4];
      for (int c = 0; c < 3; ++c)
        p[c] = srgbToLinear(linearToSrgb(std::clamp(p[c], 0.0f, 1.0f)) * (1.0f - a) + srgbColor[c] * a);
    }
  }
}

Image readImage(const fs::path& path) {
  auto in = openInput(path);
  const ImageInfo info = infoOf(in->header());
  const int w = info.width, h = info.height, nc = info.channels;
  if (w <= 0 || h <= 0 || nc <= 0) throw ImageReadError(path, "empty image");
  // Checked before the pixels are allocated: a 40-byte header may claim 65535 x 65535.
  if (uint64_t(w) * uint64_t(h) > kMaxImagePixels)
    throw ImageReadError(path, "the image is " + std::to_string(w) + " x " + std::to_string(h) + ", more than the limit of " +
                                   std::to_string(kMaxImagePixels) + " pixels (8192 x 8192)");
  if (nc > kMaxImageChannels)
    throw ImageReadError(path, "the image has " + std::to_string(nc) + " channels, more than " + std::to_string(kMaxImageChannels));
  const size_t n = static_cast<size_t>(w) * h;
  std::vector<float> values(n * nc);
  bool ok = false;
  std::string err;
  if (info.srgb) {
    std::vector<uint8_t> bytes(n * nc);
    ok = in->read(detail::PixelType::UInt8, bytes.data(), err);
    for (size_t i = 0; i < values.size(); ++i) values[i] = bytes[i] / 255.0f;
  } else {
    ok = in->read(detail::PixelType::Float, values.data(), err);
  }
  if (!ok) throw ImageReadError(path, err.empty() ? "cannot read its pixels" : err);

  const int colors = nc >= 3 ? 3 : 1;
  const bool hasAlpha = nc == 2 || nc >= 4;
  const int alphaChannel = nc == 2 ? 1 : 3;
  Image img(w, h);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &values[i * nc];
    for (int c = 0; c < 3; ++c) {
      const float v = p[colors == 3 ? c : 0];
      img.pixels[i * 4 + c] = info.srgb ? srgbToLinear(v) : v;
    }
    img.pixels[i * 4 + 3] = hasAlpha ? p[alphaChannel] : 1.0f;
  }
  return img;
}

}  // namespace sprig
