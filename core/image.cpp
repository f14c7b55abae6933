#include "core/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/paths.h"
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

std::vector<uint8_t> toSrgb8(const Image& image, int channels) {
  size_t n = static_cast<size_t>(image.width) * image.height;
  std::vector<uint8_t> out(n * channels);
  auto quantize = [](float v) {
    return v > 0.0f ? static_cast<uint8_t>(std::lround(std::min(v, 1.0f) * 255.0f)) : uint8_t{0};
  };
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

/// Opens out on path with spec, writes pixels of type `type`, closes; false on any failure
/// with the writer's first error in `error`.
bool writeOne(OIIO::ImageOutput& out, const fs::path& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
              const void* pixels, std::string& error) {
  bool ok = out.open(path.string(), spec) && out.write_image(type, pixels);
  error = out.geterror();
  ok = out.close() && ok;
  if (error.empty()) error = out.geterror();
  return ok;
}

}  // namespace

void writeImage(const Image& image, const fs::path& path, ImageEncoding encoding) {
  const ImageFormat format = imageFormatFor(path);
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw std::invalid_argument("cannot write image '" + path.string() + "': image is empty or malformed");
  const fs::path dir = path.parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw std::runtime_error("cannot write image '" + path.string() + "': folder '" + dir.string() + "' does not exist");

  TempPath temp(path);
  auto out = OIIO::ImageOutput::create(temp.path().string());
  if (!out) throw std::runtime_error("cannot write image '" + path.string() + "': " + OIIO::geterror());
  std::string error;
  bool ok = false;
  if (encoding == ImageEncoding::TextureMap) {
    // RGB floats (sRGB-encoded in double for 8-bit files); OIIO converts to the file type.
    const bool linear = format == ImageFormat::Exr;
    const size_t n = static_cast<size_t>(image.width) * image.height;
    std::vector<float> rgb(n * 3);
    for (size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const float v = image.pixels[i * 4 + c];
        rgb[i * 3 + c] = linear ? v : static_cast<float>(linearToSrgb(static_cast<double>(v)));
      }
    OIIO::ImageSpec spec(image.width, image.height, 3, linear ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", linear ? "Linear" : "sRGB");
    ok = writeOne(*out, temp.path(), spec, OIIO::TypeDesc::FLOAT, rgb.data(), error);
  } else if (format == ImageFormat::Exr) {
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::HALF);
    spec.attribute("compression", "zip");
    ok = writeOne(*out, temp.path(), spec, OIIO::TypeDesc::FLOAT, image.pixels.data(), error);
  } else {
    const int channels = format == ImageFormat::Jpeg ? 3 : 4;
    const std::vector<uint8_t> bytes = toSrgb8(image, channels);
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    if (format == ImageFormat::Jpeg) spec.attribute("CompressionQuality", 92);
    ok = writeOne(*out, temp.path(), spec, OIIO::TypeDesc::UINT8, bytes.data(), error);
  }
  if (!ok) throw std::runtime_error("cannot write image '" + path.string() + "': " + error);
  temp.commit();
}

void writeAnimatedGif(const std::vector<Image>& frames, double fps, const fs::path& path) {
  if (frames.empty()) throw std::runtime_error(path.string() + ": no frames to write");
  TempPath tmp(path);
  {
    auto writer = OIIO::ImageOutput::create(tmp.path().string());
    if (!writer) throw std::runtime_error(path.string() + ": cannot write GIF: " + OIIO::geterror());
    OIIO::ImageSpec spec(frames.front().width, frames.front().height, 3, OIIO::TypeDesc::UINT8);
    // GIF frame delays are centiseconds: FramesPerSecond as the rational 100 / delay.
    const int delayCs = std::max(1, static_cast<int>(std::lround(100.0 / std::max(fps, 0.01))));
    const int rate[2] = {100, delayCs};
    spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
    spec.attribute("oiio:LoopCount", 0);
    for (size_t i = 0; i < frames.size(); ++i) {
      const auto mode = i == 0 ? OIIO::ImageOutput::Create : OIIO::ImageOutput::AppendSubimage;
      if (!writer->open(tmp.path().string(), spec, mode))
        throw std::runtime_error(path.string() + ": cannot write GIF: " + writer->geterror());
      const std::vector<uint8_t> bytes = toSrgb8(frames[i], 3);
      if (!writer->write_image(OIIO::TypeDesc::UINT8, bytes.data()))
        throw std::runtime_error(path.string() + ": cannot write GIF frame: " + writer->geterror());
    }
    if (!writer->close()) throw std::runtime_error(path.string() + ": cannot write GIF: " + writer->geterror());
  }
  tmp.commit();
}

ImageReadError::ImageReadError(const fs::path& path, std::string reason)
    : std::runtime_error("cannot read image '" + path.string() + "': " + reason), reason_(std::move(reason)) {}

namespace {

/// The opened file, or ImageReadError with OIIO's message.
std::unique_ptr<OIIO::ImageInput> openInput(const fs::path& path) {
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    const std::string err = OIIO::geterror();
    throw ImageReadError(path, err.empty() ? "not an image OpenImageIO can read" : err);
  }
  return in;
}

ImageInfo infoOf(const OIIO::ImageSpec& spec) {
  ImageInfo info;
  info.width = spec.width;
  info.height = spec.height;
  info.channels = spec.nchannels;
  const std::string cs = asciiLower(spec.get_string_attribute("oiio:ColorSpace"));
  const bool integer = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  info.srgb = cs == "srgb" || (cs.empty() && integer);
  return info;
}

}  // namespace

ImageInfo readImageInfo(const fs::path& path) {
  auto in = openInput(path);
  ImageInfo info = infoOf(in->spec());
  in->close();
  return info;
}

Image readImage(const fs::path& path) {
  auto in = openInput(path);
  const ImageInfo info = infoOf(in->spec());
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
  if (info.srgb) {
    std::vector<uint8_t> bytes(n * nc);
    ok = in->read_image(0, 0, 0, nc, OIIO::TypeDesc::UINT8, bytes.data());
    for (size_t i = 0; i < values.size(); ++i) values[i] = bytes[i] / 255.0f;
  } else {
    ok = in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, values.data());
  }
  const std::string err = in->geterror();
  in->close();
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
