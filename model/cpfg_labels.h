#pragma once
/// cpfg's `@L` labels as the renderer writes them (render::TextLabel): the turtle's text at
/// its position, coloured by the colour map and set in the view file's `font:`, as cpfg's
/// window draws them (platformQt.cpp, DrawString): docs/GRAMMAR.md, "Labels".

#include <string>
#include <vector>

#include "lsystem/skeleton.h"
#include "model/species.h"
#include "render/geometry.h"

namespace sprig {

/// Folder of the label fonts (Debian's fonts-dejavu-core and fonts-dejavu-extra).
inline constexpr const char* kLabelFontFolder = "/usr/share/fonts/truetype/dejavu";

/// A label font: a TrueType file and its size in pixels.
struct LabelFont {
  std::string file;
  int sizePixels = 16;
};

/// The font Sprig sets a cpfg `font:` line in (an X11 name; empty: cpfg's default
/// `-*-courier-bold-r-*-*-12-*-...`), read as cpfg's Qt window reads it: fields split at
/// `-` (an empty one read as `*`), the size field 7 taken as points (field 6 when field 7
/// is not in (0, 100]; 12 when neither is), weight bold, black or medium as bold, slant
/// `italic` as italic, the family (field 2, `_` read as a space) matched to DejaVu: Sans
/// Mono for courier and other fixed-width names, Serif for times and other serif names,
/// Sans otherwise (`*` too: Qt's default family). Points become pixels at 96 per inch
/// (12 pt: 16 px). A name of fewer than 8 fields: Qt's default font, Sans at 9 pt.
LabelFont cpfgLabelFont(const std::string& xlfd);

/// The labels of skeleton, as style colours and sets them: each label's colour is its
/// colour index's palette entry (the colour map's bytes, shown as they are), black without
/// one; the font is cpfgLabelFont(style.cpfgFont).
std::vector<render::TextLabel> cpfgLabels(const lsystem::Skeleton& skeleton, const SkeletonStyle& style);

}  // namespace sprig
