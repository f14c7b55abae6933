#include "textures/registry.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/parallel.h"

namespace sprig::textures {

TextureId TextureRegistry::add(Texture texture) {
  textures_.push_back(std::move(texture));
  return static_cast<TextureId>(textures_.size() - 1);
}

TextureId TextureRegistry::addImage(const std::string& path, const SourceLoc& where) {
  return add(ImageTexture::open(path, where));
}

Vec3 TextureRegistry::color(TextureId id, Vec2 uv, const Vec3& position) const {
  const Texture& t = textures_.at(id);
  return std::visit(
      [&](const auto& tex) -> Vec3 {
        using T = std::decay_t<decltype(tex)>;
        if constexpr (std::is_same_v<T, ConstantTexture>) {
          return tex.color;
        } else if constexpr (std::is_same_v<T, NoiseTexture>) {
          return tex.options().solid ? tex.color(DVec3(position)) : tex.color(uv);
        } else {
          return tex.color(uv);
        }
      },
      t);
}

ImageRgb bake(const TextureRegistry& registry, TextureId id, int width, int height) {
  ImageRgb img;
  img.width = std::max(0, width);
  img.height = std::max(0, height);
  img.rgb.assign(static_cast<size_t>(img.width) * img.height * 3, 0.0f);
  parallelFor(0, static_cast<size_t>(img.height), [&](size_t y) {
    for (int x = 0; x < img.width; ++x) {
      Vec2 uv((x + 0.5f) / img.width, (static_cast<float>(y) + 0.5f) / img.height);
      Vec3 c = registry.color(id, uv);
      float* p = &img.rgb[(y * img.width + x) * 3];
      p[0] = c.x;
      p[1] = c.y;
      p[2] = c.z;
    }
  });
  return img;
}

void writeImage(const ImageRgb& image, const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  bool linear = ext == ".exr";
  TempPath temp(path);
  auto out = OIIO::ImageOutput::create(temp.path().string());
  if (!out) throw std::runtime_error("cannot write '" + path + "': " + OIIO::geterror());
  OIIO::ImageSpec spec(image.width, image.height, 3, linear ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8);
  spec.attribute("oiio:ColorSpace", linear ? "Linear" : "sRGB");
  std::vector<float> pixels = image.rgb;
  if (!linear) {
    for (float& v : pixels) v = static_cast<float>(linearToSrgb(v));
  }
  if (!out->open(temp.path().string(), spec) || !out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()) ||
      !out->close()) {
    throw std::runtime_error("cannot write '" + path + "': " + out->geterror());
  }
  temp.commit();
}

}  // namespace sprig::textures
