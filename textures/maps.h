#pragma once
/// The texture images Sprig ships in textures/maps/, and how each is made.
///
/// Every map is a procedural texture baked at its size (registry.h bake) and written as
/// 8-bit sRGB PNG. The test suite re-bakes them and compares with the files, so the files
/// always are Sprig's own, current output; `test_textures "[.maps]"` regenerates them.

#include <string>
#include <vector>

#include "textures/registry.h"

namespace sprig::textures {

/// One shipped map: file name under textures/maps/, square size in pixels, texture.
struct MapSpec {
  std::string file;
  int size = 512;
  Texture texture;
  std::string description;
};

/// bark.png, shell_stripes.png, shell_spots.png, leaf.png.
std::vector<MapSpec> shippedMaps();

}  // namespace sprig::textures
