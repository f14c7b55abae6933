#pragma once
/// Small helpers for writing JSON text (numbers in shortest round-trip form).

#include <string>
#include <string_view>

#include "core/types.h"

namespace sprig::json {

/// Shortest text that reads back as v; `null` for NaN and infinities.
std::string number(double v);
/// A quoted, escaped JSON string.
std::string string(std::string_view s);
/// `[x, y, z]`.
std::string vec3(const DVec3& v);

}  // namespace sprig::json
