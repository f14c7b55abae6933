/// core/detail/image_backend.h through OpenImageIO: still images (GIFs: core/gif_encoder.h).

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <stdexcept>

#include "backends/backends.h"
#include "backends/png_check.h"

namespace sprig::backends {

namespace {

using detail::ImageFileHeader;
using detail::ImageFileReader;
using detail::ImageFileSpec;
using detail::PixelType;

OIIO::TypeDesc typeOf(PixelType t) {
  switch (t) {
    case PixelType::UInt8: return OIIO::TypeDesc::UINT8;
    case PixelType::Half: return OIIO::TypeDesc::HALF;
    case PixelType::Float: return OIIO::TypeDesc::FLOAT;
  }
  return OIIO::TypeDesc::UNKNOWN;
}

/// Opens out on path with spec, writes pixels of type `type`, closes; false on any failure
/// with the writer's first error in `error`.
bool writeOne(OIIO::ImageOutput& out, const std::string& path, const OIIO::ImageSpec& spec, OIIO::TypeDesc type,
              const void* pixels, std::string& error) {
  bool ok = out.open(path, spec) && out.write_image(type, pixels);
  error = out.geterror();
  ok = out.close() && ok;
  if (error.empty()) error = out.geterror();
  return ok;
}

bool write(const std::string& path, const ImageFileSpec& s, PixelType dataType, const void* data, std::string& error) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) {
    error = OIIO::geterror();
    return false;
  }
  OIIO::ImageSpec spec(s.width, s.height, s.channels, typeOf(s.fileType));
  if (!s.colorSpace.empty()) spec.attribute("oiio:ColorSpace", s.colorSpace);
  if (!s.compression.empty()) spec.attribute("compression", s.compression);
  if (s.quality > 0) spec.attribute("CompressionQuality", s.quality);
  if (s.pngLevel >= 0) spec.attribute("png:compressionLevel", s.pngLevel);
  return writeOne(*out, path, spec, typeOf(dataType), data, error);
}

/// Pixels of a PNG read through libpng before OpenImageIO reads it (backends/png_check.h):
/// core/image.h refuses larger images before it asks for their pixels.
constexpr uint64_t kMaxCheckedPixels = uint64_t(1) << 26;

class OiioReader final : public ImageFileReader {
 public:
  OiioReader(std::unique_ptr<OIIO::ImageInput> in, std::string path) : in_(std::move(in)), path_(std::move(path)) {
    const OIIO::ImageSpec& spec = in_->spec();
    header_.width = spec.width;
    header_.height = spec.height;
    header_.channels = spec.nchannels;
    header_.colorSpace = spec.get_string_attribute("oiio:ColorSpace");
    header_.integer8or16 = spec.format.basetype == OIIO::TypeDesc::UINT8 || spec.format.basetype == OIIO::TypeDesc::UINT16;
  }
  ~OiioReader() override { in_->close(); }

  const ImageFileHeader& header() const override { return header_; }

  bool read(PixelType type, void* out, std::string& error) override {
    error = pngReadProblem(path_, true, kMaxCheckedPixels);
    if (!error.empty()) {
      in_->close();
      return false;
    }
    const bool ok = in_->read_image(0, 0, 0, header_.channels, typeOf(type), out);
    error = in_->geterror();
    in_->close();
    return ok;
  }

 private:
  std::unique_ptr<OIIO::ImageInput> in_;
  std::string path_;
  ImageFileHeader header_;
};

std::unique_ptr<ImageFileReader> open(const std::string& path, std::string& error) {
  // A PNG's header chunks are read first with libpng's messages kept (backends/png_check.h).
  error = pngReadProblem(path, false, 0);
  if (!error.empty()) return nullptr;
  auto in = OIIO::ImageInput::open(path);
  if (!in) {
    error = OIIO::geterror();
    return nullptr;
  }
  return std::make_unique<OiioReader>(std::move(in), path);
}

bool textCoverage(const std::string& text, const std::string& fontFile, int sizePixels, std::vector<float>& coverage, int& width,
                  int& height, int& originX, int& originY, std::string& error) {
  const OIIO::ROI box = OIIO::ImageBufAlgo::text_size(text, sizePixels, fontFile);
  if (!box.defined()) {
    error = OIIO::geterror();
    if (error.empty()) error = "the font '" + fontFile + "' cannot be read";
    return false;
  }
  // text_size's box is relative to the baseline's start; a pad keeps antialiased edges.
  const int pad = 2 + sizePixels / 8;
  originX = pad - box.xbegin;
  originY = pad - box.ybegin;
  width = box.width() + 2 * pad;
  height = box.height() + 2 * pad;
  OIIO::ImageBuf buf(OIIO::ImageSpec(width, height, 1, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::zero(buf);
  const float white[1] = {1.0f};
  if (!OIIO::ImageBufAlgo::render_text(buf, originX, originY, text, sizePixels, fontFile, white)) {
    error = buf.geterror();
    return false;
  }
  coverage.assign(static_cast<size_t>(width) * height, 0.0f);
  if (!buf.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 1), OIIO::TypeDesc::FLOAT, coverage.data())) {
    error = buf.geterror();
    return false;
  }
  return true;
}

bool resizeBox(const float* in, int width, int height, float* out, int outWidth, int outHeight, std::string& error) {
  const OIIO::ImageBuf src(OIIO::ImageSpec(width, height, 4, OIIO::TypeDesc::FLOAT), const_cast<float*>(in));
  OIIO::ImageBuf dst(OIIO::ImageSpec(outWidth, outHeight, 4, OIIO::TypeDesc::FLOAT), out);
  // The filter's width is in output pixels: 1 averages the input pixels under each one.
  const bool ok = OIIO::ImageBufAlgo::resize(dst, src, "box", 1.0f, OIIO::ROI(0, outWidth, 0, outHeight, 0, 1, 0, 4), 1);
  if (!ok) error = dst.geterror();
  return ok;
}

}  // namespace

const detail::ImageBackend& oiioImage() {
  static const detail::ImageBackend table{&write, &open, &resizeBox, &textCoverage};
  return table;
}

}  // namespace sprig::backends
