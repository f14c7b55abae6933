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
#include "core/types.h"
#include "textures/image_texture.h"
#include "textures/procedural.h"

namespace sprig::textures {

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

  const Texture& get(TextureId id) const { return textures_.at(id); }
  size_t size() const { return textures_.size(); }

 private:
  std::vector<Texture> textures_;
};

/// An RGB float image in linear light, rows top to bottom.
struct ImageRgb {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  ///< width * height * 3 values
};

/// Samples texture `id` at pixel centers, u = (x + 0.5) / width, v = (y + 0.5) / height
/// (v = 0 at the top, as in image lookups). Rows run in parallel; output is the same at
/// any thread count.
ImageRgb bake(const TextureRegistry& registry, TextureId id, int width, int height);

/// Writes an image atomically (core/atomic_file.h): 8-bit sRGB for PNG and JPEG, linear
/// half floats for EXR. Throws std::runtime_error when the file cannot be written.
void writeImage(const ImageRgb& image, const std::string& path);

}  // namespace sprig::textures
