#pragma once
/// The texture registry: TextureId -> texture, evaluated as color(id, uv, position).
///
/// A closed set of kinds (procedural textures and image files) held in a std::variant.
/// The renderer registers each texture once and looks colors up from many threads: all
/// lookups are const and thread-safe. Ids are dense, in order of registration.

#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "core/diagnostics.h"
#include "core/image.h"
#include "core/types.h"
#include "textures/image_texture.h"
#include "textures/procedural.h"

namespace sprig::textures {

/// Index of a registered texture (dense, from 0).
using TextureId = uint32_t;

/// A uniform color.
struct ConstantTexture {
  Vec3 color{0.5f};
};

/// Every kind of texture the registry holds.
using Texture = std::variant<ConstantTexture, NoiseTexture, BarkTexture, StripesTexture, SpotsTexture, LeafTexture,
                             ImageTexture>;

/// Textures by id.
class TextureRegistry {
 public:
  /// Registers a texture; returns its id (0, 1, 2, ... in order).
  TextureId add(Texture texture);
  /// Opens an image file and registers it. Throws InputError at `where` when the file is
  /// missing or unreadable (see ImageTexture::open).
  TextureId addImage(const std::string& path, const SourceLoc& where);

  /// Linear RGB of texture `id` at natural coordinates uv; `position` is used by solid
  /// textures (NoiseTexture with solid = true). An id not registered is a programmer
  /// error (std::out_of_range).
  Vec3 color(TextureId id, Vec2 uv, const Vec3& position = Vec3(0)) const;

  /// The texture registered as id; std::out_of_range for an unknown id.
  const Texture& get(TextureId id) const { return textures_.at(id); }
  /// Number of registered textures.
  size_t size() const { return textures_.size(); }

 private:
  std::vector<Texture> textures_;
};

/// Samples texture `id` at pixel centers, u = (x + 0.5) / width, v = (y + 0.5) / height
/// (v = 0 at the top, as in image lookups), into linear RGB with alpha 1 (negative sizes
/// count as 0). Rows run in parallel; output is the same at any thread count. Write it
/// with writeImage(image, path, ImageEncoding::TextureMap) (core/image.h).
Image bake(const TextureRegistry& registry, TextureId id, int width, int height);

}  // namespace sprig::textures
