#include "core/inr_volume.h"

#include <cmath>
#include <cstring>
#include <map>
#include <optional>

#include "core/atomic_file.h"

namespace sprig {
namespace {

constexpr std::string_view kMagic = "#INRIMAGE-4#{";
constexpr std::string_view kEnd = "##}";

enum class VoxelType { Float, Unsigned, Signed };

struct Header {
  std::array<int, 3> dims{0, 0, 0};
  int vdim = 1;
  VoxelType type = VoxelType::Float;
  int bits = 0;
  bool bigEndian = false;
  std::array<double, 3> voxel{1, 1, 1};
  std::array<double, 3> origin{0, 0, 0};
  size_t size = 0;  // header bytes
};

class HeaderParser {
 public:
  HeaderParser(std::string_view bytes, const std::string& path, const VolumeLimits& limits)
      : bytes_(bytes), path_(path), limits_(limits) {}

  Header parse() {
    if (bytes_.substr(0, kMagic.size()) != kMagic)
      fail(1, 1, "not an INRIMAGE-4 volume: the file must start with '#INRIMAGE-4#{'");
    size_t pos = bytes_.find('\n');
    int line = 1;
    bool ended = false;
    bool typeSeen = false;
    while (pos != std::string_view::npos && pos + 1 < bytes_.size()) {
      const size_t start = pos + 1;
      ++line;
      pos = bytes_.find('\n', start);
      if (pos == std::string_view::npos) fail(line, 1, "the header ends without '##}' and a newline");
      std::string_view text = bytes_.substr(start, pos - start);
      requireText(text, line);
      if (text.substr(0, kEnd.size()) == kEnd) {
        header_.size = pos + 1;
        ended = true;
        break;
      }
      if (text.empty() || text[0] == '#') continue;
      const size_t eq = text.find('=');
      if (eq == std::string_view::npos) fail(line, 1, "expected KEY=value in the header");
      const std::string key(text.substr(0, eq));
      const std::string value(text.substr(eq + 1));
      const int valueCol = int(eq) + 2;
      if (key == "XDIM" || key == "YDIM" || key == "ZDIM") {
        header_.dims[key[0] - 'X'] = dimension(value, line, valueCol, key);
      } else if (key == "VDIM") {
        header_.vdim = int(integer(value, line, valueCol, key));
        if (header_.vdim != 1) fail(line, valueCol, "VDIM=" + value + ": only scalar volumes (VDIM=1) are read");
      } else if (key == "TYPE") {
        typeSeen = true;
        if (value == "float") header_.type = VoxelType::Float;
        else if (value == "unsigned fixed") header_.type = VoxelType::Unsigned;
        else if (value == "signed fixed") header_.type = VoxelType::Signed;
        else fail(line, valueCol, "unknown TYPE '" + value + "' (expected float, unsigned fixed or signed fixed)");
      } else if (key == "PIXSIZE") {
        if (value == "8 bits") header_.bits = 8;
        else if (value == "16 bits") header_.bits = 16;
        else if (value == "32 bits") header_.bits = 32;
        else if (value == "64 bits") header_.bits = 64;
        else fail(line, valueCol, "unknown PIXSIZE '" + value + "' (expected 8, 16, 32 or 64 bits)");
        pixLine_ = line;
      } else if (key == "CPU") {
        if (value == "decm" || value == "alpha" || value == "pc") header_.bigEndian = false;
        else if (value == "sun" || value == "sgi") header_.bigEndian = true;
        else fail(line, valueCol, "unknown CPU '" + value + "' (expected decm, alpha, pc, sun or sgi)");
      } else if (key == "VX" || key == "VY" || key == "VZ") {
        const double v = real(value, line, valueCol, key);
        if (!(v > 0)) fail(line, valueCol, key + " must be a positive voxel size");
        header_.voxel[key[1] - 'X'] = v;
      } else if (key == "TX" || key == "TY" || key == "TZ") {
        header_.origin[key[1] - 'X'] = real(value, line, valueCol, key);
      } else if (key == "SCALE") {
        if (value != "2**0") fail(line, valueCol, "SCALE=" + value + ": fixed-point scaling is not implemented (only 2**0)");
      } else {
        fail(line, 1, "unknown INR header key '" + key + "'");
      }
    }
    if (!ended) fail(line + 1, 1, "the header ends without '##}' and a newline");
    for (int a = 0; a < 3; ++a)
      if (header_.dims[a] == 0) fail(line, 1, std::string("the header lacks ") + char('X' + a) + "DIM");
    if (!typeSeen) fail(line, 1, "the header lacks TYPE");
    if (header_.bits == 0) fail(line, 1, "the header lacks PIXSIZE");
    if (header_.type == VoxelType::Float && header_.bits != 32 && header_.bits != 64)
      fail(pixLine_, 1, "a float volume has PIXSIZE 32 or 64 bits");
    if (header_.type != VoxelType::Float && header_.bits == 64)
      fail(pixLine_, 1, "fixed-point voxels of 64 bits are not implemented");
    return header_;
  }

