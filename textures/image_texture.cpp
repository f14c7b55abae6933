#include "textures/image_texture.h"

#include <OpenImageIO/texture.h>

#include <algorithm>
#include <filesystem>

#include "core/image.h"
#include "core/srgb.h"

namespace sprig::textures {

namespace {

/// OIIO's shared texture system, configured once.
OIIO::TextureSystem* textureSystem() {
  static OIIO::TextureSystem* ts = [] {
    OIIO::TextureSystem* t = OIIO::TextureSystem::create(true);
    t->attribute("automip", 1);      // mip-map untiled files (PNG, JPEG) on first use
    t->attribute("autotile", 64);
    t->attribute("accept_untiled", 1);
    return t;
  }();
  return ts;
}

}  // namespace

struct ImageTexture::Impl {
  std::string path;
  OIIO::ustring name;
  OIIO::TextureSystem::TextureHandle* handle = nullptr;
  int width = 0, height = 0, channels = 0;
  bool srgb = false;
};

ImageTexture ImageTexture::open(const std::string& path, const SourceLoc& where) {
  auto fail = [&](const std::string& reason) -> ImageTexture {
    throw InputError(where, "cannot read texture '" + path + "': " + reason);
  };
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return fail("no such file");
  if (!std::filesystem::is_regular_file(path, ec)) return fail("not a regular file");
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

  OIIO::TextureSystem* ts = textureSystem();
  impl->name = OIIO::ustring(path);
  impl->handle = ts->get_texture_handle(impl->name);
  if (!impl->handle || !ts->good(impl->handle)) return fail(ts->geterror());
  ImageTexture t;
  t.impl_ = std::move(impl);
  return t;
}

Vec3 ImageTexture::color(Vec2 uv, Vec2 duvdx, Vec2 duvdy) const {
  const Impl& m = *impl_;
  OIIO::TextureOpt opt;
  opt.swrap = OIIO::TextureOpt::WrapPeriodic;
  opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
  float rgb[3] = {0, 0, 0};
  int n = std::min(3, m.channels);
  textureSystem()->texture(m.handle, nullptr, opt, uv.x, uv.y, duvdx.x, duvdx.y, duvdy.x, duvdy.y, n, rgb);
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
