#pragma once
/// The bark keys of species files, read in one place for every kind that has bark:
/// `tree.bark` of a tree species and a `{bark: {...}}` texture of a blob species. Both read
/// the same key list, defaults and ranges here, so `sprig schema` lists the same bark keys
/// for both kinds and a key cannot drift between them.

#include "model/yaml_reader.h"
#include "textures/bark_look.h"

namespace sprig {

/// Reads the bark look keys of map m into look (present keys replace look's values, which
/// are the defaults): the pattern (`furrows`, `warp`, `along_frequency`, `sharpness`,
/// `grain`, `cracks`, `maturity`, `lenticels`, `lenticel_frequency`, `braid`, `peel`,
/// `peel_frequency`), the colours (`ridge_color`, `furrow_color`, `young_color`,
/// `lenticel_color`, `peel_color`), the ridge on PCM seams (`ridge_darkening`,
/// `ridge_lines`, `ridge_relief`) and the arcs over branches (`ridge_arc`,
/// `ridge_arc_relief`, `ridge_arc_rise`, `ridge_arc_droop`, `ridge_arc_spread`,
/// `ridge_arc_width`, and `ridge_arc_height`: the arc raised as geometry). Values out of range and wrong types are reported to m's diagnostics
/// at their `file:line:col`. The caller reads its kind's own keys and calls m.finish().
void readBarkLook(MapReader& m, textures::BarkLook& look);

}  // namespace sprig
