#include "textures/registry.h"

#include <algorithm>

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

Image bake(const TextureRegistry& registry, TextureId id, int width, int height) {
  Image img(std::max(0, width), std::max(0, height));
  parallelFor(0, static_cast<size_t>(img.height), [&](size_t y) {
    for (int x = 0; x < img.width; ++x) {
      Vec2 uv((x + 0.5f) / img.width, (static_cast<float>(y) + 0.5f) / img.height);
      img.set(x, static_cast<int>(y), Vec4(registry.color(id, uv), 1.0f));
    }
  });
  return img;
}

}  // namespace sprig::textures
