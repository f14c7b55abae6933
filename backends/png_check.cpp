#include "backends/png_check.h"

#include <png.h>

#include <cctype>
#include <csetjmp>
#include <cstdio>
#include <string>
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
  // A compressed text or colour profile inflates to at most this (overlongChunk bounds
  // the chunks themselves by the file's size).
  png_set_chunk_malloc_max(r.png, kMaxPngChunkBytes);
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

/// The first chunk of the PNG at file (whose 8-byte signature was read) that claims more
/// bytes than the file holds after its header, as "TYPE: chunk claims N bytes, M are left",
/// or "". libpng allocates a chunk's data at its claimed length and clears it, before it
/// reads a byte: a tEXt of a few bytes claiming 1.3 GB took 1.3 GB. Leaves the file at the
/// end of the signature.
std::string overlongChunk(std::FILE* file) {
  if (std::fseek(file, 0, SEEK_END) != 0) return {};
  const long size = std::ftell(file);
  long at = 8;
  std::string problem;
  while (problem.empty() && at + 12 <= size && std::fseek(file, at, SEEK_SET) == 0) {
    unsigned char header[8];
    if (std::fread(header, 1, 8, file) != 8) break;
    const uint64_t length = uint64_t(header[0]) << 24 | uint64_t(header[1]) << 16 | uint64_t(header[2]) << 8 | header[3];
    const uint64_t left = static_cast<uint64_t>(size - at - 12);
    if (length > left) {
      std::string type;
      for (int i = 4; i < 8; ++i) type += std::isalpha(header[i]) ? static_cast<char>(header[i]) : '?';
      problem = type + ": chunk claims " + std::to_string(length) + " bytes, " + std::to_string(left) + " are left";
    }
    at += static_cast<long>(12 + length);
  }
  std::fseek(file, 8, SEEK_SET);
  return problem;
}

}  // namespace

std::string pngReadProblem(const std::string& path, bool pixels, uint64_t maxPixels) {
  PngRead r;
  r.file = std::fopen(path.c_str(), "rb");
  if (!r.file) return {};
  png_byte signature[8];
  const bool isPng = std::fread(signature, 1, 8, r.file) == 8 && png_sig_cmp(signature, 0, 8) == 0;
  if (isPng) r.message = overlongChunk(r.file);
  if (isPng && r.message.empty()) r.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &r, keepError, dropWarning);
  if (r.png) r.info = png_create_info_struct(r.png);
  const bool ok = r.message.empty() && (!r.info || readPng(r, pixels, maxPixels));
  if (r.png) png_destroy_read_struct(&r.png, r.info ? &r.info : nullptr, nullptr);
  std::fclose(r.file);
  return ok ? std::string() : "PNG read error: " + r.message;
}

}  // namespace sprig::backends
