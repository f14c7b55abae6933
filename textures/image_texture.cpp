#include "textures/image_texture.h"

#include <algorithm>
#include <filesystem>

#include "core/atomic_file.h"
#include "core/image.h"
#include "core/srgb.h"
#include "textures/detail/texture_backend.h"

namespace sprig::textures {

struct ImageTexture::Impl {
  std::string path;
  detail::TextureHandle* handle = nullptr;
  int width = 0, height = 0, channels = 0;
  bool srgb = false;
};

ImageTexture ImageTexture::open(const std::string& path, const SourceLoc& where) {
  auto fail = [&](const std::string& reason) -> ImageTexture {
    throw InputError(where, "cannot read texture '" + path + "': " + reason);
  };
  if (std::string reason = notRegularFileReason(path); !reason.empty()) throw InputError(where, FileReadError(path, reason).what());
  ImageInfo info;
  try {
    info = readImageInfo(path);
  } catch (const ImageReadError& e) {
    return fail(e.reason());
  }
  auto impl = std::make_shared<Impl>();
  impl->path = path;
  impl->width = info.width;
  impl->height = info.height;
  impl->channels = info.channels;
  impl->srgb = info.srgb;
  if (impl->width <= 0 || impl->height <= 0 || impl->channels <= 0) return fail("empty image");

  std::string error;
  impl->handle = detail::textureBackend().handle(path, error);
  if (!impl->handle) return fail(error);
  ImageTexture t;
  t.impl_ = std::move(impl);
  return t;
}

Vec3 ImageTexture::color(Vec2 uv, Vec2 duvdx, Vec2 duvdy) const {
  const Impl& m = *impl_;
  float rgb[3] = {0, 0, 0};
  int n = std::min(3, m.channels);
  detail::textureBackend().lookup(m.handle, n, uv.x, uv.y, duvdx.x, duvdx.y, duvdy.x, duvdy.y, rgb);
  if (n == 1) rgb[1] = rgb[2] = rgb[0];
  if (n == 2) rgb[2] = 0;
  Vec3 c(rgb[0], rgb[1], rgb[2]);
  if (m.srgb) {
    for (int k = 0; k < 3; ++k) c[k] = static_cast<float>(srgbToLinear(static_cast<double>(std::clamp(c[k], 0.0f, 1.0f))));
  }
  return c;
}

int ImageTexture::width() const { return impl_->width; }
int ImageTexture::height() const { return impl_->height; }
int ImageTexture::channels() const { return impl_->channels; }
bool ImageTexture::srgb() const { return impl_->srgb; }
const std::string& ImageTexture::path() const { return impl_->path; }

}  // namespace sprig::textures
