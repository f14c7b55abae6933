#include "core/gif_encoder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <unordered_map>

namespace sprig {

namespace {

struct Colour {
  std::array<int, 3> c;
  uint32_t count;
};

/// A median-cut box: colours[begin, end) and its widest channel's extent.
struct Box {
  size_t begin, end;
  int channel = 0, extent = 0;
};

void measure(const std::vector<Colour>& colours, Box& box) {
  std::array<int, 3> lo{255, 255, 255}, hi{0, 0, 0};
  for (size_t i = box.begin; i < box.end; ++i)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], colours[i].c[k]);
      hi[k] = std::max(hi[k], colours[i].c[k]);
    }
  box.extent = -1;
  for (int k = 0; k < 3; ++k)
    if (hi[k] - lo[k] > box.extent) {
      box.extent = hi[k] - lo[k];
      box.channel = k;
    }
}

/// Writes codes of growing width least significant bit first, in sub-blocks of 255 bytes.
class CodeWriter {
 public:
  explicit CodeWriter(std::string& out) : out_(out) {}
  void write(uint32_t code, int bits) {
    acc_ |= code << used_;
    used_ += bits;
    while (used_ >= 8) {
      push(static_cast<char>(acc_ & 255u));
      acc_ >>= 8;
      used_ -= 8;
    }
  }
  void finish() {
    if (used_ > 0) push(static_cast<char>(acc_ & 255u));
    if (!block_.empty()) flushBlock();
    out_.push_back('\0');
  }

 private:
  void push(char byte) {
    block_.push_back(byte);
    if (block_.size() == 255) flushBlock();
  }
  void flushBlock() {
    out_.push_back(static_cast<char>(block_.size()));
    out_ += block_;
    block_.clear();
  }
  std::string& out_;
  std::string block_;
  uint32_t acc_ = 0;
  int used_ = 0;
};

/// LZW-compresses 8-bit indices as GIF image data (minimum code size 8), the codes growing
/// to 12 bits and the table cleared when full.
void writeLzw(const std::vector<uint8_t>& indices, std::string& out) {
  constexpr uint32_t kClear = 256, kEnd = 257, kMaxCode = 4095;
  out.push_back(8);
  CodeWriter w(out);
  std::vector<uint16_t> next(size_t(kMaxCode + 1) * 256, 0);  // next[code·256 + byte]: the longer string's code
  int bits = 9;
  uint32_t last = kEnd;  // the highest code assigned
  w.write(kClear, bits);
  uint32_t cur = indices.front();
  for (size_t i = 1; i < indices.size(); ++i) {
    const uint8_t k = indices[i];
    if (uint16_t code = next[size_t(cur) * 256 + k]) {
      cur = code;
      continue;
    }
    w.write(cur, bits);
    next[size_t(cur) * 256 + k] = static_cast<uint16_t>(++last);
    if (last >= (1u << bits)) ++bits;
    if (last == kMaxCode) {
      w.write(kClear, bits);
      std::fill(next.begin(), next.end(), 0);
      bits = 9;
      last = kEnd;
    }
    cur = k;
  }
  w.write(cur, bits);
  w.write(kClear, bits);
  w.write(kEnd, 9);
  w.finish();
}

void putU16(std::string& out, int v) {
  out.push_back(static_cast<char>(v & 255));
  out.push_back(static_cast<char>((v >> 8) & 255));
}

}  // namespace

std::vector<uint8_t> gifPalette(const std::vector<uint8_t>& rgb, int maxColours) {
  std::unordered_map<uint32_t, uint32_t> counts;
  for (size_t i = 0; i + 2 < rgb.size(); i += 3) ++counts[(uint32_t(rgb[i]) << 16) | (uint32_t(rgb[i + 1]) << 8) | rgb[i + 2]];
  std::vector<std::pair<uint32_t, uint32_t>> sorted(counts.begin(), counts.end());
  std::sort(sorted.begin(), sorted.end());  // a fixed order: the same frame, the same palette
  std::vector<Colour> colours;
  colours.reserve(sorted.size());
  for (const auto& [packed, n] : sorted) colours.push_back({{int(packed >> 16), int((packed >> 8) & 255), int(packed & 255)}, n});

  // Median cut over distinct colours: split the box of widest extent at its median colour.
  std::vector<Box> boxes{{0, colours.size()}};
  measure(colours, boxes[0]);
  while (boxes.size() < size_t(maxColours)) {
    size_t pick = boxes.size();
    for (size_t b = 0; b < boxes.size(); ++b)
      if (boxes[b].end - boxes[b].begin > 1 && (pick == boxes.size() || boxes[b].extent > boxes[pick].extent)) pick = b;
    if (pick == boxes.size()) break;  // every box holds one colour
    Box box = boxes[pick];
    const int ch = box.channel;
    std::sort(colours.begin() + box.begin, colours.begin() + box.end, [ch](const Colour& a, const Colour& b) {
      return a.c[ch] != b.c[ch] ? a.c[ch] < b.c[ch] : a.c < b.c;
    });
    Box lower{box.begin, box.begin + (box.end - box.begin) / 2}, upper{lower.end, box.end};
    measure(colours, lower);
    measure(colours, upper);
    boxes[pick] = lower;
    boxes.push_back(upper);
  }
  std::vector<uint8_t> palette;
  palette.reserve(3 * boxes.size());
  for (const Box& box : boxes) {
    double sum[3] = {0, 0, 0}, weight = 0;
    for (size_t i = box.begin; i < box.end; ++i) {
      for (int k = 0; k < 3; ++k) sum[k] += double(colours[i].c[k]) * colours[i].count;
      weight += colours[i].count;
    }
    for (int k = 0; k < 3; ++k) palette.push_back(static_cast<uint8_t>(std::lround(sum[k] / weight)));
  }
  return palette;
}

