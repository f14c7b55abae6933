#include "textures/maps.h"

namespace sprig::textures {

std::vector<MapSpec> shippedMaps() {
  // Options name only what differs from their defaults (designated, in declaration order).
  return {
      {"bark.png", 512,
       BarkTexture({.furrows = 8, .warp = 0.7, .alongFrequency = 2.0, .sharpness = 2.2, .tileV = 1, .seed = 1}),
       "ridged bark, 8 furrows around; tiles in u and v"},
      {"shell_stripes.png", 512,
       StripesTexture({.frequency = 9, .duty = 0.35, .wobble = 0.12, .softness = 0.06, .seed = 2}),
       "wavy brown growth lines on a cream shell"},
      {"shell_spots.png", 512, SpotsTexture({.frequency = 7, .radius = 0.28, .seed = 3}),
       "brown spots on a cream shell"},
      {"leaf.png", 512, LeafTexture({.seed = 4}),
       "leaf blade: midrib at u = 0.5, lateral veins toward the tip (v = 1)"},
  };
}

}  // namespace sprig::textures
