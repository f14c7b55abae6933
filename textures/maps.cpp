#include "textures/maps.h"

namespace sprig::textures {

std::vector<MapSpec> shippedMaps() {
  std::vector<MapSpec> maps;

  BarkOptions bark;
  bark.furrows = 8;
  bark.warp = 0.7;
  bark.alongFrequency = 2.0;
  bark.sharpness = 2.2;
  bark.seed = 1;
  bark.tileV = 1;  // the map tiles in v too
  maps.push_back({"bark.png", 512, BarkTexture(bark),
                  "ridged bark, 8 furrows around; tiles in u and v"});

  StripesOptions stripes;
  stripes.frequency = 9;
  stripes.duty = 0.35;
  stripes.wobble = 0.12;
  stripes.softness = 0.06;
  stripes.seed = 2;
  maps.push_back({"shell_stripes.png", 512, StripesTexture(stripes),
                  "wavy brown growth lines on a cream shell"});

  SpotsOptions spots;
  spots.frequency = 7;
  spots.radius = 0.28;
  spots.seed = 3;
  maps.push_back({"shell_spots.png", 512, SpotsTexture(spots), "brown spots on a cream shell"});

  LeafOptions leaf;
  leaf.seed = 4;
  maps.push_back({"leaf.png", 512, LeafTexture(leaf),
                  "leaf blade: midrib at u = 0.5, lateral veins toward the tip (v = 1)"});
  return maps;
}

}  // namespace sprig::textures
