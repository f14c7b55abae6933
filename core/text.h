#pragma once
/// The one check every reader of a text file (grammar, species YAML, OBJ, ASCII PLY, OFF)
/// runs before parsing: the bytes are UTF-8 text without NUL or other control bytes.
/// A binary file given as text fails with one error naming the byte offset; its bytes
/// are never echoed.

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/diagnostics.h"

namespace sprig {

/// The first byte of a text that is not UTF-8 text.
struct TextFault {
  size_t offset = 0;  ///< 0-based byte offset in the text
  int line = 1;       ///< 1-based
  int col = 1;        ///< 1-based, in bytes
  std::string what;   ///< "byte 0x00 (NUL)", "byte 0xff is not UTF-8", ...
};

/// The first NUL or control byte (other than tab, line feed, carriage return, form feed
/// and vertical tab) or invalid UTF-8 sequence (overlong, surrogate, above U+10FFFF,
/// truncated) of text, or nullopt when text is UTF-8 text. Linear in text's size.
std::optional<TextFault> findNonText(std::string_view text);

/// `byte 0x00 (NUL) at byte offset 12 is not text: <what> must be UTF-8 text (is this a
/// binary file?)`, the message every reader reports for fault.
std::string nonTextMessage(const TextFault& fault, std::string_view what);

/// Adds one error at file:line:col (no source line is quoted) and returns false when text
/// is not UTF-8 text; what names the kind of file ("a grammar file").
bool checkText(std::string_view text, const std::string& file, std::string_view what, DiagnosticList& diags);

/// Throws InputError (one error, as checkText) when text is not UTF-8 text.
void requireText(std::string_view text, const std::string& file, std::string_view what);

}  // namespace sprig
