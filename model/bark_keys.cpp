#include "model/bark_keys.h"

#include <string>

namespace sprig {

void readBarkLook(MapReader& m, textures::BarkLook& look) {
  // The branch bark ridge on PCM seams.
  look.ridgeDarkening = m.number("ridge_darkening", look.ridgeDarkening, 0.0, 1.0);
  look.ridgeLines = static_cast<int>(m.integer("ridge_lines", look.ridgeLines, 0, 64));
  look.ridgeRelief = m.number("ridge_relief", look.ridgeRelief, 0.0, 4.0);

  // The arcs over branches.
  textures::RidgeArcOptions& arc = look.ridgeArc;
  arc.darkening = m.number("ridge_arc", arc.darkening, 0.0, 1.0);
  arc.relief = m.number("ridge_arc_relief", arc.relief, 0.0, 4.0);
  arc.rise = m.number("ridge_arc_rise", arc.rise, -10.0, 10.0);
  arc.droop = m.number("ridge_arc_droop", arc.droop, 0.0, 10.0);
  arc.spread = m.number("ridge_arc_spread", arc.spread, 0.1, 20.0);
  arc.width = m.number("ridge_arc_width", arc.width, 0.01, 5.0);
  arc.height = m.number("ridge_arc_height", arc.height, 0.0, 2.0);

  // The pattern.
  textures::BarkOptions& b = look.pattern;
  b.furrows = static_cast<int>(m.integer("furrows", b.furrows, 1, 1000));
  b.warp = m.number("warp", b.warp, 0.0, 100.0);
  b.alongFrequency = m.number("along_frequency", b.alongFrequency, 0.0, 1e4);
  b.sharpness = m.number("sharpness", b.sharpness, 1e-3, 100.0);
  b.grain = m.number("grain", b.grain, 0.0, 10.0);
  b.cracks = m.number("cracks", b.cracks, 0.0, 10.0);
  b.maturity = m.number("maturity", b.maturity, 0.0, 1.0);
  b.lenticels = m.number("lenticels", b.lenticels, 0.0, 1.0);
  b.lenticelFrequency = m.number("lenticel_frequency", b.lenticelFrequency, 0.0, 1e4);
  b.braid = m.number("braid", b.braid, -1e3, 1e3);
  b.peel = m.number("peel", b.peel, 0.0, 1.0);
  b.peelFrequency = m.number("peel_frequency", b.peelFrequency, 1e-3, 1e4);

  // The colours: unset ones keep the kind's defaults (BarkLook::resolved).
  auto optColor = [&m](std::string_view key, std::optional<Vec3>& out) {
    if (auto n = m.get(key))
      if (auto c = n->asColor(m.diagnostics(), "'" + std::string(key) + "'")) out = *c;
  };
  optColor("ridge_color", look.ridgeColor);
  optColor("furrow_color", look.furrowColor);
  optColor("young_color", look.youngColor);
  optColor("lenticel_color", look.lenticelColor);
  optColor("peel_color", look.peelColor);
}

}  // namespace sprig