 private:
  [[noreturn]] void fail(int line, int col, const std::string& message) const {
    throw InputError(SourceLoc{path_, line, col}, message);
  }

  void requireText(std::string_view text, int line) const {
    for (size_t i = 0; i < text.size(); ++i) {
      const auto c = static_cast<unsigned char>(text[i]);
      if (c < 0x20 && c != '\t' && c != '\r')
        fail(line, int(i) + 1, "byte " + std::to_string(c) + " is not text: the INR header must be text");
    }
  }

  long long integer(const std::string& value, int line, int col, const std::string& key) const {
    std::optional<double> v = parseFiniteNumber(value);
    if (!v || *v != std::floor(*v) || std::fabs(*v) > 1e12) fail(line, col, key + " must be an integer, not '" + value + "'");
    return static_cast<long long>(*v);
  }

  int dimension(const std::string& value, int line, int col, const std::string& key) const {
    const long long n = integer(value, line, col, key);
    if (n < 1 || n > limits_.maxDimension)
      fail(line, col, key + "=" + value + " is outside 1.." + std::to_string(limits_.maxDimension) +
                          " (VolumeLimits::maxDimension)");
    return int(n);
  }

  double real(const std::string& value, int line, int col, const std::string& key) const {
    std::optional<double> v = parseFiniteNumber(value);
    if (!v) fail(line, col, key + " must be a finite number, not '" + value + "'");
    return *v;
  }

  std::string_view bytes_;
  const std::string& path_;
  const VolumeLimits& limits_;
  Header header_;
  int pixLine_ = 0;
};

// The voxel at p as a float, of the header's type, size and byte order.
float decode(const unsigned char* p, const Header& h) {
  const int n = h.bits / 8;
  unsigned char b[8];
  for (int i = 0; i < n; ++i) b[i] = h.bigEndian ? p[n - 1 - i] : p[i];
  uint64_t u = 0;
  for (int i = n - 1; i >= 0; --i) u = (u << 8) | b[i];
  if (h.type == VoxelType::Float) {
    if (n == 4) {
      float f;
      uint32_t w = uint32_t(u);
      std::memcpy(&f, &w, 4);
      return f;
    }
    double d;
    std::memcpy(&d, &u, 8);
    return float(d);
  }
  if (h.type == VoxelType::Unsigned) return float(u);
  const uint64_t sign = uint64_t(1) << (h.bits - 1);
  return float(int64_t(u ^ sign) - int64_t(sign));  // two's complement of bits width
}

}  // namespace

ScalarVolume parseInrVolume(std::string_view bytes, const std::string& displayPath, const VolumeLimits& limits) {
  const Header h = HeaderParser(bytes, displayPath, limits).parse();
  const uint64_t voxels = uint64_t(h.dims[0]) * h.dims[1] * h.dims[2];
  if (voxels > limits.maxVoxels)
    throw InputError(SourceLoc{displayPath}, "the volume has " + std::to_string(voxels) + " voxels, more than the limit of " +
                                                 std::to_string(limits.maxVoxels) + " (VolumeLimits::maxVoxels)");
  const uint64_t need = voxels * uint64_t(h.bits / 8);
  const uint64_t have = bytes.size() - h.size;
  if (h.size % 256 != 0)
    throw InputError(SourceLoc{displayPath}, "the INR header is " + std::to_string(h.size) +
                                                 " bytes long, not a multiple of 256: the file is damaged");
  if (have != need)
    throw InputError(SourceLoc{displayPath}, "the header describes " + std::to_string(need) + " bytes of voxels but " +
                                                 std::to_string(have) + " follow it");
  ScalarVolume v;
  v.dims = h.dims;
  v.voxel = h.voxel;
  v.origin = h.origin;
  v.values.resize(size_t(voxels));
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data()) + h.size;
  const size_t step = size_t(h.bits / 8);
  for (size_t i = 0; i < v.values.size(); ++i) {
    const float f = decode(data + i * step, h);
    if (!std::isfinite(f))
      throw InputError(SourceLoc{displayPath}, "voxel " + std::to_string(i) + " is not a finite number");
    v.values[i] = f;
  }
  return v;
}

ScalarVolume readInrVolume(const std::filesystem::path& path, std::string displayPath, const VolumeLimits& limits) {
  if (displayPath.empty()) displayPath = path.string();
  const uint64_t maxBytes = limits.maxVoxels * 8 + (uint64_t(1) << 20);
  const std::string bytes = readInputFile(path, displayPath, maxBytes, "VolumeLimits::maxVoxels");
  return parseInrVolume(bytes, displayPath, limits);
}

}  // namespace sprig
