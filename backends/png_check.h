#pragma once
/// A PNG read through libpng with a handler that keeps libpng's messages instead of printing
/// them.
///
/// libpng's default error handler prints "libpng error: ..." on stderr, and OpenImageIO
/// 2.4's PNG reader installs one that records the message and returns, after which libpng
/// calls its default anyway. So before OpenImageIO opens or reads a PNG, the backends read
/// it here: a handler that keeps the first message and jumps out means nothing reaches
/// stderr, and a file libpng refuses never reaches OpenImageIO.

#include <cstdint>
#include <string>

namespace sprig::backends {

/// The most a compressed text or colour profile of a PNG may inflate to: 64 MiB (libpng's
/// error beyond it: "... too large"). A chunk itself may not claim more bytes than the
/// file holds after it.
constexpr uint64_t kMaxPngChunkBytes = uint64_t(64) << 20;

/// libpng's first error for the PNG file at path ("PNG read error: MESSAGE", the words
/// OpenImageIO uses), or "" when it reads: its chunks up to the image data, and with pixels
/// (an image of at most maxPixels pixels; larger ones are checked to the image data only)
/// every row and the chunks after them. A chunk that claims more bytes than the file holds
/// after it is refused before libpng allocates it ("PNG read error: tEXt: chunk claims
/// 1296891924 bytes, 370 are left"). A file
/// that is not a PNG or cannot be opened gives "" (OpenImageIO reports it). Warnings are
/// dropped. Cost: one decode of the image.
std::string pngReadProblem(const std::string& path, bool pixels, uint64_t maxPixels);

}  // namespace sprig::backends
