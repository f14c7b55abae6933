#include "core/paths.h"

#include <algorithm>

namespace sprig {

std::string asciiLower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c); });
  return text;
}

std::string lowerExtension(const std::filesystem::path& path) { return asciiLower(path.extension().string()); }

}  // namespace sprig
