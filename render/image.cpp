#include "render/image.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/atomic_file.h"

namespace sprig::render {

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

float linearToSrgb(float v) {
  if (!(v > 0.0f)) return 0.0f;
  if (v >= 1.0f) return 1.0f;
  return v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
}

std::vector<uint8_t> toSrgb8(const Image& image, int channels) {
  size_t n = static_cast<size_t>(image.width) * image.height;
  std::vector<uint8_t> out(n * channels);
  auto quantize = [](float v) { return static_cast<uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) out[i * channels + c] = quantize(linearToSrgb(image.pixels[i * 4 + c]));
    if (channels == 4) out[i * channels + 3] = quantize(image.pixels[i * 4 + 3]);
  }
  return out;
}

ImageFormat imageFormatFor(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".jpg" || ext == ".jpeg") return ImageFormat::Jpeg;
  if (ext == ".exr") return ImageFormat::Exr;
  throw std::invalid_argument("cannot write image '" + path.string() + "': unknown extension '" + ext +
                              "' (supported: .png, .jpg, .jpeg, .exr)");
}

void writeImage(const Image& image, const fs::path& path) {
  ImageFormat format = imageFormatFor(path);
  if (image.width <= 0 || image.height <= 0 || image.pixels.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw std::invalid_argument("cannot write image '" + path.string() + "': image is empty or malformed");
  fs::path dir = path.parent_path();
  if (!dir.empty() && !fs::is_directory(dir))
    throw std::runtime_error("cannot write image '" + path.string() + "': folder '" + dir.string() + "' does not exist");

  TempPath temp(path);
  auto out = OIIO::ImageOutput::create(temp.path().string());
  if (!out) throw std::runtime_error("cannot write image '" + path.string() + "': " + OIIO::geterror());
  bool ok = false;
  if (format == ImageFormat::Exr) {
    OIIO::ImageSpec spec(image.width, image.height, 4, OIIO::TypeDesc::HALF);
    spec.attribute("compression", "zip");
    ok = out->open(temp.path().string(), spec) &&
         out->write_image(OIIO::TypeDesc::FLOAT, image.pixels.data());
  } else {
    int channels = format == ImageFormat::Jpeg ? 3 : 4;
    std::vector<uint8_t> bytes = toSrgb8(image, channels);
    OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    if (format == ImageFormat::Jpeg) spec.attribute("CompressionQuality", 92);
    ok = out->open(temp.path().string(), spec) && out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  }
  std::string err = out->geterror();
  ok = out->close() && ok;
  if (!ok) throw std::runtime_error("cannot write image '" + path.string() + "': " + (err.empty() ? out->geterror() : err));
  temp.commit();
}

}  // namespace sprig::render
