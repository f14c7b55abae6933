#include "backends/png_check.h"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <vector>

namespace sprig::backends {

namespace {

/// What the handlers and the reading share; it lives outside the setjmp frame.
struct PngRead {
  std::FILE* file = nullptr;
  png_structp png = nullptr;
  png_infop info = nullptr;
  std::string message;
  std::vector<png_byte> row;
};

[[noreturn]] void keepError(png_structp png, png_const_charp text) {
  auto* r = static_cast<PngRead*>(png_get_error_ptr(png));
  if (r->message.empty()) r->message = text ? text : "unknown error";
  png_longjmp(png, 1);
}

void dropWarning(png_structp, png_const_charp) {}

/// The reading, in a frame that holds no object with a destructor (longjmp skips them).
/// Returns false when libpng reported an error (its message in r.message).
bool readPng(PngRead& r, bool pixels, uint64_t maxPixels) {
  if (setjmp(png_jmpbuf(r.png))) return false;
  png_init_io(r.png, r.file);
  png_set_sig_bytes(r.png, 8);
  png_read_info(r.png, r.info);
  const uint64_t width = png_get_image_width(r.png, r.info), height = png_get_image_height(r.png, r.info);
  if (!pixels || width * height > maxPixels) return true;
  png_set_expand(r.png);
  const int passes = png_set_interlace_handling(r.png);
  png_read_update_info(r.png, r.info);
  r.row.resize(png_get_rowbytes(r.png, r.info));
  for (int pass = 0; pass < passes; ++pass)
    for (uint64_t y = 0; y < height; ++y) png_read_row(r.png, r.row.data(), nullptr);
  png_read_end(r.png, nullptr);
  return true;
}

}  // namespace

std::string pngReadProblem(const std::string& path, bool pixels, uint64_t maxPixels) {
  PngRead r;
  r.file = std::fopen(path.c_str(), "rb");
  if (!r.file) return {};
  png_byte signature[8];
  const bool isPng = std::fread(signature, 1, 8, r.file) == 8 && png_sig_cmp(signature, 0, 8) == 0;
  if (isPng) r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, keepError, dropWarning);
  if (r.png) r.info = png_create_info_struct(r.png);
  const bool ok = !r.info || readPng(r, pixels, maxPixels);
  if (r.png) png_destroy_read_struct(&r.png, r.info ? &r.info : nullptr, nullptr);
  std::fclose(r.file);
  return ok ? std::string() : "PNG read error: " + r.message;
}

}  // namespace sprig::backends
