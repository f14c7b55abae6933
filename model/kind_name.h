#pragma once

#include <string>

namespace sprig {

/// A species kind with its indefinite article, for messages: "a shell species", "an
/// organism species". Kinds are lower-case English words (model/kinds.cpp).
inline std::string speciesOfKind(const std::string& kind) {
  const bool vowel = !kind.empty() && std::string("aeiou").find(kind[0]) != std::string::npos;
  return (vowel ? "an " : "a ") + kind + " species";
}

}  // namespace sprig
