#include "model/bark_keys.h"

#include <string>

namespace sprig {

void readBarkLook(MapReader& m, textures::BarkLook& look) {
  // The branch bark ridge on PCM seams.
  look.ridgeDarkening = m.number({"ridge_darkening", "Darkening of the bark on PCM seams (the branch bark ridge), 0 to 1."}, look.ridgeDarkening, 0.0, 1.0);
  look.ridgeLines = static_cast<int>(m.integer({"ridge_lines", "Folds of bunched bark across the ridge's band, parallel to the seam."}, look.ridgeLines, 0, 64));
  look.ridgeRelief = m.number({"ridge_relief", "The ridge's shading relief (normal tilt; slope 1.5 · relief on the flanks)."}, look.ridgeRelief, 0.0, 4.0);

  // The arcs over branches.
  textures::RidgeArcOptions& arc = look.ridgeArc;
  arc.darkening = m.number({"ridge_arc", "Darkening of the arc over each branch (0: no arc unless `ridge_arc_relief`)."}, arc.darkening, 0.0, 1.0);
  arc.relief = m.number({"ridge_arc_relief", "The arc's shading relief (slope up to 1.54 · relief)."}, arc.relief, 0.0, 4.0);
  arc.rise = m.number({"ridge_arc_rise", "The arc's apex above the branch's footprint, in branch radii."}, arc.rise, -10.0, 10.0);
  arc.droop = m.number({"ridge_arc_droop", "Slope of the arc's arms, in branch radii."}, arc.droop, 0.0, 10.0);
  arc.spread = m.number({"ridge_arc_spread", "The arc's half-length around the parent, in branch radii."}, arc.spread, 0.1, 20.0);
  arc.width = m.number({"ridge_arc_width", "The arc's half-width, in branch radii."}, arc.width, 0.01, 5.0);
  arc.height = m.number({"ridge_arc_height", "The arc raised as geometry: the wood over its crest higher by this many branch radii at the apex (0: no geometry)."}, arc.height, 0.0, 2.0);

  // The pattern.
  textures::BarkOptions& b = look.pattern;
  b.furrows = static_cast<int>(m.integer({"furrows", "Ridges around a branch when `ridge_width` is 0."}, b.furrows, 1, 1000));
  b.warp = m.number({"warp", "Sideways wander of the furrows, in ridge widths."}, b.warp, 0.0, 100.0);
  b.alongFrequency = m.number({"along_frequency", "Noise features per unit of v along the branch (plates 1/(1.5 · this) long)."}, b.alongFrequency, 0.0, 1e4);
  b.sharpness = m.number({"sharpness", "Ridge profile exponent (above 1: narrow furrows)."}, b.sharpness, 1e-3, 100.0);
  b.grain = m.number({"grain", "Fine lengthwise grain."}, b.grain, 0.0, 10.0);
  b.cracks = m.number({"cracks", "Depth of the cross cracks of mature bark."}, b.cracks, 0.0, 10.0);
  b.maturity = m.number({"maturity", "Bark age, 0 (smooth young bark) to 1 (fully furrowed), when `mature_radius` is 0."}, b.maturity, 0.0, 1.0);
  b.lenticels = m.number({"lenticels", "Share of lenticel cells holding a lenticel, 0 to 1."}, b.lenticels, 0.0, 1.0);
  b.lenticelFrequency = m.number({"lenticel_frequency", "Lenticel rows per unit of v."}, b.lenticelFrequency, 0.0, 1e4);
  b.braid = m.number({"braid", "Braided furrows: a second set drifting the other way by this many ridge widths per unit of v (long lens-shaped ridges)."}, b.braid, -1e3, 1e3);
  b.peel = m.number({"peel", "Peeling bark: share of old bark (`peel_color`) still on at maturity 1, over the fresh bark below."}, b.peel, 0.0, 1.0);
  b.peelFrequency = m.number({"peel_frequency", "Peeling patches per unit of v."}, b.peelFrequency, 1e-3, 1e4);

  // The colours: unset ones keep the kind's defaults (BarkLook::resolved).
  auto optColor = [&m](Key key, std::optional<Vec3>& out) {
    if (auto n = m.get(key))
      if (auto c = n->asColor(m.diagnostics(), "'" + std::string(key.name) + "'")) out = *c;
  };
  optColor({"ridge_color", "Colour of the bark ridges (default: the kind's wood colour)."}, look.ridgeColor);
  optColor({"furrow_color", "Colour of the furrows between ridges (default: 0.3 × the ridge colour)."}, look.furrowColor);
  optColor({"young_color", "Colour of young, smooth bark (default: the ridge colour)."}, look.youngColor);
  optColor({"lenticel_color", "Colour of the lenticels."}, look.lenticelColor);
  optColor({"peel_color", "Colour of the old, peeling bark."}, look.peelColor);
}

}  // namespace sprig
