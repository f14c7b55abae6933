#include "model/cpfg_labels.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace sprig {

namespace {

/// An X11 font name's fields as cpfg's DrawString splits them.
std::vector<std::string> xlfdFields(const std::string& name) {
  std::vector<std::string> out;
  std::string buf;
  for (char c : name) {
    if (c != '-') {
      buf += c;
    } else {
      out.push_back(buf.empty() ? std::string("*") : buf);
      buf.clear();
    }
  }
  if (!buf.empty()) out.push_back(buf);
  return out;
}

/// The points of a size field, 0 when it is not a number in (0, 100].
int points(const std::string& field) {
  const int v = std::atoi(field.c_str());
  return v > 0 && v <= 100 ? v : 0;
}

bool containsAny(const std::string& s, std::initializer_list<const char*> words) {
  return std::any_of(words.begin(), words.end(), [&](const char* w) { return s.find(w) != std::string::npos; });
}

}  // namespace

LabelFont cpfgLabelFont(const std::string& xlfd) {
  const std::vector<std::string> f = xlfdFields(xlfd.empty() ? "-*-courier-bold-r-*-*-12-*-*-*-*-*-*-*" : xlfd);
  std::string family = "DejaVuSans";
  bool bold = false, italic = false;
  int pt = 9;
  if (f.size() >= 8) {
    pt = points(f[7]);
    if (pt == 0) pt = points(f[6]);
    if (pt == 0) pt = 12;
    std::string name = f[2];
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (containsAny(name, {"courier", "mono", "fixed", "terminal", "typewriter", "clean", "lucidatypewriter"}))
      family = "DejaVuSansMono";
    else if (containsAny(name, {"times", "serif", "roman", "schoolbook", "palatino", "charter", "bookman", "georgia"}) &&
             name.find("sans") == std::string::npos)
      family = "DejaVuSerif";
    bold = f[3] == "bold" || f[3] == "black" || f[3] == "medium";
    italic = f[4] == "italic";
  }
  std::string style;
  if (bold) style += "Bold";
  if (italic) style += family == "DejaVuSerif" ? "Italic" : "Oblique";
  LabelFont out;
  out.file = std::string(kLabelFontFolder) + "/" + family + (style.empty() ? "" : "-" + style) + ".ttf";
  out.sizePixels = static_cast<int>(std::lround(pt * 96.0 / 72.0));
  return out;
}

std::vector<render::TextLabel> cpfgLabels(const lsystem::Skeleton& skeleton, const SkeletonStyle& style) {
  std::vector<render::TextLabel> out;
  if (skeleton.labels.empty()) return out;
  const LabelFont font = cpfgLabelFont(style.cpfgFont);
  out.reserve(skeleton.labels.size());
  for (const lsystem::Label& l : skeleton.labels) {
    render::TextLabel t;
    t.position = Vec3(l.position);
    t.text = l.text;
    if (l.color >= 0 && static_cast<size_t>(l.color) < style.palette.size()) t.color = style.palette[static_cast<size_t>(l.color)];
    t.fontFile = font.file;
    t.sizePixels = font.sizePixels;
    out.push_back(std::move(t));
  }
  return out;
}

}  // namespace sprig
