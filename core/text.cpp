#include "core/text.h"

#include <cstdio>

namespace sprig {

namespace {

bool isControl(unsigned char c) {
  return (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v') || c == 0x7f;
}

/// Length of the valid UTF-8 sequence starting at text[i] (a byte >= 0x80), or 0.
size_t utf8Length(std::string_view text, size_t i) {
  auto b = [&](size_t k) { return static_cast<unsigned char>(text[k]); };
  unsigned char c = b(i);
  size_t n = c >= 0xc2 && c <= 0xdf ? 2 : c >= 0xe0 && c <= 0xef ? 3 : c >= 0xf0 && c <= 0xf4 ? 4 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (size_t k = 1; k < n; ++k)
    if ((b(i + k) & 0xc0) != 0x80) return 0;
  // Overlong forms, UTF-16 surrogates and code points above U+10FFFF.
  if (c == 0xe0 && b(i + 1) < 0xa0) return 0;
  if (c == 0xed && b(i + 1) >= 0xa0) return 0;
  if (c == 0xf0 && b(i + 1) < 0x90) return 0;
  if (c == 0xf4 && b(i + 1) >= 0x90) return 0;
  return n;
}

}  // namespace

std::optional<TextFault> findNonText(std::string_view text) {
  int line = 1;
  size_t lineStart = 0;
  for (size_t i = 0; i < text.size();) {
    auto c = static_cast<unsigned char>(text[i]);
    if (c < 0x80 && !isControl(c)) {
      if (c == '\n') ++line, lineStart = i + 1;
      ++i;
      continue;
    }
    size_t n = c >= 0x80 ? utf8Length(text, i) : 0;
    if (n) {
      i += n;
      continue;
    }
    char hex[8];
    std::snprintf(hex, sizeof hex, "0x%02x", c);
    TextFault f;
    f.offset = i;
    f.line = line;
    f.col = static_cast<int>(i - lineStart) + 1;
    f.what = std::string("byte ") + hex + (c == 0 ? " (NUL)" : "");
    return f;
  }
  return std::nullopt;
}

std::string nonTextMessage(const TextFault& fault, std::string_view what) {
  return fault.what + " at byte offset " + std::to_string(fault.offset) + " is not text: " + std::string(what) +
         " must be UTF-8 text (is this a binary file?)";
}

bool checkText(std::string_view text, const std::string& file, std::string_view what, DiagnosticList& diags) {
  auto fault = findNonText(text);
  if (!fault) return true;
  diags.error(SourceLoc{file, fault->line, fault->col}, nonTextMessage(*fault, what));
  return false;
}

void requireText(std::string_view text, const std::string& file, std::string_view what) {
  DiagnosticList diags;
  if (!checkText(text, file, what, diags)) diags.throwIfErrors();
}

}  // namespace sprig
