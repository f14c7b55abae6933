/// textures/detail/texture_backend.h through OpenImageIO's TextureSystem.

#include <OpenImageIO/texture.h>

#include "backends/backends.h"
#include "backends/png_check.h"

namespace sprig::backends {

namespace {

using textures::detail::TextureHandle;

/// OIIO's shared texture system, configured once.
OIIO::TextureSystem* textureSystem() {
  static OIIO::TextureSystem* ts = [] {
    OIIO::TextureSystem* t = OIIO::TextureSystem::create(true);
    t->attribute("automip", 1);  // mip-map untiled files (PNG, JPEG) on first use
    t->attribute("autotile", 64);
    t->attribute("accept_untiled", 1);
    return t;
  }();
  return ts;
}

OIIO::TextureSystem::TextureHandle* oiioHandle(TextureHandle* h) {
  return reinterpret_cast<OIIO::TextureSystem::TextureHandle*>(h);
}

TextureHandle* handle(const std::string& path, std::string& error) {
  // The texture system reads the pixels later, in the render's threads: a PNG is read
  // whole here first, with libpng's messages kept (backends/png_check.h).
  error = pngReadProblem(path, true, uint64_t(1) << 26);
  if (!error.empty()) return nullptr;
  OIIO::TextureSystem* ts = textureSystem();
  OIIO::TextureSystem::TextureHandle* h = ts->get_texture_handle(OIIO::ustring(path));
  if (!h || !ts->good(h)) {
    error = ts->geterror();
    return nullptr;
  }
  return reinterpret_cast<TextureHandle*>(h);
}

void lookup(TextureHandle* texture, int channels, float s, float t, float dsdx, float dtdx, float dsdy, float dtdy,
            float* out) {
  OIIO::TextureOpt opt;
  opt.swrap = OIIO::TextureOpt::WrapPeriodic;
  opt.twrap = OIIO::TextureOpt::WrapPeriodic;
  opt.interpmode = OIIO::TextureOpt::InterpBilinear;
  opt.mipmode = OIIO::TextureOpt::MipModeTrilinear;
  textureSystem()->texture(oiioHandle(texture), nullptr, opt, s, t, dsdx, dtdx, dsdy, dtdy, channels, out);
}

}  // namespace

const textures::detail::TextureBackend& oiioTexture() {
  static const textures::detail::TextureBackend table{&handle, &lookup};
  return table;
}

}  // namespace sprig::backends