std::vector<uint8_t> gifDither(const std::vector<uint8_t>& rgb, int width, int height, const std::vector<uint8_t>& palette) {
  const int n = static_cast<int>(palette.size() / 3);
  std::unordered_map<uint32_t, uint8_t> nearestOf;
  auto nearest = [&](const std::array<int, 3>& c) {
    const uint32_t key = (uint32_t(c[0]) << 16) | (uint32_t(c[1]) << 8) | uint32_t(c[2]);
    if (auto it = nearestOf.find(key); it != nearestOf.end()) return it->second;
    int best = 0, bestDistance = 1 << 30;
    for (int p = 0; p < n; ++p) {
      const int d0 = palette[3 * p] - c[0], d1 = palette[3 * p + 1] - c[1], d2 = palette[3 * p + 2] - c[2];
      const int d = d0 * d0 + d1 * d1 + d2 * d2;
      if (d < bestDistance) {
        bestDistance = d;
        best = p;
      }
    }
    return nearestOf[key] = static_cast<uint8_t>(best);
  };
  // Floyd-Steinberg, errors in sixteenths: 7 right, 3 down-left, 5 down, 1 down-right.
  std::vector<int> err(size_t(3) * (width + 2), 0), below(size_t(3) * (width + 2), 0);
  std::vector<uint8_t> out(size_t(width) * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      std::array<int, 3> want;
      for (int k = 0; k < 3; ++k) want[k] = std::clamp(rgb[3 * i + k] + err[3 * (x + 1) + k] / 16, 0, 255);
      const uint8_t p = nearest(want);
      out[i] = p;
      for (int k = 0; k < 3; ++k) {
        const int e = rgb[3 * i + k] + err[3 * (x + 1) + k] / 16 - palette[3 * p + k];
        err[3 * (x + 2) + k] += 7 * e;
        below[3 * x + k] += 3 * e;
        below[3 * (x + 1) + k] += 5 * e;
        below[3 * (x + 2) + k] += e;
      }
    }
    std::swap(err, below);
    std::fill(below.begin(), below.end(), 0);
  }
  return out;
}

std::string encodeGif(int width, int height, int delayCs, size_t frameCount,
                      const std::function<std::vector<uint8_t>(size_t)>& frameRgb) {
  if (width < 1 || height < 1 || width > 65535 || height > 65535) throw std::invalid_argument("GIF frame size out of range");
  std::string out = "GIF89a";
  putU16(out, width);
  putU16(out, height);
  out += std::string("\0\0\0", 3);  // no global colour table, background 0, square pixels
  out += "\x21\xFF\x0BNETSCAPE2.0\x03\x01";  // loop forever
  putU16(out, 0);
  out.push_back('\0');
  constexpr uint8_t kTransparent = 255;
  std::vector<uint8_t> shown(size_t(3) * width * height, 0);  // the colours on the canvas so far
  for (size_t f = 0; f < frameCount; ++f) {
    const std::vector<uint8_t> rgb = frameRgb(f);
    if (rgb.size() != size_t(3) * width * height) throw std::invalid_argument("GIF frame of the wrong size");
    std::vector<uint8_t> palette = gifPalette(rgb, kTransparent);
    std::vector<uint8_t> indices = gifDither(rgb, width, height, palette);
    // A pixel shown in the colour the previous frames left there is transparent: runs of
    // one index compress well, and the picture is the same.
    for (size_t i = 0; i < indices.size(); ++i) {
      const uint8_t* c = &palette[3 * size_t(indices[i])];
      if (f > 0 && std::equal(c, c + 3, shown.begin() + 3 * i))
        indices[i] = kTransparent;
      else
        std::copy(c, c + 3, shown.begin() + 3 * i);
    }
    palette.resize(3 * 256, 0);
    out += "\x21\xF9\x04";  // graphic control: keep this frame under the next; index 255 transparent after the first
    out.push_back(f > 0 ? '\x05' : '\x04');
    putU16(out, delayCs);
    out.push_back(static_cast<char>(kTransparent));
    out.push_back('\0');
    out.push_back('\x2C');  // image descriptor: the whole canvas, a 256-colour local table
    putU16(out, 0);
    putU16(out, 0);
    putU16(out, width);
    putU16(out, height);
    out.push_back('\x87');
    out.append(reinterpret_cast<const char*>(palette.data()), palette.size());
    writeLzw(indices, out);
  }
  out.push_back('\x3B');
  return out;
}

}  // namespace sprig
