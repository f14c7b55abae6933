#pragma once
/// Small helpers for file names.

#include <filesystem>
#include <string>

namespace sprig {

/// `text` with ASCII letters lower-cased (no locale); other bytes unchanged.
std::string asciiLower(std::string text);

/// The path's extension with its dot, ASCII lower-cased: "x/Y.PNG" -> ".png", "a" -> "".
std::string lowerExtension(const std::filesystem::path& path);

}  // namespace sprig
