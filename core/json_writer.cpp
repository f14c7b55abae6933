#include "core/json_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace sprig::json {

std::string number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, res.ptr);
}

std::string string(std::string_view s) {
  std::string out;
  out.reserve(s.size() + 2);
  out.push_back('"');
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
          out += buf;
        } else {
          out.push_back(c);
        }
    }
  }
  out.push_back('"');
  return out;
}

std::string vec3(const DVec3& v) {
  // Appended piece by piece: GCC 12's -Wrestrict misfires on `"[" + std::string&&`.
  std::string out = "[";
  out += number(v.x);
  out += ", ";
  out += number(v.y);
  out += ", ";
  out += number(v.z);
  out += ']';
  return out;
}

}  // namespace sprig::json
